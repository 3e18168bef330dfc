/* recon_clean.c - mesh cleaning for reconstructed surfaces: edge
 * statistics, the largest connected component, hole filling by fans and
 * simplification by quadric error edge collapse. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/recon_geom.h"

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return x < y ? -1 : x > y;
}

static uint64_t edge_key(uint32_t a, uint32_t b) {
  return a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
}

void hearth_mesh_edge_stats(const hearth_mesh *m, size_t *n_boundary, size_t *n_nonmanifold) {
  size_t nb = 0, nn = 0, ne = 3 * m->n_triangles;
  uint64_t *e = malloc((ne ? ne : 1) * sizeof *e);
  if (e) {
    for (size_t t = 0; t < m->n_triangles; t++)
      for (int c = 0; c < 3; c++)
        e[3 * t + c] = edge_key(m->indices[3 * t + c], m->indices[3 * t + (c + 1) % 3]);
    qsort(e, ne, sizeof *e, cmp_u64);
    for (size_t i = 0; i < ne;) {
      size_t j = i;
      while (j < ne && e[j] == e[i]) j++;
      if (j - i == 1) nb++;
      if (j - i > 2) nn++;
      i = j;
    }
  }
  free(e);
  if (n_boundary) *n_boundary = nb;
  if (n_nonmanifold) *n_nonmanifold = nn;
}

static uint32_t uf_find(uint32_t *p, uint32_t x) {
  while (p[x] != x) {
    p[x] = p[p[x]];
    x = p[x];
  }
  return x;
}

/* Keep the triangles with keep[t] set and the vertices they use. */
static hearth_status compact(hearth_mesh *m, const uint8_t *keep, hearth_err *err) {
  uint32_t *remap = malloc((m->n_vertices ? m->n_vertices : 1) * sizeof *remap);
  if (!remap) return hearth_err_set(err, HEARTH_E_NOMEM, "mesh compact");
  for (size_t v = 0; v < m->n_vertices; v++) remap[v] = UINT32_MAX;
  size_t nt = 0, nv = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    if (!keep[t]) continue;
    for (int c = 0; c < 3; c++) {
      uint32_t v = m->indices[3 * t + c];
      if (remap[v] == UINT32_MAX) {
        remap[v] = (uint32_t)nv;
        nv++;
      }
      m->indices[3 * nt + c] = remap[v];
    }
    nt++;
  }
  /* move positions in order of their new index (new <= old always) */
  float *np = malloc((nv ? nv : 1) * 3 * sizeof *np);
  if (!np) {
    free(remap);
    return hearth_err_set(err, HEARTH_E_NOMEM, "mesh compact");
  }
  for (size_t v = 0; v < m->n_vertices; v++)
    if (remap[v] != UINT32_MAX) memcpy(np + 3 * (size_t)remap[v], m->positions + 3 * v, 12);
  free(m->positions);
  m->positions = np;
  free(m->uvs);
  m->uvs = NULL;
  m->n_vertices = nv;
  m->n_triangles = nt;
  free(remap);
  return HEARTH_OK;
}

hearth_status hearth_mesh_keep_largest(hearth_mesh *m, hearth_err *err) {
  if (!m->n_triangles) return HEARTH_OK;
  uint32_t *par = malloc(m->n_vertices * sizeof *par);
  size_t *count = calloc(m->n_vertices, sizeof *count);
  uint8_t *keep = malloc(m->n_triangles);
  if (!par || !count || !keep) {
    free(par);
    free(count);
    free(keep);
    return hearth_err_set(err, HEARTH_E_NOMEM, "mesh components");
  }
  for (size_t v = 0; v < m->n_vertices; v++) par[v] = (uint32_t)v;
  for (size_t t = 0; t < m->n_triangles; t++) {
    uint32_t a = uf_find(par, m->indices[3 * t]);
    for (int c = 1; c < 3; c++) {
      uint32_t b = uf_find(par, m->indices[3 * t + c]);
      if (a != b) par[b] = a;
    }
  }
  size_t best = 0;
  uint32_t best_root = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    uint32_t r = uf_find(par, m->indices[3 * t]);
    if (++count[r] > best) {
      best = count[r];
      best_root = r;
    }
  }
  for (size_t t = 0; t < m->n_triangles; t++) {
    const uint32_t *f = m->indices + 3 * t;
    keep[t] = uf_find(par, f[0]) == best_root && f[0] != f[1] && f[1] != f[2] && f[0] != f[2];
  }
  hearth_status s = compact(m, keep, err);
  free(par);
  free(count);
  free(keep);
  return s;
}

