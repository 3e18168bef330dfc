/* recon_atlas.c - a UV atlas for a triangle mesh: charts by normal
 * clustering, cut until each is a disc that flattens without folds, LSCM
 * per chart, common texel density, shelf packing with gutters. See
 * hearth_mesh_atlas in hearth/recon_geom.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/recon_geom.h"
#include "recon_atlas.h"

void hearth_atlas_opts_default(hearth_atlas_opts *o) {
  memset(o, 0, sizeof *o);
  o->min_chart_faces = 8;
  o->kmeans_iterations = 4;
  o->smooth_passes = 3;
  o->texture_size = 1024;
  o->gutter_texels = 4;
  o->cg_max_iterations = 4000;
  o->max_chart_stretch = 1.1;
  o->max_face_stretch = 2;
}

#define NO_FACE UINT32_MAX

/* ---- face geometry and edge adjacency ------------------------------------ */
static void face_geometry(const hearth_mesh *m, size_t t, double n[3], double *area) {
  const uint32_t *ix = m->indices + 3 * t;
  const float *a = m->positions + 3 * (size_t)ix[0], *b = m->positions + 3 * (size_t)ix[1],
              *c = m->positions + 3 * (size_t)ix[2];
  double e1[3], e2[3];
  for (int k = 0; k < 3; k++) e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  *area = 0.5 * l;
  for (int k = 0; k < 3; k++) n[k] = l > 0 ? n[k] / l : 0;
}

typedef struct half_rec {
  uint32_t lo, hi;
  size_t corner; /* 3 * triangle + k: the edge from corner k to k+1 */
} half_rec;

static int half_cmp(const void *pa, const void *pb) {
  const half_rec *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  return a->corner < b->corner ? -1 : a->corner > b->corner;
}

/* adj[3t+k]: the triangle across edge k of t when exactly two triangles
 * use that edge, NO_FACE otherwise (boundary or non-manifold). */
static hearth_status build_adjacency(const hearth_mesh *m, uint32_t *adj, hearth_err *err) {
  size_t n = 3 * m->n_triangles;
  half_rec *h = hearth_alloc_array(n, sizeof *h);
  if (!h) return hearth_err_set(err, HEARTH_E_NOMEM, "atlas: adjacency");
  for (size_t c = 0; c < n; c++) {
    uint32_t a = m->indices[c], b = m->indices[c - c % 3 + (c % 3 + 1) % 3];
    h[c].lo = a < b ? a : b;
    h[c].hi = a < b ? b : a;
    h[c].corner = c;
    adj[c] = NO_FACE;
  }
  qsort(h, n, sizeof *h, half_cmp);
  for (size_t i = 0; i < n;) {
    size_t j = i + 1;
    while (j < n && h[j].lo == h[i].lo && h[j].hi == h[i].hi) j++;
    if (j - i == 2) {
      adj[h[i].corner] = (uint32_t)(h[i + 1].corner / 3);
      adj[h[i + 1].corner] = (uint32_t)(h[i].corner / 3);
    }
    i = j;
  }
  free(h);
  return HEARTH_OK;
}

/* ---- the work: a queue of face lists ------------------------------------- */
typedef struct atlas_ctx {
  const hearth_mesh *m;
  const hearth_atlas_opts *o;
  uint32_t *adj;
  double *centroid; /* 3 per face */
  uint32_t *mark;   /* per face: the stamp of the list it is in */
  uint32_t stamp;
  uint32_t *faces_buf; /* scratch for splits */
  double *key_buf;
  /* queue of lists: faces of list i are queue_faces[start[i] .. start[i+1]) */
  uint32_t *qfaces;
  size_t qn, qcap;
  size_t *qstart;
  size_t nlists, lcap;
  atlas_chart *charts;
  size_t n_charts, ccap;
  size_t n_splits, n_merges;
  int cg_max;
  ra_flat_scratch flat;
} atlas_ctx;

