/* Fuzz target: read arbitrary bytes as a thermal calibration frame (CSV,
 * PNG or TIFF, recognised from the content). A failed read leaves no
 * image; a successful one is a 1-channel F32 plane of at least one pixel,
 * and an image frame's values lie within its sample range. */
#include <math.h>
#include <stdlib.h>
#include "hearth/thermal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_err err;
  hearth_image img;
  hearth_frame_kind kind;
  if (hearth_frame_read_mem(data, size, "fuzz.frame", &img, &kind, &err) != HEARTH_OK) {
    if (img.data) abort();
    return 0;
  }
  if (!img.data || img.channels != 1 || img.type != HEARTH_PIX_F32 || !img.width || !img.height)
    abort();
  float hi = kind == HEARTH_FRAME_PNG16 || kind == HEARTH_FRAME_TIFF16 ? 65535.0f : 255.0f;
  const float *p = img.data;
  for (size_t i = 0; kind != HEARTH_FRAME_CSV && i < img.width * img.height; i++)
    if (!(p[i] >= 0.0f && p[i] <= hi)) abort();
  hearth_image_free(&img);
  return 0;
}
