/* Temperature / colour mapping onto a UV layout (see include/hearth/map.h).
 *
 * Two parallel phases. Views: each view is cast and splatted by one worker
 * and reduced to one value per texel it observes (the view's mean there,
 * its weight and best viewing cosine). For max fusion these fold at once
 * into the worker's own maxima maps; for mean and robust fusion they are
 * kept as the view's records, sorted by texel. Texels: bands of rows merge
 * the workers' maxima, or fold every view's records in view order
 * (weighted mean or weighted median), touching only the band's slice of
 * the maps. Nothing is shared between workers while it is written, maxima
 * do not depend on which worker saw which view, and records are folded in
 * the same order whatever the thread count: the result does not depend on
 * it. Within a view, pixels are visited in raster order by one thread. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "map/map_internal.h"

#define MAX_BACKFACE_SKIPS 8
/* One bilinear touch of a texel by a splat within one view; a view's
 * touches are sorted by texel (stably: pixel order within a texel) and
 * reduced in one pass into the view's records, each texel's sums added up
 * in the same order as pixel by pixel. */
typedef struct touch {
  uint32_t q;  /* texel */
  uint32_t sk; /* 4 * (index into the view's splats) + corner (bit 0: +x, bit 1: +y) */
} touch;

/* a view's record of a texel: the texel's index in rec_q, then REC_WORDS(C)
 * floats: the weight (sum of bilinear weights), the best viewing cosine and
 * per channel the mean (the weighted sum for mean fusion) */
#define REC_WORDS(C) (2 + (size_t)(C))
#define BAND_TEXELS 16384 /* texels per band of the fusion phase (whole rows) */

/* a float as an unsigned integer of the same order (-0 below +0, NaN not
 * used), never 0 for a float: a zeroed map holds "none" below every value */
static inline uint32_t max_code(float f) {
  uint32_t b;
  memcpy(&b, &f, sizeof b);
  return b & 0x80000000u ? ~b : b | 0x80000000u;
}
static inline float max_decode(uint32_t c) {
  uint32_t b = c & 0x80000000u ? c & 0x7fffffffu : ~c;
  float f;
  memcpy(&f, &b, sizeof f);
  return f;
}

void hearth_map_opts_default(hearth_map_opts *o) {
  memset(o, 0, sizeof *o);
  o->resolution = 1024;
  o->fusion = HEARTH_FUSE_MAX;
  o->min_cos = 0.0;
  o->pixel_stride = 1;
}

void hearth_map_result_free(hearth_map_result *r) {
  if (!r) return;
  free(r->observed);
  free(r->filled);
  free(r->mask);
  free(r->best_cos);
  free(r->view_hits);
  memset(r, 0, sizeof *r);
}

/* one hit pixel's splat: its bilinear footprint, island, cosine and value;
 * a view's splats become touches of texels (see touch) */
typedef struct splat {
  double fx, fy;  /* bilinear fractions */
  int32_t x0, y0; /* lower-left texel of the 2 x 2 footprint */
  uint32_t island;
  float cosv;
  float val[3];
} splat;
#define PREFETCH_AHEAD 8 /* touches ahead whose texel's island is prefetched */

/* the bilinear weight of corner k (bit 0: +x, bit 1: +y) of a splat */
static inline float corner_weight(const splat *e, int k) {
  return (float)(((k & 1) ? e->fx : 1.0 - e->fx) * ((k >> 1) ? e->fy : 1.0 - e->fy));
}

typedef struct map_ctx {
  const hearth_mesh *mesh;
  const hearth_raycaster *rc;
  const hearth_camera *cam;
  const hearth_map_view *views;
  size_t n_views;
  const hearth_map_opts *opts;
  size_t R;
  int C;
  /* layout */
  const uint32_t *island_of_texel; /* UINT32_MAX off the surface */
  const uint32_t *island_of_tri;
  uint32_t n_islands;
  const float *tri_normal; /* 3 per triangle, unit */
  /* pixel grid */
  size_t n_pix, pix_w, pix_h;
  const float *pix_dir; /* 3 per pixel, camera frame, unit */
  const uint32_t *pix_index; /* image pixel index of grid pixel */
  const uint32_t *tile_order; /* grid pixels in 4x4 tiles: coherent packets of 16 */
  double sphere[4];           /* mesh bounding sphere: rays that miss it are not cast */
  const hearth_ray_fan *fan;  /* the pixel grid as a ray fan (NULL: cast rays) */
  const uint8_t *view_fan;    /* per view: the mesh lies in front, the fan applies */
  void **fan_scratch;         /* per thread */
  /* per-thread scratch, indexed by thread */
  int n_threads;
  int cast_threads; /* threads for ray casting when views are processed serially */
  /* per thread: a view's touches and the sort's second buffer (4 per pixel) */
  touch **touches, **touches_tmp;
  /* mean and robust fusion: the views' records (see REC_WORDS), each
   * view's sorted by texel: made in the worker's scratch (room for 4 per
   * pixel), kept in an allocation of their own size */
  uint32_t **rec_q;
  float **rec_d;
  size_t *n_rec;
  uint32_t **scratch_q; /* per thread */
  float **scratch_d;
  /* max fusion folds each view into per-worker maps instead (the maximum
   * does not depend on the order): the view means' maximum per texel and
   * channel as order-preserving codes (see max_code; 0 for none) and the
   * best viewing cosine (0 for none); worker 0's are the result's own
   * observed and best_cos arrays */
  int dense;
  uint32_t **max_code;
  float **max_cos;
  splat **splats; /* per thread: n_pix */
  uint8_t **sil; /* per thread: n_pix silhouette flags */
  float *hit_t; /* per thread: n_pix */
  uint32_t *hit_tri;
  float *hit_b1, *hit_b2;
  float *ray_org, *ray_dir;
  hearth_ray_hit *hits;
  /* outputs */
  uint32_t *view_hits;
  _Atomic int failed; /* 1 out of memory, 2 a view not in front after all */
} map_ctx;

