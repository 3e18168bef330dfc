/* Hole-centre detection on a hole target (the paper's 84-hole plate by
 * default).
 *
 * Colour: the holes are usually dark blobs on the white plate. Thermal: the
 * holes usually show the warmed backing; the matrix is percentile-clipped,
 * scaled to 8 bits and upsampled (a private copy) so blob detection has
 * smooth shapes to work with. When the usual polarity finds no target the
 * inverted image is tried (holes brighter in colour, cooler in thermal).
 * Either way the blobs are ordered by the target lattice
 * (calib_order.c) and each centre is then refined as an intensity-weighted
 * centroid on the raw values (thermal: the untouched matrix, native pixels)
 * inside an elliptical window shaped by the blob's own second moments. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

void hearth_detect_opts_default(hearth_detect_opts *o) {
  memset(o, 0, sizeof *o);
  o->upsample = 4;
  o->clip_lo_pct = 1.0;
  o->clip_hi_pct = 99.5;
  o->max_blur_frac = 0.4;
}

typedef struct blob {
  double area;          /* in the detection image's pixels */
  double cx, cy;        /* native pixels */
  double sxx, sxy, syy; /* covariance, native pixels^2 */
  int touches_border;
} blob;

/* Otsu threshold of a 256-bin histogram */
static int otsu(const size_t hist[256]) {
  double total = 0, sum = 0;
  for (int i = 0; i < 256; i++) {
    total += (double)hist[i];
    sum += (double)i * (double)hist[i];
  }
  double wb = 0, sb = 0, best = -1;
  int thr = 128;
  for (int t = 0; t < 256; t++) {
    wb += (double)hist[t];
    if (wb == 0) continue;
    double wf = total - wb;
    if (wf == 0) break;
    sb += (double)t * (double)hist[t];
    double mb = sb / wb, mf = (sum - sb) / wf;
    double between = wb * wf * (mb - mf) * (mb - mf);
    if (between > best) {
      best = between;
      thr = t;
    }
  }
  return thr;
}

/* connected components (8-connected) of pixels > thr in a U8 image, by
 * runs: each row's foreground runs are joined to overlapping runs of the row
 * above with union-find, and the moments are summed in closed form per run.
 * Blob statistics are converted to native pixels: native = (j + 0.5) s - 0.5. */
typedef struct run_t {
  int32_t parent;
  int32_t x0, x1; /* inclusive */
  int32_t y;
} run_t;

static int32_t run_find(run_t *r, int32_t i) {
  while (r[i].parent != i) {
    r[i].parent = r[r[i].parent].parent;
    i = r[i].parent;
  }
  return i;
}

/* bit 7 of each byte of the result is set where that byte of p[0..8) is
 * > t: the low 7 bits are compared by an add that cannot carry across
 * bytes, then combined with the top bits */
static inline uint64_t gt8(const uint8_t *p, int t) {
  const uint64_t ones = 0x0101010101010101ULL, tops = 0x8080808080808080ULL;
  uint64_t x;
  memcpy(&x, p, 8);
  uint64_t c = (x & ~tops) + ones * (uint64_t)(0x7f - (t & 0x7f));
  return (t < 128 ? (x | c) : (x & c)) & tops;
}

