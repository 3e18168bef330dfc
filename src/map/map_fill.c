/* Nearest-observed fill within islands (see map_internal.h): every surface
 * texel that was not observed takes the observed texel of its own island at
 * the smallest Euclidean distance between texel centres. This is an exact
 * distance transform with feature indices, run per island over its bounding
 * box in two separable passes: the nearest seed row in every column (a
 * downward and an upward sweep), then along every row the lower envelope of
 * the parabolas (x - c)^2 + (row - seed_row(c))^2. Ties go to a fixed rule
 * (the upper seed within a column, the left parabola along a row). Islands
 * are independent and each is done whole by one worker, so the result does
 * not depend on the thread count. The cost is the sum of the islands'
 * bounding-box areas (about the surface for packed atlases). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "map/map_internal.h"

/* grow box by the run of island texels [x0, x1] of row y */
static void box_add_run(island_box *bx, size_t x0, size_t x1, size_t y, int seed, size_t todo) {
  int32_t xa = (int32_t)x0, xb = (int32_t)x1, yy = (int32_t)y;
  if (xa < bx->x0) bx->x0 = xa;
  if (xb > bx->x1) bx->x1 = xb;
  if (yy < bx->y0) bx->y0 = yy;
  if (yy > bx->y1) bx->y1 = yy;
  bx->has_seed |= (uint8_t)seed;
  bx->n_todo += todo;
}

/* run by run of one island along each row */
void map_fill_prepare_rows(size_t R, size_t C, const uint32_t *island_of_texel, size_t y0,
                           size_t y1, hearth_map_result *out, island_box *box) {
  for (size_t y = y0; y < y1; y++) {
    const size_t row = y * R;
    uint32_t run_isl = UINT32_MAX;
    size_t run_x0 = 0, run_todo = 0;
    int run_seed = 0;
    for (size_t x = 0; x <= R; x++) {
      uint32_t isl = UINT32_MAX;
      int seen = 0;
      if (x < R) {
        const size_t q = row + x;
        for (size_t c = 0; c < C; c++) {
          if (out->observed[q * C + c] > -INFINITY) out->mask[q] = HEARTH_TEXEL_OBSERVED;
          else out->observed[q * C + c] = NAN;
          out->filled[q * C + c] = out->observed[q * C + c];
        }
        isl = island_of_texel[q];
        seen = out->mask[q] == HEARTH_TEXEL_OBSERVED;
      }
      if (isl != run_isl) {
        if (run_isl != UINT32_MAX) box_add_run(&box[run_isl], run_x0, x - 1, y, run_seed, run_todo);
        run_isl = isl;
        run_x0 = x;
        run_todo = 0;
        run_seed = 0;
      }
      run_seed |= seen;
      run_todo += !seen;
    }
  }
}

typedef struct fill_ctx {
  size_t R, C;
  const uint32_t *island_of_texel;
  uint8_t *mask; /* observed texels in; filled ones marked */
  const float *observed;
  float *filled; /* out: the filled texels' values */
  const island_box *box;
  const uint32_t *order; /* islands with work, largest box first */
  uint32_t n;
  int *failed; /* per worker: out of memory */
} fill_ctx;

static size_t box_area(const island_box *b) {
  return (size_t)(b->x1 - b->x0 + 1) * (size_t)(b->y1 - b->y0 + 1);
}

/* one island's scratch over its W x H box; the fill of the island owns it */
typedef struct island_scratch {
  int16_t *srow; /* W * H: nearest seed row in the column, -1 none (rows < R <= 16384 fit) */
  int16_t *cur;  /* W */
  int32_t *env;  /* W: columns on the lower envelope */
  int64_t *zn;   /* W + 1: where each takes over from the one before: x = zn / zd */
  int64_t *zd;   /* exactly (zd > 0; the first has none) */
} island_scratch;

static void island_scratch_free(island_scratch *s) {
  free(s->srow);
  free(s->cur);
  free(s->env);
  free(s->zn);
  free(s->zd);
}

