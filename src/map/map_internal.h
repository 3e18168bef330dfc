/* Private to the map area: the state the phases of a mapping share.
 *
 * hearth_map_views_with_layout (map_core.c) runs them in turn:
 *   map_layout.c  the layout: UV raster and islands, triangle normals, the
 *                 mesh's bounding sphere, the camera's pixel grid and ray fan
 *   map_cast.c    each view cast and splatted by one worker and reduced to
 *                 one value per texel it observes, folded into the fusion
 *                 rule's state (max_maps or view_records); for mean fusion
 *                 the splats themselves are folded into the sums
 *   map_fuse.c    fusion across views over bands of whole texel rows
 *   map_fill.c    the nearest-observed fill within each UV island
 *
 * Nothing is shared between workers while it is written: each worker casts
 * into its own map_worker, folds into its own maxima maps or its view's
 * records, and each band of the fusion writes only its slice of the maps.
 * Maxima do not depend on which worker saw which view, and records are
 * folded in view order: the result does not depend on the thread count. */
#ifndef HEARTH_MAP_INTERNAL_H
#define HEARTH_MAP_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include "hearth/map.h"

/* The part of a mapping fixed by the mesh, the camera, the resolution and
 * the pixel stride; read-only once made (map_layout.c). */
struct hearth_map_layout {
  const hearth_mesh *mesh;
  hearth_camera cam;
  size_t R, stride;
  uint32_t *island_of_tri;
  uint32_t *island_of_texel; /* R * R; UINT32_MAX off the surface */
  uint32_t n_islands;
  float *tri_normal; /* 3 per triangle, unit */
  float *cos_normal; /* 3 per triangle, unit: the smoothed normals the viewing
                           cosines take (opts normal_passes > 0), else NULL */
  int normal_passes;
  double sphere[4];     /* mesh bounding sphere: rays that miss it are not cast */
  size_t pw, ph, np;    /* pixel grid: every stride-th pixel */
  const float *pix_dir; /* 3 per grid pixel, camera frame, unit (0: never cast); the
                           fan's own directions where there is a fan */
  int own_pix_dir;      /* pix_dir is the layout's (no fan) */
  hearth_ray_fan *fan;  /* the pixel grid as a ray fan; NULL where it cannot hold it */
};

/* a view's record of a texel: the texel's index (in the q arrays), then
 * REC_WORDS(C) floats: the weight (sum of bilinear weights), the best
 * viewing cosine and per channel the mean (the weighted sum for mean
 * fusion) */
#define REC_WORDS(C) (2 + (size_t)(C))
#define BAND_TEXELS 16384 /* texels per band of the fusion phase (whole rows) */

/* one hit pixel's splat: its bilinear footprint, island, cosine and value
   (32 bytes: a view's splats are the mapping's largest scratch) */
typedef struct splat {
  double fx, fy;  /* bilinear fractions */
  int16_t x0, y0; /* lower-left texel of the 2 x 2 footprint: -1..R-1, R <= 16384 */
  uint32_t island;
  float cosv;
  union {
    float t;        /* one channel: the temperature */
    uint8_t rgb[3]; /* three: the colour (views of three channels are U8) */
  } val;
} splat;

/* channel c of a splat's value, of C channels */
static inline float splat_value(const splat *e, int C, int c) {
  return C == 1 ? e->val.t : (float)e->val.rgb[c];
}

/* the bilinear weight of corner k (bit 0: +x, bit 1: +y) of a splat */
static inline float corner_weight(const splat *e, int k) {
  return (float)(((k & 1) ? e->fx : 1.0 - e->fx) * ((k >> 1) ? e->fy : 1.0 - e->fy));
}

/* corner k of a splat (see corner_weight) in an R x R map: 1 with its
   texel in *q and its weight in *wk when the corner lies on the map and
   weighs anything, else 0 */
static inline int splat_corner(const splat *e, int k, size_t R, uint32_t *q, float *wk) {
  const long tx = (long)e->x0 + (k & 1), ty = (long)e->y0 + (k >> 1);
  if (tx < 0 || ty < 0 || tx >= (long)R || ty >= (long)R) return 0;
  *wk = corner_weight(e, k);
  *q = (uint32_t)((size_t)ty * R + (size_t)tx);
  return *wk > 0.0f;
}