static hearth_status find_blobs(const uint8_t *img, size_t w, size_t h, int thr, double s,
                                blob **out, size_t *n_out, hearth_err *err) {
  size_t cap = 4096, nr = 0;
  run_t *runs = malloc(sizeof(run_t) * cap);
  if (!runs) return hearth_err_set(err, HEARTH_E_NOMEM, "blob detection: out of memory");
  size_t prev_begin = 0, prev_end = 0;
  for (size_t y = 0; y < h; y++) {
    const uint8_t *row = img + y * w;
    size_t cur_begin = nr, p = prev_begin;
    size_t x = 0;
    while (x < w) {
      /* eight bytes at a time through plain background and run interiors */
      while (x + 8 <= w && gt8(row + x, thr) == 0) x += 8;
      while (x < w && row[x] <= thr) x++;
      if (x >= w) break;
      size_t x0 = x;
      while (x + 8 <= w && gt8(row + x, thr) == 0x8080808080808080ULL) x += 8;
      while (x < w && row[x] > thr) x++;
      if (nr == cap) {
        run_t *nrs = realloc(runs, sizeof(run_t) * cap * 2);
        if (!nrs) {
          free(runs);
          return hearth_err_set(err, HEARTH_E_NOMEM, "blob detection: out of memory");
        }
        runs = nrs;
        cap *= 2;
      }
      run_t *r = &runs[nr];
      r->parent = (int32_t)nr;
      r->x0 = (int32_t)x0;
      r->x1 = (int32_t)(x - 1);
      r->y = (int32_t)y;
      /* previous-row runs touching [x0 - 1, x] (8-connectivity) */
      while (p < prev_end && runs[p].x1 < (int32_t)x0 - 1) p++;
      for (size_t q = p; q < prev_end && runs[q].x0 <= (int32_t)x; q++) {
        int32_t a = run_find(runs, (int32_t)q), b = run_find(runs, (int32_t)nr);
        if (a != b) runs[a > b ? a : b].parent = a < b ? a : b;
      }
      nr++;
    }
    prev_begin = cur_begin;
    prev_end = nr;
  }
  /* accumulate moments per root */
  double *acc = hearth_calloc_array(nr ? nr : 1, 7 * sizeof(double));
  if (!acc) {
    free(runs);
    return hearth_err_set(err, HEARTH_E_NOMEM, "blob detection: out of memory");
  }
  for (size_t i = 0; i < nr; i++) {
    int32_t root = run_find(runs, (int32_t)i);
    double a = runs[i].x0, b = runs[i].x1, y = runs[i].y, n = b - a + 1;
    double sx = (a + b) * n / 2;
    double sxx = (b * (b + 1) * (2 * b + 1) - (a - 1) * a * (2 * a - 1)) / 6;
    double *m = acc + 7 * (size_t)root;
    m[0] += n;
    m[1] += sx;
    m[2] += n * y;
    m[3] += sxx;
    m[4] += y * sx;
    m[5] += n * y * y;
    if (runs[i].x0 == 0 || runs[i].x1 == (int32_t)w - 1 || runs[i].y == 0 ||
        runs[i].y == (int32_t)h - 1)
      m[6] = 1;
  }
  size_t n = 0, bcap = 256;
  blob *bl = malloc(sizeof(blob) * bcap);
  if (!bl) {
    free(runs);
    free(acc);
    return hearth_err_set(err, HEARTH_E_NOMEM, "blob detection: out of memory");
  }
  for (size_t i = 0; i < nr; i++) {
    if (runs[i].parent != (int32_t)i) continue;
    const double *m = acc + 7 * i;
    double a = m[0];
    if (a < 4) continue;
    if (n == bcap) {
      blob *nb = realloc(bl, sizeof(blob) * bcap * 2);
      if (!nb) {
        free(runs);
        free(acc);
        free(bl);
        return hearth_err_set(err, HEARTH_E_NOMEM, "blob detection: out of memory");
      }
      bl = nb;
      bcap *= 2;
    }
    blob *b = &bl[n++];
    double mx = m[1] / a, my = m[2] / a;
    b->area = a;
    b->cx = (mx + 0.5) * s - 0.5;
    b->cy = (my + 0.5) * s - 0.5;
    b->sxx = (m[3] / a - mx * mx + 1.0 / 12) * s * s;
    b->sxy = (m[4] / a - mx * my) * s * s;
    b->syy = (m[5] / a - my * my + 1.0 / 12) * s * s;
    b->touches_border = m[6] != 0;
  }
  free(runs);
  free(acc);
  *out = bl;
  *n_out = n;
  return HEARTH_OK;
}