static int push_list(atlas_ctx *c, const uint32_t *faces, size_t n) {
  if (c->qn + n > c->qcap) {
    size_t cap = c->qcap ? c->qcap : 1024;
    while (cap < c->qn + n) cap *= 2;
    uint32_t *q = realloc(c->qfaces, cap * sizeof *q);
    if (!q) return -1;
    c->qfaces = q, c->qcap = cap;
  }
  if (c->nlists + 2 > c->lcap) {
    size_t cap = c->lcap ? 2 * c->lcap : 256;
    size_t *s = realloc(c->qstart, cap * sizeof *s);
    if (!s) return -1;
    c->qstart = s, c->lcap = cap;
    if (c->nlists == 0) c->qstart[0] = 0;
  }
  memcpy(c->qfaces + c->qn, faces, n * sizeof *faces);
  c->qn += n;
  c->qstart[++c->nlists] = c->qn;
  return 0;
}

/* Push each edge-connected component of faces[0..n) (all marked with the
 * current stamp) as a list of its own, faces in ascending order of their
 * first appearance by breadth-first search from the lowest face. */
static int push_components(atlas_ctx *c, uint32_t *faces, size_t n) {
  uint32_t st = c->stamp;
  uint32_t *comp = c->faces_buf;
  for (size_t i = 0; i < n; i++) {
    if (c->mark[faces[i]] != st) continue; /* already in a component */
    size_t head = 0, tail = 0;
    comp[tail++] = faces[i];
    c->mark[faces[i]] = st + 1;
    while (head < tail) {
      uint32_t t = comp[head++];
      for (int k = 0; k < 3; k++) {
        uint32_t nb = c->adj[3 * (size_t)t + k];
        if (nb != NO_FACE && c->mark[nb] == st) {
          c->mark[nb] = st + 1;
          comp[tail++] = nb;
        }
      }
    }
    if (push_list(c, comp, tail)) return -1;
  }
  c->stamp += 2;
  return 0;
}

static int cmp_key(const void *pa, const void *pb) {
  const double *a = pa, *b = pb;
  if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
  return a[1] < b[1] ? -1 : a[1] > b[1];
}

/* Cut faces[0..n) (n >= 2) at the median of the centroids along their
 * longest extent and push the components of both halves. */
static int split_list(atlas_ctx *c, const uint32_t *faces, size_t n) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      double x = c->centroid[3 * (size_t)faces[i] + k];
      lo[k] = x < lo[k] ? x : lo[k];
      hi[k] = x > hi[k] ? x : hi[k];
    }
  int ax = 0;
  for (int k = 1; k < 3; k++)
    if (hi[k] - lo[k] > hi[ax] - lo[ax]) ax = k;
  double *key = c->key_buf; /* pairs (coordinate, face) */
  for (size_t i = 0; i < n; i++) {
    key[2 * i] = c->centroid[3 * (size_t)faces[i] + ax];
    key[2 * i + 1] = (double)faces[i];
  }
  qsort(key, n, 2 * sizeof *key, cmp_key);
  uint32_t *half = malloc(n * sizeof *half);
  if (!half) return -1;
  c->n_splits++;
  size_t mid = n / 2;
  for (int part = 0; part < 2; part++) {
    size_t a = part ? mid : 0, b = part ? n : mid, h = 0;
    for (size_t i = a; i < b; i++) half[h++] = (uint32_t)key[2 * i + 1];
    for (size_t i = 0; i < h; i++) c->mark[half[i]] = c->stamp;
    if (push_components(c, half, h)) {
      free(half);
      return -1;
    }
  }
  free(half);
  return 0;
}

/* ---- first charts: normal clustering ------------------------------------- */
static const double k_axes[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                    {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};

static int nearest_dir(const double n[3], const double dir[6][3]) {
  int best = 0;
  double bd = -INFINITY;
  for (int d = 0; d < 6; d++) {
    double x = n[0] * dir[d][0] + n[1] * dir[d][1] + n[2] * dir[d][2];
    if (x > bd) bd = x, best = d;
  }
  return best;
}

/* The normals clustered: each face's (area-weighted) averaged with its
 * edge neighbours', smooth_passes times, so noise does not shatter the
 * charts; unit vectors into sn. tmp: 3 * n_triangles scratch. */
static void smooth_normals(const atlas_ctx *c, const double *fn, const double *area, double *sn,
                           double *tmp) {
  const size_t nt = c->m->n_triangles;
  for (size_t i = 0; i < 3 * nt; i++) sn[i] = fn[i] * area[i / 3];
  for (int pass = 0; pass < c->o->smooth_passes; pass++) {
    for (size_t t = 0; t < nt; t++) {
      double v[3] = {sn[3 * t], sn[3 * t + 1], sn[3 * t + 2]};
      for (int k = 0; k < 3; k++) {
        uint32_t nb = c->adj[3 * t + k];
        if (nb == NO_FACE) continue;
        for (int j = 0; j < 3; j++) v[j] += sn[3 * (size_t)nb + j];
      }
      double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int j = 0; j < 3; j++) tmp[3 * t + j] = l > 0 ? v[j] / l * area[t] : 0;
    }
    memcpy(sn, tmp, 3 * nt * sizeof *sn);
  }
  for (size_t t = 0; t < nt; t++) {
    double *v = sn + 3 * t, l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int j = 0; j < 3; j++) v[j] = l > 0 ? v[j] / l : 0;
  }
}

