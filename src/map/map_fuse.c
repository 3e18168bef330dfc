/* Fusion across views (see map_internal.h), over bands of whole texel rows,
 * each band touching only its slice of the maps: for max fusion the
 * workers' maxima maps merged and decoded; for mean fusion the sums the
 * views were folded into (in view order, as they were done) divided in
 * place; for robust fusion every view's records of the band's texels
 * folded in view order (the weighted median). Each band then prepares its rows for the
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

int map_records_alloc(view_records *r, size_t n_views, int stream, size_t R, int C, int want_cos) {
  r->n_views = n_views;
  if (!stream) {
    r->q = calloc(n_views ? n_views : 1, sizeof *r->q);
    r->d = calloc(n_views ? n_views : 1, sizeof *r->d);
    r->n = calloc(n_views ? n_views : 1, sizeof *r->n);
    return r->q && r->d && r->n;
  }
  /* calloc: the pages of texels no view observes are never touched */
  r->acc = calloc(R * R, (size_t)C * sizeof *r->acc);
  r->acc_owned = 1;
  r->acc_w = calloc(R * R, sizeof *r->acc_w);
  if (want_cos) r->best_cos = calloc(R * R, sizeof *r->best_cos);
  if (!r->acc || !r->acc_w || (want_cos && !r->best_cos)) return 0;
  if (pthread_mutex_init(&r->mu, NULL)) return 0;
  if (pthread_cond_init(&r->turn, NULL)) {
    pthread_mutex_destroy(&r->mu);
    return 0;
  }
  r->have_mu = 1;
  return 1;
}

void map_records_free(view_records *r) {
  for (size_t v = 0; r->q && v < r->n_views; v++) free(r->q[v]);
  for (size_t v = 0; r->d && v < r->n_views; v++) free(r->d[v]);
  free(r->q);
  free(r->d);
  free(r->n);
  if (r->acc_owned) free(r->acc);
  free(r->acc_w);
  free(r->best_cos);
  if (r->have_mu) {
    pthread_mutex_destroy(&r->mu);
    pthread_cond_destroy(&r->turn);
  }
  memset(r, 0, sizeof *r);
}

/* n splats of one view into the sums: corner by corner in pixel order, a
   corner only into a texel of the splat's own island (as the other rules'
   reduction of a view's touches) */
static void add_splats(view_records *r, const uint32_t *iot, size_t R, const splat *sp, size_t n,
                       int C) {
  for (size_t i = 0; i < n; i++) {
    const splat *e = &sp[i];
    for (int k = 0; k < 4; k++) {
      uint32_t q;
      float wk;
      if (!splat_corner(e, k, R, &q, &wk) || iot[q] != e->island) continue;
      if (r->best_cos && e->cosv > r->best_cos[q]) r->best_cos[q] = e->cosv;
      float *a = r->acc + q * (size_t)C;
      for (int c = 0; c < C; c++) a[c] += wk * splat_value(e, C, c);
      r->acc_w[q] += wk;
    }
  }
}

