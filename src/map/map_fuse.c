/* Fusion across views (see map_internal.h), over bands of whole texel rows,
 * each band touching only its slice of the maps: for max fusion the
 * workers' maxima maps merged and decoded; for mean and robust fusion every
 * view's records of the band's texels folded in view order (the weighted
 * mean, or the weighted median). Each band then prepares its rows for the
 * fill (map_fill.c). Also the fusion rules' state: max fusion's maps and
 * the views' records. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "map/map_internal.h"

/* rows [b, e) of every worker's maxima maps: zero (no maximum) */
typedef struct zero_pass {
  const max_maps *mx;
  size_t R, C;
} zero_pass;
static void zero_maps(void *ctx, size_t b, size_t e, int t) {
  const zero_pass *z = ctx;
  const size_t C = z->C, q0 = b * z->R, nq = (e - b) * z->R;
  (void)t;
  for (int w = 0; w < z->mx->n; w++) {
    memset(z->mx->code[w] + q0 * C, 0, nq * C * sizeof(uint32_t));
    if (z->mx->cos) memset(z->mx->cos[w] + q0, 0, nq * sizeof(float));
  }
}

int map_max_alloc(max_maps *mx, int n, size_t R, int C, int want_cos, hearth_map_result *out) {
  const size_t N = R * R;
  mx->n = n;
  mx->code = calloc((size_t)n, sizeof *mx->code);
  if (want_cos) mx->cos = calloc((size_t)n, sizeof *mx->cos);
  if (!mx->code || (want_cos && !mx->cos)) return 0;
  out->observed = hearth_alloc_array(N, (size_t)C * sizeof(float));
  mx->code[0] = (uint32_t *)(void *)out->observed;
  if (want_cos) mx->cos[0] = out->best_cos = hearth_alloc_array(N, sizeof(float));
  for (int t = 1; t < n; t++) {
    mx->code[t] = hearth_alloc_array(N, (size_t)C * sizeof(uint32_t));
    if (want_cos) mx->cos[t] = hearth_alloc_array(N, sizeof(float));
  }
  for (int t = 0; t < n; t++)
    if (!mx->code[t] || (want_cos && !mx->cos[t])) return 0;
  zero_pass z = {mx, R, (size_t)C};
  hearth_parallel_chunks(R, 32, n, zero_maps, &z);
  return 1;
}

void map_max_free(max_maps *mx) {
  /* worker 0's maps are the result's arrays */
  for (int t = 1; mx->code && t < mx->n; t++) free(mx->code[t]);
  for (int t = 1; mx->cos && t < mx->n; t++) free(mx->cos[t]);
  free(mx->code);
  free(mx->cos);
  memset(mx, 0, sizeof *mx);
}

int map_records_alloc(view_records *r, size_t n_views) {
  r->n_views = n_views;
  r->q = calloc(n_views ? n_views : 1, sizeof *r->q);
  r->d = calloc(n_views ? n_views : 1, sizeof *r->d);
  r->n = calloc(n_views ? n_views : 1, sizeof *r->n);
  return r->q && r->d && r->n;
}

void map_records_free(view_records *r) {
  for (size_t v = 0; r->q && v < r->n_views; v++) free(r->q[v]);
  for (size_t v = 0; r->d && v < r->n_views; v++) free(r->d[v]);
  free(r->q);
  free(r->d);
  free(r->n);
  memset(r, 0, sizeof *r);
}

/* a (value, weight) pair of one view at one texel */
typedef struct vw {
  float v, w;
} vw;
static int cmp_vw(const void *a, const void *b) {
  float x = ((const vw *)a)->v, y = ((const vw *)b)->v;
  return (x > y) - (x < y);
}
/* weighted median of n pairs; sorts in place */
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

