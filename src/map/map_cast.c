/* Casting and splatting one view (see map_internal.h).
 *
 * A view is done whole by one worker, in its own map_worker: its grid
 * pixels are cast (through the ray fan, or as traced rays), pixels near a
 * silhouette are dropped, every remaining hit splats its value bilinearly
 * into the UV map, and the view is reduced to one value per texel it
 * observes (the view's mean there, its weight and best viewing cosine).
 * For max fusion that value folds at once into the worker's maxima maps;
 * for robust and corrected fusion it becomes the view's record of the
 * texel. Mean fusion skips the reduction: the splats go into the sums.
 * Within a view, pixels are visited in raster order. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "map/map_internal.h"

#define MAX_BACKFACE_SKIPS 8
#define PREFETCH_AHEAD 8 /* touches ahead whose texel's island is prefetched */

int map_worker_alloc(map_worker *w, const hearth_map_layout *l, int C, int kind) {
  const size_t np = l->np;
  /* the rays' origins and directions in one block: a frame's hits fit in
     it once the rays are cast (6 words a pixel against 5) */
  w->ray_org = hearth_alloc_array(np, 6 * sizeof(float));
  w->ray_dir = w->ray_org ? w->ray_org + 3 * np : NULL;
  w->hits = hearth_alloc_array(np, sizeof(hearth_ray_hit));
  w->sil = hearth_alloc_array(np, 1);
  w->splats = hearth_alloc_array(np, sizeof(splat));
  int ok = w->ray_org && w->hits && w->sil && w->splats;
  if (kind != WORKER_SPLATS) {
    w->touches = hearth_alloc_array(np, 4 * sizeof(touch));
    w->touches_tmp = hearth_alloc_array(np, 4 * sizeof(touch));
    ok &= w->touches && w->touches_tmp;
  }
  if (l->fan) {
    w->fan_scratch = calloc(1, hearth_ray_fan_scratch_size(l->fan, l->mesh->n_vertices));
    ok &= w->fan_scratch != NULL;
  }
  if (kind == WORKER_RECORDS) {
    w->rec_q = hearth_alloc_array(np, 4 * sizeof(uint32_t));
    w->rec_d = hearth_alloc_array(np, 4 * REC_WORDS(C) * sizeof(float));
    ok &= w->rec_q && w->rec_d;
  }
  return ok;
}

void map_worker_free(map_worker *w) {
  free(w->ray_org); /* ray_dir lies in its block */
  free(w->hits);
  free(w->sil);
  free(w->splats);
  free(w->touches);
  free(w->touches_tmp);
  free(w->fan_scratch);
  free(w->rec_q);
  free(w->rec_d);
  memset(w, 0, sizeof *w);
}

static float image_value(const hearth_image *img, size_t idx, int c) {
  if (img->type == HEARTH_PIX_F32)
    return ((const float *)img->data)[idx * (size_t)img->channels + (size_t)c];
  return (float)((const uint8_t *)img->data)[idx * (size_t)img->channels + (size_t)c];
}

/* a box of grid pixels */
typedef struct pix_box {
  size_t x0, x1, y0, y1; /* inclusive; x0 > x1 when empty */
} pix_box;

/* A view's hits are kept in the frame of their box grown by the 2 pixels
 * the silhouette filter reads (clipped to the grid), row after row, so
 * that a view touches memory in proportion to its box rather than to the
 * rows of the camera's grid it spans. Fan views keep them in the worker's
 * hits array and traced ones in its rays' block; the other of the two is
 * the silhouette filters' scratch. */
typedef struct hit_frame {
  pix_box box;          /* the hits' box, grid pixels */
  size_t x0, y0, w, h;  /* the frame, grid pixels (w = h = 0 without hits) */
  hearth_ray_hit *hits; /* w * h: front-face hits, misses elsewhere (prim UINT32_MAX, t +inf) */
  float *scratch;       /* 2 * w * h floats */
} hit_frame;