static float image_value(const hearth_image *img, size_t idx, int c) {
  if (img->type == HEARTH_PIX_F32) return ((const float *)img->data)[idx * (size_t)img->channels + (size_t)c];
  return (float)((const uint8_t *)img->data)[idx * (size_t)img->channels + (size_t)c];
}

/* a box of grid pixels */
typedef struct pix_box {
  size_t x0, x1, y0, y1; /* inclusive; x0 > x1 when empty */
} pix_box;

/* record a hit (or a miss) of grid pixel p = (px, py) */
static void keep_hit(map_ctx *m, int t, size_t p, size_t px, size_t py, const hearth_ray_hit *h, pix_box *box) {
  size_t n = m->n_pix;
  float *ht = m->hit_t + (size_t)t * n, *b1 = m->hit_b1 + (size_t)t * n, *b2 = m->hit_b2 + (size_t)t * n;
  uint32_t *tri = m->hit_tri + (size_t)t * n;
  if (h->prim != UINT32_MAX && h->front) {
    if (px < box->x0) box->x0 = px;
    if (px > box->x1) box->x1 = px;
    if (py < box->y0) box->y0 = py;
    if (py > box->y1) box->y1 = py;
    ht[p] = h->t;
    tri[p] = h->prim;
    b1[p] = h->b1;
    b2[p] = h->b2;
  } else {
    ht[p] = INFINITY;
    tri[p] = UINT32_MAX;
  }
}

/* cast every grid pixel of view v; fill hit_* arrays of thread t and grow
 * box around the hits. Through the fan where the view has the whole mesh in
 * front; otherwise rays go to Embree in 4x4 pixel tiles (packets of nearly
 * parallel rays), and rays that miss the mesh's bounding sphere are not
 * cast at all. */
static void cast_view(map_ctx *m, size_t v, int t, pix_box *box) {
  const hearth_rigid *T = &m->views[v].T_world_from_cam;
  size_t n = m->n_pix;
  if (m->view_fan[v]) {
    /* the whole mesh lies in front of this view: rasterise */
    hearth_ray_hit *hits = m->hits + (size_t)t * n;
    size_t fb[4];
    if (hearth_ray_fan_cast(m->fan, m->mesh, T, m->fan_scratch[t], hits, fb, NULL)) {
      m->failed = 2; /* cannot happen: the bounding sphere lies in front */
      return;
    }
    if (fb[0] > fb[1]) return; /* no hit */
    /* the hits' box, and misses in a 2-pixel ring around it (what the
       silhouette filter reads) */
    const size_t W = m->pix_w, H = m->pix_h;
    float *ht = m->hit_t + (size_t)t * n;
    uint32_t *tri = m->hit_tri + (size_t)t * n;
    for (size_t y = fb[2] >= 2 ? fb[2] - 2 : 0; y <= fb[3] + 2 && y < H; y++)
      for (size_t x = fb[0] >= 2 ? fb[0] - 2 : 0; x <= fb[1] + 2 && x < W; x++) {
        size_t p = y * W + x;
        if (x >= fb[0] && x <= fb[1] && y >= fb[2] && y <= fb[3]) {
          keep_hit(m, t, p, x, y, &hits[p], box);
        } else {
          ht[p] = INFINITY;
          tri[p] = UINT32_MAX;
        }
      }
    return;
  }
  float *org = m->ray_org + (size_t)t * 3 * n, *dir = m->ray_dir + (size_t)t * 3 * n;
  hearth_ray_hit *hits = m->hits + (size_t)t * n;
  const double *S = m->sphere;
  double oc[3] = {S[0] - T->t[0], S[1] - T->t[1], S[2] - T->t[2]};
  double oc2 = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2];
  double r2 = S[3] * S[3];
  for (size_t i = 0; i < n; i++) {
    size_t p = m->tile_order[i];
    const float *d = m->pix_dir + 3 * p;
    double w[3];
    for (int k = 0; k < 3; k++) w[k] = T->R[3 * k] * d[0] + T->R[3 * k + 1] * d[1] + T->R[3 * k + 2] * d[2];
    /* squared distance of the sphere centre from the ray (unit direction),
     * or from the origin when the centre lies behind it */
    double along = oc[0] * w[0] + oc[1] * w[1] + oc[2] * w[2];
    double dist2 = along > 0 ? oc2 - along * along : oc2;
    int skip = dist2 > r2;
    for (int k = 0; k < 3; k++) {
      org[3 * i + k] = (float)T->t[k];
      dir[3 * i + k] = skip ? 0.0f : (float)w[k]; /* a zero direction is not cast */
    }
  }
  /* views already run in parallel: cast on this thread only, unless there
     is a single worker for all views */
  hearth_raycast_batch_mt(m->rc, n, org, dir, 0.0f, INFINITY, hits, m->n_threads > 1 ? 1 : m->cast_threads);
  for (size_t i = 0; i < n; i++) {
    size_t p = m->tile_order[i];
    hearth_ray_hit h = hits[i];
    /* back faces are culled: continue the ray behind them */
    for (int k = 0; k < MAX_BACKFACE_SKIPS && h.prim != UINT32_MAX && !h.front; k++) {
      double o[3] = {org[3 * i], org[3 * i + 1], org[3 * i + 2]};
      double d[3] = {dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]};
      double tn = (double)h.t * (1.0 + 1e-6) + 1e-7;
      if (!hearth_raycast(m->rc, o, d, tn, INFINITY, &h)) h.prim = UINT32_MAX;
    }
    keep_hit(m, t, p, p % m->pix_w, p / m->pix_w, &h, box);
  }
}