/* k-th smallest of v[0..n) (v reordered) */
static double select_kth(double *v, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  while (lo < hi) {
    double piv = v[lo + (hi - lo) / 2];
    size_t i = lo, j = hi;
    while (i <= j) {
      while (v[i] < piv) i++;
      while (v[j] > piv) j--;
      if (i <= j) {
        double t = v[i];
        v[i] = v[j];
        v[j] = t;
        i++;
        if (j == 0) break;
        j--;
      }
    }
    if (k <= j) hi = j;
    else if (k >= i) lo = i;
    else return v[k];
  }
  return v[k];
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* keep hole-like blobs: not on the border, area within 5x of the median */
static size_t filter_blobs(blob *bl, size_t n) {
  if (!n) return 0;
  double *areas = malloc(sizeof(double) * n);
  if (!areas) return 0;
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (!bl[i].touches_border && bl[i].area >= 12) areas[m++] = bl[i].area;
  if (!m) {
    free(areas);
    return 0;
  }
  qsort(areas, m, sizeof(double), cmp_double);
  double med = areas[m / 2];
  free(areas);
  size_t k = 0;
  for (size_t i = 0; i < n; i++) {
    blob *b = &bl[i];
    if (b->touches_border || b->area < 12 || b->area < med / 5 || b->area > med * 5) continue;
    /* a hole's moments describe a proper ellipse */
    double det = b->sxx * b->syy - b->sxy * b->sxy;
    if (!(det > 0)) continue;
    bl[k++] = *b;
  }
  return k;
}

/* the raw values refinement reads: a float matrix, or 8-bit colour read as
 * luma on the fly (no full-size gray copy of a 1080p frame) */
typedef struct pixsrc {
  const float *f;
  const uint8_t *u8;
  int ch;
} pixsrc;

/* one row span [x0, x1] of the raw values as floats (colour: luma) */
static void px_row(const pixsrc *P, size_t w, long y, long x0, long x1, float *out) {
  size_t base = (size_t)y * w + (size_t)x0, n = (size_t)(x1 - x0 + 1);
  if (P->f) {
    memcpy(out, P->f + base, n * sizeof(float));
  } else if (P->ch >= 3) {
    const uint8_t *q = P->u8 + base * (size_t)P->ch;
    for (size_t i = 0; i < n; i++, q += P->ch)
      out[i] = (float)(0.299 * q[0] + 0.587 * q[1] + 0.114 * q[2]);
  } else if (P->ch == 1) {
    const uint8_t *restrict q = P->u8 + base;
    for (size_t i = 0; i < n; i++) out[i] = q[i]; /* vectorised: unit stride */
  } else {
    const uint8_t *q = P->u8 + base * (size_t)P->ch;
    for (size_t i = 0; i < n; i++) out[i] = q[i * (size_t)P->ch];
  }
}

/* columns of row offset dy where ia dx^2 + 2 ib dx dy + id dy^2 <= r2
 * (dx = x - cx), widened by a pixel each side against rounding; 0 if the
 * row misses the ellipse (with the same slack) */
static int ellipse_span(double ia, double ib, double id, double dy, double r2, double cx, long *x0,
                        long *x1) {
  double disc = ib * ib * dy * dy - ia * (id * dy * dy - r2);
  if (disc < 0) disc = 0;
  double sq = sqrt(disc), lo = (-ib * dy - sq) / ia, hi = (-ib * dy + sq) / ia;
  /* rows just outside still get a short span around the nearest point:
   * the exact per-pixel test rejects them */
  *x0 = (long)floor(cx + lo) - 1;
  *x1 = (long)ceil(cx + hi) + 1;
  return 1;
}

/* refine one hole: intensity-weighted centroid of s * (I - bg) inside the
 * ellipse 1.5x the hole, bg the median of the ring 1.35..1.75x; returns the
 * blur estimate (sigma / radius) or NAN if the hole vanished */
static double refine_centre(const pixsrc *I, size_t w, size_t h, double sign, const double S[3],
                            double c[2], double *scratch, size_t scratch_n, float *row) {
  /* ellipse metric: d^2 = x^T (4 S)^-1 x, 1 at the hole edge */
  double a = 4 * S[0], b = 4 * S[1], d = 4 * S[2];
  double det = a * d - b * b;
  if (!(det > 0)) return NAN;
  double ia = d / det, ib = -b / det, id = a / det;
  double ex = sqrt(a), ey = sqrt(d);
  double cx = c[0], cy = c[1], var = NAN, bg = 0;
  for (int it = 0; it < 8; it++) {
    /* background: median of the ring 1.35..1.75 (clipped to the image);
     * after two rounds the window no longer moves enough to change it */
    if (it < 2) {
      long x0 = (long)floor(cx - 1.75 * ex - 1), x1 = (long)ceil(cx + 1.75 * ex + 1);
      long y0 = (long)floor(cy - 1.75 * ey - 1), y1 = (long)ceil(cy + 1.75 * ey + 1);
      if (x0 < 0) x0 = 0;
      if (y0 < 0) y0 = 0;
      if (x1 >= (long)w) x1 = (long)w - 1;
      if (y1 >= (long)h) y1 = (long)h - 1;
      size_t m = 0;
      /* 8-bit gray (the luma plane of a JPEG): the median from a histogram,
       * the same value as selecting it from the list */
      int u8 = I->u8 && I->ch == 1;
      uint32_t hist[256];
      if (u8) memset(hist, 0, sizeof hist);
      for (long y = y0; y <= y1; y++) {
        /* only the columns near the ring: the outer span of this row, less
         * the inside of the inner one (a pixel of slack each side, the
         * exact test decides) */
        double dy = (double)y - cy;
        long a1, b1, a0, b0;
        if (!ellipse_span(ia, ib, id, dy, 1.75 * 1.75, cx, &a1, &b1)) continue;
        if (a1 < x0) a1 = x0;
        if (b1 > x1) b1 = x1;
        if (a1 > b1) continue;
        if (!ellipse_span(ia, ib, id, dy, 1.35 * 1.35, cx, &a0, &b0) || a0 + 2 > b0 - 2) {
          a0 = b1 + 1;
          b0 = b1;
        } else {
          a0 += 2;
          b0 -= 2;
          if (a0 < a1) a0 = a1;
          if (a0 > b0) a0 = b1 + 1;
        }
        px_row(I, w, y, a1, b1, row);
        for (long x = a1; x <= b1; x++) {
          if (x == a0) {
            x = b0;
            continue;
          }
          double dx = (double)x - cx;
          double q = ia * dx * dx + 2 * ib * dx * dy + id * dy * dy;
          if (q >= 1.35 * 1.35 && q <= 1.75 * 1.75 && m < scratch_n) {
            if (u8) hist[(int)row[x - a1]]++, m++;
            else scratch[m++] = row[x - a1];
          }
        }
      }
      if (m < 8) return NAN;
      if (u8) {
        size_t cum = 0, k = m / 2;
        int v = 0;
        while (v < 255 && (cum += hist[v]) <= k) v++;
        bg = v;
      } else {
        bg = select_kth(scratch, m, m / 2);
      }
    }
    /* the centroid window must lie wholly inside the image */
    long x0 = (long)floor(cx - 1.5 * ex), x1 = (long)ceil(cx + 1.5 * ex);
    long y0 = (long)floor(cy - 1.5 * ey), y1 = (long)ceil(cy + 1.5 * ey);
    if (x0 < 0 || y0 < 0 || x1 >= (long)w || y1 >= (long)h) return NAN;
    double sw = 0, sx = 0, sy = 0, sq = 0;
    for (long y = y0; y <= y1; y++) {
      double dy = (double)y - cy;
      long xa, xb;
      if (!ellipse_span(ia, ib, id, dy, 1.5 * 1.5, cx, &xa, &xb)) continue;
      if (xa < x0) xa = x0;
      if (xb > x1) xb = x1;
      if (xa > xb) continue;
      px_row(I, w, y, xa, xb, row);
      for (long x = xa; x <= xb; x++) {
        double dx = (double)x - cx;
        double q = ia * dx * dx + 2 * ib * dx * dy + id * dy * dy;
        if (q > 1.5 * 1.5) continue;
        double wt = sign * ((double)row[x - xa] - bg);
        if (wt <= 0) continue;
        sw += wt;
        sx += wt * dx;
        sy += wt * dy;
        sq += wt * q;
      }
    }
    if (!(sw > 0)) return NAN;
    double mx = sx / sw, my = sy / sw;
    var = sq / sw;
    cx += mx;
    cy += my;
    /* a thousandth of a pixel: far below the centres' noise (hundredths) */
    if (hypot(mx, my) < 1e-3) break;
  }
  c[0] = cx;
  c[1] = cy;
  /* unit disc: E[q] = 1/2; blur sigma (in radii) adds 2 sigma^2 */
  double s2 = (var - 0.5) / 2;
  return s2 > 0 ? sqrt(s2) : 0.0;
}

/* common tail: blobs -> ordered, refined centres on the raw image */
static hearth_status finish(blob *bl, size_t nb, const pixsrc *raw, size_t w, size_t h, double sign,
                            const hearth_detect_opts *o, hearth_detection *det, hearth_err *err) {
  det->found = 0;
  det->reason[0] = 0;
  memset(det->centres, 0, sizeof det->centres);
  double(*pts)[2] = malloc(sizeof(double) * 2 * (nb ? nb : 1));
  if (!pts) return hearth_err_set(err, HEARTH_E_NOMEM, "detection: out of memory");
  for (size_t i = 0; i < nb; i++) {
    pts[i][0] = bl[i].cx;
    pts[i][1] = bl[i].cy;
  }
  hearth_target tdef;
  const size_t holes = hearth_target_holes(hearth_target_or_default(&o->target, &tdef));
  double(*ord)[2] = malloc(sizeof(*ord) * (holes ? holes : 1));
  double *blur = malloc(sizeof(double) * (holes ? holes : 1));
  float *row = malloc(sizeof(float) * w);
  if (!ord || !blur || !row) {
    free(pts);
    free(ord);
    free(blur);
    free(row);
    return hearth_err_set(err, HEARTH_E_NOMEM, "detection: out of memory");
  }
  hearth_status st = HEARTH_OK;
  if (!hearth_target_order(&o->target, (const double(*)[2])pts, nb, ord, det->reason,
                           sizeof det->reason))
    goto done;
  /* match ordered points back to their blobs for the window shapes */
  double scratch[4096];
  for (size_t i = 0; i < holes; i++) {
    size_t bi = 0;
    for (size_t j = 0; j < nb; j++)
      if (pts[j][0] == ord[i][0] && pts[j][1] == ord[i][1]) {
        bi = j;
        break;
      }
    double S[3] = {bl[bi].sxx, bl[bi].sxy, bl[bi].syy};
    double c[2] = {ord[i][0], ord[i][1]};
    blur[i] = refine_centre(raw, w, h, sign, S, c, scratch, 4096, row);
    if (isnan(blur[i])) {
      snprintf(det->reason, sizeof det->reason,
               "hole %zu at (%.1f, %.1f) could not be refined (too close to the edge)", i,
               ord[i][0], ord[i][1]);
      goto done;
    }
    det->centres[i][0] = c[0];
    det->centres[i][1] = c[1];
  }
  qsort(blur, holes, sizeof(double), cmp_double);
  double med_blur = holes % 2 ? blur[holes / 2] : 0.5 * (blur[holes / 2 - 1] + blur[holes / 2]);
  if (med_blur > o->max_blur_frac) {
    snprintf(det->reason, sizeof det->reason,
             "blurred: edge spread %.2f of the hole radius (limit %.2f)", med_blur,
             o->max_blur_frac);
    goto done;
  }
  det->found = 1;
done:
  free(pts);
  free(ord);
  free(blur);
  free(row);
  return st;
}

/* blob detection at a few thresholds: Otsu first, then fixed fractions
 * between the typical level (median) and the blob peaks (99.5th
 * percentile). Blurred plates defeat Otsu (the valley fills in); the first
 * threshold that yields the whole ordered plate wins. */
static hearth_status detect_multi(const uint8_t *U, size_t W, size_t H, double scale,
                                  const pixsrc *raw, size_t w, size_t h, double sign,
                                  const hearth_detect_opts *o, hearth_detection *det,
                                  hearth_err *err) {
  /* four interleaved histograms: consecutive equal pixels would otherwise
   * serialise on one counter */
  size_t hist[256] = {0}, n = W * H;
  {
    uint32_t h4[4][256];
    memset(h4, 0, sizeof h4);
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
      h4[0][U[i]]++;
      h4[1][U[i + 1]]++;
      h4[2][U[i + 2]]++;
      h4[3][U[i + 3]]++;
    }
    for (; i < n; i++) h4[0][U[i]]++;
    for (int k = 0; k < 256; k++) hist[k] = (size_t)h4[0][k] + h4[1][k] + h4[2][k] + h4[3][k];
  }
  int med = 0, p995 = 255, p01 = 0, p99 = 255;
  size_t acc = 0;
  for (int i = 0; i < 256; i++) {
    acc += hist[i];
    if (acc * 2 <= n) med = i + 1;
    if (acc * 1000 < n * 995) p995 = i + 1;
    if (acc * 100 < n) p01 = i + 1;
    if (acc * 100 < n * 99) p99 = i + 1;
  }
  /* then a sweep of the levels between the 1st and 99th percentiles, for
   * holes of low contrast beside a distractor (a person, a window) that
   * sets the percentiles, or level with the background */
  enum { NFIX = 9, NT = NFIX + 64 };
  int thr[NT] = {otsu(hist)};
  static const int frac[NFIX - 1] = {50, 35, 65, 75, 85, 25, 45, 55};
  for (int k = 1; k < NFIX; k++) thr[k] = med + (p995 - med) * frac[k - 1] / 100;
  for (int k = NFIX; k < NT; k++) thr[k] = -1;
  for (int k = NFIX, t = p01 + 3; k < NT && t < p99; k++, t += 4) thr[k] = t;
  char first_reason[256] = "";
  for (int k = 0; k < NT; k++) {
    int dup = 0;
    for (int q = 0; q < k; q++) dup |= thr[q] == thr[k];
    if (thr[k] < 0) break;
    if (dup || thr[k] >= 255) continue;
    blob *bl = NULL;
    size_t nb = 0;
    hearth_status st = find_blobs(U, W, H, thr[k], scale, &bl, &nb, err);
    if (st) return st;
    nb = filter_blobs(bl, nb);
    st = finish(bl, nb, raw, w, h, sign, o, det, err);
    free(bl);
    if (st) return st;
    if (det->found || !strncmp(det->reason, "blurred", 7)) return HEARTH_OK;
    if (!first_reason[0]) snprintf(first_reason, sizeof first_reason, "%s", det->reason);
  }
  snprintf(det->reason, sizeof det->reason, "%s", first_reason);
  return HEARTH_OK;
}