static const hearth_ray_hit k_miss = {INFINITY, UINT32_MAX, 0.0f, 0.0f, 0};

/* the frame of box (its arrays not yet set), as the fan's framed cast
   makes it with a growth of 2 */
static void frame_of(const hearth_map_layout *l, const pix_box *box, hit_frame *f) {
  f->box = *box;
  f->x0 = f->y0 = f->w = f->h = 0;
  if (box->x0 > box->x1) return;
  f->x0 = box->x0 >= 2 ? box->x0 - 2 : 0;
  f->y0 = box->y0 >= 2 ? box->y0 - 2 : 0;
  f->w = (box->x1 + 2 < l->pw ? box->x1 + 2 : l->pw - 1) - f->x0 + 1;
  f->h = (box->y1 + 2 < l->ph ? box->y1 + 2 : l->ph - 1) - f->y0 + 1;
}

/* grid pixel (x, y)'s place in the frame */
static inline size_t frame_at(const hit_frame *f, size_t x, size_t y) {
  return (y - f->y0) * f->w + (x - f->x0);
}

static inline int front_hit(const hearth_ray_hit *h) { return h->prim != UINT32_MAX && h->front; }

static inline void box_add(pix_box *box, size_t x, size_t y) {
  if (x < box->x0) box->x0 = x;
  if (x > box->x1) box->x1 = x;
  if (y < box->y0) box->y0 = y;
  if (y > box->y1) box->y1 = y;
}

/* view v, whose camera has the whole mesh in front: rasterised through the
 * fan, its hits kept in the frame of their box grown by 2 (the fan's hits
 * are all front faces, so its box is the hits' box and its frame theirs) */
static void cast_fan(map_ctx *m, size_t v, map_worker *w, hit_frame *f) {
  const hearth_map_layout *l = m->l;
  size_t fb[4], fr[4];
  if (hearth_ray_fan_cast_framed(l->fan, l->mesh, &m->views[v].T_world_from_cam, w->fan_scratch, 2,
                                 w->hits, fb, fr, NULL)) {
    m->failed = 2; /* cannot happen: the bounding sphere lies in front */
    return;
  }
  /* the fan's frame is where it wrote the hits (all zero without hits) */
  f->box =
      fb[0] <= fb[1] ? (pix_box){fb[0], fb[1], fb[2], fb[3]} : (pix_box){SIZE_MAX, 0, SIZE_MAX, 0};
  f->x0 = fr[0];
  f->y0 = fr[1];
  f->w = fr[2];
  f->h = fr[3];
  f->hits = w->hits;
  f->scratch = w->ray_org;
}

/* the grid pixels in 4x4 tiles (coherent packets of 16): the block after (pw, ph) runs for
   each with x, y and its place i in that order */
#define FOR_TILED_PIXELS(pw, ph, ...)                                       \
  do {                                                                      \
    size_t i = 0;                                                           \
    for (size_t ty = 0; ty < (ph); ty += 4)                                 \
      for (size_t tx = 0; tx < (pw); tx += 4)                               \
        for (size_t y = ty; y < ty + 4 && y < (ph); y++)                    \
          for (size_t x = tx; x < tx + 4 && x < (pw); x++, i++) __VA_ARGS__ \
  } while (0)

/* view v by traced rays, in 4x4 pixel tiles (packets of nearly parallel
 * rays); rays that miss the mesh's bounding sphere are not cast at all, and
 * back faces are culled by continuing the ray behind them */