static uint32_t set_find(uint32_t *par, uint32_t a) {
  while (par[a] != a) a = par[a] = par[par[a]];
  return a;
}

/* Label faces by k-means on their normals, split into components, merge
 * small components, and islands inside one larger component, into their
 * best neighbour; push every component. */
static hearth_status first_charts(atlas_ctx *c, const double *fn, const double *area,
                                  hearth_err *err) {
  const size_t nt = c->m->n_triangles;
  double dir[6][3];
  memcpy(dir, k_axes, sizeof dir);
  uint32_t *comp = malloc(nt * sizeof *comp);
  uint32_t *csize = calloc(nt, sizeof *csize);
  uint32_t *count = calloc(nt, sizeof *count);
  uint32_t *lab = comp; /* labels first, then components */
  if (!comp || !csize || !count) {
    free(comp), free(csize), free(count);
    return hearth_err_set(err, HEARTH_E_NOMEM, "atlas: charts");
  }
  for (int it = 0; it <= c->o->kmeans_iterations; it++) {
    double sum[6][3] = {{0}};
    for (size_t t = 0; t < nt; t++) {
      int d = nearest_dir(fn + 3 * t, (const double(*)[3])dir);
      lab[t] = (uint32_t)d;
      for (int k = 0; k < 3; k++) sum[d][k] += area[t] * fn[3 * t + k];
    }
    if (it == c->o->kmeans_iterations) break;
    for (int d = 0; d < 6; d++) {
      double l = sqrt(sum[d][0] * sum[d][0] + sum[d][1] * sum[d][1] + sum[d][2] * sum[d][2]);
      if (l > 0)
        for (int k = 0; k < 3; k++) dir[d][k] = sum[d][k] / l;
    }
  }
  /* components of equal label: comp[t] = id, by breadth-first search */
  uint32_t *label = malloc(nt * sizeof *label);
  if (!label) {
    free(comp), free(csize), free(count);
    return hearth_err_set(err, HEARTH_E_NOMEM, "atlas: charts");
  }
  memcpy(label, lab, nt * sizeof *label);
  uint32_t *bfs = c->faces_buf;
  for (size_t t = 0; t < nt; t++) comp[t] = NO_FACE;
  uint32_t ncomp = 0;
  for (size_t t0 = 0; t0 < nt; t0++) {
    if (comp[t0] != NO_FACE) continue;
    size_t head = 0, tail = 0;
    bfs[tail++] = (uint32_t)t0;
    comp[t0] = ncomp;
    while (head < tail) {
      uint32_t t = bfs[head++];
      for (int k = 0; k < 3; k++) {
        uint32_t nb = c->adj[3 * (size_t)t + k];
        if (nb != NO_FACE && comp[nb] == NO_FACE && label[nb] == label[t]) {
          comp[nb] = ncomp;
          bfs[tail++] = nb;
        }
      }
    }
    csize[ncomp++] = (uint32_t)tail;
  }
  free(label);
  /* small components join the neighbour they share most edges with; faces
     of one component are found through a bucket list */
  uint32_t *first = malloc(((size_t)ncomp + 1) * sizeof *first);
  uint32_t *order = malloc(nt * sizeof *order);
  uint32_t *par = malloc(((size_t)ncomp + 1) * sizeof *par); /* merged sets */
  if (!first || !order || !par) {
    free(comp), free(csize), free(count), free(first), free(order), free(par);
    return hearth_err_set(err, HEARTH_E_NOMEM, "atlas: charts");
  }
  first[0] = 0;
  for (uint32_t k = 0; k < ncomp; k++) first[k + 1] = first[k] + csize[k];
  for (uint32_t k = 0; k < ncomp; k++) count[k] = first[k], par[k] = k;
  for (size_t t = 0; t < nt; t++) order[count[comp[t]]++] = (uint32_t)t;
  memset(count, 0, nt * sizeof *count);
  uint32_t *touched = c->faces_buf;
  for (uint32_t k = 0; k < ncomp; k++) {
    if (par[k] != k) continue;
    size_t nto = 0;
    for (uint32_t i = first[k]; i < first[k + 1]; i++) {
      uint32_t t = order[i];
      for (int e = 0; e < 3; e++) {
        uint32_t nb = c->adj[3 * (size_t)t + e];
        if (nb == NO_FACE) continue;
        uint32_t q = set_find(par, comp[nb]);
        if (q != k && count[q]++ == 0) touched[nto++] = q;
      }
    }
    uint32_t best = NO_FACE, bc = 0;
    for (size_t i = 0; i < nto; i++) {
      uint32_t q = touched[i];
      if (count[q] > bc || (count[q] == bc && q < best)) bc = count[q], best = q;
      count[q] = 0;
    }
    /* small, or an island inside one larger chart (which it would leave
       with a hole) */
    if (best == NO_FACE ||
        !(csize[k] < c->o->min_chart_faces || (nto == 1 && csize[k] < csize[best])))
      continue;
    par[k] = best;
    csize[best] += csize[k];
    csize[k] = 0;
  }
  for (size_t t = 0; t < nt; t++) comp[t] = set_find(par, comp[t]);
  free(par);
  /* every surviving component as a list, faces ascending */
  for (uint32_t k = 0; k < ncomp; k++) count[k] = 0;
  for (size_t t = 0; t < nt; t++) count[comp[t]]++;
  first[0] = 0;
  for (uint32_t k = 0; k < ncomp; k++) first[k + 1] = first[k] + count[k];
  for (uint32_t k = 0; k < ncomp; k++) count[k] = first[k];
  for (size_t t = 0; t < nt; t++) order[count[comp[t]]++] = (uint32_t)t;
  hearth_status s = HEARTH_OK;
  for (uint32_t k = 0; k < ncomp && !s; k++) {
    if (first[k + 1] == first[k]) continue;
    if (push_list(c, order + first[k], first[k + 1] - first[k]))
      s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: charts");
  }
  free(comp), free(csize), free(count), free(first), free(order);
  return s;
}

