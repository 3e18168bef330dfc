/* Fuzz target for calibration/target.json (hearth_target_parse) and the
 * target block of detections.json. A target that parses must pass its own
 * check, have 1..HEARTH_TARGET_MAX_HOLES holes, and give finite plate
 * points in row order; the ordering must accept it without reading out of
 * bounds. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/calib.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  hearth_err err;
  hearth_target t;
  if (hearth_target_parse(text, size, "fuzz", &t, &err) == HEARTH_OK) {
    if (hearth_target_check(&t, "fuzz", &err) != HEARTH_OK) abort();
    size_t n = hearth_target_holes(&t);
    if (n < 1 || n > HEARTH_TARGET_MAX_HOLES) abort();
    double(*xyz)[3] = malloc(sizeof(*xyz) * n);
    double(*uv)[2] = malloc(sizeof(*uv) * n);
    double(*out)[2] = malloc(sizeof(*out) * n);
    if (!xyz || !uv || !out) abort();
    hearth_target_points(&t, xyz);
    for (size_t i = 0; i < n; i++) {
      if (!isfinite(xyz[i][0]) || !isfinite(xyz[i][1]) || xyz[i][2] != 0) abort();
      if (i && xyz[i][1] < xyz[i - 1][1]) abort(); /* row by row */
      uv[i][0] = 100 + xyz[i][0] / t.pitch_m * 15;
      uv[i][1] = 100 + xyz[i][1] / t.pitch_m * 15;
    }
    char why[256];
    /* the target seen straight on: found (the order of an upright view) */
    if (!hearth_target_order(&t, (const double(*)[2])uv, n, out, why, sizeof why)) abort();
    free(xyz);
    free(uv);
    free(out);
  }
  hearth_detections d;
  hearth_detections_parse(text, size, "fuzz", &d, &err);
  hearth_detections_free(&d);
  return 0;
}