/* detect_multi with the usual polarity, then (not found, not blurred) on
 * the inverted image with the opposite sign; U is inverted in place. The
 * reason kept for a frame found in neither is the usual polarity's. */
static hearth_status detect_polarities(uint8_t *U, size_t W, size_t H, double scale,
                                       const pixsrc *raw, size_t w, size_t h, double sign,
                                       const hearth_detect_opts *o, hearth_detection *det,
                                       hearth_err *err) {
  hearth_status st = detect_multi(U, W, H, scale, raw, w, h, sign, o, det, err);
  if (st || det->found || !strncmp(det->reason, "blurred", 7)) return st;
  char first[256];
  snprintf(first, sizeof first, "%s", det->reason);
  for (size_t i = 0; i < W * H; i++) U[i] = (uint8_t)(255 - U[i]);
  st = detect_multi(U, W, H, scale, raw, w, h, -sign, o, det, err);
  if (st || det->found || !strncmp(det->reason, "blurred", 7)) return st;
  snprintf(det->reason, sizeof det->reason, "%s", first);
  return HEARTH_OK;
}

hearth_status hearth_detect_plate_thermal(const hearth_image *temps, const hearth_detect_opts *o,
                                          hearth_detection *det, hearth_err *err) {
  hearth_detect_opts def;
  if (!o) {
    hearth_detect_opts_default(&def);
    o = &def;
  }
  if (!temps || !det || !temps->data)
    return hearth_err_set(err, HEARTH_E_ARG, "thermal detection: missing argument");
  if (temps->type != HEARTH_PIX_F32 || temps->channels != 1)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "thermal detection: expected a 1-channel float matrix");
  size_t w = temps->width, h = temps->height, npx = w * h;
  int up = o->upsample >= 1 && o->upsample <= 8 ? o->upsample : 4;
  if (w < 16 || h < 16 || w > 4096 || h > 4096)
    return hearth_err_set(err, HEARTH_E_SIZE, "thermal detection: %zux%zu matrix", w, h);
  const float *T = temps->data;
  hearth_status st = HEARTH_OK;
  uint8_t *g8 = malloc(npx);
  /* 16 bytes of slack: the upsampling writes whole blocks of 16 */
  uint8_t *U = malloc(npx * (size_t)up * (size_t)up + 16);
  if (!g8 || !U) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "thermal detection: out of memory");
    goto done;
  }
  /* per-frame percentile clip -> 8 bit (a copy; the matrix is untouched) */
  {
    float mn = T[0], mx = T[0];
    for (size_t i = 0; i < npx; i++) {
      if (!(T[i] >= mn)) mn = T[i];
      if (!(T[i] <= mx)) mx = T[i];
    }
    if (!isfinite(mn) || !isfinite(mx)) {
      st = hearth_err_set(err, HEARTH_E_RANGE, "thermal detection: non-finite temperatures");
      goto done;
    }
    /* 4096-bin histogram percentiles (exact enough for a display clip) */
    size_t hist[4096] = {0};
    double span = (double)mx - (double)mn;
    for (size_t i = 0; i < npx; i++) {
      size_t b = span > 0 ? (size_t)(((double)T[i] - mn) / span * 4095.0) : 0;
      hist[b]++;
    }
    double lo = mn, hi = mx;
    size_t acc = 0, klo = (size_t)(o->clip_lo_pct / 100.0 * (double)npx),
           khi = (size_t)(o->clip_hi_pct / 100.0 * (double)npx);
    int got_lo = 0;
    for (int b = 0; b < 4096; b++) {
      acc += hist[b];
      if (!got_lo && acc > klo) {
        lo = mn + span * b / 4095.0;
        got_lo = 1;
      }
      if (acc > khi || b == 4095) {
        hi = mn + span * (b + 1) / 4095.0;
        break;
      }
    }
    if (!(hi > lo)) {
      det->found = 0;
      snprintf(det->reason, sizeof det->reason, "flat image: no plate");
      goto done;
    }
    for (size_t i = 0; i < npx; i++) {
      double v = ((double)T[i] - lo) / (hi - lo) * 255.0;
      g8[i] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
    }
  }
  /* bilinear upsampling: up pixel j samples native (j + 0.5) / up - 0.5.
   * Separable and in fixed point (weights in 1/256): every native row is
   * interpolated along x once, then each output row blends two of those */
  size_t W = w * (size_t)up, H = h * (size_t)up;
  {
    uint32_t *cx0 = hearth_alloc_array(W, sizeof(uint32_t) * 2);
    uint16_t *cw = hearth_alloc_array(W, sizeof(uint16_t));
    size_t Wp = (W + 15) / 16 * 16;
    uint16_t *hx = hearth_calloc_array(Wp * h, sizeof(uint16_t));
    if (!cx0 || !cw || !hx) {
      free(cx0);
      free(cw);
      free(hx);
      st = hearth_err_set(err, HEARTH_E_NOMEM, "thermal detection: out of memory");
      goto done;
    }
    for (size_t x = 0; x < W; x++) {
      double fx = ((double)x + 0.5) / up - 0.5;
      if (fx < 0) fx = 0;
      if (fx > (double)(w - 1)) fx = (double)(w - 1);
      size_t x0 = (size_t)fx;
      cx0[2 * x] = (uint32_t)x0;
      cx0[2 * x + 1] = (uint32_t)(x0 + 1 < w ? x0 + 1 : x0);
      cw[x] = (uint16_t)lround((fx - (double)x0) * 256.0);
    }
    for (size_t y = 0; y < h; y++) {
      const uint8_t *restrict g = g8 + y * w;
      uint16_t *restrict d = hx + y * Wp;
      for (size_t x = 0; x < W; x++)
        d[x] = (uint16_t)(g[cx0[2 * x]] * (256u - cw[x]) + g[cx0[2 * x + 1]] * (uint32_t)cw[x]);
    }
    for (size_t y = 0; y < H; y++) {
      double fy = ((double)y + 0.5) / up - 0.5;
      if (fy < 0) fy = 0;
      if (fy > (double)(h - 1)) fy = (double)(h - 1);
      size_t y0 = (size_t)fy, y1 = y0 + 1 < h ? y0 + 1 : y0;
      uint32_t wy = (uint32_t)lround((fy - (double)y0) * 256.0), wy0 = 256u - wy;
      const uint16_t *restrict h0 = hx + y0 * Wp, *restrict h1 = hx + y1 * Wp;
      /* a block past the row end spills into the next row (rewritten
       * next) or the slack */
      uint8_t *restrict dst = U + y * W;
      /* fixed blocks of 16 (the rows are padded) so the compiler vectorises */
      for (size_t xb = 0; xb < Wp; xb += 16)
        for (size_t k = 0; k < 16; k++)
          dst[xb + k] = (uint8_t)((h0[xb + k] * wy0 + h1[xb + k] * wy + 32768u) >> 16);
    }
    free(cx0);
    free(cw);
    free(hx);
  }
  pixsrc src = {T, NULL, 1};
  st = detect_polarities(U, W, H, 1.0 / up, &src, w, h, +1.0, o, det, err);
