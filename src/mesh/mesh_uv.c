/* UV islands (union-find over shared UV edges) and texel rasterisation of
 * the UV layout. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/mesh.h"

/* ---- islands ---------------------------------------------------------------- */

static uint32_t float_bits(float f) {
  if (f == 0.0f) f = 0.0f; /* -0 and +0 are the same coordinate */
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

static uint64_t mix64(uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return k;
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

/* Weld: vertices with bit-identical UVs share one id (an open-addressing
 * table of the UV bits; ids 0..n_uv-1 in order of first appearance).
 * Returns 0 when out of memory. */
static int uv_weld(const hearth_mesh *m, uint32_t *uv_id, uint32_t *n_uv) {
  size_t nv = m->n_vertices, cap = 16;
  while (cap < 2 * nv) cap *= 2;
  uint64_t *hkey = hearth_alloc_array(cap, sizeof *hkey);
  uint32_t *hid = hearth_alloc_array(cap, sizeof *hid);
  if (!hkey || !hid) {
    free(hkey);
    free(hid);
    return 0;
  }
  for (size_t i = 0; i < cap; i++) hid[i] = UINT32_MAX;
  uint32_t n = 0;
  for (size_t i = 0; i < nv; i++) {
    uint64_t key = ((uint64_t)float_bits(m->uvs[2 * i]) << 32) | float_bits(m->uvs[2 * i + 1]);
    size_t h = (size_t)mix64(key) & (cap - 1);
    while (hid[h] != UINT32_MAX && hkey[h] != key) h = (h + 1) & (cap - 1);
    if (hid[h] == UINT32_MAX) {
      hkey[h] = key;
      hid[h] = n++;
    }
    uv_id[i] = hid[h];
  }
  free(hkey);
  free(hid);
  *n_uv = n;
  return 1;
}

hearth_status hearth_uv_islands(const hearth_mesh *m, uint32_t *island_of_tri, uint32_t *n_islands,
                                hearth_err *err) {
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
  uint32_t *uv_id = hearth_alloc_array(nv ? nv : 1, sizeof *uv_id);
  uint32_t *parent = hearth_alloc_array(nt ? nt : 1, sizeof *parent);
  uint32_t *start = NULL, *other = NULL, *tri = NULL;
  uint32_t n_uv = 0;
  if (!uv_id || !parent || !uv_weld(m, uv_id, &n_uv)) goto oom;
  /* edges in UV space, grouped by their lower end (a counting sort); two
   * triangles with the same edge join. A degenerate edge (both ends welded)
   * joins nothing. Island labels do not depend on the order of the unions. */
  start = calloc((size_t)n_uv + 1, sizeof *start);
  other = hearth_alloc_array(ne ? ne : 1, sizeof *other);
  tri = hearth_alloc_array(ne ? ne : 1, sizeof *tri);
  if (!start || !other || !tri) goto oom;
  for (size_t t = 0; t < nt; t++) {
    parent[t] = (uint32_t)t;
    for (int k = 0; k < 3; k++) {
      uint32_t a = uv_id[m->indices[t * 3 + k]], b = uv_id[m->indices[t * 3 + (k + 1) % 3]];
      if (a != b) start[(a < b ? a : b) + 1]++;
    }
  }
  for (uint32_t i = 0; i < n_uv; i++) start[i + 1] += start[i];
  for (size_t t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) {
      uint32_t a = uv_id[m->indices[t * 3 + k]], b = uv_id[m->indices[t * 3 + (k + 1) % 3]];
      if (a == b) continue;
      uint32_t lo = a < b ? a : b, hi = a < b ? b : a, at = start[lo]++;
      other[at] = hi;
      tri[at] = (uint32_t)t;
    }
  /* start[i] is now the end of group i, the beginning of group i + 1.
   * Groups are a vertex's edges (a handful); a large one (a fan's centre)
   * is sorted by the far end instead of compared pair by pair. */
  for (uint32_t g = 0, b0 = 0; g < n_uv; b0 = start[g], g++) {
    uint32_t len = start[g] - b0;
    if (len <= 32) {
      for (uint32_t i = b0; i < start[g]; i++)
        for (uint32_t j = i + 1; j < start[g]; j++)
          if (other[i] == other[j]) uf_union(parent, tri[i], tri[j]);
      continue;
    }
    uint64_t *pairs = hearth_alloc_array(len, sizeof *pairs);
    if (!pairs) goto oom;
    for (uint32_t i = 0; i < len; i++) pairs[i] = ((uint64_t)other[b0 + i] << 32) | tri[b0 + i];
    qsort(pairs, len, sizeof *pairs, cmp_u64);
    for (uint32_t i = 1; i < len; i++)
      if (pairs[i] >> 32 == pairs[i - 1] >> 32)
        uf_union(parent, (uint32_t)pairs[i - 1], (uint32_t)pairs[i]);
    free(pairs);
  }
  free(start);
  free(other);
  free(tri);
  start = other = tri = NULL;
  /* labels in order of each island's lowest triangle */
  uint32_t count = 0;
  for (size_t t = 0; t < nt; t++) {
    uint32_t r = uf_find(parent, (uint32_t)t);
    if (r == t) island_of_tri[t] = count++;
    else island_of_tri[t] = island_of_tri[r];
  }
  *n_islands = count;
  free(uv_id);
  free(parent);
  return HEARTH_OK;
oom:
  free(uv_id);
  free(parent);
  free(start);
  free(other);
  free(tri);
  return hearth_err_set(err, HEARTH_E_NOMEM, "UV islands: out of memory for %zu triangles", nt);
}

/* ---- UV tiles ----------------------------------------------------------------- */

/* One island's extent and what folding does to it. */
typedef struct tile_island {
  double lo[2], hi[2]; /* UV bounds over its triangles' corners */
  size_t n_tris, first_tri;
  uint8_t wrap[2];   /* most restrictive hearth_uv_wrap of its triangles */
  int8_t action;     /* 0 nothing, 1 move, 2 straddles, 3 clamped */
  uint8_t mirror[2]; /* axis reflected (MIRRORED_REPEAT, odd tile) */
  double tile[2];    /* the tile it lies in */
} tile_island;

/* the tile an extent [lo, hi] lies in (with the slack), or 0 if it spans
   more; tile 0 first, so an island at a border of [0,1] stays */
static int tile_of(double lo, double hi, double *k) {
  *k = 0.0;
  if (lo >= -HEARTH_UV_TILE_SLACK && hi <= 1.0 + HEARTH_UV_TILE_SLACK) return 1;
  *k = floor(0.5 * (lo + hi));
  return lo >= *k - HEARTH_UV_TILE_SLACK && hi <= *k + 1.0 + HEARTH_UV_TILE_SLACK;
}

/* whether [lo, hi] runs past an integer by more than the slack on both sides */
static int crosses_border(double lo, double hi) {
  double n = floor(lo + HEARTH_UV_TILE_SLACK) + 1.0;
  return n < hi - HEARTH_UV_TILE_SLACK;
}

hearth_status hearth_uv_fold_tiles(hearth_mesh *m, const uint8_t *wrap, hearth_uv_tiles *out,
                                   hearth_err *err) {
  memset(out, 0, sizeof *out);
  out->first_left = SIZE_MAX;
  if (!m->uvs) return HEARTH_OK;
  hearth_status s = hearth_mesh_validate(m, "UV tiles", err);
  if (s != HEARTH_OK) return s;
  size_t nv = m->n_vertices, nt = m->n_triangles;
  /* nothing to do when every UV lies in the unit square (with the slack) */
  int outside = 0;
  for (size_t i = 0; i < 2 * nv && !outside; i++)
    outside = m->uvs[i] < -HEARTH_UV_TILE_SLACK || m->uvs[i] > 1.0 + HEARTH_UV_TILE_SLACK;
  if (!outside) return HEARTH_OK;

  /* islands: union-find over welded UV points, joined by every triangle */
  uint32_t *uv_id = hearth_alloc_array(nv ? nv : 1, sizeof *uv_id);
  uint32_t *parent = NULL, n_uv = 0;
  tile_island *isl = NULL;
  if (!uv_id || !uv_weld(m, uv_id, &n_uv)) goto oom;
  parent = hearth_alloc_array(n_uv ? n_uv : 1, sizeof *parent);
  isl = hearth_calloc_array(n_uv ? n_uv : 1, sizeof *isl);
  if (!parent || !isl) goto oom;
  for (uint32_t i = 0; i < n_uv; i++) {
    parent[i] = i;
    isl[i].lo[0] = isl[i].lo[1] = INFINITY;
    isl[i].hi[0] = isl[i].hi[1] = -INFINITY;
  }
  const uint32_t *ix = m->indices;
  for (size_t t = 0; t < nt; t++) {
    uf_union(parent, uv_id[ix[3 * t]], uv_id[ix[3 * t + 1]]);
    uf_union(parent, uv_id[ix[3 * t]], uv_id[ix[3 * t + 2]]);
  }
  /* each island's extent, triangle count and wrap modes, kept at its root */
  for (size_t t = 0; t < nt; t++) {
    tile_island *is = &isl[uf_find(parent, uv_id[ix[3 * t]])];
    if (!is->n_tris++) is->first_tri = t;
    for (int k = 0; k < 3; k++) {
      const float *uv = m->uvs + 2 * (size_t)ix[3 * t + k];
      for (int a = 0; a < 2; a++) {
        if (uv[a] < is->lo[a]) is->lo[a] = uv[a];
        if (uv[a] > is->hi[a]) is->hi[a] = uv[a];
      }
    }
    for (int a = 0; wrap && a < 2; a++)
      if (wrap[2 * t + a] > is->wrap[a]) is->wrap[a] = wrap[2 * t + a];
  }
  /* what each island needs: its tile per axis, then a move, or nothing */
  for (uint32_t r = 0; r < n_uv; r++) {
    tile_island *is = &isl[r];
    if (!is->n_tris) continue;
    int fits =
        tile_of(is->lo[0], is->hi[0], &is->tile[0]) & tile_of(is->lo[1], is->hi[1], &is->tile[1]);
    int clamped = 0;
    for (int a = 0; a < 2; a++)
      if (is->tile[a] != 0.0 && is->wrap[a] == HEARTH_UV_CLAMP_TO_EDGE) clamped = 1;
    if (!fits) is->action = 2;
    else if (is->tile[0] == 0.0 && is->tile[1] == 0.0) is->action = 0;
    else if (clamped) is->action = 3;
    else is->action = 1;
    if (is->action == 1) {
      int mir = 0;
      for (int a = 0; a < 2; a++) {
        is->mirror[a] = is->wrap[a] == HEARTH_UV_MIRRORED_REPEAT && fmod(is->tile[a], 2.0) != 0.0;
        mir |= is->mirror[a];
      }
      out->moved++;
      out->mirrored += mir != 0;
    } else if (is->action >= 2) {
      if (is->action == 2) out->straddling++;
      else out->clamped++;
      out->triangles_left += is->n_tris;
      if (is->first_tri < out->first_left) out->first_left = is->first_tri;
    }
  }
  /* triangles crossing a tile border, among the islands that span tiles */
  for (size_t t = 0; t < nt && out->straddling; t++) {
    if (isl[uf_find(parent, uv_id[ix[3 * t]])].action != 2) continue;
    int cross = 0;
    for (int a = 0; a < 2; a++) {
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < 3; k++) {
        double v = m->uvs[2 * (size_t)ix[3 * t + k] + a];
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
      }
      cross |= crosses_border(lo, hi);
    }
    out->triangles_straddling += (size_t)cross;
  }
  /* move: every vertex goes with its island (u - i, or i + 1 - u reflected;
     both exact in double, rounded once to float) */
  for (size_t v = 0; v < nv && out->moved; v++) {
    const tile_island *is = &isl[uf_find(parent, uv_id[v])];
    if (is->action != 1) continue;
    for (int a = 0; a < 2; a++) {
      double x = m->uvs[2 * v + a], k = is->tile[a];
      m->uvs[2 * v + a] = (float)(is->mirror[a] ? k + 1.0 - x : x - k);
    }
  }
  free(uv_id);
  free(parent);
  free(isl);
  return HEARTH_OK;
oom:
  free(uv_id);
  free(parent);
  free(isl);
  return hearth_err_set(err, HEARTH_E_NOMEM, "UV tiles: out of memory for %zu vertices", nv);
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

/* Edge function of a point against the directed edge a->b, evaluated
 * canonically (endpoints in a fixed order, sign flipped after) so two
 * triangles sharing an edge get exactly opposite values: no texel centre
 * on a shared edge falls through the crack. Split in two: the endpoint
 * order (and sign) fixed once per edge, then evaluated per point. */
typedef struct edge_c {
  double ax, ay, dx, dy; /* dx, dy carry the sign */
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
  /* negating dx and dy negates the value exactly: (-a) b - (-c) d = -(a b - c d)
     in floating point too */
  e->ax = ax, e->ay = ay, e->dx = swap ? ax - bx : bx - ax, e->dy = swap ? ay - by : by - ay;
}
static inline double edge_eval(const edge_c *e, double px, double py) {
  return e->dx * (py - e->ay) - e->dy * (px - e->ax);
}

/* texel coordinates: texel (col, row) has its centre at integer (col, row) */
static void tri_uv(const hearth_mesh *m, size_t t, size_t R, double x[3], double y[3]) {
  for (int k = 0; k < 3; k++) {
    uint32_t v = m->indices[t * 3 + k];
    x[k] = (double)m->uvs[2 * (size_t)v] * (double)R - 0.5;
    y[k] = (double)m->uvs[2 * (size_t)v + 1] * (double)R - 0.5;
  }
}

static inline double min3d(double a, double b, double c) {
  double m = a < b ? a : b;
  return m < c ? m : c;
}
static inline double max3d(double a, double b, double c) {
  double m = a > b ? a : b;
  return m > c ? m : c;
}

/* texel-centre bounding boxes of triangles [t0, t1), clipped to the map
   (x0 > x1 when a triangle covers no texel centre) */
static void bbox_range(void *vctx, size_t t0, size_t t1, int thread_index) {
  const raster_ctx *c = vctx;
  const double R = (double)c->R;
  (void)thread_index;
  for (size_t t = t0; t < t1; t++) {
    double x[3], y[3];
    tri_uv(c->m, t, c->R, x, y);
    /* (finite: the mesh was validated) */
    double xl = min3d(x[0], x[1], x[2]), xh = max3d(x[0], x[1], x[2]);
    double yl = min3d(y[0], y[1], y[2]), yh = max3d(y[0], y[1], y[2]);
    double c0 = ceil(xl), c1 = floor(xh), r0 = ceil(yl), r1 = floor(yh);
    c0 = c0 > 0.0 ? c0 : 0.0;
    r0 = r0 > 0.0 ? r0 : 0.0;
    c1 = c1 < R - 1.0 ? c1 : R - 1.0;
    r1 = r1 < R - 1.0 ? r1 : R - 1.0;
    int32_t *bb = c->bbox + t * 4;
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
    /* the band's texels start empty */
    for (size_t q = (size_t)r_lo * R; q < (size_t)(r_hi + 1) * R; q++)
      c->tri_of_texel[q] = UINT32_MAX;
    if (c->bary)
      memset(c->bary + (size_t)r_lo * R * 3, 0, (size_t)(r_hi + 1 - r_lo) * R * 3 * sizeof(float));
    /* triangles in index order; a texel keeps the first (lowest) one */
    for (size_t t = 0; t < m->n_triangles; t++) {
      const int32_t *bb = c->bbox + t * 4;
      if (bb[0] > bb[1]) continue;
      int64_t row0 = bb[2] > r_lo ? bb[2] : r_lo, row1 = bb[3] < r_hi ? bb[3] : r_hi;
      if (row0 > row1) continue;
      double x[3], y[3];
      tri_uv(m, t, R, x, y);
      /* the three edge functions, set up once per triangle; twice the
       * signed area is vertex 2 against edge 0->1 */
      edge_c e[3];
      edge_setup(x[1], y[1], x[2], y[2], &e[0]);
      edge_setup(x[2], y[2], x[0], y[0], &e[1]);
      edge_setup(x[0], y[0], x[1], y[1], &e[2]);
      double area = edge_eval(&e[2], x[2], y[2]);
      if (area == 0.0 || !isfinite(area)) continue;
      if (area < 0.0) {
        /* clockwise: every edge turned round (exactly) so that inside is
           positive; the barycentrics w_k / area are unchanged */
        for (int j = 0; j < 3; j++) {
          e[j].dx = -e[j].dx;
          e[j].dy = -e[j].dy;
        }
        area = -area;
      }
      const double inv = 1.0 / area;
      for (int64_t row = row0; row <= row1; row++) {
        double py = (double)row;
        for (int64_t col = bb[0]; col <= bb[1]; col++) {
          size_t idx = (size_t)row * R + (size_t)col;
          if (c->tri_of_texel[idx] != UINT32_MAX) continue;
          double px = (double)col;
          /* w_k: edge opposite vertex k, positive inside */
          double w0 = edge_eval(&e[0], px, py);
          double w1 = edge_eval(&e[1], px, py);
          double w2 = edge_eval(&e[2], px, py);
          if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
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
  if (!m->uvs)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "UV rasterisation: the mesh has no UVs");
  if (R == 0 || R > 65536)
    return hearth_err_set(err, HEARTH_E_RANGE, "UV rasterisation: resolution %zu outside 1..65536",
                          R);
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
  /* texel-centre bounding boxes, clipped to the map, in parallel chunks */
  raster_ctx c = {m, R, 0, bbox, tri_of_texel, bary};
  int nth = hearth_default_threads();
  hearth_parallel_chunks(m->n_triangles, 8192, nth, bbox_range, &c);
  /* row bands in parallel; within a band triangles go in index order, so
   * the result does not depend on the thread count */
  size_t nbands = (size_t)nth * 8;
  if (nbands > R) nbands = R;
  c.rows_per_band = (R + nbands - 1) / nbands;
  nbands = (R + c.rows_per_band - 1) / c.rows_per_band;
  hearth_parallel_chunks(nbands, 1, nth, raster_band, &c);
  free(bbox);
  return HEARTH_OK;
}
