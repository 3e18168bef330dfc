/* The Turbo colour map (Mikhailov, Google AI blog, 2019) through the
 * published fifth-order polynomial fit of each channel, and the colouring of
 * temperature images with it. */
#include <math.h>
#include <string.h>
#include "hearth/image.h"

/* published coefficients of c(t) = sum_k a_k t^k, k = 0..5, per channel */
static const double k_turbo_coef[3][6] = {
    {0.13572138, 4.61539260, -42.66032258, 132.13108234, -152.94239396, 59.28637943},
    {0.09140261, 2.19418839, 4.84296658, -14.18503333, 4.27729857, 2.82956604},
    {0.10667330, 12.64194608, -60.58204836, 110.36276771, -89.90310912, 27.34824973},
};

void hearth_turbo(double t, uint8_t rgb[3]) {
  /* NaN maps like 0 so the output is always defined */
  if (!(t >= 0)) t = 0;
  if (t > 1) t = 1;
  for (int c = 0; c < 3; c++) {
    const double *a = k_turbo_coef[c];
    double v = a[5];
    for (int k = 4; k >= 0; k--) v = v * t + a[k];
    /* the fit overshoots [0, 1] slightly near the ends */
    double b = floor(v * 255.0 + 0.5);
    rgb[c] = (uint8_t)(b < 0 ? 0 : b > 255 ? 255 : b);
  }
}

hearth_status hearth_turbo_image(const hearth_image *temps, double lo, double hi,
                                 const uint8_t nan_rgb[3], hearth_image *rgb, hearth_err *err) {
  memset(rgb, 0, sizeof *rgb);
  if (!temps || !temps->data || temps->type != HEARTH_PIX_F32 || temps->channels != 1)
    return hearth_err_set(err, HEARTH_E_ARG, "turbo: expected a 1-channel F32 image");
  if (!isfinite(lo) || !isfinite(hi) || !(hi > lo))
    return hearth_err_set(err, HEARTH_E_RANGE, "turbo: range [%g, %g]: expected lo < hi", lo, hi);
  hearth_status s = hearth_image_alloc(rgb, temps->width, temps->height, 3, HEARTH_PIX_U8, err);
  if (s) return s;
  static const uint8_t k_black[3] = {0, 0, 0};
  if (!nan_rgb) nan_rgb = k_black;
  /* a 1024-entry table: finer than the 8-bit output can show */
  enum { LUT_N = 1024 };
  uint8_t lut[LUT_N][3];
  for (int i = 0; i < LUT_N; i++) hearth_turbo((double)i / (LUT_N - 1), lut[i]);
  const float *in = temps->data;
  uint8_t *out = rgb->data;
  size_t n = temps->width * temps->height;
  double scale = (LUT_N - 1) / (hi - lo);
  for (size_t i = 0; i < n; i++) {
    double v = in[i];
    const uint8_t *c;
    if (isnan(v)) {
      c = nan_rgb;
    } else {
      double u = (v - lo) * scale;
      int k = u <= 0 ? 0 : u >= LUT_N - 1 ? LUT_N - 1 : (int)(u + 0.5);
      c = lut[k];
    }
    out[3 * i] = c[0];
    out[3 * i + 1] = c[1];
    out[3 * i + 2] = c[2];
  }
  return HEARTH_OK;
}