/* ---- hole filling ---------------------------------------------------------- */
/* Close the boundary loop loop[0..n) (each loop[q] -> loop[q+1] a boundary
 * edge used forwards by its triangle) with a fan around its centroid. */
static hearth_status fan_fill(hearth_mesh *m, const uint32_t *loop, size_t n, hearth_err *err) {
  size_t nv = m->n_vertices, nt = m->n_triangles;
  float *np = realloc(m->positions, (nv + 1) * 3 * sizeof *np);
  if (!np) return hearth_err_set(err, HEARTH_E_NOMEM, "fill holes");
  m->positions = np;
  uint32_t *ni = realloc(m->indices, (nt + n) * 3 * sizeof *ni);
  if (!ni) return hearth_err_set(err, HEARTH_E_NOMEM, "fill holes");
  m->indices = ni;
  double c[3] = {0, 0, 0};
  for (size_t q = 0; q < n; q++)
    for (int a = 0; a < 3; a++) c[a] += np[3 * (size_t)loop[q] + a] / (double)n;
  for (int a = 0; a < 3; a++) np[3 * nv + a] = (float)c[a];
  for (size_t q = 0; q < n; q++) {
    ni[3 * (nt + q)] = loop[(q + 1) % n];
    ni[3 * (nt + q) + 1] = loop[q];
    ni[3 * (nt + q) + 2] = (uint32_t)nv;
  }
  m->n_vertices = nv + 1;
  m->n_triangles = nt + n;
  return HEARTH_OK;
}

/* 1 if the loop loop[0..n) is to be closed under rule r */
static int loop_closes(const hearth_mesh *m, const uint32_t *loop, size_t n,
                       const hearth_hole_rule *r) {
  if (n > r->max_edges) return 0;
  if (n <= r->small_edges) return 1;
  double d = 0;
  for (size_t q = 0; q < n; q++) {
    const float *p = m->positions + 3 * (size_t)loop[q];
    d += r->plane[0] * p[0] + r->plane[1] * p[1] + r->plane[2] * p[2] + r->plane[3];
  }
  return fabs(d / (double)n) <= r->tol_m;
}

hearth_status hearth_mesh_fill_holes(hearth_mesh *m, size_t max_edges, size_t *n_filled,
                                     hearth_err *err) {
  const hearth_hole_rule r = {max_edges, max_edges, {0, 0, 0, 0}, 0};
  return hearth_mesh_fill_holes_near(m, &r, n_filled, NULL, err);
}

/* Walk m's boundary loops: those rule closes are closed in `fill` (m
   itself, or NULL to only count); *filled, *open and *open_edges receive
   the loops closed, the loops of 3 or more edges left open and their
   edges. */