static void cast_rays(const map_ctx *m, size_t v, map_worker *w, hit_frame *f) {
  const hearth_map_layout *l = m->l;
  const hearth_rigid *T = &m->views[v].T_world_from_cam;
  const size_t n = l->np, pw = l->pw, ph = l->ph;
  float *org = w->ray_org, *dir = w->ray_dir;
  hearth_ray_hit *hits = w->hits;
  const double *S = l->sphere;
  double oc[3] = {S[0] - T->t[0], S[1] - T->t[1], S[2] - T->t[2]};
  double oc2 = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2];
  double r2 = S[3] * S[3];
  FOR_TILED_PIXELS(pw, ph, {
    const float *d = l->pix_dir + 3 * (y * pw + x);
    double wd[3];
    for (int k = 0; k < 3; k++)
      wd[k] = T->R[3 * k] * d[0] + T->R[3 * k + 1] * d[1] + T->R[3 * k + 2] * d[2];
    /* squared distance of the sphere centre from the ray (unit direction),
     * or from the origin when the centre lies behind it */
    double along = oc[0] * wd[0] + oc[1] * wd[1] + oc[2] * wd[2];
    double dist2 = along > 0 ? oc2 - along * along : oc2;
    int skip = dist2 > r2;
    for (int k = 0; k < 3; k++) {
      org[3 * i + k] = (float)T->t[k];
      dir[3 * i + k] = skip ? 0.0f : (float)wd[k]; /* a zero direction is not cast */
    }
  });
  /* views already run in parallel: cast on this thread only, unless there
     is a single worker for all views */
  hearth_raycast_batch_mt(m->rc, n, org, dir, 0.0f, INFINITY, hits,
                          m->n_threads > 1 ? 1 : m->cast_threads);
  /* back faces skipped, then the front hits' box; then the hits kept in
     its frame */
  pix_box box = {SIZE_MAX, 0, SIZE_MAX, 0};
  FOR_TILED_PIXELS(pw, ph, {
    hearth_ray_hit h = hits[i];
    for (int k = 0; k < MAX_BACKFACE_SKIPS && h.prim != UINT32_MAX && !h.front; k++) {
      double o[3] = {org[3 * i], org[3 * i + 1], org[3 * i + 2]};
      double d[3] = {dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]};
      double tn = (double)h.t * (1.0 + 1e-6) + 1e-7;
      if (!hearth_raycast(m->rc, o, d, tn, INFINITY, &h)) h.prim = UINT32_MAX;
    }
    hits[i] = h;
    if (front_hit(&h)) box_add(&box, x, y);
  });
  /* the rays are cast: their block holds the frame's hits, the hits'
     array is the scratch */
  frame_of(l, &box, f);
  f->hits = (hearth_ray_hit *)(void *)w->ray_org;
  f->scratch = (float *)(void *)w->hits;
  if (box.x0 > box.x1) return;
  for (size_t k = 0; k < f->w * f->h; k++) f->hits[k] = k_miss;
  FOR_TILED_PIXELS(pw, ph, {
    if (x >= box.x0 && x <= box.x1 && y >= box.y0 && y <= box.y1 && front_hit(&hits[i]))
      f->hits[frame_at(f, x, y)] = hits[i];
  });
}

/* silhouette flags: 1 if a grid pixel lies within 2 pixels of a
 * silhouette, i.e. a pixel in its 5x5 neighbourhood (clipped to the image)
 * misses the surface or lies at a clearly different depth (more than 3%).
 * The lens blur and the pixel footprint mix the two sides of such an edge,
 * so these pixels do not measure one surface. Computed with separable 5x5
 * minimum and maximum filters of the hit distance (a miss is +inf). Only
 * pixels inside the hits' box get flags; the filters read up to 2 pixels
 * beyond it, the rest of the frame, which holds misses there. Every array
 * is indexed within the frame, which the clipping to the image keeps
 * as it was: the frame ends 2 pixels beyond the box or at the image's
 * edge. */
