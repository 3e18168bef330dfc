/* UV islands (union-find over shared UV edges) and texel rasterisation of
 * the UV layout. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/mesh.h"

/* ---- islands ---------------------------------------------------------------- */

/* a 64-bit key with the index of its vertex (UV weld) or triangle (edges) */
typedef struct key_id {
  uint64_t key;
  uint32_t id;
} key_id;

/* sort by key, then id, for arrays built in increasing id order: a stable
 * LSD radix sort over 16-bit digits (digits that are equal in every key
 * are skipped); 10x faster than qsort on a 100k-triangle mesh */
static int sort_key_id(key_id *a, size_t n) {
  if (n < 2) return 1;
  key_id *tmp = hearth_alloc_array(n, sizeof *tmp);
  uint32_t *count = calloc(4 * 65536, sizeof *count);
  if (!tmp || !count) {
    free(tmp);
    free(count);
    return 0;
  }
  for (size_t i = 0; i < n; i++)
    for (int d = 0; d < 4; d++) count[d * 65536 + ((a[i].key >> (16 * d)) & 0xFFFF)]++;
  key_id *src = a, *dst = tmp;
  for (int d = 0; d < 4; d++) {
    uint32_t *c = count + d * 65536;
    if (c[(src[0].key >> (16 * d)) & 0xFFFF] == n) continue; /* one digit value throughout */
    uint32_t sum = 0;
    for (int k = 0; k < 65536; k++) {
      uint32_t x = c[k];
      c[k] = sum;
      sum += x;
    }
    for (size_t i = 0; i < n; i++) dst[c[(src[i].key >> (16 * d)) & 0xFFFF]++] = src[i];
    key_id *t = src;
    src = dst;
    dst = t;
  }
  if (src != a) memcpy(a, src, n * sizeof *a);
  free(tmp);
  free(count);
  return 1;
}

