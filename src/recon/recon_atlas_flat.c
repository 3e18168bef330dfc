/* recon_atlas_flat.c - one chart of the UV atlas: the disc test and the LSCM
 * flattening with its fold and overlap checks (recon_atlas_pack.c packs
 * the charts). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "recon_atlas.h"

#define NO_ID UINT32_MAX

void ra_chart_free(atlas_chart *c) {
  if (!c) return;
  free(c->face), free(c->vertex), free(c->corner), free(c->uv);
  memset(c, 0, sizeof *c);
}

void ra_flat_scratch_free(ra_flat_scratch *s) {
  if (!s) return;
  free(s->vmap), free(s->fmark);
  memset(s, 0, sizeof *s);
}

static uint32_t uf_find(uint32_t *p, uint32_t a) {
  while (p[a] != a) a = p[a] = p[p[a]];
  return a;
}

/* 1 when the chart (faces marked with stamp st, corners in chart
 * vertices) is a topological disc: every edge used once (boundary) or
 * twice (interior) within it, every vertex on 0 or 2 boundary edges, one
 * boundary loop, V - E + F = 1. Connectedness is the caller's. -1 without
 * memory. */
static int is_disc(const uint32_t *adj, const uint32_t *fmark, uint32_t st, const uint32_t *faces,
                   const uint32_t *corner, size_t n, size_t nv) {
  uint32_t *deg = calloc(nv, sizeof *deg), *par = malloc(nv * sizeof *par);
  if (!deg || !par) {
    free(deg), free(par);
    return -1;
  }
  for (size_t v = 0; v < nv; v++) par[v] = (uint32_t)v;
  size_t n_int = 0, n_bnd = 0;
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      uint32_t nb = adj[3 * (size_t)faces[i] + k];
      if (nb != NO_ID && fmark[nb] == st) {
        n_int++;
        continue;
      }
      n_bnd++;
      uint32_t a = corner[3 * i + k], b = corner[3 * i + (k + 1) % 3];
      deg[a]++, deg[b]++;
      a = uf_find(par, a), b = uf_find(par, b);
      if (a != b) par[a < b ? b : a] = a < b ? a : b;
    }
  int ok = n_bnd > 0 && n_int % 2 == 0;
  size_t loops = 0;
  for (size_t v = 0; ok && v < nv; v++) {
    if (deg[v] != 0 && deg[v] != 2) ok = 0;
    if (deg[v] && uf_find(par, (uint32_t)v) == v) loops++;
  }
  long chi = (long)nv - (long)(n_int / 2 + n_bnd) + (long)n;
  free(deg), free(par);
  return ok && loops == 1 && chi == 1;
}

/* the chart's sparse LSCM system: two rows per triangle, 6 entries each */
typedef struct lscm_sys {
  size_t n_rows;
  uint32_t *col; /* 6 per row */
  double *val;   /* 6 per row */
} lscm_sys;

/* y = A^T A x over all columns (ncol), pinned columns of the result zeroed */
static void normal_apply(const lscm_sys *A, const double *x, double *y, size_t ncol,
                         const uint32_t pin[4]) {
  memset(y, 0, ncol * sizeof *y);
  for (size_t r = 0; r < A->n_rows; r++) {
    const uint32_t *c = A->col + 6 * r;
    const double *v = A->val + 6 * r;
    double s = 0;
    for (int j = 0; j < 6; j++) s += v[j] * x[c[j]];
    for (int j = 0; j < 6; j++) y[c[j]] += v[j] * s;
  }
  for (int k = 0; k < 4; k++) y[pin[k]] = 0;
}