static hearth_status boundary_walk(const hearth_mesh *m, hearth_mesh *fill,
                                   const hearth_hole_rule *rule, size_t *n_filled, size_t *n_open,
                                   size_t *n_open_edges, hearth_err *err) {
  *n_filled = *n_open = *n_open_edges = 0;
  size_t ne = 3 * m->n_triangles;
  if (!ne) return HEARTH_OK;
  uint64_t *und = malloc(ne * sizeof *und);
  uint64_t *dir = malloc(ne * sizeof *dir);
  if (!und || !dir) {
    free(und);
    free(dir);
    return hearth_err_set(err, HEARTH_E_NOMEM, "fill holes");
  }
  for (size_t t = 0; t < m->n_triangles; t++)
    for (int c = 0; c < 3; c++) {
      uint32_t a = m->indices[3 * t + c], b = m->indices[3 * t + (c + 1) % 3];
      und[3 * t + c] = edge_key(a, b);
    }
  qsort(und, ne, sizeof *und, cmp_u64);
  /* boundary half-edges: directed edges whose undirected edge occurs once */
  size_t nb = 0;
  for (size_t t = 0; t < m->n_triangles; t++)
    for (int c = 0; c < 3; c++) {
      uint32_t a = m->indices[3 * t + c], b = m->indices[3 * t + (c + 1) % 3];
      uint64_t k = edge_key(a, b);
      uint64_t *hit = bsearch(&k, und, ne, sizeof *und, cmp_u64);
      size_t lo = (size_t)(hit - und), hi = lo;
      while (lo > 0 && und[lo - 1] == k) lo--;
      while (hi + 1 < ne && und[hi + 1] == k) hi++;
      if (hi == lo) dir[nb++] = (uint64_t)a << 32 | b;
    }
  free(und);
  qsort(dir, nb, sizeof *dir, cmp_u64);
  uint8_t *used = calloc(nb ? nb : 1, 1);
  uint32_t *loop = malloc((nb ? nb : 1) * sizeof *loop);
  hearth_status s = HEARTH_OK;
  if (!used || !loop) s = hearth_err_set(err, HEARTH_E_NOMEM, "fill holes");
  size_t filled = 0, open = 0, open_edges = 0;
  uint32_t *at = malloc((m->n_vertices ? m->n_vertices : 1) * sizeof *at);
  if (!at && !s) s = hearth_err_set(err, HEARTH_E_NOMEM, "fill holes");
  for (size_t v = 0; at && v < m->n_vertices; v++) at[v] = UINT32_MAX;
  for (size_t e0 = 0; e0 < nb && !s; e0++) {
    if (used[e0]) continue;
    /* walk boundary edges head to tail; whenever the walk comes back to a
     * vertex of its path, the path from there is a closed loop (two holes
     * touching at a vertex give two loops) */
    size_t n = 0, e = e0;
    for (;;) {
      used[e] = 1;
      uint32_t from = (uint32_t)(dir[e] >> 32), to = (uint32_t)dir[e];
      at[from] = (uint32_t)n;
      loop[n++] = from;
      if (at[to] != UINT32_MAX) {
        size_t j = at[to], len = n - j;
        if (len >= 3 && fill && loop_closes(m, loop + j, len, rule)) {
          if ((s = fan_fill(fill, loop + j, len, err))) break;
          filled++;
        } else if (len >= 3) {
          open++;
          open_edges += len;
        }
        for (size_t q = j; q < n; q++) at[loop[q]] = UINT32_MAX;
        n = j;
      }
      uint64_t k = (uint64_t)to << 32;
      size_t lo = 0, hi = nb;
      while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (dir[mid] < k) lo = mid + 1;
        else hi = mid;
      }
      size_t next = nb;
      for (size_t q = lo; q < nb && (uint32_t)(dir[q] >> 32) == to; q++)
        if (!used[q]) {
          next = q;
          break;
        }
      if (next == nb) break;
      e = next;
    }
    for (size_t q = 0; q < n; q++) at[loop[q]] = UINT32_MAX;
  }
  free(at);
  free(used);
  free(loop);
  free(dir);
  *n_filled = filled;
  *n_open = open;
  *n_open_edges = open_edges;
  return s;
}

hearth_status hearth_mesh_fill_holes_near(hearth_mesh *m, const hearth_hole_rule *rule,
                                          size_t *n_filled, size_t *n_open, hearth_err *err) {
  size_t filled, open, open_edges;
  hearth_status s = boundary_walk(m, m, rule, &filled, &open, &open_edges, err);
  if (m->uvs) {
    free(m->uvs);
    m->uvs = NULL;
  }
  if (n_filled) *n_filled = s ? 0 : filled;
  if (n_open) *n_open = s ? 0 : open;
  return s;
}

hearth_status hearth_mesh_open_loops(const hearth_mesh *m, size_t *n_loops, size_t *n_edges,
                                     hearth_err *err) {
  const hearth_hole_rule none = {0, 0, {0, 0, 0, 0}, 0};
  size_t filled, open, edges;
  hearth_status s = boundary_walk(m, NULL, &none, &filled, &open, &edges, err);
  if (n_loops) *n_loops = s ? 0 : open;
  if (n_edges) *n_edges = s ? 0 : edges;
  return s;
}

/* ---- quadric error simplification ------------------------------------------ */
typedef struct qentry {
  double cost;
  uint32_t u, v;
  uint32_t vu, vv; /* versions of u and v when computed */
} qentry;

typedef struct qheap {
  qentry *a;
  size_t n, cap;
} qheap;

