/* Fuzz target: decode arbitrary bytes as PNG; whatever decodes must encode
 * again and decode back to the same pixels. */
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_err err;
  hearth_image img, back;
  if (hearth_png_read_mem(data, size, "fuzz.png", &img, &err) != HEARTH_OK) {
    if (img.data) abort(); /* a failed read leaves no image */
    return 0;
  }
  /* keep the round trip cheap for large inputs */
  if (hearth_image_bytes(&img) <= ((size_t)1 << 20)) {
    uint8_t *enc = NULL;
    size_t n = 0;
    if (hearth_png_encode(&img, &enc, &n, &err) != HEARTH_OK) abort();
    if (hearth_png_read_mem(enc, n, "reencoded.png", &back, &err) != HEARTH_OK) abort();
    if (back.width != img.width || back.height != img.height || back.channels != img.channels ||
        back.type != img.type || memcmp(back.data, img.data, hearth_image_bytes(&img)) != 0)
      abort();
    hearth_image_free(&back);
    free(enc);
  }
  hearth_image_free(&img);
  return 0;
}