/* ---- small charts merged ------------------------------------------------ */
typedef struct size_key {
  size_t n, i;
} size_key;

static int cmp_size(const void *pa, const void *pb) {
  const size_key *a = pa, *b = pb;
  if (a->n != b->n) return a->n < b->n ? -1 : 1;
  return a->i < b->i ? -1 : a->i > b->i;
}

/* Each chart of at most RA_MERGE_FACES faces, smallest first, joins the
 * neighbouring chart of at most RA_MERGE_INTO faces it shares most edges
 * with (then the next) when the two flatten as one within the limits; the
 * charts left keep their order. -1 without memory. */
static int merge_small(atlas_ctx *c, const ra_flat_limits *lim) {
  const size_t nt = c->m->n_triangles, n = c->n_charts;
  uint32_t *of = hearth_alloc_array(nt, sizeof *of);
  size_key *key = hearth_alloc_array(n ? n : 1, sizeof *key);
  uint32_t *faces = hearth_alloc_array(nt, sizeof *faces);
  int rc = 0;
  if (!of || !key || !faces) {
    free(of), free(key), free(faces);
    return -1;
  }
  for (size_t k = 0; k < n; k++) {
    for (size_t f = 0; f < c->charts[k].n_faces; f++) of[c->charts[k].face[f]] = (uint32_t)k;
    key[k] = (size_key){c->charts[k].n_faces, k};
  }
  qsort(key, n, sizeof *key, cmp_size);
  for (size_t i = 0; i < n && rc == 0; i++) {
    size_t k = key[i].i;
    atlas_chart *a = &c->charts[k];
    if (a->n_faces == 0 || a->n_faces > RA_MERGE_FACES) continue;
    /* the neighbours with their shared edges, at most 3 per face */
    uint32_t nb[3 * RA_MERGE_FACES], cnt[3 * RA_MERGE_FACES];
    size_t nn = 0;
    for (size_t f = 0; f < a->n_faces; f++)
      for (int e = 0; e < 3; e++) {
        uint32_t t = c->adj[3 * (size_t)a->face[f] + e];
        if (t == NO_FACE || of[t] == k) continue;
        size_t j = 0;
        while (j < nn && nb[j] != of[t]) j++;
        if (j == nn) nb[nn] = of[t], cnt[nn++] = 0;
        cnt[j]++;
      }
    for (size_t tries = 0; tries < nn; tries++) {
      size_t bj = nn;
      for (size_t j = 0; j < nn; j++)
        if (cnt[j] && (bj == nn || cnt[j] > cnt[bj] || (cnt[j] == cnt[bj] && nb[j] < nb[bj])))
          bj = j;
      if (bj == nn) break;
      uint32_t q = nb[bj];
      cnt[bj] = 0;
      atlas_chart *b = &c->charts[q];
      if (b->n_faces > RA_MERGE_INTO) continue;
      memcpy(faces, b->face, b->n_faces * sizeof *faces);
      memcpy(faces + b->n_faces, a->face, a->n_faces * sizeof *faces);
      atlas_chart m;
      int r = ra_chart_flatten(c->m, c->adj, faces, b->n_faces + a->n_faces, lim, &c->flat, &m);
      if (r < 0) rc = -1;
      if (r) continue;
      for (size_t f = 0; f < a->n_faces; f++) of[a->face[f]] = q;
      if (m.cg_iterations > c->cg_max) c->cg_max = m.cg_iterations;
      ra_chart_free(a);
      ra_chart_free(b);
      *b = m;
      c->n_merges++;
      break;
    }
  }
  size_t kept = 0;
  for (size_t k = 0; k < n; k++)
    if (c->charts[k].n_faces) c->charts[kept++] = c->charts[k];
  c->n_charts = kept;
  free(of), free(key), free(faces);
  return rc;
}

