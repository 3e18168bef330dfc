/* Fuzz target: decode arbitrary bytes as JPEG; a decoded image has a
 * supported layout and a failed read leaves nothing allocated. */
#include <stdlib.h>
#include "hearth/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_err err;
  hearth_image img;
  if (hearth_jpeg_read_mem(data, size, "fuzz.jpg", &img, &err) != HEARTH_OK) {
    if (img.data) abort();
    return 0;
  }
  if (img.type != HEARTH_PIX_U8 || (img.channels != 1 && img.channels != 3) || img.width == 0 ||
      img.height == 0 || img.width > HEARTH_IMAGE_MAX_DIM || img.height > HEARTH_IMAGE_MAX_DIM)
    abort();
  hearth_image_free(&img);
  return 0;
}
