/* Fuzz target for the thermal CSV reader: any size (so small inputs reach
 * every path) with the recognised layout and metadata, and the default
 * 256x192 through the plain entry point. Checks that a success returns a
 * consistent finite in-range image and a consistent description, and that a
 * failure leaves neither and names the file. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/thermal.h"

static void check_info(const hearth_thermal_info *in, const hearth_image *img) {
  if (in->width != img->width || in->height != img->height) abort();
  if (!in->encoding || !in->line_ends || !hearth_csv_layout_name(in->layout)) abort();
  if (in->separator != ',' && in->separator != ';' && in->separator != '\t') abort();
  if (in->first_line == 0 || in->last_line < in->first_line ||
      in->header_lines + 1 != in->first_line || in->size_line >= in->first_line)
    abort();
  if (in->n_meta > in->n_meta_lines || (in->n_meta && !in->meta)) abort();
  for (size_t i = 0; i < in->n_meta; i++) {
    const hearth_csv_meta *m = &in->meta[i];
    if (!m->key || !m->value || strlen(m->key) > 255 || strlen(m->value) > 255 ||
        m->line >= in->first_line)
      abort();
    if (hearth_thermal_info_get(in, m->key) == NULL) abort();
  }
  if ((in->layout == HEARTH_CSV_AXIS || in->layout == HEARTH_CSV_FRAME) != (in->label != NULL))
    abort();
}

static void run(const uint8_t *data, size_t size, const hearth_csv_opts *opts, int with_info) {
  hearth_image img;
  hearth_thermal_info info;
  hearth_err err = {0};
  hearth_status s =
      with_info ? hearth_thermal_parse_csv_ex((const char *)data, size, "fuzz.csv", opts, &img,
                                              &info, &err)
                : hearth_thermal_parse_csv((const char *)data, size, "fuzz.csv", opts, &img, &err);
  if (s == HEARTH_OK) {
    if (img.channels != 1 || img.type != HEARTH_PIX_F32 || !img.data || !img.width || !img.height)
      abort();
    const float *t = img.data;
    for (size_t i = 0; i < img.width * img.height; i++)
      if (!(t[i] >= HEARTH_THERMAL_MIN_C && t[i] <= HEARTH_THERMAL_MAX_C)) abort();
    if (with_info) check_info(&info, &img);
  } else {
    if (img.data || strncmp(err.msg, "fuzz.csv: ", 10) != 0) abort();
    if (with_info && (info.meta || info.label || info.n_meta)) abort();
  }
  if (with_info) hearth_thermal_info_free(&info);
  hearth_image_free(&img);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_csv_opts any = {0, 0};
  run(data, size, &any, 1);
  run(data, size, NULL, 0);
  return 0;
}
