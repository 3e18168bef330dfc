/* Fuzz target: decode arbitrary bytes as JPEG; a decoded image has a
 * supported layout and a failed read leaves nothing allocated; the grid
 * read (every step-th pixel and row) of a file that decodes holds the full
 * decode's pixels, and a window of the grid the grid's. */
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
  /* a window of the grid (from the input's size): the grid's pixels */
  const size_t x0 = size % gw, y0 = (size / 7) % gh;
  const size_t win[4] = {x0, y0, 1 + (size / 3) % (gw - x0), 1 + (size / 5) % (gh - y0)};
  hearth_image part;
  if (hearth_jpeg_read_grid_window_mem(data, size, "fuzz.jpg", st, win, &part, &err) != HEARTH_OK)
    abort();
  if (part.width != win[2] || part.height != win[3] || part.channels != img.channels) abort();
  for (size_t y = 0; y < win[3]; y++)
    if (memcmp((const uint8_t *)part.data + y * win[2] * c, g + ((y0 + y) * gw + x0) * c,
               win[2] * c))
      abort();
  hearth_image_free(&part);
  /* a window beyond the grid is refused, nothing allocated */
  const size_t out[4] = {x0, y0, gw - x0 + 1, 1};
  if (hearth_jpeg_read_grid_window_mem(data, size, "fuzz.jpg", st, out, &part, &err) == HEARTH_OK ||
      part.data)
    abort();
  hearth_image_free(&grid);
  hearth_image_free(&img);
  return 0;
}