/* silhouette flags: 1 if a grid pixel lies within 2 pixels of a
 * silhouette, i.e. a pixel in its 5x5 neighbourhood (clipped to the image)
 * misses the surface or lies at a clearly different depth (more than 3%).
 * The lens blur and the pixel footprint mix the two sides of such an edge,
 * so these pixels do not measure one surface. Computed with separable 5x5
 * minimum and maximum filters of the hit distance (a miss is +inf). Only
 * pixels inside box (the hits' bounding box) get flags; the filters read up
 * to 2 pixels beyond it, where ht holds the misses. */
static void silhouettes(const map_ctx *m, const float *ht, const pix_box *box, float *lo, float *hi,
                        float *tmp_lo, float *tmp_hi, uint8_t *sil) {
  size_t W = m->pix_w, H = m->pix_h;
  size_t ry0 = box->y0 >= 2 ? box->y0 - 2 : 0, ry1 = box->y1 + 2 < H ? box->y1 + 2 : H - 1;
  for (size_t y = ry0; y <= ry1; y++) {
    const float *r = ht + y * W;
    for (size_t x = box->x0; x <= box->x1; x++) {
      size_t a = x >= 2 ? x - 2 : 0, b = x + 2 < W ? x + 2 : W - 1;
      float mn = r[a], mx = r[a];
      for (size_t k = a + 1; k <= b; k++) {
        mn = r[k] < mn ? r[k] : mn;
        mx = r[k] > mx ? r[k] : mx;
      }
      tmp_lo[y * W + x] = mn;
      tmp_hi[y * W + x] = mx;
    }
  }
  for (size_t y = box->y0; y <= box->y1; y++) {
    size_t a = y >= 2 ? y - 2 : 0, b = y + 2 < H ? y + 2 : H - 1;
    for (size_t x = box->x0; x <= box->x1; x++) {
      float mn = tmp_lo[a * W + x], mx = tmp_hi[a * W + x];
      for (size_t k = a + 1; k <= b; k++) {
        float l = tmp_lo[k * W + x], h = tmp_hi[k * W + x];
        mn = l < mn ? l : mn;
        mx = h > mx ? h : mx;
      }
      lo[y * W + x] = mn;
      hi[y * W + x] = mx;
    }
  }
  for (size_t y = box->y0; y <= box->y1; y++)
    for (size_t x = box->x0; x <= box->x1; x++) {
      size_t p = y * W + x;
      float t0 = ht[p];
      if (!isfinite(t0)) {
        sil[p] = 1;
        continue;
      }
      float tol = 0.03f * t0;
      sil[p] = !isfinite(hi[p]) || hi[p] - t0 > tol || t0 - lo[p] > tol;
    }
}