void map_splats_fold(view_records *r, size_t v, const splat *sp, size_t n, const uint32_t *iot,
                     size_t R, int C) {
  /* the views before v are in once next reaches v; until v is in, no other
     view touches the sums, so they are added without the lock */
  pthread_mutex_lock(&r->mu);
  while (r->next != v) pthread_cond_wait(&r->turn, &r->mu);
  pthread_mutex_unlock(&r->mu);
  add_splats(r, iot, R, sp, n, C);
  pthread_mutex_lock(&r->mu);
  r->next = v + 1;
  pthread_cond_broadcast(&r->turn);
  pthread_mutex_unlock(&r->mu);
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

/* texels [q0, q1), robust fusion: no view yet */
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
   a texel; the views are summed already, in the result's observed map,
   whose sums become the means in place (-inf where no view observed) */
static void fold_mean(const map_ctx *m, hearth_map_result *out, size_t q0, size_t q1) {
  const view_records *r = m->rec;
  const size_t C = (size_t)m->C;
  const uint32_t *iot = m->l->island_of_texel;
  for (size_t q = q0; q < q1; q++) {
    const float w = r->acc_w[q];
    if (out->best_cos) out->best_cos[q] = r->best_cos ? r->best_cos[q] : 0.0f;
    out->mask[q] = iot[q] == UINT32_MAX ? HEARTH_TEXEL_NONE : HEARTH_TEXEL_UNOBSERVED;
    float *a = out->observed + q * C;
    for (size_t c = 0; c < C; c++) a[c] = w > 0.0f ? a[c] / w : -INFINITY;
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

/* ---- corrected fusion ------------------------------------------------------------- */
/* one view's record of a texel for the corrected fusion */
typedef struct cr {
  float v, w, c, t; /* value, weight, viewing cosine, the view's time */
  int pass;         /* the view's pass */
} cr;
static int cmp_cr(const void *a, const void *b) {
  float x = ((const cr *)a)->v, y = ((const cr *)b)->v;
  return (x > y) - (x < y);
}
/* weighted median of the values of n records; sorts a */
static double cr_median(cr *a, size_t n) {
  qsort(a, n, sizeof *a, cmp_cr);
  double total = 0, acc = 0;
  for (size_t i = 0; i < n; i++) total += a[i].w;
  for (size_t i = 0; i < n; i++) {
    acc += a[i].w;
    if (acc >= 0.5 * total) return a[i].v;
  }
  return n ? a[n - 1].v : NAN;
}

/* The emissivity of a typical dielectric surface (paint, glaze, plastic,
   glass: refractive index 1.6 in the long-wave infrared, normal emissivity
   0.947) at viewing cosine c relative to its normal value, from Fresnel's
   equations: the factor a reading's excess over ambient is divided by. */
static double dielectric_falloff(double c) {
  const double n = 1.6;
  if (c > 1.0) c = 1.0;
  double ct = sqrt(1.0 - (1.0 - c * c) / (n * n));
  double rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
  double r0 = (n - 1.0) / (n + 1.0);
  return (1.0 - 0.5 * (rs * rs + rp * rp)) / (1.0 - r0 * r0);
}

/* a reading of excess v - A over ambient seen at cosine c, as seen along
   the normal (the correction limited to 25 %) */
static double normal_equivalent(double v, double A, double c) {
  double f = dielectric_falloff(c);
  return A + (v - A) / (f < 0.8 ? 0.8 : f);
}

/* the records of texels [q0, q1) gathered texel by texel in view order:
   on return cnt[i] is the end of texel i's records in bs_all. Returns the
   count, or SIZE_MAX out of memory. */
static size_t gather_cr(const map_ctx *m, uint32_t *cnt, cr **all, size_t *cap, size_t q0,
                        size_t q1) {
  const view_records *r = m->rec;
  const size_t RW = REC_WORDS(m->C), nq = q1 - q0;
  size_t total = 0;
  memset(cnt, 0, (nq + 1) * sizeof *cnt);
  for (size_t v = 0; v < r->n_views; v++) {
    const uint32_t *rq = r->q[v];
    for (size_t k = lower_bound_u32(rq, r->n[v], (uint32_t)q0); k < r->n[v] && rq[k] < q1; k++) {
      cnt[rq[k] - q0 + 1]++;
      total++;
    }
  }
  if (!total) return 0;
  if (total > *cap) {
    free(*all);
    *cap = total;
    *all = hearth_alloc_array(total, sizeof **all);
    if (!*all) return SIZE_MAX;
  }
  for (size_t i = 0; i < nq; i++) cnt[i + 1] += cnt[i];
  for (size_t v = 0; v < r->n_views; v++) {
    const uint32_t *rq = r->q[v];
    const float *rd = r->d[v];
    const float tv = (float)m->views[v].time_s;
    for (size_t k = lower_bound_u32(rq, r->n[v], (uint32_t)q0); k < r->n[v] && rq[k] < q1; k++)
      (*all)[cnt[rq[k] - q0]++] =
          (cr){rd[k * RW + 2], rd[k * RW], rd[k * RW + 1], tv, m->views[v].pass};
  }
  return total;
}

/* the views kept at a texel: within 0.2 of its best cosine (and above
   0.2), weighted by cos^4 */
static size_t keep_near_best(cr *a, size_t n) {
  float best = 0;
  for (size_t i = 0; i < n; i++) best = a[i].c > best ? a[i].c : best;
  const float lo = best - 0.2f > 0.2f ? best - 0.2f : 0.2f;
  size_t k = 0;
  for (size_t i = 0; i < n; i++)
    if (a[i].c >= lo) {
      float c2 = a[i].c * a[i].c;
      a[k] = a[i];
      a[k++].w *= c2 * c2;
    }
  return k;
}

/* A view that sees a texel well may still leave it without a record: its
   pixels are coarser than the texels, and each splats only into the four
   texels around its hit. Such a texel's records then come from oblique
   views alone. A texel whose own records are all seen more than the keep
   band (0.2) more obliquely than the best record of a texel within
   BORROW_R texels of its island borrows the records of those neighbours
   that lie within the band of that best cosine, their weight halved per
   texel of distance; the oblique records then fall out of the keep band. */
#define BORROW_R 2
#define BORROW_SPAN ((2 * BORROW_R + 1) * (2 * BORROW_R + 1))

/* view v's record of texel p, or NULL */
static const float *record_of(const view_records *r, size_t v, uint32_t p, size_t RW) {
  size_t k = lower_bound_u32(r->q[v], r->n[v], p);
  return k < r->n[v] && r->q[v][k] == p ? r->d[v] + k * RW : NULL;
}

/* texel q's n records in a (room for n_views * BORROW_SPAN) with the
   neighbours' records borrowed where they see it much better (above);
   returns the new count */
static size_t borrow_neighbours(const map_ctx *m, size_t q, cr *a, size_t n) {
  const long R = (long)m->l->R, x = (long)q % R, y = (long)q / R;
  const size_t RW = REC_WORDS(m->C);
  const uint32_t *iot = m->l->island_of_texel;
  const float *best = m->corr_best;
  float nb = 0;
  for (long dy = -BORROW_R; dy <= BORROW_R; dy++)
    for (long dx = -BORROW_R; dx <= BORROW_R; dx++) {
      const long px = x + dx, py = y + dy;
      if (px < 0 || py < 0 || px >= R || py >= R) continue;
      const size_t p = (size_t)(py * R + px);
      if (iot[p] == iot[q] && best[p] > nb) nb = best[p];
    }
  if (nb <= best[q] + 0.2f) return n;
  const float lo = nb - 0.2f;
  for (long dy = -BORROW_R; dy <= BORROW_R; dy++)
    for (long dx = -BORROW_R; dx <= BORROW_R; dx++) {
      const long px = x + dx, py = y + dy;
      if ((!dx && !dy) || px < 0 || py < 0 || px >= R || py >= R) continue;
      const size_t p = (size_t)(py * R + px);
      if (iot[p] != iot[q] || best[p] < lo) continue;
      const long d = labs(dx) > labs(dy) ? labs(dx) : labs(dy);
      const float f = ldexpf(1.0f, -(int)d);
      for (size_t v = 0; v < m->n_views; v++) {
        const float *rec = record_of(m->rec, v, (uint32_t)p, RW);
        if (rec && rec[1] >= lo)
          a[n++] = (cr){rec[2], rec[0] * f, rec[1], (float)m->views[v].time_s, m->views[v].pass};
      }
    }
  return n;
}

/* texels [q0, q1), corrected fusion: each kept view's reading brought back
   to time 0, then their weighted median */
static int fold_corrected(const map_ctx *m, hearth_map_result *out, uint32_t *cnt, cr **all,
                          size_t *cap, cr *tmp, size_t q0, size_t q1) {
  size_t total = gather_cr(m, cnt, all, cap, q0, q1);
  if (total == SIZE_MAX) return 0;
  if (!total) return 1;
  const double A = m->corr_ambient, k = m->corr_rate;
  for (size_t i = 0, start = 0; i < q1 - q0; start = cnt[i], i++) {
    size_t n = cnt[i] - start;
    if (!n) continue;
    memcpy(tmp, *all + start, n * sizeof *tmp);
    for (size_t j = 0; j < n; j++)
      if (out->best_cos && tmp[j].c > out->best_cos[q0 + i]) out->best_cos[q0 + i] = tmp[j].c;
    n = borrow_neighbours(m, q0 + i, tmp, n);
    n = keep_near_best(tmp, n);
    for (size_t j = 0; j < n; j++) {
      double v = normal_equivalent(tmp[j].v, A, tmp[j].c);
      tmp[j].v = (float)(A + (v - A) * exp(k * tmp[j].t));
    }
    out->observed[q0 + i] = (float)cr_median(tmp, n);
  }
  return 1;
}

/* the cooling-rate estimate: per texel the slope of a regression of
   log |reading - ambient| on time (centred within each pass) and its
   weight, per band; the rate is their weighted median */
typedef struct rate_pass {
  const map_ctx *m;
  vw **slopes;  /* per band: (slope, weight) per texel that has one; owned */
  size_t *n;    /* per band */
  size_t *seen; /* per band: texels with any record */
  int *nomem;   /* per worker */
} rate_pass;

static void rate_bands(void *ctx, size_t b, size_t e, int t) {
  rate_pass *rp = ctx;
  const map_ctx *m = rp->m;
  const size_t R = m->l->R, N = R * R;
  const size_t rows = R < BAND_TEXELS ? BAND_TEXELS / R : 1, band = rows * R;
  uint32_t *cnt = hearth_alloc_array(band + 1, sizeof *cnt);
  cr *tmp = hearth_alloc_array(m->n_views ? m->n_views : 1, sizeof *tmp), *all = NULL;
  size_t cap = 0;
  const double A = m->corr_ambient;
  if (!cnt || !tmp) {
    rp->nomem[t] = 1;
    goto done;
  }
  for (size_t bi = b; bi < e; bi++) {
    const size_t q0 = bi * band, q1 = q0 + band < N ? q0 + band : N;
    size_t total = gather_cr(m, cnt, &all, &cap, q0, q1);
    if (total == SIZE_MAX) {
      rp->nomem[t] = 1;
      goto done;
    }
    vw *out = total ? hearth_alloc_array(q1 - q0, sizeof *out) : NULL;
    if (total && !out) {
      rp->nomem[t] = 1;
      goto done;
    }
    rp->slopes[bi] = out;
    for (size_t i = 0, start = 0; total && i < q1 - q0; start = cnt[i], i++) {
      size_t n = cnt[i] - start, k = 0;
      rp->seen[bi] += n > 0;
      if (n < 2) continue;
      /* the views the fold keeps (near the best angle, so that emissivity
         changes little among them), within 60 degrees of the normal and
         clearly off ambient */
      memcpy(tmp, all + start, n * sizeof *tmp);
      n = keep_near_best(tmp, n);
      for (size_t j = 0; j < n; j++) {
        tmp[j].v = (float)normal_equivalent(tmp[j].v, A, tmp[j].c);
        if (tmp[j].c >= 0.5f && fabs(tmp[j].v - A) >= 1.5) tmp[k++] = tmp[j];
      }
      if (k < 2) continue;
      /* readings far from the texel's median (mirrored sources) left out */
      cr med_buf[64];
      size_t nm = k < 64 ? k : 64;
      memcpy(med_buf, tmp, nm * sizeof *med_buf);
      const double med = cr_median(med_buf, nm), tol = 1.0 + 0.4 * fabs(med - A);
      if (fabs(med - A) < 3.0) continue; /* too close to ambient to tell a rate */
      double sxx = 0, sxy = 0;
      /* centred within each pass: across passes the viewing geometry
         changes with time (the elevation rises), within one only the
         azimuth does */
      for (size_t j0 = 0; j0 < k; j0++) {
        int seen = 0;
        for (size_t j1 = 0; j1 < j0 && !seen; j1++) seen = tmp[j1].pass == tmp[j0].pass;
        if (seen) continue;
        double sw = 0, st = 0, sy = 0, stt = 0, sty = 0;
        for (size_t j = j0; j < k; j++) {
          if (tmp[j].pass != tmp[j0].pass) continue;
          if (fabs(tmp[j].v - med) > tol || (tmp[j].v - A) * (med - A) <= 0) continue;
          const double w = tmp[j].w, x = tmp[j].t, y = log(fabs(tmp[j].v - A));
          sw += w;
          st += w * x;
          sy += w * y;
          stt += w * x * x;
          sty += w * x * y;
        }
        if (sw <= 0) continue;
        sxx += stt - st * st / sw;
        sxy += sty - st * sy / sw;
      }
      if (sxx > 1.0) out[rp->n[bi]++] = (vw){(float)(-sxy / sxx), (float)sxx};
    }
  }
done:
  free(cnt);
  free(tmp);
  free(all);
}

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

int map_correction_estimate(map_ctx *m, int nt) {
  /* ambient: the median of every view's border ring, 3 pixels wide, where
     the turntable, the table and the backdrop are seen */
  size_t n = 0, cap = 0;
  for (size_t v = 0; v < m->n_views; v++) {
    const hearth_image *im = m->views[v].image;
    if (im->width > 6 && im->height > 6) cap += 2 * 3 * (im->width + im->height);
  }
  float *ring = hearth_alloc_array(cap ? cap : 1, sizeof *ring);
  if (!ring) return 0;
  for (size_t v = 0; v < m->n_views; v++) {
    const hearth_image *im = m->views[v].image;
    if (!(im->width > 6 && im->height > 6)) continue;
    const float *px = im->data;
    for (size_t y = 0; y < im->height; y++)
      for (size_t x = 0; x < im->width; x++)
        if ((x < 3 || y < 3 || x + 3 >= im->width || y + 3 >= im->height) && n < cap &&
            isfinite(px[y * im->width + x]))
          ring[n++] = px[y * im->width + x];
  }
  if (n) {
    qsort(ring, n, sizeof *ring, cmp_float);
    m->corr_ambient = ring[n / 2];
  } else {
    m->corr_ambient = 0;
  }
  free(ring);
  m->corr_rate = 0;
  /* every texel's best viewing cosine among its records */
  const size_t RW = REC_WORDS(m->C), NT = m->l->R * m->l->R;
  m->corr_best = calloc(NT ? NT : 1, sizeof *m->corr_best);
  if (!m->corr_best) return 0;
  for (size_t v = 0; v < m->n_views; v++)
    for (size_t j = 0; j < m->rec->n[v]; j++) {
      const uint32_t q = m->rec->q[v][j];
      const float c = m->rec->d[v][j * RW + 1];
      if (c > m->corr_best[q]) m->corr_best[q] = c;
    }
  if (!n) return 1;
  /* the rate: the weighted median of the texels' slopes, gathered in band
     order (a texel's weight is its spread of times, so texels seen over a
     short time count little; outlying texels do not pull it) */
  const size_t R = m->l->R, rows = R < BAND_TEXELS ? BAND_TEXELS / R : 1;
  const size_t nb = (R + rows - 1) / rows;
  rate_pass rp = {m, calloc(nb, sizeof(vw *)), calloc(nb, sizeof(size_t)),
                  calloc(nb, sizeof(size_t)), calloc((size_t)nt, sizeof(int))};
  int ok = rp.slopes && rp.n && rp.seen && rp.nomem;
  if (ok) hearth_parallel_chunks(nb, 4, nt, rate_bands, &rp);
  for (int t = 0; ok && t < nt; t++) ok = !rp.nomem[t];
  size_t total = 0, seen = 0;
  for (size_t b = 0; ok && b < nb; b++) {
    total += rp.n[b];
    seen += rp.seen[b];
  }
  /* a rate needs support: at least 2 % of the observed texels (a state
     near ambient has almost none, and no rate to correct) */
  if (total < 64 || total < seen / 50) total = 0;
  vw *all = ok && total ? hearth_alloc_array(total, sizeof *all) : NULL;
  if (ok && total && !all) ok = 0;
  if (ok && total) {
    size_t k0 = 0;
    for (size_t b = 0; b < nb; b++) {
      if (rp.n[b]) memcpy(all + k0, rp.slopes[b], rp.n[b] * sizeof *all);
      k0 += rp.n[b];
    }
    double k = weighted_median(all, total);
    m->corr_rate = k < 0 ? 0 : k > 0.01 ? 0.01 : k;
  }
  free(all);
  for (size_t b = 0; rp.slopes && b < nb; b++) free(rp.slopes[b]);
  free(rp.slopes);
  free(rp.n);
  free(rp.seen);
  free(rp.nomem);
  return ok;
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
  cr *call = NULL, *ctmp = NULL;
  size_t ccap = 0;
  if (fusion == HEARTH_FUSE_ROBUST || fusion == HEARTH_FUSE_CORRECTED) {
    bs.cnt = hearth_alloc_array(band + 1, sizeof *bs.cnt);
    bs.tmp = hearth_alloc_array(nv ? nv : 1, sizeof *bs.tmp);
  }
  if (fusion == HEARTH_FUSE_CORRECTED)
    ctmp = hearth_alloc_array((nv ? nv : 1) * BORROW_SPAN, sizeof *ctmp);
  if (((fusion == HEARTH_FUSE_ROBUST || fusion == HEARTH_FUSE_CORRECTED) && (!bs.cnt || !bs.tmp)) ||
      (fusion == HEARTH_FUSE_CORRECTED && !ctmp)) {
    fp->nomem[t] = 1;
    goto done;
  }
  island_box *box = fp->parts + (size_t)t * ((size_t)m->l->n_islands + 1);
  for (size_t bi = b; bi < e; bi++) {
    const size_t q0 = bi * band, q1 = q0 + band < N ? q0 + band : N;
    if (m->max) {
      merge_maxima(m, out, q0, q1);
    } else if (fusion == HEARTH_FUSE_MEAN) {
      fold_mean(m, out, q0, q1);
    } else {
      clear_band(m, out, q0, q1);
      if (fusion == HEARTH_FUSE_CORRECTED) {
        if (!fold_corrected(m, out, bs.cnt, &call, &ccap, ctmp, q0, q1)) {
          fp->nomem[t] = 1;
          goto done;
        }
      } else if (!fold_robust(m, out, &bs, q0, q1)) {
        fp->nomem[t] = 1;
        goto done;
      }
    }
    map_fill_prepare_rows(R, C, m->l->island_of_texel, q0 / R, q1 / R, out, box);
  }
done:
  free(call);
  free(ctmp);
  free(bs.cnt);
  free(bs.all);
  free(bs.tmp);
}
