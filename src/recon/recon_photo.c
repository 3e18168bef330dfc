/* recon_photo.c - a colour view as the turntable route's photometric term
 * sees it: its grey level at half resolution, band-passed (a small blur
 * less a large one, both normalised over the cut-out so that neither the
 * background nor the silhouette leaks in), NaN off the object; sampled
 * bilinearly with its gradient. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"
#include "recon_internal.h"

/* box passes of the two blurs (radius in half-resolution pixels) */
#define PH_SMALL_R 1
#define PH_SMALL_PASSES 2
#define PH_LARGE_R 4
#define PH_LARGE_PASSES 3
/* least cut-out weight of a blurred pixel to be kept */
#define PH_MIN_WEIGHT 0.6f

void rc_photo_free(rc_photo *ph) {
  if (!ph) return;
  free(ph->img);
  memset(ph, 0, sizeof *ph);
}

/* one separable box pass of radius r over a w x h image, in place (tmp:
 * w * h scratch) */
static void box_pass(float *a, float *tmp, int w, int h, int r) {
  for (int y = 0; y < h; y++) {
    const float *row = a + (size_t)y * w;
    float *out = tmp + (size_t)y * w;
    double s = 0;
    int lo = 0, hi = -1;
    for (int x = 0; x < w; x++) {
      int l = x - r < 0 ? 0 : x - r, u = x + r >= w ? w - 1 : x + r;
      while (hi < u) s += row[++hi];
      while (lo < l) s -= row[lo++];
      out[x] = (float)(s / (2 * r + 1));
    }
  }
  for (int x = 0; x < w; x++) {
    double s = 0;
    int lo = 0, hi = -1;
    for (int y = 0; y < h; y++) {
      int l = y - r < 0 ? 0 : y - r, u = y + r >= h ? h - 1 : y + r;
      while (hi < u) s += tmp[(size_t)++hi * w + x];
      while (lo < l) s -= tmp[(size_t)lo++ * w + x];
      a[(size_t)y * w + x] = (float)(s / (2 * r + 1));
    }
  }
}

/* the blur of g * m normalised by the blur of m, into out (NaN where the
 * mask's weight is under PH_MIN_WEIGHT) */
static void masked_blur(const float *g, const float *m, int w, int h, int r, int passes, float *out,
                        float *wgt, float *tmp) {
  size_t n = (size_t)w * h;
  for (size_t i = 0; i < n; i++) {
    out[i] = g[i] * m[i];
    wgt[i] = m[i];
  }
  for (int p = 0; p < passes; p++) {
    box_pass(out, tmp, w, h, r);
    box_pass(wgt, tmp, w, h, r);
  }
  for (size_t i = 0; i < n; i++) out[i] = wgt[i] >= PH_MIN_WEIGHT ? out[i] / wgt[i] : NAN;
}

hearth_status rc_photo_load(const char *rgb_path, const char *cut_path, const hearth_camera *rgb,
                            rc_photo *ph, hearth_err *err) {
  memset(ph, 0, sizeof *ph);
  hearth_image gray = {0}, cut = {0};
  hearth_status s = hearth_jpeg_read_gray(rgb_path, &gray, err);
  if (!s) s = hearth_png_read(cut_path, &cut, err);
  if (!s && (gray.width != (size_t)rgb->width || gray.height != (size_t)rgb->height ||
             gray.type != HEARTH_PIX_U8 || gray.channels != 1))
    s = hearth_err_set(err, HEARTH_E_SIZE, "%s: %zux%zu, the colour camera is %dx%d", rgb_path,
                       gray.width, gray.height, rgb->width, rgb->height);
  if (!s && (cut.width != gray.width || cut.height != gray.height))
    s = hearth_err_set(err, HEARTH_E_SIZE, "%s: %zux%zu, its colour image is %zux%zu", cut_path,
                       cut.width, cut.height, gray.width, gray.height);
  if (s) {
    hearth_image_free(&gray);
    hearth_image_free(&cut);
    return s;
  }
  const int W = rgb->width, w = W / 2, h = rgb->height / 2;
  size_t n = (size_t)w * h;
  float *g = malloc(n * sizeof *g), *m = malloc(n * sizeof *m);
  float *sm = malloc(n * sizeof *sm), *lg = malloc(n * sizeof *lg);
  float *wgt = malloc(n * sizeof *wgt), *tmp = malloc(n * sizeof *tmp);
  if (!g || !m || !sm || !lg || !wgt || !tmp) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s", rgb_path);
  } else {
    /* 2 x 2 means; a half pixel is on the object when its four are */
    const uint8_t *px = gray.data;
    for (int y = 0; y < h; y++)
      for (int x = 0; x < w; x++) {
        size_t p = (size_t)(2 * y) * W + 2 * x;
        size_t q[4] = {p, p + 1, p + W, p + W + 1};
        double v = 0;
        int on = 1;
        for (int k = 0; k < 4; k++) {
          v += px[q[k]];
          on &= rc_cutout_at(&cut, q[k]);
        }
        g[(size_t)y * w + x] = (float)(v / (4.0 * 255.0));
        m[(size_t)y * w + x] = (float)on;
      }
    masked_blur(g, m, w, h, PH_SMALL_R, PH_SMALL_PASSES, sm, wgt, tmp);
    masked_blur(g, m, w, h, PH_LARGE_R, PH_LARGE_PASSES, lg, wgt, tmp);
    for (size_t i = 0; i < n; i++) sm[i] = m[i] > 0 ? sm[i] - lg[i] : NAN;
    ph->img = sm;
    sm = NULL;
    ph->w = w;
    ph->h = h;
  }
  free(g);
  free(m);
  free(sm);
  free(lg);
  free(wgt);
  free(tmp);
  hearth_image_free(&gray);
  hearth_image_free(&cut);
  return s;
}

/* bilinear value at half-resolution (x, y); 0 when a neighbour is off */
static int bilinear(const rc_photo *ph, double x, double y, double *v) {
  if (!(x >= 0 && y >= 0 && x < ph->w - 1 && y < ph->h - 1)) return 0;
  int x0 = (int)x, y0 = (int)y;
  double fx = x - x0, fy = y - y0;
  const float *a = ph->img + (size_t)y0 * ph->w + x0, *b = a + ph->w;
  if (isnan(a[0]) || isnan(a[1]) || isnan(b[0]) || isnan(b[1])) return 0;
  *v = (1 - fy) * ((1 - fx) * a[0] + fx * a[1]) + fy * ((1 - fx) * b[0] + fx * b[1]);
  return 1;
}

int rc_photo_sample(const rc_photo *ph, const double uv[2], double *val, double grad[2]) {
  if (!ph->img) return 0;
  /* full-resolution pixel centres to half-resolution ones */
  double x = (uv[0] + 0.5) * 0.5 - 0.5, y = (uv[1] + 0.5) * 0.5 - 0.5;
  double c, l, r, t, b;
  if (!bilinear(ph, x, y, &c)) return 0;
  *val = c;
  if (!grad) return 1;
  if (!bilinear(ph, x - 1, y, &l) || !bilinear(ph, x + 1, y, &r) || !bilinear(ph, x, y - 1, &t) ||
      !bilinear(ph, x, y + 1, &b))
    return 0;
  /* per full-resolution pixel */
  grad[0] = 0.25 * (r - l);
  grad[1] = 0.25 * (b - t);
  return 1;
}