/* One bilinear touch of a texel by a splat within one view; a view's
 * touches are sorted by texel (stably: pixel order within a texel) and
 * reduced in one pass, each texel's sums added up in the same order as
 * pixel by pixel. */
typedef struct touch {
  uint32_t q;  /* texel */
  uint32_t sk; /* 4 * (index into the view's splats) + corner (bit 0: +x, bit 1: +y) */
} touch;

/* One worker's scratch for casting and splatting a view; each array holds
 * one view (the pixel grid's np pixels, or 4 touches a pixel). The worker
 * owns every array. */
typedef struct map_worker {
  float *ray_org, *ray_dir;     /* 3 * np each, one block: traced rays; after their cast, the
                               frame's hits (map_cast.c), or a fan view's filter scratch */
  hearth_ray_hit *hits;         /* np: the cast's hits (a fan view's in its frame); after a traced
                               view's, its filter scratch */
  uint8_t *sil;                 /* np: silhouette flags, in the frame */
  splat *splats;                /* np */
  touch *touches, *touches_tmp; /* 4 * np: a view's touches and the sort's second buffer
                                   (NULL for mean fusion, which folds the splats) */
  void *fan_scratch;            /* the ray fan's scratch (NULL without a fan) */
  uint32_t *rec_q;              /* 4 * np: robust and corrected fusion: a view's records, */
  float *rec_d;                 /* made here, then kept in view_records (else NULL) */
} map_worker;

/* what a worker's scratch holds beyond the cast and the splats */
enum {
  WORKER_MAXIMA = 0,  /* max fusion: touches, reduced into the worker's maxima */
  WORKER_RECORDS = 1, /* robust and corrected fusion: touches reduced to records */
  WORKER_SPLATS = 2   /* mean fusion: the splats alone, folded into the sums */
};

/* Max fusion: each worker folds its views' means into maps of its own (the
 * maximum does not depend on the order); the fusion merges them. */
typedef struct max_maps {
  int n;           /* workers */
  uint32_t **code; /* per worker: R * R * C maxima as order-preserving codes (see max_code), 0 none */
  float **cos;     /* per worker: R * R best viewing cosines, 0 none; NULL with skip_best_cos */
} max_maps;

/* Robust and corrected fusion: each view's records (see REC_WORDS), sorted
 * by texel, in an allocation of their own size; the fusion folds them in
 * view order. Mean fusion needs no records: a view's splats go into
 * per-texel sums, corner by corner in pixel order, once every view before
 * it has gone in (the sums see the views in view order whatever the
 * threads). A worker whose view is done before its turn waits for it with
 * the splats in its scratch: a copy would cost the memory of a view's
 * splats at the moment the sums are fullest. */
typedef struct view_records {
  size_t n_views;
  uint32_t **q; /* robust and corrected fusion, per view: n[v] texels (NULL for mean) */
  float **d;    /* per view: n[v] * REC_WORDS(C) words (NULL for mean) */
  size_t *n;    /* (NULL for mean) */
  /* mean fusion (NULL otherwise): R * R * C sums of the weighted values and
     R * R sums of the weights, zero where no view observed; the fusion
     turns acc into the result's observed map in place (acc_owned 0) */
  float *acc, *acc_w;
  int acc_owned;
  float *best_cos;     /* R * R best viewing cosines (0: none); NULL with skip_best_cos */
  size_t next;         /* mean fusion: the first view not yet folded */
  pthread_mutex_t mu;  /* guards next */
  pthread_cond_t turn; /* next moved */
  int have_mu;
} view_records;

/* one mapping of a view set: what the cast and fusion phases read, and the
 * fusion rule's state they write */