static double dotn(const double *a, const double *b, size_t n) {
  double s = 0;
  for (size_t i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* Preconditioned CG on A^T A x = 0 with the pinned entries of x fixed
 * (their values are x's on entry, the rest start from x too). Returns the
 * iterations taken, -1 without memory. */
static int lscm_solve(const lscm_sys *A, double *x, size_t ncol, const uint32_t pin[4],
                      int max_it) {
  double *r = malloc(ncol * sizeof *r), *z = malloc(ncol * sizeof *z),
         *p = malloc(ncol * sizeof *p), *q = malloc(ncol * sizeof *q),
         *dg = calloc(ncol, sizeof *dg);
  if (!r || !z || !p || !q || !dg) {
    free(r), free(z), free(p), free(q), free(dg);
    return -1;
  }
  for (size_t i = 0; i < A->n_rows * 6; i++) dg[A->col[i]] += A->val[i] * A->val[i];
  for (size_t i = 0; i < ncol; i++)
    if (!(dg[i] > 0)) dg[i] = 1;
  normal_apply(A, x, r, ncol, pin);
  for (size_t i = 0; i < ncol; i++) r[i] = -r[i];
  double r0 = sqrt(dotn(r, r, ncol));
  int it = 0;
  if (r0 > 0) {
    for (size_t i = 0; i < ncol; i++) p[i] = z[i] = r[i] / dg[i];
    double rz = dotn(r, z, ncol);
    for (; it < max_it; it++) {
      normal_apply(A, p, q, ncol, pin);
      double pq = dotn(p, q, ncol);
      if (!(pq > 0)) break;
      double alpha = rz / pq;
      for (size_t i = 0; i < ncol; i++) x[i] += alpha * p[i], r[i] -= alpha * q[i];
      if (sqrt(dotn(r, r, ncol)) <= 1e-9 * r0) {
        it++;
        break;
      }
      for (size_t i = 0; i < ncol; i++) z[i] = r[i] / dg[i];
      double rz1 = dotn(r, z, ncol);
      double beta = rz1 / rz;
      rz = rz1;
      for (size_t i = 0; i < ncol; i++) p[i] = z[i] + beta * p[i];
    }
  }
  free(r), free(z), free(p), free(q), free(dg);
  return it;
}

static void sub3(const float *a, const float *b, double o[3]) {
  for (int k = 0; k < 3; k++) o[k] = (double)a[k] - b[k];
}
static void cross3(const double a[3], const double b[3], double o[3]) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3v(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* the triangle in its own plane: q0 = 0, q1 on +x, q2 above; returns its area */
static double local_frame(const hearth_mesh *m, uint32_t f, double q[3][2]) {
  const uint32_t *ix = m->indices + 3 * (size_t)f;
  const float *p0 = m->positions + 3 * (size_t)ix[0], *p1 = m->positions + 3 * (size_t)ix[1],
              *p2 = m->positions + 3 * (size_t)ix[2];
  double e1[3], e2[3], n[3], y[3];
  sub3(p1, p0, e1);
  sub3(p2, p0, e2);
  double l1 = sqrt(dot3v(e1, e1));
  cross3(e1, e2, n);
  double ln = sqrt(dot3v(n, n));
  memset(q, 0, 6 * sizeof(double));
  if (!(l1 > 0) || !(ln > 0)) {
    q[1][0] = l1;
    q[2][0] = l1 > 0 ? dot3v(e2, e1) / l1 : sqrt(dot3v(e2, e2));
    return 0;
  }
  double x[3] = {e1[0] / l1, e1[1] / l1, e1[2] / l1};
  for (int k = 0; k < 3; k++) n[k] /= ln;
  cross3(n, x, y);
  q[1][0] = l1;
  q[2][0] = dot3v(e2, x);
  q[2][1] = dot3v(e2, y);
  return 0.5 * ln;
}

static double uv_area(const double *uv, const uint32_t *c) {
  const double *a = uv + 2 * (size_t)c[0], *b = uv + 2 * (size_t)c[1], *d = uv + 2 * (size_t)c[2];
  return 0.5 * ((b[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (b[1] - a[1]));
}

static double orient2(const double *a, const double *b, const double *c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* 1 when no two boundary edges of the flattened chart that share no vertex
 * meet (touching counts): with every triangle positively oriented, a
 * simple boundary makes the map one-to-one. -1 without memory. */
static int simple_boundary(const uint32_t *adj, const uint32_t *fmark, uint32_t st,
                           const uint32_t *faces, const uint32_t *corner, size_t n,
                           const double *uv) {
  uint32_t *seg = malloc(3 * n * 2 * sizeof *seg);
  if (!seg) return -1;
  size_t ns = 0;
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      uint32_t nb = adj[3 * (size_t)faces[i] + k];
      if (nb != NO_ID && fmark[nb] == st) continue;
      seg[2 * ns] = corner[3 * i + k], seg[2 * ns + 1] = corner[3 * i + (k + 1) % 3];
      ns++;
    }
  int ok = 1;
  for (size_t i = 0; i < ns && ok; i++) {
    const double *a = uv + 2 * (size_t)seg[2 * i], *b = uv + 2 * (size_t)seg[2 * i + 1];
    for (size_t j = i + 1; j < ns; j++) {
      if (seg[2 * j] == seg[2 * i] || seg[2 * j] == seg[2 * i + 1] ||
          seg[2 * j + 1] == seg[2 * i] || seg[2 * j + 1] == seg[2 * i + 1])
        continue;
      const double *c = uv + 2 * (size_t)seg[2 * j], *d = uv + 2 * (size_t)seg[2 * j + 1];
      if (fmax(a[0], b[0]) < fmin(c[0], d[0]) || fmax(c[0], d[0]) < fmin(a[0], b[0]) ||
          fmax(a[1], b[1]) < fmin(c[1], d[1]) || fmax(c[1], d[1]) < fmin(a[1], b[1]))
        continue;
      double o1 = orient2(a, b, c), o2 = orient2(a, b, d), o3 = orient2(c, d, a),
             o4 = orient2(c, d, b);
      if (o1 * o2 <= 0 && o3 * o4 <= 0) {
        ok = 0;
        break;
      }
    }
  }
  free(seg);
  return ok;
}

/* L2 stretch of triangle q (its own plane) mapped to UV triangle w */
static double tri_stretch(const double q[3][2], const double w[3][2]) {
  double au =
      0.5 * ((w[1][0] - w[0][0]) * (w[2][1] - w[0][1]) - (w[2][0] - w[0][0]) * (w[1][1] - w[0][1]));
  if (!(au > 0)) return INFINITY;
  double a = 0, c = 0;
  for (int k = 0; k < 2; k++) {
    double ss = (q[0][k] * (w[1][1] - w[2][1]) + q[1][k] * (w[2][1] - w[0][1]) +
                 q[2][k] * (w[0][1] - w[1][1])) /
                (2 * au);
    double sv = (q[0][k] * (w[2][0] - w[1][0]) + q[1][k] * (w[0][0] - w[2][0]) +
                 q[2][k] * (w[1][0] - w[0][0])) /
                (2 * au);
    a += ss * ss, c += sv * sv;
  }
  return sqrt(0.5 * (a + c));
}

/* LSCM of the chart's vertices; 0 done, 1 folded/overlapping, -1 memory */
static int flatten_lscm(const hearth_mesh *m, const uint32_t *adj, const uint32_t *fmark,
                        uint32_t st, const uint32_t *faces, size_t n, atlas_chart *ch,
                        const ra_flat_limits *lim) {
  const size_t nv = ch->n_vertices;
  /* the chart's mean plane and the start: projection onto it */
  double N[3] = {0, 0, 0};
  for (size_t i = 0; i < n; i++) {
    const uint32_t *ix = m->indices + 3 * (size_t)faces[i];
    double e1[3], e2[3], c[3];
    sub3(m->positions + 3 * (size_t)ix[1], m->positions + 3 * (size_t)ix[0], e1);
    sub3(m->positions + 3 * (size_t)ix[2], m->positions + 3 * (size_t)ix[0], e2);
    cross3(e1, e2, c);
    for (int k = 0; k < 3; k++) N[k] += c[k];
  }
  double ln = sqrt(dot3v(N, N));
  if (!(ln > 0)) return 1;
  for (int k = 0; k < 3; k++) N[k] /= ln;
  int least = 0;
  for (int k = 1; k < 3; k++)
    if (fabs(N[k]) < fabs(N[least])) least = k;
  double ax[3] = {0, 0, 0}, e1[3], e2[3];
  ax[least] = 1;
  cross3(N, ax, e1);
  double l1 = sqrt(dot3v(e1, e1));
  for (int k = 0; k < 3; k++) e1[k] /= l1;
  cross3(N, e1, e2);
  double *x = malloc(2 * nv * sizeof *x);
  if (!x) return -1;
  const float *o = m->positions + 3 * (size_t)ch->vertex[0];
  for (size_t v = 0; v < nv; v++) {
    double d[3];
    sub3(m->positions + 3 * (size_t)ch->vertex[v], o, d);
    x[2 * v] = dot3v(d, e1);
    x[2 * v + 1] = dot3v(d, e2);
  }
  /* pins: the extremes along the start's longer extent */
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (size_t v = 0; v < nv; v++)
    for (int k = 0; k < 2; k++)
      lo[k] = fmin(lo[k], x[2 * v + k]), hi[k] = fmax(hi[k], x[2 * v + k]);
  int a = hi[1] - lo[1] > hi[0] - lo[0];
  uint32_t p0 = 0, p1 = 0;
  for (size_t v = 1; v < nv; v++) {
    if (x[2 * v + a] < x[2 * (size_t)p0 + a]) p0 = (uint32_t)v;
    if (x[2 * v + a] > x[2 * (size_t)p1 + a]) p1 = (uint32_t)v;
  }
  if (p0 == p1) {
    free(x);
    return 1;
  }
  const uint32_t pin[4] = {2 * p0, 2 * p0 + 1, 2 * p1, 2 * p1 + 1};
  /* the system: sqrt(area) (dv/dx + du/dy, dv/dy - du/dx) per triangle */
  double a3_total = 0;
  lscm_sys A = {0};
  A.col = malloc(12 * n * sizeof *A.col);
  A.val = malloc(12 * n * sizeof *A.val);
  double *area = malloc(n * sizeof *area);
  if (!A.col || !A.val || !area) {
    free(x), free(A.col), free(A.val), free(area);
    return -1;
  }
  for (size_t i = 0; i < n; i++) {
    double q[3][2];
    area[i] = local_frame(m, faces[i], q);
    a3_total += area[i];
  }
  const double eps_area = 1e-10 * a3_total / (double)n;
  for (size_t i = 0; i < n; i++) {
    if (!(area[i] > eps_area)) continue;
    double q[3][2];
    local_frame(m, faces[i], q);
    double w = sqrt(area[i]), inv = 1.0 / (2 * area[i]);
    uint32_t *c1 = A.col + 6 * A.n_rows, *c2 = c1 + 6;
    double *v1 = A.val + 6 * A.n_rows, *v2 = v1 + 6;
    for (int j = 0; j < 3; j++) {
      const double *qa = q[(j + 1) % 3], *qb = q[(j + 2) % 3];
      double gx = -(qb[1] - qa[1]) * inv, gy = (qb[0] - qa[0]) * inv;
      uint32_t u = 2 * ch->corner[3 * i + j];
      c1[2 * j] = u, v1[2 * j] = w * gy;
      c1[2 * j + 1] = u + 1, v1[2 * j + 1] = w * gx;
      c2[2 * j] = u, v2[2 * j] = -w * gx;
      c2[2 * j + 1] = u + 1, v2[2 * j + 1] = w * gy;
    }
    A.n_rows += 2;
  }
  int it = lscm_solve(&A, x, 2 * nv, pin, lim->cg_max);
  free(A.col), free(A.val);
  if (it < 0) {
    free(x), free(area);
    return -1;
  }
  ch->cg_iterations = it;
  /* folds: every proper triangle keeps its orientation and some area */
  double auv = 0;
  for (size_t i = 0; i < n; i++)
    if (area[i] > eps_area) auv += uv_area(x, ch->corner + 3 * i);
  int ok = auv > 0 && a3_total > 0;
  double k2 = ok ? auv / a3_total : 0;
  for (size_t i = 0; i < n && ok; i++)
    if (area[i] > eps_area && !(uv_area(x, ch->corner + 3 * i) > 1e-6 * k2 * area[i])) ok = 0;
  if (!ok) {
    free(x), free(area);
    return 1;
  }
  double sc = sqrt(a3_total / auv);
  for (size_t i = 0; i < 2 * nv; i++) x[i] *= sc;
  /* distortion: the chart's L2 stretch and its worst triangle's */
  double sum = 0, worst = 0;
  for (size_t i = 0; i < n; i++) {
    if (!(area[i] > eps_area)) continue;
    double q[3][2], w[3][2];
    local_frame(m, faces[i], q);
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 2; k++) w[j][k] = x[2 * (size_t)ch->corner[3 * i + j] + k];
    double l2 = tri_stretch(q, w);
    sum += area[i] * l2 * l2;
    worst = fmax(worst, l2);
  }
  free(area);
  if (sqrt(sum / a3_total) > lim->max_chart_stretch || worst > lim->max_face_stretch) {
    free(x);
    return 1;
  }
  int r = simple_boundary(adj, fmark, st, faces, ch->corner, n, x);
  if (r != 1) {
    free(x);
    return r < 0 ? -1 : 1;
  }
  ch->uv = x;
  return 0;
}

int ra_chart_flatten(const hearth_mesh *m, const uint32_t *adj, const uint32_t *faces, size_t n,
                     const ra_flat_limits *lim, ra_flat_scratch *sc, atlas_chart *out) {
  memset(out, 0, sizeof *out);
  if (sc->nv < m->n_vertices || sc->nt < m->n_triangles) {
    ra_flat_scratch_free(sc);
    sc->vmap = malloc(m->n_vertices * sizeof *sc->vmap);
    sc->fmark = calloc(m->n_triangles, sizeof *sc->fmark);
    if (!sc->vmap || !sc->fmark) return -1;
    for (size_t v = 0; v < m->n_vertices; v++) sc->vmap[v] = NO_ID;
    sc->nv = m->n_vertices, sc->nt = m->n_triangles;
  }
  uint32_t st = ++sc->stamp;
  for (size_t i = 0; i < n; i++) sc->fmark[faces[i]] = st;
  out->face = malloc(n * sizeof *out->face);
  out->corner = malloc(3 * n * sizeof *out->corner);
  out->vertex = malloc(3 * n * sizeof *out->vertex);
  if (!out->face || !out->corner || !out->vertex) {
    ra_chart_free(out);
    return -1;
  }
  memcpy(out->face, faces, n * sizeof *faces);
  size_t nv = 0;
  for (size_t i = 0; i < n; i++)
    for (int j = 0; j < 3; j++) {
      uint32_t v = m->indices[3 * (size_t)faces[i] + j];
      if (sc->vmap[v] == NO_ID) sc->vmap[v] = (uint32_t)nv, out->vertex[nv++] = v;
      out->corner[3 * i + j] = sc->vmap[v];
    }
  for (size_t v = 0; v < nv; v++) sc->vmap[out->vertex[v]] = NO_ID;
  out->n_faces = n;
  out->n_vertices = nv;
  int r;
  if (n == 1 && nv == 3) {
    double q[3][2];
    local_frame(m, faces[0], q);
    out->uv = malloc(6 * sizeof *out->uv);
    if (!out->uv) r = -1;
    else {
      for (int j = 0; j < 3; j++)
        for (int k = 0; k < 2; k++) out->uv[2 * out->corner[j] + k] = q[j][k];
      r = 0;
    }
  } else {
    r = is_disc(adj, sc->fmark, st, faces, out->corner, n, nv);
    if (r == 1) r = flatten_lscm(m, adj, sc->fmark, st, faces, n, out, lim);
    else if (r == 0) r = n > 1 ? 1 : 0; /* a lone face with a repeated vertex: kept as it is */
    if (r == 0 && !out->uv) {
      out->uv = calloc(2 * nv, sizeof *out->uv);
      if (!out->uv) r = -1;
    }
  }
  if (r) ra_chart_free(out);
  return r;
}