/* pass 1: the nearest seed row above (downward sweep), then below; a texel
   is a seed exactly where the downward sweep put its own row */
static void nearest_seed_rows(const fill_ctx *c, uint32_t isl, size_t W, size_t H,
                              island_scratch *s) {
  const island_box *b = &c->box[isl];
  const uint32_t *iot = c->island_of_texel;
  const uint8_t *mask = c->mask;
  int16_t *cur = s->cur;
  for (size_t x = 0; x < W; x++) cur[x] = -1;
  for (size_t r = 0; r < H; r++) {
    const size_t q0 = ((size_t)b->y0 + r) * c->R + (size_t)b->x0;
    int16_t *row = s->srow + r * W;
    for (size_t x = 0; x < W; x++) {
      int seed = iot[q0 + x] == isl && mask[q0 + x] == HEARTH_TEXEL_OBSERVED;
      cur[x] = seed ? (int16_t)r : cur[x];
      row[x] = cur[x];
    }
  }
  for (size_t x = 0; x < W; x++) cur[x] = -1;
  for (size_t r = H; r-- > 0;) {
    int16_t *row = s->srow + r * W;
    const int ir = (int)r;
    for (size_t x = 0; x < W; x++) {
      int up = row[x];
      cur[x] = up == ir ? (int16_t)ir : cur[x];
      int dn = cur[x];
      row[x] = dn >= 0 && (up < 0 || dn - ir < ir - up) ? (int16_t)dn : (int16_t)up;
    }
  }
}

/* pass 2, row r of the box: the lower envelope of the columns' parabolas,
   and each unobserved texel of the island filled from the seed of the
   parabola lowest at its column */
static void fill_row(const fill_ctx *c, uint32_t isl, size_t W, size_t r, island_scratch *s) {
  const island_box *b = &c->box[isl];
  const size_t R = c->R, q0 = ((size_t)b->y0 + r) * R + (size_t)b->x0;
  const int16_t *row = s->srow + r * W;
  int32_t *env = s->env;
  int64_t *zn = s->zn, *zd = s->zd;
  /* parabola of column c: (x - c)^2 + dy_c^2; the one of column x takes
     over from v's at (f_x - f_v) / (2 (x - v)) with f_c = c^2 + dy_c^2.
     Kept as exact integer fractions: the comparisons need no division */
  long k = -1;
  const int64_t ir = (int64_t)r;
  for (size_t x = 0; x < W; x++) {
    if (row[x] < 0) continue;
    const int64_t ix = (int64_t)x, dy = (int64_t)row[x] - ir, fx = dy * dy + ix * ix;
    int64_t num = 0, den = 1;
    while (k >= 0) {
      const int64_t v = env[k], dv = (int64_t)row[v] - ir;
      num = fx - (dv * dv + v * v);
      den = 2 * (ix - v);
      /* the first parabola reigns from -infinity: never popped */
      if (k == 0 || num * zd[k] > zn[k] * den) break;
      k--;
    }
    env[++k] = (int32_t)x;
    zn[k] = num;
    zd[k] = den;
  }
  if (k < 0) return; /* no seed in any column: only possible when the island has none */
  const uint32_t *iot = c->island_of_texel;
  uint8_t *mask = c->mask;
  long j = 0;
  for (size_t x = 0; x < W; x++) {
    size_t q = q0 + x;
    if (iot[q] != isl || mask[q] == HEARTH_TEXEL_OBSERVED) continue;
    while (j < k && zn[j + 1] <= (int64_t)x * zd[j + 1]) j++;
    size_t sc = (size_t)env[j], seed = ((size_t)b->y0 + (size_t)row[sc]) * R + (size_t)b->x0 + sc;
    for (size_t ch = 0; ch < c->C; ch++) c->filled[q * c->C + ch] = c->observed[seed * c->C + ch];
    mask[q] = HEARTH_TEXEL_FILLED; /* read again only as "not observed" */
  }
}