static void process_view(map_ctx *m, size_t v, int t) {
  const hearth_mesh *mesh = m->mesh;
  size_t R = m->R, n = m->n_pix;
  int C = m->C;
  size_t n_touched = 0;
  pix_box box = {SIZE_MAX, 0, SIZE_MAX, 0};
  cast_view(m, v, t, &box);
  if (m->failed) return;
  if (box.x0 > box.x1) box = (pix_box){1, 0, 1, 0}; /* no hit: empty */
  const float *ht = m->hit_t + (size_t)t * n, *hb1 = m->hit_b1 + (size_t)t * n,
              *hb2 = m->hit_b2 + (size_t)t * n;
  const uint32_t *htri = m->hit_tri + (size_t)t * n;
  const hearth_image *img = m->views[v].image;
  int edges = m->opts->fusion == HEARTH_FUSE_ROBUST || !m->opts->keep_edges;
  uint8_t *sil = m->sil[t];
  if (edges) {
    /* the ray arrays are free again: scratch for the filters */
    float *scratch = m->ray_org + (size_t)t * 3 * n;
    float *scratch2 = m->ray_dir + (size_t)t * 3 * n;
    if (box.x0 <= box.x1) silhouettes(m, ht, &box, scratch, scratch + n, scratch2, scratch2 + n, sil);
  }
  const float *pd = m->pix_dir;
  const double *Rw = m->views[v].T_world_from_cam.R;
  uint32_t hits = 0;
  float min_cos = (float)m->opts->min_cos;
  splat *sp = m->splats[t];
  size_t n_sp = 0;
  /* the hits, in raster order within their bounding box */
  for (size_t py = box.y0; py <= box.y1 && box.x0 <= box.x1; py++) {
    for (size_t p = py * m->pix_w + box.x0; p <= py * m->pix_w + box.x1; p++) {
      uint32_t tri = htri[p];
      if (tri == UINT32_MAX) continue;
      if (edges && sil[p]) continue;
      const float *nrm = m->tri_normal + 3 * (size_t)tri, *dc = pd + 3 * p;
      float d[3];
      for (int k = 0; k < 3; k++) d[k] = (float)(Rw[3 * k] * dc[0] + Rw[3 * k + 1] * dc[1] + Rw[3 * k + 2] * dc[2]);
      float cosv = -(nrm[0] * d[0] + nrm[1] * d[1] + nrm[2] * d[2]);
      if (cosv < min_cos) continue;
      hits++;
      /* UV of the hit point */
      const uint32_t *ix = mesh->indices + 3 * (size_t)tri;
      float b1 = hb1[p], b2 = hb2[p], b0 = 1.0f - b1 - b2;
      float u = b0 * mesh->uvs[2 * ix[0]] + b1 * mesh->uvs[2 * ix[1]] + b2 * mesh->uvs[2 * ix[2]];
      float vv = b0 * mesh->uvs[2 * ix[0] + 1] + b1 * mesh->uvs[2 * ix[1] + 1] +
                 b2 * mesh->uvs[2 * ix[2] + 1];
      double x = (double)u * (double)R - 0.5, y = (double)vv * (double)R - 0.5;
      double x0f = floor(x), y0f = floor(y);
      /* footprints entirely off the map add nothing */
      if (!(x0f >= -1.0 && y0f >= -1.0 && x0f < (double)R && y0f < (double)R)) continue;
      splat *e = &sp[n_sp++];
      e->fx = x - x0f;
      e->fy = y - y0f;
      e->x0 = (int32_t)x0f;
      e->y0 = (int32_t)y0f;
      e->island = m->island_of_tri[tri];
      e->cosv = cosv;
      size_t src = m->pix_index[p];
      for (int c = 0; c < C; c++) e->val[c] = image_value(img, src, c);
    }
  }
  /* the touches, in pixel order */
  touch *tc = m->touches[t];
  size_t n_tc = 0;
  for (size_t i = 0; i < n_sp; i++) {
    const splat *e = &sp[i];
    for (int k = 0; k < 4; k++) {
      long tx = (long)e->x0 + (k & 1), ty = (long)e->y0 + (k >> 1);
      if (tx < 0 || ty < 0 || tx >= (long)R || ty >= (long)R) continue;
      if (!(corner_weight(e, k) > 0.0f)) continue;
      tc[n_tc++] = (touch){(uint32_t)((size_t)ty * R + (size_t)tx), (uint32_t)(4 * i + (size_t)k)};
    }
  }
  /* stable LSD radix sort by texel, 11-bit digits (at most 3: R <= 16384
     gives 28 bits), every digit's histogram from one read */
  {
    touch *src = tc, *dst = m->touches_tmp[t];
    size_t bits = 1;
    while (bits < 32 && ((size_t)1 << bits) < R * R) bits++;
    size_t nd = (bits + 10) / 11;
    size_t count[3][2048 + 1];
    memset(count, 0, sizeof count);
    for (size_t i = 0; i < n_tc; i++)
      for (size_t d = 0; d < nd; d++) count[d][((src[i].q >> (11 * d)) & 2047) + 1]++;
    for (size_t d = 0; d < nd; d++) {
      size_t *cd = count[d], shift = 11 * d;
      for (size_t b = 0; b < 2048; b++) cd[b + 1] += cd[b];
      for (size_t i = 0; i < n_tc; i++) dst[cd[(src[i].q >> shift) & 2047]++] = src[i];
      touch *x = src;
      src = dst;
      dst = x;
    }
    tc = src;
  }
  m->view_hits[v] = hits;
  /* each texel's touches in pixel order: splat only from the texel's own
   * island; one record per texel with any */
  const uint32_t *iot = m->island_of_texel;
  const size_t RW = REC_WORDS(C);
  int fusion = m->opts->fusion;
  uint32_t *rq = m->scratch_q[t];
  float *rd = m->scratch_d[t];
  uint32_t *mc = m->dense ? m->max_code[t] : NULL;
  float *mcos = m->dense && m->max_cos ? m->max_cos[t] : NULL;
  for (size_t i = 0; i < n_tc;) {
    uint32_t q = tc[i].q;
    size_t j = i;
    while (j < n_tc && tc[j].q == q) j++;
    if (j + PREFETCH_AHEAD < n_tc) {
      __builtin_prefetch(&iot[tc[j + PREFETCH_AHEAD].q], 0);
      if (mc) __builtin_prefetch(&mc[(size_t)tc[j + PREFETCH_AHEAD].q * (size_t)C], 1);
    }
    uint32_t island = iot[q];
    float wsum = 0.0f, best_cos = 0.0f, sum[3] = {0.0f, 0.0f, 0.0f};
    int any = 0;
    for (size_t k = i; k < j; k++) {
      const splat *e = &sp[tc[k].sk >> 2];
      if (e->island != island) continue;
      if (!any || e->cosv > best_cos) best_cos = e->cosv;
      any = 1;
      float w = corner_weight(e, (int)(tc[k].sk & 3));
      wsum += w;
      for (int c = 0; c < C; c++) sum[c] += w * e->val[c];
    }
    i = j;
    if (!any) continue;
    if (mc) {
      /* + 0.0f: a negative zero becomes +0, so equal means give one code */
      if (mcos && best_cos > mcos[q]) mcos[q] = best_cos;
      for (int c = 0; c < C; c++) {
        uint32_t code = max_code(sum[c] / wsum + 0.0f);
        if (code > mc[(size_t)q * (size_t)C + (size_t)c]) mc[(size_t)q * (size_t)C + (size_t)c] = code;
      }
      continue;
    }
    float *d = rd + n_touched * RW;
    rq[n_touched++] = q;
    d[0] = wsum;
    d[1] = best_cos;
    /* + 0.0f: a negative zero becomes +0, so equal means cannot make the
       maximum's bits depend on which view came first */
    for (int c = 0; c < C; c++) d[2 + c] = fusion == HEARTH_FUSE_MEAN ? sum[c] : sum[c] / wsum + 0.0f;
  }
  if (mc) return; /* folded into the worker's maps: no records */
  m->n_rec[v] = n_touched;
  m->rec_q[v] = hearth_alloc_array(n_touched ? n_touched : 1, sizeof *rq);
  m->rec_d[v] = hearth_alloc_array(n_touched ? n_touched : 1, RW * sizeof *rd);
  if (!m->rec_q[v] || !m->rec_d[v]) {
    m->failed = 1;
    return;
  }
  memcpy(m->rec_q[v], rq, n_touched * sizeof *rq);
  memcpy(m->rec_d[v], rd, n_touched * RW * sizeof *rd);
}

/* rows [b, e) of every worker's maxima maps: zero (no maximum) */
static void zero_maps(void *ctx, size_t b, size_t e, int t) {
  map_ctx *m = ctx;
  const size_t C = (size_t)m->C, q0 = b * m->R, nq = (e - b) * m->R;
  (void)t;
  for (int w = 0; w < m->n_threads; w++) {
    memset(m->max_code[w] + q0 * C, 0, nq * C * sizeof(uint32_t));
    if (m->max_cos) memset(m->max_cos[w] + q0, 0, nq * sizeof(float));
  }
}

/* views [b, e) on worker t; views are handed out one at a time to whichever
   worker is free (they differ in cost, and a shared machine slows workers
   unevenly); a view's records do not depend on the worker */