/* ---- output ---------------------------------------------------------------- */
/* chart: each triangle's chart (n_charts of them); sum: 2 per chart,
 * zeroed scratch */
static void chart_stats(const hearth_mesh *out, const uint32_t *chart, double *sum,
                        hearth_atlas_stats *st) {
  double a3 = 0, auv = 0;
  for (size_t t = 0; t < out->n_triangles; t++) {
    const uint32_t *ix = out->indices + 3 * t;
    const float *u0 = out->uvs + 2 * (size_t)ix[0], *u1 = out->uvs + 2 * (size_t)ix[1],
                *u2 = out->uvs + 2 * (size_t)ix[2];
    double n[3], a;
    face_geometry(out, t, n, &a);
    double au = 0.5 * (((double)u1[0] - u0[0]) * ((double)u2[1] - u0[1]) -
                       ((double)u2[0] - u0[0]) * ((double)u1[1] - u0[1]));
    auv += fabs(au);
    if (a > 0 && au > 0) a3 += a;
  }
  st->packing_efficiency = auv;
  if (a3 <= 0) return;
  /* the common scale: UV length per surface length */
  double auv_nd = 0;
  double s_l2 = 0, s_max = 0, s_area = 0, s_angle = 0;
  for (int pass = 0; pass < 2; pass++) {
    double k = pass ? sqrt(a3 / auv_nd) : 1; /* surface length per UV length */
    for (size_t t = 0; t < out->n_triangles; t++) {
      const uint32_t *ix = out->indices + 3 * t;
      double q[3][3], s[3], tt[3];
      for (int v = 0; v < 3; v++) {
        for (int j = 0; j < 3; j++) q[v][j] = out->positions[3 * (size_t)ix[v] + j];
        s[v] = out->uvs[2 * (size_t)ix[v]];
        tt[v] = out->uvs[2 * (size_t)ix[v] + 1];
      }
      double n[3], a;
      face_geometry(out, t, n, &a);
      double au = 0.5 * ((s[1] - s[0]) * (tt[2] - tt[0]) - (s[2] - s[0]) * (tt[1] - tt[0]));
      if (!(a > 0 && au > 0)) continue;
      if (!pass) {
        auv_nd += au;
        continue;
      }
      double Ss[3], St[3];
      for (int j = 0; j < 3; j++) {
        Ss[j] =
            (q[0][j] * (tt[1] - tt[2]) + q[1][j] * (tt[2] - tt[0]) + q[2][j] * (tt[0] - tt[1])) /
            (2 * au);
        St[j] = (q[0][j] * (s[2] - s[1]) + q[1][j] * (s[0] - s[2]) + q[2][j] * (s[1] - s[0])) /
                (2 * au);
      }
      double A = (Ss[0] * Ss[0] + Ss[1] * Ss[1] + Ss[2] * Ss[2]) / (k * k);
      double B = (Ss[0] * St[0] + Ss[1] * St[1] + Ss[2] * St[2]) / (k * k);
      double C = (St[0] * St[0] + St[1] * St[1] + St[2] * St[2]) / (k * k);
      double root = sqrt((A - C) * (A - C) + 4 * B * B);
      double G = sqrt(0.5 * (A + C + root)), g2 = 0.5 * (A + C - root);
      double g = sqrt(g2 > 0 ? g2 : 0);
      double l2 = sqrt(0.5 * (A + C));
      s_l2 += a * l2 * l2;
      if (l2 > s_max) s_max = l2;
      sum[2 * (size_t)chart[t]] += a * l2 * l2, sum[2 * (size_t)chart[t] + 1] += a;
      if (g > 0) {
        s_area += a * fabs(log(G * g));
        s_angle += a * log(G / g);
      }
    }
  }
  st->stretch_l2 = sqrt(s_l2 / a3);
  for (size_t k = 0; k < st->n_charts; k++)
    if (sum[2 * k + 1] > 0)
      st->stretch_l2_chart_max = fmax(st->stretch_l2_chart_max, sqrt(sum[2 * k] / sum[2 * k + 1]));
  st->stretch_l2_max = s_max;
  st->area_distortion = s_area / a3;
  st->angle_distortion = s_angle / a3;
}