static void silhouettes(const hit_frame *f, uint8_t *sil) {
  const size_t W = f->w, H = f->h;
  const hearth_ray_hit *ht = f->hits;
  float *tmp_lo = f->scratch, *tmp_hi = f->scratch + W * H;
  const pix_box b = {f->box.x0 - f->x0, f->box.x1 - f->x0, f->box.y0 - f->y0, f->box.y1 - f->y0};
  size_t ry0 = b.y0 >= 2 ? b.y0 - 2 : 0, ry1 = b.y1 + 2 < H ? b.y1 + 2 : H - 1;
  for (size_t y = ry0; y <= ry1; y++) {
    const hearth_ray_hit *r = ht + y * W;
    for (size_t x = b.x0; x <= b.x1; x++) {
      size_t a = x >= 2 ? x - 2 : 0, e = x + 2 < W ? x + 2 : W - 1;
      float mn = r[a].t, mx = r[a].t;
      for (size_t k = a + 1; k <= e; k++) {
        mn = r[k].t < mn ? r[k].t : mn;
        mx = r[k].t > mx ? r[k].t : mx;
      }
      tmp_lo[y * W + x] = mn;
      tmp_hi[y * W + x] = mx;
    }
  }
  /* the vertical pass, and each pixel's flag from its neighbourhood's
     extremes */
  for (size_t y = b.y0; y <= b.y1; y++) {
    size_t a = y >= 2 ? y - 2 : 0, e = y + 2 < H ? y + 2 : H - 1;
    for (size_t x = b.x0; x <= b.x1; x++) {
      const size_t p = y * W + x;
      const float t0 = ht[p].t;
      if (!isfinite(t0)) {
        sil[p] = 1;
        continue;
      }
      float lo = tmp_lo[a * W + x], hi = tmp_hi[a * W + x];
      for (size_t k = a + 1; k <= e; k++) {
        float lv = tmp_lo[k * W + x], hv = tmp_hi[k * W + x];
        lo = lv < lo ? lv : lo;
        hi = hv > hi ? hv : hi;
      }
      float tol = 0.03f * t0;
      sil[p] = !isfinite(hi) || hi - t0 > tol || t0 - lo > tol;
    }
  }
}

/* crease flags, added to the silhouette flags sil: a hit pixel whose 3 x 3
 * neighbourhood (within the hits' box) hits a face whose normal is more
 * than acos(cmin) off its own face's. Bit 1 marks them while the
 * neighbourhoods are read, then they become 1. */
static void creases(const hearth_map_layout *l, const hit_frame *f, float cmin, uint8_t *sil) {
  const pix_box *b = &f->box;
  const hearth_ray_hit *fh = f->hits;
  for (size_t y = b->y0; y <= b->y1; y++)
    for (size_t x = b->x0; x <= b->x1; x++) {
      const size_t fk = frame_at(f, x, y);
      if (fh[fk].prim == UINT32_MAX || sil[fk]) continue;
      const float *n0 = l->tri_normal + 3 * (size_t)fh[fk].prim;
      int cr = 0;
      for (size_t yy = y > b->y0 ? y - 1 : y; yy <= y + 1 && yy <= b->y1 && !cr; yy++)
        for (size_t xx = x > b->x0 ? x - 1 : x; xx <= x + 1 && xx <= b->x1 && !cr; xx++) {
          const uint32_t t1 = fh[frame_at(f, xx, yy)].prim;
          if (t1 == UINT32_MAX) continue;
          const float *n1 = l->tri_normal + 3 * (size_t)t1;
          cr = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] < cmin;
        }
      if (cr) sil[fk] = 2;
    }
  for (size_t y = b->y0; y <= b->y1; y++)
    for (size_t x = b->x0; x <= b->x1; x++)
      if (sil[frame_at(f, x, y)] == 2) sil[frame_at(f, x, y)] = 1;
}

/* The splats of view v's hits within box, in raster order: hits at a
 * silhouette (with edges) or seen more obliquely than min_cos are dropped,
 * and so are footprints entirely off the map. *n_hits counts the hits kept
 * before that last test (the view's pixels on the surface). */