static void views_range(void *ctx, size_t b, size_t e, int t) {
  map_ctx *m = ctx;
  for (size_t v = b; v < e; v++) process_view(m, v, t);
}

/* weighted median of n (value, weight) pairs; sorts in place */
typedef struct vw {
  float v, w;
} vw;
static int cmp_vw(const void *a, const void *b) {
  float x = ((const vw *)a)->v, y = ((const vw *)b)->v;
  return (x > y) - (x < y);
}
static float weighted_median(vw *a, size_t n) {
  qsort(a, n, sizeof *a, cmp_vw);
  double total = 0, acc = 0;
  for (size_t i = 0; i < n; i++) total += a[i].w;
  for (size_t i = 0; i < n; i++) {
    acc += a[i].w;
    if (acc >= 0.5 * total) return a[i].v;
  }
  return a[n - 1].v;
}

/* per-texel passes over whole rows, in parallel (each texel is written by
 * one worker, from its own inputs: the result does not depend on the split) */
typedef struct texel_pass {
  const map_ctx *m;
  hearth_map_result *out;
  island_box *parts;   /* per worker: the islands' boxes (n_islands + 1) */
  size_t (*counts)[4]; /* per worker: observed, filled, unobserved, surface */
  int *nomem;          /* per worker */
} texel_pass;