static hearth_status write_output(atlas_ctx *c, hearth_mesh *out, uint32_t *chart_of_tri,
                                  hearth_err *err) {
  const hearth_mesh *m = c->m;
  size_t nv = 0;
  for (size_t k = 0; k < c->n_charts; k++) nv += c->charts[k].n_vertices;
  hearth_status s = hearth_mesh_alloc(out, nv, m->n_triangles, 1, err);
  if (s) return s;
  size_t base = 0;
  for (size_t k = 0; k < c->n_charts; k++) {
    const atlas_chart *ch = &c->charts[k];
    for (size_t v = 0; v < ch->n_vertices; v++) {
      memcpy(out->positions + 3 * (base + v), m->positions + 3 * (size_t)ch->vertex[v],
             3 * sizeof(float));
      out->uvs[2 * (base + v)] = (float)ch->uv[2 * v];
      out->uvs[2 * (base + v) + 1] = (float)ch->uv[2 * v + 1];
    }
    for (size_t f = 0; f < ch->n_faces; f++) {
      size_t t = ch->face[f];
      for (int j = 0; j < 3; j++)
        out->indices[3 * t + j] = (uint32_t)(base + ch->corner[3 * f + j]);
      if (chart_of_tri) chart_of_tri[t] = (uint32_t)k;
    }
    base += ch->n_vertices;
  }
  return HEARTH_OK;
}