static size_t splat_hits(const map_ctx *m, size_t v, const hearth_image *img, int grid,
                         map_worker *w, const hit_frame *f, int edges, uint32_t *n_hits) {
  const pix_box *box = &f->box;
  const hearth_map_layout *l = m->l;
  const size_t st = l->stride, W = (size_t)l->cam.width;
  const hearth_mesh *mesh = l->mesh;
  const size_t R = l->R;
  const int C = m->C;
  const double *Rw = m->views[v].T_world_from_cam.R;
  const float min_cos = (float)m->opts->min_cos;
  const hearth_ray_hit *fh = f->hits;
  const uint8_t *sil = w->sil;
  splat *sp = w->splats;
  uint32_t hits = 0;
  size_t n_sp = 0;
  for (size_t py = box->y0; py <= box->y1 && box->x0 <= box->x1; py++) {
    for (size_t px = box->x0; px <= box->x1; px++) {
      const size_t p = py * l->pw + px, fk = frame_at(f, px, py);
      uint32_t tri = fh[fk].prim;
      if (tri == UINT32_MAX) continue;
      if (edges && sil[fk]) continue;
      const float *nrm = l->tri_normal + 3 * (size_t)tri, *dc = l->pix_dir + 3 * p;
      float d[3];
      for (int k = 0; k < 3; k++)
        d[k] = (float)(Rw[3 * k] * dc[0] + Rw[3 * k + 1] * dc[1] + Rw[3 * k + 2] * dc[2]);
      float cosv = -(nrm[0] * d[0] + nrm[1] * d[1] + nrm[2] * d[2]);
      if (cosv < min_cos) continue;
      hits++;
      /* UV of the hit point */
      const uint32_t *ix = mesh->indices + 3 * (size_t)tri;
      float b1 = fh[fk].b1, b2 = fh[fk].b2, b0 = 1.0f - b1 - b2;
      float u = b0 * mesh->uvs[2 * ix[0]] + b1 * mesh->uvs[2 * ix[1]] + b2 * mesh->uvs[2 * ix[2]];
      float vv = b0 * mesh->uvs[2 * ix[0] + 1] + b1 * mesh->uvs[2 * ix[1] + 1] +
                 b2 * mesh->uvs[2 * ix[2] + 1];
      double x = (double)u * (double)R - 0.5, y = (double)vv * (double)R - 0.5;
      double x0f = floor(x), y0f = floor(y);
      if (!(x0f >= -1.0 && y0f >= -1.0 && x0f < (double)R && y0f < (double)R)) continue;
      splat *e = &sp[n_sp++];
      e->fx = x - x0f;
      e->fy = y - y0f;
      e->x0 = (int16_t)x0f;
      e->y0 = (int16_t)y0f;
      e->island = l->island_of_tri[tri];
      if (l->cos_normal) {
        /* the viewing cosine from the smoothed normal (the hit stays the
           face's); a face turned away from it counts as grazing */
        const float *sn = l->cos_normal + 3 * (size_t)tri;
        cosv = -(sn[0] * d[0] + sn[1] * d[1] + sn[2] * d[2]);
        if (cosv < 0.01f) cosv = 0.01f;
      }
      e->cosv = cosv;
      /* the camera pixel of grid pixel p */
      size_t src = grid ? p : (py * st) * W + px * st;
      /* one channel: F32 temperatures; three: U8 colour (view_channels) */
      if (C == 1) e->val.t = image_value(img, src, 0);
      else
        for (int c = 0; c < 3; c++)
          e->val.rgb[c] = ((const uint8_t *)img->data)[src * (size_t)img->channels + (size_t)c];
    }
  }
  *n_hits = hits;
  return n_sp;
}

/* The touches of n_sp splats, sorted by texel (pixel order within a
 * texel): in w->touches or w->touches_tmp, whichever the sort ended in.
 * *n_out is their count. */