/* the first of n sorted texels at or above q */
static size_t lower_bound_u32(const uint32_t *a, size_t n, uint32_t q) {
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (a[mid] < q) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/* Fusion over bands of whole rows, into the band's slice of observed, mask,
 * best_cos and filled: for max fusion the workers' maxima maps merged and
 * decoded; otherwise every view's records of the band's texels folded in
 * view order (the weighted mean, or the weighted median). A worker sets
 * nomem[t] if its scratch cannot be had. */
static void fuse_bands(void *ctx, size_t b, size_t e, int t) {
  const texel_pass *tp = ctx;
  const map_ctx *m = tp->m;
  hearth_map_result *out = tp->out;
  const size_t R = m->R, C = (size_t)m->C, N = R * R, RW = REC_WORDS(C), nv = m->n_views;
  const size_t rows = R < BAND_TEXELS ? BAND_TEXELS / R : 1, band = rows * R;
  const int fusion = m->opts->fusion;
  double *acc = NULL; /* mean: sums per channel and weight, per texel of a band */
  uint32_t *cnt = NULL; /* robust: records per texel of a band, then offsets */
  vw *all = NULL, *tmp = NULL;
  size_t all_cap = 0, nv_band = nv; /* views with records */
  if (fusion == HEARTH_FUSE_MEAN) acc = hearth_alloc_array(band, (C + 1) * sizeof *acc);
  if (fusion == HEARTH_FUSE_ROBUST) {
    cnt = hearth_alloc_array(band + 1, sizeof *cnt);
    tmp = hearth_alloc_array(nv ? nv : 1, sizeof *tmp);
  }
  if ((fusion == HEARTH_FUSE_MEAN && !acc) || (fusion == HEARTH_FUSE_ROBUST && (!cnt || !tmp))) {
    tp->nomem[t] = 1;
    goto done;
  }
  for (size_t bi = b; bi < e; bi++) {
    const size_t q0 = bi * band, q1 = q0 + band < N ? q0 + band : N, nq = q1 - q0;
    if (m->dense) {
      /* the workers' maxima, decoded (worker 0's codes are read from and
         then overwritten by the values): -inf where none */
      const uint32_t *code = m->max_code[0];
      for (size_t q = q0; q < q1; q++) {
        for (int w = 1; m->max_cos && w < m->n_threads; w++) {
          const float cw = m->max_cos[w][q];
          if (cw > out->best_cos[q]) out->best_cos[q] = cw;
        }
        out->mask[q] = m->island_of_texel[q] == UINT32_MAX ? HEARTH_TEXEL_NONE : HEARTH_TEXEL_UNOBSERVED;
        for (size_t c = 0; c < C; c++) {
          uint32_t k = code[q * C + c];
          for (int w = 1; w < m->n_threads; w++) {
            const uint32_t kw = m->max_code[w][q * C + c];
            k = kw > k ? kw : k;
          }
          out->observed[q * C + c] = k ? max_decode(k) : -INFINITY;
        }
      }
      nv_band = 0;
    } else {
      for (size_t q = q0; q < q1; q++) {
        if (out->best_cos) out->best_cos[q] = 0.0f;
        out->mask[q] = m->island_of_texel[q] == UINT32_MAX ? HEARTH_TEXEL_NONE : HEARTH_TEXEL_UNOBSERVED;
        for (size_t c = 0; c < C; c++) out->observed[q * C + c] = -INFINITY;
      }
      nv_band = nv;
    }
    if (acc) memset(acc, 0, nq * (C + 1) * sizeof *acc);
    if (cnt) memset(cnt, 0, (nq + 1) * sizeof *cnt);
    size_t total = 0;
    for (size_t v = 0; v < nv_band; v++) {
      const uint32_t *rq = m->rec_q[v];
      const float *rd = m->rec_d[v];
      size_t k = lower_bound_u32(rq, m->n_rec[v], (uint32_t)q0);
      for (; k < m->n_rec[v] && rq[k] < q1; k++) {
        const size_t q = rq[k];
        const float *d = rd + k * RW;
        if (out->best_cos && d[1] > out->best_cos[q]) out->best_cos[q] = d[1];
        if (fusion == HEARTH_FUSE_MAX) {
          for (size_t c = 0; c < C; c++)
            if (d[2 + c] > out->observed[q * C + c]) out->observed[q * C + c] = d[2 + c];
        } else if (fusion == HEARTH_FUSE_MEAN) {
          /* each view counts with its total weight at this texel */
          double *a = acc + (q - q0) * (C + 1);
          for (size_t c = 0; c < C; c++) a[c] += d[2 + c];
          a[C] += d[0];
        } else {
          cnt[q - q0 + 1]++;
          total++;
        }
      }
    }
    if (fusion == HEARTH_FUSE_MEAN) {
      for (size_t q = q0; q < q1; q++) {
        const double *a = acc + (q - q0) * (C + 1);
        if (a[C] > 0.0)
          for (size_t c = 0; c < C; c++) out->observed[q * C + c] = (float)(a[c] / a[C]);
      }
    } else if (fusion == HEARTH_FUSE_ROBUST && total) {
      /* every view's (value, weight) per texel, in view order */
      if (total > all_cap) {
        free(all);
        all_cap = total;
        all = hearth_alloc_array(all_cap, sizeof *all);
        if (!all) {
          tp->nomem[t] = 1;
          goto done;
        }
      }
      for (size_t i = 0; i < nq; i++) cnt[i + 1] += cnt[i];
      for (size_t v = 0; v < nv; v++) {
        const uint32_t *rq = m->rec_q[v];
        const float *rd = m->rec_d[v];
        for (size_t k = lower_bound_u32(rq, m->n_rec[v], (uint32_t)q0); k < m->n_rec[v] && rq[k] < q1; k++)
          all[cnt[rq[k] - q0]++] = (vw){rd[k * RW + 2], rd[k * RW]};
      }
      /* cnt[i] is now the end of texel i's records (the start of i + 1's) */
      for (size_t i = 0, start = 0; i < nq; start = cnt[i], i++) {
        size_t n = cnt[i] - start;
        if (!n) continue;
        memcpy(tmp, all + start, n * sizeof *tmp);
        out->observed[q0 + i] = weighted_median(tmp, n);
      }
    }
    map_fill_prepare_rows(R, C, m->island_of_texel, q0 / R, q1 / R, out,
                          tp->parts + (size_t)t * ((size_t)m->n_islands + 1));
  }
done:
  free(acc);
  free(cnt);
  free(all);
  free(tmp);
}

/* the texels of each kind, counted by rows */
static void count_rows(void *ctx, size_t b, size_t e, int t) {
  const texel_pass *tp = ctx;
  const uint8_t *mask = tp->out->mask;
  size_t R = tp->m->R, n_obs = 0, n_fill = 0, n_unobs = 0, n_none = 0;
  for (size_t q = b * R; q < e * R; q++) {
    uint8_t mk = mask[q];
    n_obs += mk == HEARTH_TEXEL_OBSERVED;
    n_fill += mk == HEARTH_TEXEL_FILLED;
    n_unobs += mk == HEARTH_TEXEL_UNOBSERVED;
    n_none += mk == HEARTH_TEXEL_NONE;
  }
  size_t *cnt = tp->counts[t];
  cnt[0] += n_obs;
  cnt[1] += n_fill;
  cnt[2] += n_unobs;
  cnt[3] += (e - b) * R - n_none;
}

static void free_scratch(map_ctx *m) {
  for (int t = 0; t < m->n_threads; t++) {
    if (m->touches) free(m->touches[t]);
    if (m->touches_tmp) free(m->touches_tmp[t]);
    if (m->splats) free(m->splats[t]);
    if (m->sil) free(m->sil[t]);
    if (m->fan_scratch) free(m->fan_scratch[t]);
  }
  free(m->fan_scratch);
  /* worker 0's maxima are the result's arrays */
  for (int t = 1; m->max_code && t < m->n_threads; t++) free(m->max_code[t]);
  for (int t = 1; m->max_cos && t < m->n_threads; t++) free(m->max_cos[t]);
  free(m->max_code);
  free(m->max_cos);
  free(m->touches);
  free(m->touches_tmp);
  for (int t = 0; m->scratch_q && t < m->n_threads; t++) free(m->scratch_q[t]);
  for (int t = 0; m->scratch_d && t < m->n_threads; t++) free(m->scratch_d[t]);
  free(m->scratch_q);
  free(m->scratch_d);
  for (size_t v = 0; m->rec_q && v < m->n_views; v++) free(m->rec_q[v]);
  for (size_t v = 0; m->rec_d && v < m->n_views; v++) free(m->rec_d[v]);
  free(m->rec_q);
  free(m->rec_d);
  free(m->n_rec);
  free(m->splats);
  free(m->sil);
  free(m->hit_t);
  free(m->hit_tri);
  free(m->hit_b1);
  free(m->hit_b2);
  free(m->ray_org);
  free(m->ray_dir);
  free(m->hits);
}


hearth_status hearth_map_views_with_layout(const hearth_map_layout *l, const hearth_raycaster *rc_in,
                                          const hearth_map_view *views, size_t n_views,
                                          const hearth_map_opts *opts_in, hearth_map_result *out,
                                          hearth_map_timing *timing, hearth_err *err) {
  double t_start = hearth_now();
  memset(out, 0, sizeof *out);
  hearth_map_opts opts;
  if (opts_in) opts = *opts_in;
  else hearth_map_opts_default(&opts);
  if (opts.pixel_stride < 1) opts.pixel_stride = 1;
  if (!views && n_views) return hearth_err_set(err, HEARTH_E_ARG, "map: missing views");
  if (opts.resolution != l->R || (size_t)opts.pixel_stride != l->stride)
    return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "map: the layout was made for resolution %zu, stride %zu; asked for %zu, %d", l->R,
                          l->stride, opts.resolution, opts.pixel_stride);
  const hearth_mesh *mesh = l->mesh;
  const hearth_camera *cam = &l->cam;
  const size_t R = l->R, N = R * R, np = l->np;
  int C = 0;
  for (size_t v = 0; v < n_views; v++) {
    const hearth_image *im = views[v].image;
    if (!im || !im->data) return hearth_err_set(err, HEARTH_E_ARG, "map: view %zu has no image", v);
    if (im->width != (size_t)cam->width || im->height != (size_t)cam->height)
      return hearth_err_set(err, HEARTH_E_SIZE, "map: view %zu is %zux%zu, the camera is %dx%d", v,
                            im->width, im->height, cam->width, cam->height);
    int c = im->type == HEARTH_PIX_F32 && im->channels == 1 ? 1
            : im->type == HEARTH_PIX_U8 && im->channels >= 3 ? 3 : 0;
    if (!c) return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "map: view %zu: need F32 gray or U8 RGB", v);
    if (C && c != C) return hearth_err_set(err, HEARTH_E_INCONSISTENT, "map: views mix image kinds");
    C = c;
  }
  if (!C) C = 1;
  if (opts.fusion == HEARTH_FUSE_ROBUST && C != 1)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "map: robust fusion is for temperatures only");
  hearth_status s = HEARTH_OK;
  map_ctx m;
  memset(&m, 0, sizeof m);
  hearth_raycaster *own_rc = NULL;
  uint8_t *view_fan = calloc(n_views ? n_views : 1, 1);
  island_box *parts = NULL;
  if (!view_fan) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  double t_cast0 = hearth_now();
  const double *sphere = l->sphere;
  /* a view whose camera has the whole mesh (its bounding sphere, with a
     margin) in front is rasterised through the fan; any other view casts
     rays, through a ray caster built only then */
  int need_rays = 0;
  for (size_t v = 0; v < n_views; v++) {
    const hearth_rigid *T = &views[v].T_world_from_cam;
    double d[3] = {sphere[0] - T->t[0], sphere[1] - T->t[1], sphere[2] - T->t[2]};
    double z = T->R[2] * d[0] + T->R[5] * d[1] + T->R[8] * d[2];
    view_fan[v] = l->fan && !opts.trace_rays && z > sphere[3] * (1.0 + 1e-6) + 1e-9;
    need_rays |= !view_fan[v];
  }
  if (need_rays && !rc_in) {
    double t0 = hearth_now();
    if ((s = hearth_raycaster_new(mesh, &own_rc, err))) goto done;
    if (timing) timing->build = hearth_now() - t0;
    t_cast0 = hearth_now();
  }
  int nt = opts.threads > 0 ? opts.threads : hearth_default_threads();
  if ((size_t)nt > n_views) nt = n_views ? (int)n_views : 1;
  m = (map_ctx){.mesh = mesh, .rc = rc_in ? rc_in : own_rc, .cam = cam, .views = views,
                .n_views = n_views, .opts = &opts, .R = R, .C = C, .island_of_texel = l->island_of_texel,
                .island_of_tri = l->island_of_tri, .n_islands = l->n_islands, .tri_normal = l->tri_normal, .n_pix = np,
                .pix_w = l->pw, .pix_h = l->ph, .pix_dir = l->pix_dir, .pix_index = l->pix_index,
                .tile_order = l->tile_order, .sphere = {sphere[0], sphere[1], sphere[2], sphere[3]},
                .fan = l->fan, .view_fan = view_fan, .n_threads = nt,
                .cast_threads = opts.threads > 0 ? opts.threads : hearth_default_threads()};
  m.touches = calloc((size_t)nt, sizeof *m.touches);
  m.touches_tmp = calloc((size_t)nt, sizeof *m.touches_tmp);
  m.sil = calloc((size_t)nt, sizeof *m.sil);
  m.splats = calloc((size_t)nt, sizeof *m.splats);
  m.fan_scratch = calloc((size_t)nt, sizeof *m.fan_scratch);
  m.rec_q = calloc(n_views ? n_views : 1, sizeof *m.rec_q);
  m.rec_d = calloc(n_views ? n_views : 1, sizeof *m.rec_d);
  m.n_rec = calloc(n_views ? n_views : 1, sizeof *m.n_rec);
  m.scratch_q = calloc((size_t)nt, sizeof *m.scratch_q);
  m.scratch_d = calloc((size_t)nt, sizeof *m.scratch_d);
  m.hit_t = hearth_alloc_array(np * (size_t)nt, sizeof(float));
  m.hit_tri = hearth_alloc_array(np * (size_t)nt, sizeof(uint32_t));
  m.hit_b1 = hearth_alloc_array(np * (size_t)nt, sizeof(float));
  m.hit_b2 = hearth_alloc_array(np * (size_t)nt, sizeof(float));
  m.ray_org = hearth_alloc_array(np * (size_t)nt, 3 * sizeof(float));
  m.ray_dir = hearth_alloc_array(np * (size_t)nt, 3 * sizeof(float));
  m.hits = hearth_alloc_array(np * (size_t)nt, sizeof(hearth_ray_hit));
  m.view_hits = calloc(n_views ? n_views : 1, sizeof *m.view_hits);
  m.dense = opts.fusion == HEARTH_FUSE_MAX;
  const int want_cos = !opts.skip_best_cos;
  m.max_code = calloc((size_t)nt, sizeof *m.max_code);
  if (want_cos) m.max_cos = calloc((size_t)nt, sizeof *m.max_cos);
  int bad = !m.touches || !m.touches_tmp || !m.sil || !m.splats || !m.fan_scratch || !m.rec_q || !m.rec_d ||
            !m.n_rec || !m.scratch_q || !m.scratch_d || !m.hit_t || !m.hit_tri || !m.hit_b1 || !m.hit_b2 ||
            !m.ray_org || !m.ray_dir || !m.hits || !m.view_hits || !m.max_code || (want_cos && !m.max_cos);
  if (!bad && m.dense) {
    /* the workers' maps, zeroed below (no maximum yet); worker 0's are the
       result's arrays */
    out->observed = hearth_alloc_array(N, (size_t)C * sizeof(float));
    m.max_code[0] = (uint32_t *)(void *)out->observed;
    if (want_cos) m.max_cos[0] = out->best_cos = hearth_alloc_array(N, sizeof(float));
    for (int t = 1; t < nt; t++) {
      m.max_code[t] = hearth_alloc_array(N, (size_t)C * sizeof(uint32_t));
      if (want_cos) m.max_cos[t] = hearth_alloc_array(N, sizeof(float));
    }
    for (int t = 0; t < nt; t++) bad |= !m.max_code[t] || (want_cos && !m.max_cos[t]);
    if (!bad) hearth_parallel_chunks(R, 32, nt, zero_maps, &m);
  }
  for (int t = 0; !bad && t < nt; t++) {
    m.sil[t] = hearth_alloc_array(np, 1);
    m.splats[t] = hearth_alloc_array(np, sizeof(splat));
    m.touches[t] = hearth_alloc_array(np, 4 * sizeof(touch));
    m.touches_tmp[t] = hearth_alloc_array(np, 4 * sizeof(touch));
    if (l->fan) {
      m.fan_scratch[t] = calloc(1, hearth_ray_fan_scratch_size(l->fan, mesh->n_vertices));
      bad |= !m.fan_scratch[t];
    }
    if (!m.dense) {
      m.scratch_q[t] = hearth_alloc_array(np, 4 * sizeof(uint32_t));
      m.scratch_d[t] = hearth_alloc_array(np, 4 * REC_WORDS(C) * sizeof(float));
      bad |= !m.scratch_q[t] || !m.scratch_d[t];
    }
    bad |= !m.sil[t] || !m.splats[t] || !m.touches[t] || !m.touches_tmp[t];
  }
  if (bad) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory for %d threads at R=%zu", nt, R);
    goto done;
  }
  hearth_parallel_chunks(n_views, 1, nt, views_range, &m);
  if (m.failed == 2) {
    s = hearth_err_set(err, HEARTH_E_NUMERIC, "map: a view's camera does not have the mesh in front after all");
    goto done;
  }
  if (m.failed) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory while fusing views");
    goto done;
  }
  double t_fuse0 = hearth_now();
  if (timing) timing->cast = t_fuse0 - t_cast0;

  /* results */
  out->R = R;
  out->channels = C;
  out->n_views = n_views;
  if (!m.dense) out->observed = hearth_alloc_array(N, (size_t)C * sizeof(float));
  out->filled = hearth_alloc_array(N, (size_t)C * sizeof(float));
  /* every texel of these is written by fuse_bands */
  out->mask = hearth_alloc_array(N, 1);
  if (!m.dense && want_cos) out->best_cos = hearth_alloc_array(N, sizeof(float));
  out->view_hits = m.view_hits;
  m.view_hits = NULL;
  /* per worker of the fusion: the islands' boxes, empty */
  const size_t nparts = (size_t)nt * ((size_t)l->n_islands + 1);
  parts = hearth_alloc_array(nparts, sizeof *parts);
  for (size_t i = 0; parts && i < nparts; i++) parts[i] = (island_box){INT32_MAX, INT32_MAX, -1, -1, 0, 0};
  if (!out->observed || !out->filled || !out->mask || (want_cos && !out->best_cos) || !parts) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
    goto done;
  }
  {
    const size_t rows = R < BAND_TEXELS ? BAND_TEXELS / R : 1;
    int *nomem = calloc((size_t)nt, sizeof *nomem), failed = !nomem;
    texel_pass tp = {&m, out, parts, NULL, nomem};
    if (nomem) hearth_parallel_chunks((R + rows - 1) / rows, 4, nt, fuse_bands, &tp);
    for (int t = 0; nomem && t < nt; t++) failed |= nomem[t];
    free(nomem);
    if (failed) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory while fusing");
      goto done;
    }
  }
  double t_fill0 = hearth_now();
  if (timing) timing->fuse = t_fill0 - t_fuse0;
  if (map_fill_islands(R, (size_t)C, l->island_of_texel, l->n_islands, parts, nt, out->mask, out->observed,
                       out->filled, nt)) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory while filling");
    goto done;
  }
  {
    texel_pass tp = {&m, out, NULL, NULL, NULL};
    tp.counts = calloc((size_t)nt, sizeof *tp.counts);
    if (!tp.counts) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
      goto done;
    }
    hearth_parallel_chunks(R, 32, nt, count_rows, &tp);
    for (int t = 0; t < nt; t++) {
      out->n_observed += tp.counts[t][0];
      out->n_filled += tp.counts[t][1];
      out->n_unobserved += tp.counts[t][2];
      out->n_surface += tp.counts[t][3];
    }
    free(tp.counts);
  }
  if (timing) {
    timing->fill = hearth_now() - t_fill0;
    timing->total = hearth_now() - t_start;
  }
  s = HEARTH_OK;