hearth_status hearth_mesh_atlas(const hearth_mesh *in, const hearth_atlas_opts *opts,
                                hearth_mesh *out, uint32_t *chart_of_tri, hearth_atlas_stats *stats,
                                hearth_err *err) {
  memset(out, 0, sizeof *out);
  hearth_atlas_opts o;
  if (opts) o = *opts;
  else hearth_atlas_opts_default(&o);
  if (!in || in->n_triangles == 0 || in->n_vertices == 0)
    return hearth_err_set(err, HEARTH_E_ARG, "atlas: empty mesh");
  if (in->n_triangles >= UINT32_MAX / 3 || in->n_vertices >= UINT32_MAX)
    return hearth_err_set(err, HEARTH_E_LIMIT, "atlas: %zu triangles", in->n_triangles);
  if (o.texture_size <= 0 || !(o.gutter_texels >= 0) || o.gutter_texels * 8 > o.texture_size)
    return hearth_err_set(err, HEARTH_E_ARG, "atlas: gutter %g texels of %d", o.gutter_texels,
                          o.texture_size);
  hearth_status s = hearth_mesh_validate(in, "atlas input", err);
  if (s) return s;
  const size_t nt = in->n_triangles;
  atlas_ctx c;
  memset(&c, 0, sizeof c);
  c.m = in;
  c.o = &o;
  c.adj = hearth_alloc_array(3 * nt, sizeof *c.adj);
  c.centroid = hearth_alloc_array(3 * nt, sizeof *c.centroid);
  c.mark = calloc(nt, sizeof *c.mark);
  c.faces_buf = hearth_alloc_array(nt, sizeof *c.faces_buf);
  c.key_buf = hearth_alloc_array(3 * nt, sizeof *c.key_buf);
  double *fn = hearth_alloc_array(3 * nt, sizeof *fn), *area = hearth_alloc_array(nt, sizeof *area);
  c.stamp = 1;
  if (!c.adj || !c.centroid || !c.mark || !c.faces_buf || !c.key_buf || !fn || !area) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: %zu triangles", nt);
    goto done;
  }
  if ((s = build_adjacency(in, c.adj, err))) goto done;
  for (size_t t = 0; t < nt; t++) {
    face_geometry(in, t, fn + 3 * t, area + t);
    for (int k = 0; k < 3; k++) {
      double x = 0;
      for (int j = 0; j < 3; j++) x += in->positions[3 * (size_t)in->indices[3 * t + j] + k];
      c.centroid[3 * t + k] = x / 3;
    }
  }
  {
    double *sn = hearth_alloc_array(3 * nt, sizeof *sn);
    if (!sn) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: %zu triangles", nt);
      goto done;
    }
    /* key_buf (3 per face) is free until the first cut */
    smooth_normals(&c, fn, area, sn, c.key_buf);
    s = first_charts(&c, sn, area, err);
    free(sn);
    if (s) goto done;
  }
  /* charts from the queue: discs that flatten are kept, others are cut */
  const ra_flat_limits lim = {o.cg_max_iterations, o.max_chart_stretch, o.max_face_stretch};
  for (size_t li = 0; li < c.nlists; li++) {
    size_t a = c.qstart[li], n = c.qstart[li + 1] - a;
    atlas_chart ch;
    int r = ra_chart_flatten(in, c.adj, c.qfaces + a, n, &lim, &c.flat, &ch);
    if (r < 0) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: chart of %zu faces", n);
      goto done;
    }
    if (r == 0) {
      if (c.n_charts == c.ccap) {
        size_t cap = c.ccap ? 2 * c.ccap : 64;
        atlas_chart *q = realloc(c.charts, cap * sizeof *q);
        if (!q) {
          ra_chart_free(&ch);
          s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: charts");
          goto done;
        }
        c.charts = q, c.ccap = cap;
      }
      c.charts[c.n_charts++] = ch;
      if (ch.cg_iterations > c.cg_max) c.cg_max = ch.cg_iterations;
      continue;
    }
    /* r == 1: no disc, or folded; a single face always flattens */
    if (split_list(&c, c.qfaces + a, n)) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: split");
      goto done;
    }
  }
  if (merge_small(&c, &lim)) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: merging charts");
    goto done;
  }
  if ((s = ra_pack(c.charts, c.n_charts, o.texture_size, o.gutter_texels, err))) goto done;
  {
    uint32_t *chart = chart_of_tri ? chart_of_tri : hearth_alloc_array(nt, sizeof *chart);
    double *sum = stats ? calloc(2 * c.n_charts + 2, sizeof *sum) : NULL;
    if (!chart || (stats && !sum)) s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: output");
    if (!s) s = write_output(&c, out, chart, err);
    if (!s && stats) {
      memset(stats, 0, sizeof *stats);
      stats->n_charts = c.n_charts;
      stats->n_splits = c.n_splits;
      stats->n_merges = c.n_merges;
      stats->cg_iterations_max = c.cg_max;
      chart_stats(out, chart, sum, stats);
    }
    if (chart != chart_of_tri) free(chart);
    free(sum);
    if (s) goto done;
  }
done:
  for (size_t k = 0; k < c.n_charts; k++) ra_chart_free(&c.charts[k]);
  free(c.charts);
  ra_flat_scratch_free(&c.flat);
  free(c.adj), free(c.centroid), free(c.mark), free(c.faces_buf), free(c.key_buf);
  free(c.qfaces), free(c.qstart), free(fn), free(area);
  if (s) hearth_mesh_free(out);
  return s;
}