static const touch *sorted_touches(map_worker *w, size_t n_sp, size_t R, size_t *n_out) {
  const splat *sp = w->splats;
  touch *tc = w->touches;
  size_t n_tc = 0;
  for (size_t i = 0; i < n_sp; i++) {
    const splat *e = &sp[i];
    for (int k = 0; k < 4; k++) {
      uint32_t q;
      float wk;
      if (splat_corner(e, k, R, &q, &wk)) tc[n_tc++] = (touch){q, (uint32_t)(4 * i + (size_t)k)};
    }
  }
  /* stable LSD radix sort by texel, 11-bit digits (at most 3: R <= 16384
     gives 28 bits), every digit's histogram from one read */
  touch *src = tc, *dst = w->touches_tmp;
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
  *n_out = n_tc;
  return src;
}

/* max fusion: a view's mean at texel q folded into a worker's maxima */
static inline void fold_max(uint32_t *mc, float *mcos, uint32_t q, int C, float wsum,
                            float best_cos, const float sum[3]) {
  /* + 0.0f: a negative zero becomes +0, so equal means give one code */
  if (mcos && best_cos > mcos[q]) mcos[q] = best_cos;
  for (int c = 0; c < C; c++) {
    uint32_t code = max_code(sum[c] / wsum + 0.0f);
    if (code > mc[(size_t)q * (size_t)C + (size_t)c]) mc[(size_t)q * (size_t)C + (size_t)c] = code;
  }
}

/* robust and corrected fusion: a view's record of texel q, at d (see REC_WORDS) */
static inline void put_record(float *d, int C, float wsum, float best_cos, const float sum[3]) {
  d[0] = wsum;
  d[1] = best_cos;
  /* + 0.0f: a negative zero becomes +0, so equal means cannot make the
     maximum's bits depend on which view came first */
  for (int c = 0; c < C; c++) d[2 + c] = sum[c] / wsum + 0.0f;
}

/* Each texel's touches in pixel order, splatted only from the texel's own
 * island: folded into worker t's maxima (max fusion), or made records in
 * the worker's scratch. Returns the records' count. */
static size_t reduce_touches(const map_ctx *m, map_worker *w, const touch *tc, size_t n_tc, int t) {
  const uint32_t *iot = m->l->island_of_texel;
  const int C = m->C;
  const size_t RW = REC_WORDS(C);
  const splat *sp = w->splats;
  uint32_t *mc = m->max ? m->max->code[t] : NULL;
  float *mcos = m->max && m->max->cos ? m->max->cos[t] : NULL;
  size_t n_rec = 0;
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
      float wk = corner_weight(e, (int)(tc[k].sk & 3));
      wsum += wk;
      for (int c = 0; c < C; c++) sum[c] += wk * splat_value(e, C, c);
    }
    i = j;
    if (!any) continue;
    if (mc) {
      fold_max(mc, mcos, q, C, wsum, best_cos, sum);
      continue;
    }
    w->rec_q[n_rec] = q;
    put_record(w->rec_d + n_rec * RW, C, wsum, best_cos, sum);
    n_rec++;
  }
  return n_rec;
}

/* view v's n records, made in w's scratch, kept in their own allocation */
static void keep_records(map_ctx *m, size_t v, const map_worker *w, size_t n) {
  const size_t RW = REC_WORDS(m->C);
  view_records *r = m->rec;
  r->n[v] = n;
  r->q[v] = hearth_alloc_array(n ? n : 1, sizeof *w->rec_q);
  r->d[v] = hearth_alloc_array(n ? n : 1, RW * sizeof *w->rec_d);
  if (!r->q[v] || !r->d[v]) {
    m->failed = 1;
    return;
  }
  memcpy(r->q[v], w->rec_q, n * sizeof *w->rec_q);
  memcpy(r->d[v], w->rec_d, n * RW * sizeof *w->rec_d);
}

/* view v's image made by the caller's loader into img, checked against
   the camera and the views' kind; 0 (the error in m->load_errs[v]) when
   it cannot be had */