static uint32_t float_bits(float f) {
  if (f == 0.0f) f = 0.0f; /* -0 and +0 are the same coordinate */
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

static uint32_t uf_find(uint32_t *parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

static void uf_union(uint32_t *parent, uint32_t a, uint32_t b) {
  a = uf_find(parent, a);
  b = uf_find(parent, b);
  /* the lower index becomes the root: labels do not depend on merge order */
  if (a < b) parent[b] = a;
  else if (b < a) parent[a] = b;
}

hearth_status hearth_uv_islands(const hearth_mesh *m, uint32_t *island_of_tri,
                                uint32_t *n_islands, hearth_err *err) {
  *n_islands = 0;
  if (!m->uvs) return hearth_err_set(err, HEARTH_E_NOT_FOUND, "UV islands: the mesh has no UVs");
  hearth_status s = hearth_mesh_validate(m, "UV islands", err);
  if (s != HEARTH_OK) return s;
  if (m->n_triangles > (size_t)UINT32_MAX - 1)
    return hearth_err_set(err, HEARTH_E_LIMIT, "UV islands: %zu triangles exceed the 32-bit limit",
                          m->n_triangles);
  size_t nv = m->n_vertices, nt = m->n_triangles, ne;
  if (!hearth_mul_size(nt, 3, &ne))
    return hearth_err_set(err, HEARTH_E_NOMEM, "UV islands: size overflow");
  key_id *uk = hearth_alloc_array(nv ? nv : 1, sizeof *uk);
  uint32_t *uv_id = hearth_alloc_array(nv ? nv : 1, sizeof *uv_id);
  key_id *ek = hearth_alloc_array(ne ? ne : 1, sizeof *ek);
  uint32_t *parent = hearth_alloc_array(nt ? nt : 1, sizeof *parent);
  if (!uk || !uv_id || !ek || !parent) {
    free(uk);
    free(uv_id);
    free(ek);
    free(parent);
    return hearth_err_set(err, HEARTH_E_NOMEM, "UV islands: out of memory for %zu triangles", nt);
  }
  /* weld: vertices with bit-identical UVs share one id */
  for (size_t i = 0; i < nv; i++) {
    uk[i].key = ((uint64_t)float_bits(m->uvs[2 * i]) << 32) | float_bits(m->uvs[2 * i + 1]);
    uk[i].id = (uint32_t)i;
  }
  int sorted = sort_key_id(uk, nv);
  uint32_t next = 0;
  for (size_t i = 0; i < nv; i++) {
    if (i > 0 && uk[i].key != uk[i - 1].key) next++;
    uv_id[uk[i].id] = next;
  }
  /* edges in UV space; a degenerate edge (both ends welded) joins nothing */
  size_t n_e = 0;
  for (size_t t = 0; t < nt; t++) {
    parent[t] = (uint32_t)t;
    for (int k = 0; k < 3; k++) {
      uint32_t a = uv_id[m->indices[t * 3 + k]], b = uv_id[m->indices[t * 3 + (k + 1) % 3]];
      if (a == b) continue;
      if (a > b) {
        uint32_t tmp = a;
        a = b;
        b = tmp;
      }
      ek[n_e].key = ((uint64_t)a << 32) | b;
      ek[n_e].id = (uint32_t)t;
      n_e++;
    }
  }
  sorted = sorted && sort_key_id(ek, n_e);
  for (size_t i = 1; sorted && i < n_e; i++)
    if (ek[i].key == ek[i - 1].key) uf_union(parent, ek[i - 1].id, ek[i].id);
  if (!sorted) {
    free(uk);
    free(uv_id);
    free(ek);
    free(parent);
    return hearth_err_set(err, HEARTH_E_NOMEM, "UV islands: out of memory for %zu triangles", nt);
  }
  /* labels in order of each island's lowest triangle */
  uint32_t count = 0;
  for (size_t t = 0; t < nt; t++) {
    uint32_t r = uf_find(parent, (uint32_t)t);
    if (r == t) island_of_tri[t] = count++;
    else island_of_tri[t] = island_of_tri[r];
  }
  *n_islands = count;
  free(uk);
  free(uv_id);
  free(ek);
  free(parent);
  return HEARTH_OK;
}

/* ---- rasterisation ------------------------------------------------------------ */

typedef struct raster_ctx {
  const hearth_mesh *m;
  size_t R;
  size_t rows_per_band;
  int32_t *bbox; /* per triangle: col0 col1 row0 row1 (inclusive), col0 > col1 if empty */
  uint32_t *tri_of_texel;
  float *bary;
} raster_ctx;

/* Edge function of point p against the directed edge a->b, evaluated
 * canonically (endpoints in a fixed order, sign flipped after) so two
 * triangles sharing an edge get exactly opposite values: no texel centre
 * on a shared edge falls through the crack. */
static double edge_fn(double ax, double ay, double bx, double by, double px, double py) {
  int swap = (ax > bx) || (ax == bx && ay > by);
  if (swap) {
    double tx = ax, ty = ay;
    ax = bx;
    ay = by;
    bx = tx;
    by = ty;
  }
  double e = (bx - ax) * (py - ay) - (by - ay) * (px - ax);
  return swap ? -e : e;
}

/* edge_fn split in two: the endpoint order (and sign) fixed per edge,
 * then evaluated per point with the same operations */
typedef struct edge_c {
  double ax, ay, dx, dy, sign;
} edge_c;
static void edge_setup(double ax, double ay, double bx, double by, edge_c *e) {
  int swap = (ax > bx) || (ax == bx && ay > by);
  if (swap) {
    double tx = ax, ty = ay;
    ax = bx;
    ay = by;
    bx = tx;
    by = ty;
  }
  e->ax = ax, e->ay = ay, e->dx = bx - ax, e->dy = by - ay, e->sign = swap ? -1.0 : 1.0;
}
static inline double edge_eval(const edge_c *e, double px, double py) {
  double v = e->dx * (py - e->ay) - e->dy * (px - e->ax);
  return e->sign < 0 ? -v : v;
}

/* texel coordinates: texel (col, row) has its centre at integer (col, row) */
static void tri_uv(const hearth_mesh *m, size_t t, size_t R, double x[3], double y[3]) {
  for (int k = 0; k < 3; k++) {
    uint32_t v = m->indices[t * 3 + k];
    x[k] = (double)m->uvs[2 * (size_t)v] * (double)R - 0.5;
    y[k] = (double)m->uvs[2 * (size_t)v + 1] * (double)R - 0.5;
  }
}

static void raster_band(void *vctx, size_t band0, size_t band1, int thread_index) {
  const raster_ctx *c = vctx;
  const hearth_mesh *m = c->m;
  size_t R = c->R;
  for (size_t band = band0; band < band1; band++) {
    int64_t r_lo = (int64_t)(band * c->rows_per_band);
    int64_t r_hi = (int64_t)((band + 1) * c->rows_per_band);
    if (r_hi > (int64_t)R) r_hi = (int64_t)R;
    r_hi -= 1;
    /* triangles in index order; a texel keeps the first (lowest) one */
    for (size_t t = 0; t < m->n_triangles; t++) {
      const int32_t *bb = c->bbox + t * 4;
      if (bb[0] > bb[1]) continue;
      int64_t row0 = bb[2] > r_lo ? bb[2] : r_lo, row1 = bb[3] < r_hi ? bb[3] : r_hi;
      if (row0 > row1) continue;
      double x[3], y[3];
      tri_uv(m, t, R, x, y);
      double area = edge_fn(x[0], y[0], x[1], y[1], x[2], y[2]);
      if (area == 0.0 || !isfinite(area)) continue;
      double sgn = area > 0.0 ? 1.0 : -1.0, inv = 1.0 / area;
      /* the three edge functions with their canonical endpoints fixed once
       * per triangle: the same arithmetic as edge_fn, texel by texel */
      edge_c e[3];
      edge_setup(x[1], y[1], x[2], y[2], &e[0]);
      edge_setup(x[2], y[2], x[0], y[0], &e[1]);
      edge_setup(x[0], y[0], x[1], y[1], &e[2]);
      for (int64_t row = row0; row <= row1; row++) {
        double py = (double)row;
        for (int64_t col = bb[0]; col <= bb[1]; col++) {
          size_t idx = (size_t)row * R + (size_t)col;
          if (c->tri_of_texel[idx] != UINT32_MAX) continue;
          double px = (double)col;
          /* w_k: edge opposite vertex k, positive inside for either winding */
          double w0 = edge_eval(&e[0], px, py);
          double w1 = edge_eval(&e[1], px, py);
          double w2 = edge_eval(&e[2], px, py);
          if (w0 * sgn < 0.0 || w1 * sgn < 0.0 || w2 * sgn < 0.0) continue;
          c->tri_of_texel[idx] = (uint32_t)t;
          if (c->bary) {
            float *b = c->bary + idx * 3;
            b[0] = (float)(w0 * inv);
            b[1] = (float)(w1 * inv);
            b[2] = (float)(w2 * inv);
          }
        }
      }
    }
  }
}

hearth_status hearth_uv_rasterize(const hearth_mesh *m, size_t R, uint32_t *tri_of_texel,
                                  float *bary, hearth_err *err) {
  if (!m->uvs) return hearth_err_set(err, HEARTH_E_NOT_FOUND, "UV rasterisation: the mesh has no UVs");
  if (R == 0 || R > 65536)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "UV rasterisation: resolution %zu outside 1..65536", R);
  if (m->n_triangles >= (size_t)UINT32_MAX)
    return hearth_err_set(err, HEARTH_E_LIMIT, "UV rasterisation: too many triangles (%zu)",
                          m->n_triangles);
  hearth_status s = hearth_mesh_validate(m, "UV rasterisation", err);
  if (s != HEARTH_OK) return s;
  size_t n_tex, nb4;
  if (!hearth_mul_size(R, R, &n_tex) || !hearth_mul_size(m->n_triangles, 4, &nb4))
    return hearth_err_set(err, HEARTH_E_NOMEM, "UV rasterisation: size overflow");
  int32_t *bbox = hearth_alloc_array(nb4 ? nb4 : 1, sizeof *bbox);
  if (!bbox) return hearth_err_set(err, HEARTH_E_NOMEM, "UV rasterisation: out of memory");
  for (size_t i = 0; i < n_tex; i++) tri_of_texel[i] = UINT32_MAX;
  if (bary)
    for (size_t i = 0; i < n_tex * 3; i++) bary[i] = 0.0f;
  /* texel-centre bounding boxes, clipped to the map */
  for (size_t t = 0; t < m->n_triangles; t++) {
    double x[3], y[3];
    tri_uv(m, t, R, x, y);
    double xl = fmin(x[0], fmin(x[1], x[2])), xh = fmax(x[0], fmax(x[1], x[2]));
    double yl = fmin(y[0], fmin(y[1], y[2])), yh = fmax(y[0], fmax(y[1], y[2]));
    double c0 = fmax(ceil(xl), 0.0), c1 = fmin(floor(xh), (double)R - 1.0);
    double r0 = fmax(ceil(yl), 0.0), r1 = fmin(floor(yh), (double)R - 1.0);
    int32_t *bb = bbox + t * 4;
    if (c0 > c1 || r0 > r1) {
      bb[0] = 1;
      bb[1] = 0;
      bb[2] = 1;
      bb[3] = 0;
      continue;
    }
    bb[0] = (int32_t)c0;
    bb[1] = (int32_t)c1;
    bb[2] = (int32_t)r0;
    bb[3] = (int32_t)r1;
  }
  /* row bands in parallel; within a band triangles go in index order, so
   * the result does not depend on the thread count */
  raster_ctx c = {m, R, 0, bbox, tri_of_texel, bary};
  int nth = hearth_default_threads();
  size_t nbands = (size_t)nth * 8;
  if (nbands > R) nbands = R;
  c.rows_per_band = (R + nbands - 1) / nbands;
  nbands = (R + c.rows_per_band - 1) / c.rows_per_band;
  hearth_parallel_for(nbands, nth, raster_band, &c);
  free(bbox);
  return HEARTH_OK;
}
