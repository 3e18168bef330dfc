/* Fuzz target for the thermal CSV reader: any size (so small inputs reach
 * every path) and the default 256x192. Checks that a success returns a
 * consistent finite in-range image and a failure leaves none. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/thermal.h"

static void run(const uint8_t *data, size_t size, const hearth_csv_opts *opts) {
  hearth_image img;
  hearth_err err = {0};
  hearth_status s = hearth_thermal_parse_csv((const char *)data, size, "fuzz.csv", opts, &img,
                                             &err);
  if (s == HEARTH_OK) {
    if (img.channels != 1 || img.type != HEARTH_PIX_F32 || !img.data || !img.width ||
        !img.height)
      abort();
    const float *t = img.data;
    for (size_t i = 0; i < img.width * img.height; i++)
      if (!(t[i] >= HEARTH_THERMAL_MIN_C && t[i] <= HEARTH_THERMAL_MAX_C)) abort();
  } else {
    if (img.data || strncmp(err.msg, "fuzz.csv: ", 10) != 0) abort();
  }
  hearth_image_free(&img);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_csv_opts any = {0, 0};
  run(data, size, &any);
  run(data, size, NULL);
  return 0;
}