static int heap_push(qheap *h, qentry e) {
  if (h->n == h->cap) {
    size_t nc = h->cap ? 2 * h->cap : 1024;
    qentry *na = realloc(h->a, nc * sizeof *na);
    if (!na) return -1;
    h->a = na;
    h->cap = nc;
  }
  size_t i = h->n++;
  while (i > 0) {
    size_t p = (i - 1) / 2;
    if (h->a[p].cost <= e.cost) break;
    h->a[i] = h->a[p];
    i = p;
  }
  h->a[i] = e;
  return 0;
}

static qentry heap_pop(qheap *h) {
  qentry top = h->a[0], last = h->a[--h->n];
  size_t i = 0;
  for (;;) {
    size_t l = 2 * i + 1, r = l + 1, m = i;
    double mc = last.cost;
    if (l < h->n && h->a[l].cost < mc) {
      m = l;
      mc = h->a[l].cost;
    }
    if (r < h->n && h->a[r].cost < mc) m = r;
    if (m == i) break;
    h->a[i] = h->a[m];
    i = m;
  }
  if (h->n) h->a[i] = last;
  return top;
}

typedef struct vlist {
  uint32_t *t;
  uint32_t n, cap;
} vlist;

static int vlist_add(vlist *l, uint32_t t) {
  if (l->n == l->cap) {
    uint32_t nc = l->cap ? 2 * l->cap : 8;
    uint32_t *nt = realloc(l->t, nc * sizeof *nt);
    if (!nt) return -1;
    l->t = nt;
    l->cap = nc;
  }
  l->t[l->n++] = t;
  return 0;
}

typedef struct simp {
  hearth_mesh *m;
  double *q;     /* 10 per vertex: a11 a12 a13 a14 a22 a23 a24 a33 a34 a44 */
  vlist *vt;     /* triangles of each vertex (may hold dead ones) */
  uint32_t *ver; /* version per vertex */
  uint8_t *dead_v, *dead_t;
  double *pos; /* working positions, double */
} simp;

static double q_eval(const double *q, const double p[3]) {
  double x = p[0], y = p[1], z = p[2];
  return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y +
         2 * q[5] * y * z + 2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
}

