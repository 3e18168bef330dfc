/* Thermal CSV writer: the canonical form (see hearth/thermal.h). */
#include <stdlib.h>
#include "hearth/thermal.h"

hearth_status hearth_thermal_write_csv(const char *path, const hearth_image *temps, int decimals,
                                       hearth_err *err) {
  if (!path || !temps || !temps->data)
    return hearth_err_set(err, HEARTH_E_ARG, "thermal csv: NULL argument");
  if (temps->channels != 1 || temps->type != HEARTH_PIX_F32)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "%s: image has %d channel(s) of %d-byte samples, expected 1-channel "
                          "float32",
                          path, temps->channels, (int)temps->type);
  if (decimals < 0 || decimals > 9)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: %d decimals, expected 0..9", path, decimals);
  size_t w = temps->width, h = temps->height, n;
  if (!w || !h || !hearth_mul_size(w, h, &n))
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: image is %zux%zu, expected a non-empty matrix",
                          path, w, h);
  /* "-50.xxxxxx," at most 4 + 1 + decimals + 1 bytes per value */
  size_t per = (size_t)decimals + 6, cap;
  if (!hearth_mul_size(n, per, &cap))
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: image too large", path);
  char *buf = malloc(cap + 1);
  if (!buf) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  const float *t = temps->data;
  size_t k = 0;
  for (size_t y = 0; y < h; y++) {
    for (size_t x = 0; x < w; x++) {
      double v = t[y * w + x];
      /* refuse what a reader would refuse rather than write it */
      if (!(v >= HEARTH_THERMAL_MIN_C && v <= HEARTH_THERMAL_MAX_C)) {
        free(buf);
        return hearth_err_set(err, HEARTH_E_RANGE,
                              "%s: pixel (%zu, %zu) = %g degC, expected a finite value in "
                              "%g..%g degC",
                              path, x, y, v, HEARTH_THERMAL_MIN_C, HEARTH_THERMAL_MAX_C);
      }
      int m = hearth_format_fixed(buf + k, cap + 1 - k, v, decimals);
      if (m < 0) {
        free(buf);
        return hearth_err_set(err, HEARTH_E_RANGE, "%s: pixel (%zu, %zu) cannot be formatted", path,
                              x, y);
      }
      k += (size_t)m;
      buf[k++] = x + 1 < w ? ',' : '\n';
    }
  }
  hearth_status st = hearth_write_file_atomic(path, buf, k, err);
  free(buf);
  return st;
}

void hearth_csv_opts_default(hearth_csv_opts *o) {
  o->width = 256;
  o->height = 192;
}