typedef struct map_ctx {
  const hearth_map_layout *l;
  const hearth_raycaster *rc; /* for views that trace rays */
  const hearth_map_view *views;
  size_t n_views;
  const hearth_map_opts *opts;
  int C;                   /* channels */
  int n_threads;           /* workers over views */
  int cast_threads;        /* threads for ray casting when one worker does every view */
  const uint8_t *view_fan; /* per view: the mesh lies in front, the fan applies */
  map_worker *workers;     /* n_threads */
  max_maps *max;           /* max fusion, else NULL */
  view_records *rec;       /* mean and robust fusion, else NULL */
  uint32_t *view_hits;     /* per view: pixels on the surface */
  hearth_err *load_errs;   /* per view, with opts->load: its load's error (status 0: none) */
  double corr_ambient;     /* corrected fusion: the ambient estimate (degC) */
  double corr_rate;        /* corrected fusion: the cooling rate (1/s) towards it */
  float *corr_best;        /* corrected fusion: per texel, the best viewing cosine of its
                              records (R * R, 0 without any); owned */
  _Atomic int failed;      /* 1 out of memory, 2 a view not in front after all, 3 a load failed
                              (load_errs) */
} map_ctx;

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

/* map_cast.c */
/* The scratch of one worker for the layout's pixel grid and C channels
 * (kind: WORKER_MAXIMA, _RECORDS or _SPLATS). Returns 0 out of memory;
 * map_worker_free frees what was made. */
int map_worker_alloc(map_worker *w, const hearth_map_layout *l, int C, int kind);
void map_worker_free(map_worker *w);
/* views [b, e) on worker t (a hearth_parallel_chunks function over m) */
void map_cast_views(void *ctx, size_t b, size_t e, int t);

/* map_fuse.c */
/* n workers' maxima maps for R x R texels, zeroed; worker 0's are the
 * result's observed and best_cos arrays (best_cos only with want_cos), so
 * out owns them, the maps the others. Returns 0 out of memory. */
int map_max_alloc(max_maps *mx, int n, size_t R, int C, int want_cos, hearth_map_result *out);
void map_max_free(max_maps *mx);
/* room for n views' records; with stream (mean fusion), the sums for R x R
 * texels and C channels, and with want_cos their best cosines, zeroed.
 * Returns 0 out of memory. */
int map_records_alloc(view_records *r, size_t n_views, int stream, size_t R, int C, int want_cos);
/* mean fusion: view v's n splats folded into the sums of R x R texels in
 * view order, once every view before it is in (the caller waits for its
 * turn; see view_records), each corner only into a texel of the splat's
 * island (island_of_texel). Every view must come, failed ones with n = 0. */
void map_splats_fold(view_records *r, size_t v, const splat *sp, size_t n,
                     const uint32_t *island_of_texel, size_t R, int C);
void map_records_free(view_records *r);

/* The islands' bounding boxes and counts, gathered by the fusion for the
 * fill: per worker a set of n_islands + 1 (merged in map_fill_islands). */
typedef struct island_box {
  int32_t x0, y0, x1, y1; /* inclusive; x1 < x0 for an island without texels */
  size_t n_todo;          /* surface texels to fill */
  uint8_t has_seed;       /* any observed texel */
} island_box;

/* the fusion over bands of whole rows (see map_fuse.c) */
typedef struct fuse_pass {
  const map_ctx *m;
  hearth_map_result *out; /* observed, filled, mask and best_cos written band by band */
  island_box *parts;      /* per worker: the islands' boxes */
  int *nomem;             /* per worker: out of memory */
} fuse_pass;
/* bands [b, e) of BAND_TEXELS texels (whole rows) on worker t */
void map_fuse_bands(void *ctx, size_t b, size_t e, int t);
/* corrected fusion: m's corr_ambient and corr_rate from the views and
   their records, over bands on nt workers. Returns 0 out of memory. */
int map_correction_estimate(map_ctx *m, int nt);

/* map_fill.c */
/* For rows [y0, y1) of fused maps: the mask of the observed texels, the
 * filled map as far as observed (NaN elsewhere, for the fill to write),
 * and the islands' boxes grown by the rows' texels. */
void map_fill_prepare_rows(size_t R, size_t C, const uint32_t *island_of_texel, size_t y0,
                           size_t y1, hearth_map_result *out, island_box *box);
/* Fill every island that has observed texels and unobserved ones, from the
 * islands' boxes (nw sets of n_islands + 1); writes filled and marks mask
 * for filled texels. */
hearth_status map_fill_islands(size_t R, size_t C, const uint32_t *island_of_texel,
                               uint32_t n_islands, const island_box *parts, int nw, uint8_t *mask,
                               const float *observed, float *filled, int nthreads);

#endif
