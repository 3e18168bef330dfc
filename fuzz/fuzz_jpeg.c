/* Fuzz target: decode arbitrary bytes as JPEG; a decoded image has a
 * supported layout and a failed read leaves nothing allocated; the grid
 * read (every step-th pixel and row) of a file that decodes holds the full
 * decode's pixels. */
#include <stdlib.h>
#include <string.h>
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
  const size_t st = 2 + size % 3;
  hearth_image grid;
  if (hearth_jpeg_read_grid_mem(data, size, "fuzz.jpg", st, &grid, &err) != HEARTH_OK) abort();
  const size_t gw = (img.width + st - 1) / st, gh = (img.height + st - 1) / st,
               c = (size_t)img.channels;
  if (grid.width != gw || grid.height != gh || grid.channels != img.channels) abort();
  const uint8_t *f = img.data, *g = grid.data;
  for (size_t y = 0; y < gh; y++)
    for (size_t x = 0; x < gw; x++)
      if (memcmp(g + (y * gw + x) * c, f + (y * st * img.width + x * st) * c, c)) abort();
  hearth_image_free(&grid);
  hearth_image_free(&img);
  return 0;
}