done:
  free(view_fan);
  free_scratch(&m);
  free(m.view_hits);
  hearth_raycaster_free(own_rc);
  free(parts);
  if (s) hearth_map_result_free(out);
  return s;
}

hearth_status hearth_map_views_timed(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                     const hearth_camera *cam, const hearth_map_view *views,
                                     size_t n_views, const hearth_map_opts *opts,
                                     hearth_map_result *out, hearth_map_timing *timing,
                                     hearth_err *err) {
  memset(out, 0, sizeof *out);
  if (timing) memset(timing, 0, sizeof *timing);
  if (!views && n_views) return hearth_err_set(err, HEARTH_E_ARG, "map: missing views");
  double t0 = hearth_now();
  hearth_map_layout *l = NULL;
  hearth_status s = hearth_map_layout_new(mesh, cam, opts, &l, err);
  if (s) return s;
  double t1 = hearth_now();
  s = hearth_map_views_with_layout(l, rc, views, n_views, opts, out, timing, err);
  if (timing) {
    timing->raster = t1 - t0;
    timing->total = hearth_now() - t0;
  }
  hearth_map_layout_free(l);
  return s;
}

hearth_status hearth_map_views(const hearth_mesh *mesh, const hearth_raycaster *rc,
                               const hearth_camera *cam, const hearth_map_view *views,
                               size_t n_views, const hearth_map_opts *opts,
                               hearth_map_result *out, hearth_err *err) {
  return hearth_map_views_timed(mesh, rc, cam, views, n_views, opts, out, NULL, err);
}