/* island isl, whole; returns 0 out of memory */
static int fill_one_island(const fill_ctx *c, uint32_t isl) {
  const island_box *b = &c->box[isl];
  const size_t W = (size_t)(b->x1 - b->x0 + 1), H = (size_t)(b->y1 - b->y0 + 1);
  island_scratch s;
  s.srow = hearth_alloc_array(W * H, sizeof *s.srow);
  s.cur = hearth_alloc_array(W, sizeof *s.cur);
  s.env = hearth_alloc_array(W, sizeof *s.env);
  s.zn = hearth_alloc_array(W + 1, sizeof *s.zn);
  s.zd = hearth_alloc_array(W + 1, sizeof *s.zd);
  int ok = s.srow && s.cur && s.env && s.zn && s.zd;
  if (ok) {
    nearest_seed_rows(c, isl, W, H, &s);
    for (size_t r = 0; r < H; r++) fill_row(c, isl, W, r, &s);
  }
  island_scratch_free(&s);
  return ok;
}

typedef struct isl_work {
  size_t work;
  uint32_t island;
} isl_work;
/* largest first, ties by island index: a total order */
static int cmp_isl_work(const void *a, const void *b) {
  const isl_work *x = a, *y = b;
  if (x->work != y->work) return x->work > y->work ? -1 : 1;
  return (x->island > y->island) - (x->island < y->island);
}

/* islands order[b..e), each whole on this worker */
static void fill_range(void *ctx, size_t b, size_t e, int t) {
  const fill_ctx *c = ctx;
  for (size_t i = b; i < e; i++)
    if (!fill_one_island(c, c->order[i])) c->failed[t] = 1;
}

/* the islands' boxes: minima, maxima, sums of the workers' parts (the same
   for any split of the rows) */
static void merge_boxes(const island_box *parts, int nw, uint32_t n_islands, island_box *box) {
  for (uint32_t i = 0; i < n_islands; i++) {
    island_box b = parts[i];
    for (int w = 1; w < nw; w++) {
      const island_box *o = &parts[(size_t)w * ((size_t)n_islands + 1) + i];
      if (o->x0 < b.x0) b.x0 = o->x0;
      if (o->x1 > b.x1) b.x1 = o->x1;
      if (o->y0 < b.y0) b.y0 = o->y0;
      if (o->y1 > b.y1) b.y1 = o->y1;
      b.n_todo += o->n_todo;
      b.has_seed |= o->has_seed;
    }
    box[i] = b;
  }
}

hearth_status map_fill_islands(size_t R, size_t C, const uint32_t *island_of_texel,
                               uint32_t n_islands, const island_box *parts, int nw, uint8_t *mask,
                               const float *observed, float *filled, int nthreads) {
  island_box *box = hearth_alloc_array((size_t)n_islands + 1, sizeof *box);
  isl_work *work = hearth_alloc_array((size_t)n_islands + 1, sizeof *work);
  uint32_t *order = hearth_alloc_array((size_t)n_islands + 1, sizeof *order);
  int nf = nthreads > 0 ? nthreads : hearth_default_threads();
  int *failed = calloc((size_t)nf, sizeof *failed);
  hearth_status s = HEARTH_E_NOMEM;
  if (!box || !work || !order || !failed) goto done;
  merge_boxes(parts, nw, n_islands, box);
  uint32_t n = 0;
  for (uint32_t i = 0; i < n_islands; i++)
    if (box[i].has_seed && box[i].n_todo) work[n++] = (isl_work){box_area(&box[i]), i};
  qsort(work, n, sizeof *work, cmp_isl_work);
  /* largest first, each island to whichever worker is free */
  for (uint32_t i = 0; i < n; i++) order[i] = work[i].island;
  fill_ctx c = {R, C, island_of_texel, mask, observed, filled, box, order, n, failed};
  hearth_parallel_chunks(n, 1, nf, fill_range, &c);
  s = HEARTH_OK;
  for (int w = 0; w < nf; w++)
    if (failed[w]) s = HEARTH_E_NOMEM;
done:
  free(box);
  free(work);
  free(order);
  free(failed);
  return s;
}