/* Best position for merging u and v; returns its cost. */
static double best_point(const simp *S, uint32_t u, uint32_t v, double p[3]) {
  double q[10];
  for (int i = 0; i < 10; i++) q[i] = S->q[10 * (size_t)u + i] + S->q[10 * (size_t)v + i];
  const double *pu = S->pos + 3 * (size_t)u, *pv = S->pos + 3 * (size_t)v;
  double A[9] = {q[0], q[1], q[2], q[1], q[4], q[5], q[2], q[5], q[7]};
  double b[3] = {-q[3], -q[6], -q[8]};
  double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
               A[2] * (A[3] * A[7] - A[4] * A[6]);
  double scale = fabs(A[0]) + fabs(A[4]) + fabs(A[8]);
  double len2 = 0;
  for (int a = 0; a < 3; a++) len2 += (pu[a] - pv[a]) * (pu[a] - pv[a]);
  if (scale > 0 && fabs(det) > 1e-9 * scale * scale * scale) {
    double x[3];
    x[0] = (b[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (b[1] * A[8] - A[5] * b[2]) +
            A[2] * (b[1] * A[7] - A[4] * b[2])) /
           det;
    x[1] = (A[0] * (b[1] * A[8] - A[5] * b[2]) - b[0] * (A[3] * A[8] - A[5] * A[6]) +
            A[2] * (A[3] * b[2] - b[1] * A[6])) /
           det;
    x[2] = (A[0] * (A[4] * b[2] - b[1] * A[7]) - A[1] * (A[3] * b[2] - b[1] * A[6]) +
            b[0] * (A[3] * A[7] - A[4] * A[6])) /
           det;
    double d2 = 0;
    for (int a = 0; a < 3; a++) {
      double mid = 0.5 * (pu[a] + pv[a]);
      d2 += (x[a] - mid) * (x[a] - mid);
    }
    if (d2 <= len2) {
      memcpy(p, x, sizeof x);
      return q_eval(q, p);
    }
  }
  double mid[3], best = q_eval(q, pu);
  memcpy(p, pu, 3 * sizeof *p);
  for (int a = 0; a < 3; a++) mid[a] = 0.5 * (pu[a] + pv[a]);
  double c = q_eval(q, pv);
  if (c < best) {
    best = c;
    memcpy(p, pv, 3 * sizeof *p);
  }
  c = q_eval(q, mid);
  if (c < best) {
    best = c;
    memcpy(p, mid, 3 * sizeof *p);
  }
  return best;
}

static int push_edge(simp *S, qheap *h, uint32_t u, uint32_t v) {
  double p[3];
  qentry e = {best_point(S, u, v, p), u, v, S->ver[u], S->ver[v]};
  return heap_push(h, e);
}

static void tri_normal(const double *a, const double *b, const double *c, double n[3]) {
  double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* 1 if merging v into u at p keeps the mesh manifold and flips nothing. */
static int collapse_ok(const simp *S, uint32_t u, uint32_t v, const double p[3]) {
  const uint32_t *ix = S->m->indices;
  /* link condition: the vertices adjacent to both are exactly the
   * apexes of the triangles on edge uv */
  uint32_t nbr_u[256];
  size_t nu = 0, shared_tris = 0, common = 0;
  for (uint32_t k = 0; k < S->vt[u].n; k++) {
    uint32_t t = S->vt[u].t[k];
    if (S->dead_t[t]) continue;
    int has_v = 0;
    for (int c = 0; c < 3; c++) has_v |= ix[3 * t + c] == v;
    shared_tris += has_v;
    for (int c = 0; c < 3; c++) {
      uint32_t w = ix[3 * t + c];
      if (w == u) continue;
      size_t q;
      for (q = 0; q < nu && nbr_u[q] != w; q++) {}
      if (q == nu) {
        if (nu == 256) return 0;
        nbr_u[nu++] = w;
      }
    }
  }
  if (shared_tris != 2) return 0;
  uint32_t seen[256];
  size_t ns = 0;
  for (uint32_t k = 0; k < S->vt[v].n; k++) {
    uint32_t t = S->vt[v].t[k];
    if (S->dead_t[t]) continue;
    for (int c = 0; c < 3; c++) {
      uint32_t w = ix[3 * t + c];
      if (w == v || w == u) continue;
      size_t q;
      for (q = 0; q < ns && seen[q] != w; q++) {}
      if (q < ns) continue;
      if (ns == 256) return 0;
      seen[ns++] = w;
      for (q = 0; q < nu; q++)
        if (nbr_u[q] == w) common++;
    }
  }
  if (common != 2) return 0;
  /* no triangle of u or v (other than the two removed) may flip or
   * degenerate */
  for (int side = 0; side < 2; side++) {
    uint32_t x = side ? v : u;
    for (uint32_t k = 0; k < S->vt[x].n; k++) {
      uint32_t t = S->vt[x].t[k];
      if (S->dead_t[t]) continue;
      const uint32_t *f = ix + 3 * t;
      if ((f[0] == u || f[1] == u || f[2] == u) && (f[0] == v || f[1] == v || f[2] == v)) continue;
      const double *P[3], *Q[3];
      for (int c = 0; c < 3; c++) {
        P[c] = S->pos + 3 * (size_t)f[c];
        Q[c] = (f[c] == u || f[c] == v) ? p : P[c];
      }
      double n0[3], n1[3];
      tri_normal(P[0], P[1], P[2], n0);
      tri_normal(Q[0], Q[1], Q[2], n1);
      double d = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2];
      double l0 = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
      double l1 = sqrt(n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]);
      if (!(l1 > 1e-3 * l0) || d < 0.2 * l0 * l1) return 0;
    }
  }
  return 1;
}