static int load_view(map_ctx *m, size_t v, hearth_image *img) {
  hearth_err *e = &m->load_errs[v];
  if (m->opts->load(m->opts->load_ctx, v, img, e)) return 0;
  const hearth_camera *cam = &m->l->cam;
  int kind = img->type == HEARTH_PIX_F32 && img->channels == 1  ? 1
             : img->type == HEARTH_PIX_U8 && img->channels >= 3 ? 3
                                                                : 0;
  /* the camera's image, or with load_grid its pixel grid's */
  const int grid = m->opts->load_grid;
  size_t w = grid ? m->l->pw : (size_t)cam->width, h = grid ? m->l->ph : (size_t)cam->height;
  if (!img->data || img->width != w || img->height != h)
    hearth_err_set(e, HEARTH_E_SIZE, "map: view %zu is %zux%zu, the camera%s is %zux%zu", v,
                   img->width, img->height, grid ? "'s pixel grid" : "", w, h);
  else if (kind != m->C)
    hearth_err_set(e, HEARTH_E_INCONSISTENT, "map: view %zu: its image is not of the views' kind",
                   v);
  else return 1;
  hearth_image_free(img);
  return 0;
}

/* view v on worker t; returns whether its splats went into the mean
   fusion's sums (0 for the other rules, and for a view that failed) */
static int process_view(map_ctx *m, size_t v, int t) {
  const hearth_map_layout *l = m->l;
  map_worker *w = &m->workers[t];
  hit_frame f = {{1, 0, 1, 0}, 0, 0, 0, 0, NULL, NULL}; /* no hit: empty */
  hearth_image own = {0};
  const hearth_image *img = m->views[v].image;
  if (!img) {
    /* every view tries its load, so the lowest failure is found */
    if (!load_view(m, v, &own)) {
      m->failed = 3;
      return 0;
    }
    img = &own;
  }
  if (m->view_fan[v]) cast_fan(m, v, w, &f);
  else cast_rays(m, v, w, &f);
  if (m->failed) {
    hearth_image_free(&own);
    return 0;
  }
  if (f.box.x0 > f.box.x1) f.box = (pix_box){1, 0, 1, 0}; /* no hit: empty */
  const int edges = m->opts->fusion == HEARTH_FUSE_ROBUST ||
                    m->opts->fusion == HEARTH_FUSE_CORRECTED || !m->opts->keep_edges;
  if (edges && f.box.x0 <= f.box.x1) {
    silhouettes(&f, w->sil);
    if (m->opts->crease_deg > 0)
      creases(l, &f, (float)cos(m->opts->crease_deg * M_PI / 180.0), w->sil);
  }
  uint32_t hits = 0;
  size_t n_sp = splat_hits(m, v, img, own.data && m->opts->load_grid, w, &f, edges, &hits);
  hearth_image_free(&own); /* the splats hold the values */
  m->view_hits[v] = hits;
  if (m->rec && m->rec->acc) {
    /* mean fusion: the splats into the sums, in view order */
    map_splats_fold(m->rec, v, w->splats, n_sp, l->island_of_texel, l->R, m->C);
    return 1;
  }
  size_t n_tc = 0;
  const touch *tc = sorted_touches(w, n_sp, l->R, &n_tc);
  size_t n_rec = reduce_touches(m, w, tc, n_tc, t);
  if (m->rec) keep_records(m, v, w, n_rec);
  return 0;
}

/* views are handed out one at a time to whichever worker is free (they
   differ in cost, and a shared machine slows workers unevenly); a view's
   records do not depend on the worker. For mean fusion a view that failed
   still takes its turn, folding nothing, so that the views after it do
   not wait for it (the mapping fails). */
void map_cast_views(void *ctx, size_t b, size_t e, int t) {
  map_ctx *m = ctx;
  for (size_t v = b; v < e; v++)
    if (!process_view(m, v, t) && m->rec && m->rec->acc)
      map_splats_fold(m->rec, v, NULL, 0, m->l->island_of_texel, m->l->R, m->C);
}