/* one worker's scratch for a band of the fusion; the worker owns it */
typedef struct band_scratch {
  double *acc;   /* mean: sums per channel and weight, per texel of a band */
  uint32_t *cnt; /* robust: records per texel of a band, then offsets */
  vw *all;       /* robust: every record's pair of the band, texel by texel */
  size_t all_cap;
  vw *tmp; /* robust: one texel's pairs, sorted */
} band_scratch;

/* texels [q0, q1), max fusion: the workers' maxima, decoded (worker 0's
   codes are read from and then overwritten by the values): -inf where none */
static void merge_maxima(const map_ctx *m, hearth_map_result *out, size_t q0, size_t q1) {
  const max_maps *mx = m->max;
  const size_t C = (size_t)m->C;
  const uint32_t *iot = m->l->island_of_texel;
  const uint32_t *code = mx->code[0];
  for (size_t q = q0; q < q1; q++) {
    for (int w = 1; mx->cos && w < mx->n; w++) {
      const float cw = mx->cos[w][q];
      if (cw > out->best_cos[q]) out->best_cos[q] = cw;
    }
    out->mask[q] = iot[q] == UINT32_MAX ? HEARTH_TEXEL_NONE : HEARTH_TEXEL_UNOBSERVED;
    for (size_t c = 0; c < C; c++) {
      uint32_t k = code[q * C + c];
      for (int w = 1; w < mx->n; w++) {
        const uint32_t kw = mx->code[w][q * C + c];
        k = kw > k ? kw : k;
      }
      out->observed[q * C + c] = k ? max_decode(k) : -INFINITY;
    }
  }
}

/* texels [q0, q1), mean and robust fusion: no view yet */
static void clear_band(const map_ctx *m, hearth_map_result *out, size_t q0, size_t q1) {
  const size_t C = (size_t)m->C;
  const uint32_t *iot = m->l->island_of_texel;
  for (size_t q = q0; q < q1; q++) {
    if (out->best_cos) out->best_cos[q] = 0.0f;
    out->mask[q] = iot[q] == UINT32_MAX ? HEARTH_TEXEL_NONE : HEARTH_TEXEL_UNOBSERVED;
    for (size_t c = 0; c < C; c++) out->observed[q * C + c] = -INFINITY;
  }
}

/* texels [q0, q1), mean fusion: each view counts with its total weight at
   a texel */
static void fold_mean(const map_ctx *m, hearth_map_result *out, band_scratch *bs, size_t q0,
                      size_t q1) {
  const view_records *r = m->rec;
  const size_t C = (size_t)m->C, RW = REC_WORDS(C);
  double *acc = bs->acc;
  memset(acc, 0, (q1 - q0) * (C + 1) * sizeof *acc);
  for (size_t v = 0; v < r->n_views; v++) {
    const uint32_t *rq = r->q[v];
    const float *rd = r->d[v];
    for (size_t k = lower_bound_u32(rq, r->n[v], (uint32_t)q0); k < r->n[v] && rq[k] < q1; k++) {
      const size_t q = rq[k];
      const float *d = rd + k * RW;
      if (out->best_cos && d[1] > out->best_cos[q]) out->best_cos[q] = d[1];
      double *a = acc + (q - q0) * (C + 1);
      for (size_t c = 0; c < C; c++) a[c] += d[2 + c];
      a[C] += d[0];
    }
  }
  for (size_t q = q0; q < q1; q++) {
    const double *a = acc + (q - q0) * (C + 1);
    if (a[C] > 0.0)
      for (size_t c = 0; c < C; c++) out->observed[q * C + c] = (float)(a[c] / a[C]);
  }
}

/* texels [q0, q1), robust fusion (one channel): the weighted median of
   every view's (value, weight) at a texel, gathered in view order. Returns
   0 out of memory. */
