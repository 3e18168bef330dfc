/* LeRobot's per-episode statistics (compute_stats.compute_episode_stats of
 * lerobot 0cf86487) computed the way numpy 1.26 computes them, so the
 * numbers in meta/episodes_stats.jsonl are the ones LeRobot would write:
 *   - a float32 (T, d) feature reduced over axis 0: numpy adds row after
 *     row in float32 (the reduced axis is not the inner loop), divides in
 *     float32;
 *   - float64 and int64 (T,) features: float64 sums in inner loops of at
 *     most 8192 elements, each summed pairwise (numpy's pairwise_sum);
 *   - images: integer sums for the mean, the squared deviations summed per
 *     frame and channel plane in 8192-element pairwise chunks.
 * np.std is sqrt(mean((x - mean(x))**2)) with those sums. Text is written
 * as Python's json module writes it. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "export/export_internal.h"

/* ---- text ------------------------------------------------------------------ */
static void t_reserve(ex_text *t, size_t more) {
  if (t->failed) return;
  if (t->n + more + 1 <= t->cap) return;
  size_t cap = t->cap ? t->cap : 1024;
  while (cap < t->n + more + 1) {
    if (cap > SIZE_MAX / 2) {
      t->failed = 1;
      return;
    }
    cap *= 2;
  }
  char *np = realloc(t->p, cap);
  if (!np) {
    t->failed = 1;
    return;
  }
  t->p = np, t->cap = cap;
}

static void t_put(ex_text *t, const char *s, size_t n) {
  t_reserve(t, n);
  if (t->failed) return;
  memcpy(t->p + t->n, s, n);
  t->n += n;
  t->p[t->n] = 0;
}

void ex_puts(ex_text *t, const char *s) { t_put(t, s, strlen(s)); }

void ex_printf(ex_text *t, const char *fmt, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (n < 0 || (size_t)n >= sizeof buf) {
    t->failed = 1;
    return;
  }
  t_put(t, buf, (size_t)n);
}

void ex_text_free(ex_text *t) {
  free(t->p);
  memset(t, 0, sizeof *t);
}

/* The shortest "%.*e" text that reads back as x, taken apart into its
 * digits and decimal exponent (whatever the locale's decimal point), then
 * laid out as Python's float_repr_style "short": fixed notation for
 * exponents -4..15, else d.ddde+XX. */
void ex_put_float(ex_text *t, double x) {
  if (isnan(x)) return ex_puts(t, "NaN");
  if (isinf(x)) return ex_puts(t, x > 0 ? "Infinity" : "-Infinity");
  if (x == 0) return ex_puts(t, signbit(x) ? "-0.0" : "0.0");
  char e[64];
  for (int prec = 1; prec <= 17; prec++) {
    snprintf(e, sizeof e, "%.*e", prec - 1, x);
    if (strtod(e, NULL) == x) break;
  }
  char digits[24];
  int nd = 0, neg = 0, ex = 0;
  const char *p = e;
  if (*p == '-') neg = 1, p++;
  for (; *p && *p != 'e' && *p != 'E'; p++)
    if (*p >= '0' && *p <= '9' && nd < 20) digits[nd++] = *p;
  if (*p) ex = atoi(p + 1);
  while (nd > 1 && digits[nd - 1] == '0') nd--;
  digits[nd] = 0;
  char out[64];
  int m = 0;
  if (neg) out[m++] = '-';
  if (ex >= -4 && ex < 16) {
    if (ex < 0) {
      out[m++] = '0', out[m++] = '.';
      for (int k = 0; k < -ex - 1; k++) out[m++] = '0';
      for (int k = 0; k < nd; k++) out[m++] = digits[k];
    } else {
      for (int k = 0; k <= ex; k++) out[m++] = k < nd ? digits[k] : '0';
      out[m++] = '.';
      if (nd > ex + 1)
        for (int k = ex + 1; k < nd; k++) out[m++] = digits[k];
      else out[m++] = '0';
    }
    out[m] = 0;
  } else {
    out[m++] = digits[0];
    if (nd > 1) {
      out[m++] = '.';
      for (int k = 1; k < nd; k++) out[m++] = digits[k];
    }
    snprintf(out + m, sizeof out - (size_t)m, "e%c%02d", ex < 0 ? '-' : '+', ex < 0 ? -ex : ex);
  }
  ex_puts(t, out);
}

