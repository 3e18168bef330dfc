/* Fuzz target: decode arbitrary bytes as PNG; the reader (with its own fast
 * path for plain files) must agree with its libpng route alone, in status
 * and pixels; whatever decodes must encode again and decode back to the
 * same pixels. */
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"
#include "io/io_png.h"

static int same_image(const hearth_image *a, const hearth_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         a->type == b->type && memcmp(a->data, b->data, hearth_image_bytes(a)) == 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_err err;
  hearth_image img, back;
  hearth_image ref;
  hearth_status s_ref = hearth_png_read_mem_libpng(data, size, "fuzz.png", NULL, &ref, &err);
  hearth_status s = hearth_png_read_mem(data, size, "fuzz.png", &img, &err);
  if (s != s_ref) abort();
  if (s == HEARTH_OK && !same_image(&img, &ref)) abort();
  hearth_image_free(&ref);
  if (s != HEARTH_OK) {
    if (img.data) abort(); /* a failed read leaves no image */
    return 0;
  }
  /* keep the round trip cheap for large inputs */
  if (hearth_image_bytes(&img) <= ((size_t)1 << 20)) {
    uint8_t *enc = NULL;
    size_t n = 0;
    if (hearth_png_encode(&img, &enc, &n, &err) != HEARTH_OK) abort();
    if (hearth_png_read_mem(enc, n, "reencoded.png", &back, &err) != HEARTH_OK) abort();
    if (!same_image(&back, &img)) abort();
    hearth_image_free(&back);
    free(enc);
  }
  hearth_image_free(&img);
  return 0;
}