static int fold_robust(const map_ctx *m, hearth_map_result *out, band_scratch *bs, size_t q0,
                       size_t q1) {
  const view_records *r = m->rec;
  const size_t RW = REC_WORDS(m->C), nq = q1 - q0;
  uint32_t *cnt = bs->cnt;
  size_t total = 0;
  memset(cnt, 0, (nq + 1) * sizeof *cnt);
  for (size_t v = 0; v < r->n_views; v++) {
    const uint32_t *rq = r->q[v];
    const float *rd = r->d[v];
    for (size_t k = lower_bound_u32(rq, r->n[v], (uint32_t)q0); k < r->n[v] && rq[k] < q1; k++) {
      const size_t q = rq[k];
      if (out->best_cos && rd[k * RW + 1] > out->best_cos[q]) out->best_cos[q] = rd[k * RW + 1];
      cnt[q - q0 + 1]++;
      total++;
    }
  }
  if (!total) return 1;
  if (total > bs->all_cap) {
    free(bs->all);
    bs->all_cap = total;
    bs->all = hearth_alloc_array(bs->all_cap, sizeof *bs->all);
    if (!bs->all) return 0;
  }
  for (size_t i = 0; i < nq; i++) cnt[i + 1] += cnt[i];
  for (size_t v = 0; v < r->n_views; v++) {
    const uint32_t *rq = r->q[v];
    const float *rd = r->d[v];
    for (size_t k = lower_bound_u32(rq, r->n[v], (uint32_t)q0); k < r->n[v] && rq[k] < q1; k++)
      bs->all[cnt[rq[k] - q0]++] = (vw){rd[k * RW + 2], rd[k * RW]};
  }
  /* cnt[i] is now the end of texel i's records (the start of i + 1's) */
  for (size_t i = 0, start = 0; i < nq; start = cnt[i], i++) {
    size_t n = cnt[i] - start;
    if (!n) continue;
    memcpy(bs->tmp, bs->all + start, n * sizeof *bs->tmp);
    out->observed[q0 + i] = weighted_median(bs->tmp, n);
  }
  return 1;
}

/* A worker sets nomem[t] if its scratch cannot be had. */
void map_fuse_bands(void *ctx, size_t b, size_t e, int t) {
  const fuse_pass *fp = ctx;
  const map_ctx *m = fp->m;
  hearth_map_result *out = fp->out;
  const size_t R = m->l->R, C = (size_t)m->C, N = R * R, nv = m->n_views;
  const size_t rows = R < BAND_TEXELS ? BAND_TEXELS / R : 1, band = rows * R;
  const int fusion = m->opts->fusion;
  band_scratch bs = {0};
  if (fusion == HEARTH_FUSE_MEAN) bs.acc = hearth_alloc_array(band, (C + 1) * sizeof *bs.acc);
  if (fusion == HEARTH_FUSE_ROBUST) {
    bs.cnt = hearth_alloc_array(band + 1, sizeof *bs.cnt);
    bs.tmp = hearth_alloc_array(nv ? nv : 1, sizeof *bs.tmp);
  }
  if ((fusion == HEARTH_FUSE_MEAN && !bs.acc) ||
      (fusion == HEARTH_FUSE_ROBUST && (!bs.cnt || !bs.tmp))) {
    fp->nomem[t] = 1;
    goto done;
  }
  island_box *box = fp->parts + (size_t)t * ((size_t)m->l->n_islands + 1);
  for (size_t bi = b; bi < e; bi++) {
    const size_t q0 = bi * band, q1 = q0 + band < N ? q0 + band : N;
    if (m->max) {
      merge_maxima(m, out, q0, q1);
    } else {
      clear_band(m, out, q0, q1);
      if (fusion == HEARTH_FUSE_MEAN) fold_mean(m, out, &bs, q0, q1);
      else if (!fold_robust(m, out, &bs, q0, q1)) {
        fp->nomem[t] = 1;
        goto done;
      }
    }
    map_fill_prepare_rows(R, C, m->l->island_of_texel, q0 / R, q1 / R, out, box);
  }
done:
  free(bs.acc);
  free(bs.cnt);
  free(bs.all);
  free(bs.tmp);
}