done:
  free(g8);
  free(U);
  return st;
}

hearth_status hearth_detect_plate_color(const hearth_image *img, const hearth_detect_opts *o,
                                        hearth_detection *det, hearth_err *err) {
  hearth_detect_opts def;
  if (!o) {
    hearth_detect_opts_default(&def);
    o = &def;
  }
  if (!img || !det || !img->data)
    return hearth_err_set(err, HEARTH_E_ARG, "colour detection: missing argument");
  if (img->type != HEARTH_PIX_U8 || img->channels < 1 || img->channels > 4 || img->channels == 2)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "colour detection: expected an 8-bit gray or RGB(A) image");
  size_t w = img->width, h = img->height;
  if (w < 16 || h < 16 || w > HEARTH_IMAGE_MAX_DIM || h > HEARTH_IMAGE_MAX_DIM)
    return hearth_err_set(err, HEARTH_E_SIZE, "colour detection: %zux%zu image", w, h);
  /* a small frame (an 8-bit thermal image): its luma as a matrix through
   * the thermal path, upsampled rather than halved */
  if (w < 800 && h < 800) {
    hearth_image f = {0};
    hearth_status st = hearth_image_alloc(&f, w, h, 1, HEARTH_PIX_F32, err);
    if (st) return st;
    const uint8_t *q = img->data;
    float *fv = f.data;
    int c = img->channels;
    for (size_t i = 0; i < w * h; i++, q += c)
      fv[i] = c >= 3 ? (float)(0.299 * q[0] + 0.587 * q[1] + 0.114 * q[2]) : (float)q[0];
    st = hearth_detect_plate_thermal(&f, o, det, err);
    hearth_image_free(&f);
    return st;
  }
  /* blobs are found at half resolution (2 x 2 mean of the luma, inverted so
   * the dark holes are bright); centres are refined at full resolution */
  hearth_status st = HEARTH_OK;
  size_t hw = w / 2, hh = h / 2;
  uint8_t *inv = malloc(hw * hh);
  if (!inv) return hearth_err_set(err, HEARTH_E_NOMEM, "colour detection: out of memory");
  const uint8_t *p = img->data;
  int ch = img->channels;
  if (ch == 1) {
    /* gray (the luma plane of a JPEG): the same rounding as below */
    for (size_t y = 0; y < hh; y++) {
      const uint8_t *restrict r0 = p + 2 * y * w, *restrict r1 = r0 + w;
      uint8_t *restrict d = inv + y * hw;
      for (size_t x = 0; x < hw; x++) {
        unsigned sum = (unsigned)r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1];
        d[x] = (uint8_t)(255u - (sum + 2u) / 4u);
      }
    }
  } else {
    for (size_t y = 0; y < hh; y++)
      for (size_t x = 0; x < hw; x++) {
        int sum = 0;
        for (int dy = 0; dy < 2; dy++)
          for (int dx = 0; dx < 2; dx++) {
            const uint8_t *q = p + ((2 * y + (size_t)dy) * w + 2 * x + (size_t)dx) * (size_t)ch;
            /* integer luma, weights 77/150/29 of 256 */
            sum += ch >= 3 ? (77 * q[0] + 150 * q[1] + 29 * q[2]) : 256 * q[0];
          }
        inv[y * hw + x] = (uint8_t)(255 - (sum + 512) / 1024);
      }
  }
  pixsrc src = {NULL, p, ch};
  /* half-res pixel j sits at full-res 2 j + 0.5: up = 1/2 in find_blobs terms */
  st = detect_polarities(inv, hw, hh, 2.0, &src, w, h, -1.0, o, det, err);
  free(inv);
  return st;
}