void ex_put_jstr(ex_text *t, const char *s) {
  ex_puts(t, "\"");
  for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
    char esc[8];
    switch (*c) {
      case '"': ex_puts(t, "\\\""); break;
      case '\\': ex_puts(t, "\\\\"); break;
      case '\n': ex_puts(t, "\\n"); break;
      case '\r': ex_puts(t, "\\r"); break;
      case '\t': ex_puts(t, "\\t"); break;
      case '\b': ex_puts(t, "\\b"); break;
      case '\f': ex_puts(t, "\\f"); break;
      default:
        if (*c < 0x20) {
          snprintf(esc, sizeof esc, "\\u%04x", *c);
          ex_puts(t, esc);
        } else {
          t_put(t, (const char *)c, 1);
        }
    }
  }
  ex_puts(t, "\"");
}

/* ---- numpy's sums ------------------------------------------------------------ */
/* numpy's pairwise_sum: 8 accumulators over blocks of up to 128, halves above */
static double pairwise(const double *a, size_t n) {
  if (n < 8) {
    double r = 0.0;
    for (size_t i = 0; i < n; i++) r += a[i];
    return r;
  }
  if (n <= 128) {
    double r[8];
    for (int j = 0; j < 8; j++) r[j] = a[j];
    size_t i;
    for (i = 8; i < n - n % 8; i += 8)
      for (int j = 0; j < 8; j++) r[j] += a[i + (size_t)j];
    double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; i++) res += a[i];
    return res;
  }
  size_t n2 = n / 2;
  n2 -= n2 % 8;
  return pairwise(a, n2) + pairwise(a + n2, n - n2);
}

#define NP_BUFSIZE 8192

double ex_np_sum_into(double acc, const double *x, size_t n) {
  for (size_t b = 0; b < n; b += NP_BUFSIZE)
    acc += pairwise(x + b, n - b < NP_BUFSIZE ? n - b : NP_BUFSIZE);
  return acc;
}

double ex_np_sum(const double *x, size_t n) { return ex_np_sum_into(0.0, x, n); }

void ex_stats_f32(const float *x, size_t T, int dim, ex_stats *s) {
  memset(s, 0, sizeof *s);
  s->dim = dim;
  s->count = (int64_t)T;
  float sum[EX_STATS_MAX_DIM] = {0}, mn[EX_STATS_MAX_DIM], mx[EX_STATS_MAX_DIM],
        var[EX_STATS_MAX_DIM] = {0};
  for (int j = 0; j < dim; j++) mn[j] = mx[j] = x[j];
  for (size_t i = 0; i < T; i++)
    for (int j = 0; j < dim; j++) {
      float v = x[i * (size_t)dim + (size_t)j];
      sum[j] += v;
      if (v < mn[j]) mn[j] = v;
      if (v > mx[j]) mx[j] = v;
    }
  float mean[EX_STATS_MAX_DIM];
  for (int j = 0; j < dim; j++) mean[j] = sum[j] / (float)T;
  for (size_t i = 0; i < T; i++)
    for (int j = 0; j < dim; j++) {
      float dv = x[i * (size_t)dim + (size_t)j] - mean[j];
      var[j] += dv * dv;
    }
  for (int j = 0; j < dim; j++) {
    s->min[j] = mn[j], s->max[j] = mx[j], s->mean[j] = mean[j];
    s->std[j] = sqrtf(var[j] / (float)T);
  }
}

/* mean and std of n float64 values as np.mean / np.std */
static hearth_status f64_moments(const double *x, size_t n, double *mean, double *sd,
                                 hearth_err *err) {
  double *sq = hearth_alloc_array(n, sizeof *sq);
  if (!sq) return hearth_err_set(err, HEARTH_E_NOMEM, "export: statistics of %zu values", n);
  double m = ex_np_sum(x, n) / (double)n;
  for (size_t i = 0; i < n; i++) {
    double d = x[i] - m;
    sq[i] = d * d;
  }
  *mean = m;
  *sd = sqrt(ex_np_sum(sq, n) / (double)n);
  free(sq);
  return HEARTH_OK;
}

hearth_status ex_stats_f64(const double *x, size_t T, ex_stats *s, hearth_err *err) {
  memset(s, 0, sizeof *s);
  s->dim = 1;
  s->count = (int64_t)T;
  s->min[0] = s->max[0] = x[0];
  for (size_t i = 1; i < T; i++) {
    if (x[i] < s->min[0]) s->min[0] = x[i];
    if (x[i] > s->max[0]) s->max[0] = x[i];
  }
  return f64_moments(x, T, &s->mean[0], &s->std[0], err);
}

hearth_status ex_stats_i64(const int64_t *x, size_t T, ex_stats *s, hearth_err *err) {
  memset(s, 0, sizeof *s);
  s->dim = 1;
  s->integer = 1;
  s->count = (int64_t)T;
  double *v = hearth_alloc_array(T, sizeof *v);
  if (!v) return hearth_err_set(err, HEARTH_E_NOMEM, "export: statistics of %zu values", T);
  int64_t mn = x[0], mx = x[0];
  for (size_t i = 0; i < T; i++) {
    if (x[i] < mn) mn = x[i];
    if (x[i] > mx) mx = x[i];
    v[i] = (double)x[i];
  }
  s->min[0] = (double)mn, s->max[0] = (double)mx;
  hearth_status st = f64_moments(v, T, &s->mean[0], &s->std[0], err);
  free(v);
  return st;
}