hearth_status hearth_mesh_simplify(hearth_mesh *m, size_t target, hearth_err *err) {
  if (m->n_triangles <= target) return HEARTH_OK;
  size_t nv = m->n_vertices, nt = m->n_triangles;
  simp S = {m};
  S.q = calloc(10 * nv, sizeof *S.q);
  S.vt = calloc(nv, sizeof *S.vt);
  S.ver = calloc(nv, sizeof *S.ver);
  S.dead_v = calloc(nv, 1);
  S.dead_t = calloc(nt, 1);
  S.pos = malloc(3 * nv * sizeof *S.pos);
  qheap h = {0};
  hearth_status s = HEARTH_OK;
  if (!S.q || !S.vt || !S.ver || !S.dead_v || !S.dead_t || !S.pos) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "simplify: %zu vertices", nv);
    goto done;
  }
  for (size_t i = 0; i < 3 * nv; i++) S.pos[i] = m->positions[i];
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *f = m->indices + 3 * t;
    double n[3];
    tri_normal(S.pos + 3 * (size_t)f[0], S.pos + 3 * (size_t)f[1], S.pos + 3 * (size_t)f[2], n);
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int c = 0; c < 3; c++)
      if (vlist_add(&S.vt[f[c]], (uint32_t)t)) {
        s = hearth_err_set(err, HEARTH_E_NOMEM, "simplify");
        goto done;
      }
    if (!(l > 0)) continue;
    /* plane n.x + d = 0, weighted by the triangle's area */
    double a = n[0] / l, b = n[1] / l, c = n[2] / l;
    const double *p0 = S.pos + 3 * (size_t)f[0];
    double d = -(a * p0[0] + b * p0[1] + c * p0[2]), w = 0.5 * l;
    double pq[10] = {a * a, a * b, a * c, a * d, b * b, b * c, b * d, c * c, c * d, d * d};
    for (int k = 0; k < 3; k++)
      for (int i = 0; i < 10; i++) S.q[10 * (size_t)f[k] + i] += w * pq[i];
  }
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *f = m->indices + 3 * t;
    for (int c = 0; c < 3; c++) {
      uint32_t a = f[c], b = f[(c + 1) % 3];
      if (a < b && push_edge(&S, &h, a, b)) {
        s = hearth_err_set(err, HEARTH_E_NOMEM, "simplify");
        goto done;
      }
    }
  }
  size_t alive = nt;
  while (alive > target && h.n) {
    qentry e = heap_pop(&h);
    uint32_t u = e.u, v = e.v;
    if (S.dead_v[u] || S.dead_v[v] || S.ver[u] != e.vu || S.ver[v] != e.vv) continue;
    double p[3];
    best_point(&S, u, v, p);
    if (!collapse_ok(&S, u, v, p)) continue;
    /* merge v into u */
    for (uint32_t k = 0; k < S.vt[v].n; k++) {
      uint32_t t = S.vt[v].t[k];
      if (S.dead_t[t]) continue;
      uint32_t *f = m->indices + 3 * (size_t)t;
      if (f[0] == u || f[1] == u || f[2] == u) {
        S.dead_t[t] = 1;
        alive--;
        continue;
      }
      for (int c = 0; c < 3; c++)
        if (f[c] == v) f[c] = u;
      if (vlist_add(&S.vt[u], t)) {
        s = hearth_err_set(err, HEARTH_E_NOMEM, "simplify");
        goto done;
      }
    }
    S.dead_v[v] = 1;
    for (int a = 0; a < 3; a++) S.pos[3 * (size_t)u + a] = p[a];
    for (int i = 0; i < 10; i++) S.q[10 * (size_t)u + i] += S.q[10 * (size_t)v + i];
    S.ver[u]++;
    /* drop dead triangles from u's list and queue u's edges again */
    uint32_t w = 0;
    for (uint32_t k = 0; k < S.vt[u].n; k++)
      if (!S.dead_t[S.vt[u].t[k]]) S.vt[u].t[w++] = S.vt[u].t[k];
    S.vt[u].n = w;
    for (uint32_t k = 0; k < S.vt[u].n; k++) {
      const uint32_t *f = m->indices + 3 * (size_t)S.vt[u].t[k];
      for (int c = 0; c < 3; c++) {
        if (f[c] == u) continue;
        /* each neighbour appears in two triangles; queue it from one */
        if (f[(c + 2) % 3] == u && push_edge(&S, &h, u, f[c])) {
          s = hearth_err_set(err, HEARTH_E_NOMEM, "simplify");
          goto done;
        }
      }
    }
  }
  for (size_t i = 0; i < 3 * nv; i++) m->positions[i] = (float)S.pos[i];
  {
    uint8_t *keep = malloc(nt);
    if (!keep) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "simplify");
      goto done;
    }
    for (size_t t = 0; t < nt; t++) keep[t] = !S.dead_t[t];
    s = compact(m, keep, err);
    free(keep);
  }
done:
  if (S.vt)
    for (size_t i = 0; i < nv; i++) free(S.vt[i].t);
  free(S.q);
  free(S.vt);
  free(S.ver);
  free(S.dead_v);
  free(S.dead_t);
  free(S.pos);
  free(h.a);
  return s;
}
