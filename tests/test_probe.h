/* The selector probes' reading of a Turbo-coloured thermal view: the
 * temperature of a pixel as the nearest of 256 Turbo samples over
 * 10..60 degC (the simulator's thermal colour range), and the mean over a
 * candidate's box. Shared by tests/eval and tests/sim. */
#ifndef HEARTH_TEST_PROBE_H
#define HEARTH_TEST_PROBE_H

#include <stdint.h>

static inline double probe_turbo_temp(const uint8_t *c, const uint8_t lut[256][3]) {
  int best = 0;
  long bd = -1;
  for (int k = 0; k < 256; k++) {
    long d = 0;
    for (int j = 0; j < 3; j++) d += (long)(c[j] - lut[k][j]) * (c[j] - lut[k][j]);
    if (bd < 0 || d < bd) bd = d, best = k;
  }
  return 10 + 50.0 * best / 255.0;
}

/* mean temperature over the inclusive box b = {x0, y0, x1, y1} of an RGB
 * image w pixels wide */
static inline double probe_crop_temp(const uint8_t *img, int w, const int b[4],
                                     const uint8_t lut[256][3]) {
  double s = 0;
  int n = 0;
  for (int y = b[1]; y <= b[3]; y++)
    for (int x = b[0]; x <= b[2]; x++) s += probe_turbo_temp(img + 3 * (y * w + x), lut), n++;
  return n ? s / n : 0;
}

#endif