/* compute_stats.sample_indices: estimate_num_samples(T) indices
 * np.round(np.linspace(0, T - 1, n)) (round half to even) */
static size_t sample_count(size_t T) {
  size_t lo = T < 100 ? T : 100;
  double p = floor(pow((double)T, 0.75));
  size_t k = p > 10000 ? 10000 : (size_t)p;
  return k > lo ? k : lo;
}

hearth_status ex_stats_images(const uint8_t *frames, size_t T, int w, int h, ex_stats *s,
                              hearth_err *err) {
  memset(s, 0, sizeof *s);
  s->dim = 3;
  s->image = 1;
  size_t n = sample_count(T);
  /* auto_downsample_height_width: every f-th row and column from 300 pixels up */
  int f = 1;
  if ((w > h ? w : h) >= 300) f = (int)((w > h ? (double)w : (double)h) / 150.0);
  size_t dw = ((size_t)w + (size_t)f - 1) / (size_t)f, dh = ((size_t)h + (size_t)f - 1) / (size_t)f;
  size_t plane = dw * dh;
  double *dev = hearth_alloc_array(plane, sizeof *dev);
  size_t *idx = hearth_alloc_array(n, sizeof *idx);
  if (!dev || !idx) {
    free(dev), free(idx);
    return hearth_err_set(err, HEARTH_E_NOMEM, "export: image statistics");
  }
  double step = n > 1 ? (double)(T - 1) / (double)(n - 1) : 0.0;
  for (size_t i = 0; i < n; i++) {
    double y = n > 1 ? (double)i * step : 0.0;
    if (i == n - 1 && n > 1) y = (double)(T - 1);
    idx[i] = (size_t)nearbyint(y);
  }
  size_t fs = (size_t)w * (size_t)h * 3;
  for (int c = 0; c < 3; c++) {
    uint64_t sum = 0;
    int mn = 255, mx = 0;
    for (size_t i = 0; i < n; i++) {
      const uint8_t *img = frames + idx[i] * fs;
      for (size_t y = 0; y < dh; y++)
        for (size_t x = 0; x < dw; x++) {
          int v = img[3 * ((y * (size_t)f) * (size_t)w + x * (size_t)f) + (size_t)c];
          sum += (uint64_t)v;
          if (v < mn) mn = v;
          if (v > mx) mx = v;
        }
    }
    double count = (double)n * (double)plane;
    double mean = (double)sum / count, acc = 0.0;
    for (size_t i = 0; i < n; i++) {
      const uint8_t *img = frames + idx[i] * fs;
      for (size_t y = 0; y < dh; y++)
        for (size_t x = 0; x < dw; x++) {
          double d =
              (double)img[3 * ((y * (size_t)f) * (size_t)w + x * (size_t)f) + (size_t)c] - mean;
          dev[y * dw + x] = d * d;
        }
      acc = ex_np_sum_into(acc, dev, plane); /* one output, its chunks in order */
    }
    s->min[c] = (double)mn / 255.0;
    s->max[c] = (double)mx / 255.0;
    s->mean[c] = mean / 255.0;
    s->std[c] = sqrt(acc / count) / 255.0;
  }
  s->count = (int64_t)n;
  free(dev), free(idx);
  return HEARTH_OK;
}

static void put_values(ex_text *t, const ex_stats *s, const double *v, int integer) {
  ex_puts(t, "[");
  for (int j = 0; j < s->dim; j++) {
    if (j) ex_puts(t, ", ");
    if (s->image) ex_puts(t, "[[");
    if (integer) ex_printf(t, "%lld", (long long)v[j]);
    else ex_put_float(t, v[j]);
    if (s->image) ex_puts(t, "]]");
  }
  ex_puts(t, "]");
}

void ex_put_stats(ex_text *t, const char *name, const ex_stats *s) {
  ex_put_jstr(t, name);
  ex_puts(t, ": {\"min\": ");
  put_values(t, s, s->min, s->integer);
  ex_puts(t, ", \"max\": ");
  put_values(t, s, s->max, s->integer);
  ex_puts(t, ", \"mean\": ");
  put_values(t, s, s->mean, 0);
  ex_puts(t, ", \"std\": ");
  put_values(t, s, s->std, 0);
  ex_printf(t, ", \"count\": [%lld]}", (long long)s->count);
}
