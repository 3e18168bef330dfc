/* hearth/image.h - area io (src/io/): images in memory and on disk (PNG
 * 8/16-bit, animated PNG, JPEG), the Turbo colour map and a few drawing
 * helpers for overlays and contact sheets.
 *
 * Pixels are row-major, channels interleaved, row 0 at the top; 16-bit and
 * float samples in native byte order. Every function that fills a
 * hearth_image * output allocates its data (the caller frees it with
 * hearth_image_free); on failure the output is left zeroed. */
#ifndef HEARTH_IMAGE_H
#define HEARTH_IMAGE_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum hearth_pixtype {
  HEARTH_PIX_U8 = 1,
  HEARTH_PIX_U16 = 2,
  HEARTH_PIX_F32 = 4
} hearth_pixtype;

typedef struct hearth_image {
  size_t width, height;
  int channels;        /* 1..4 */
  hearth_pixtype type; /* bytes per sample = (int)type */
  void *data;          /* owned; width*height*channels samples */
} hearth_image;

/* Allocate a zeroed image; sizes are overflow-checked. img need not be
 * initialised (it is overwritten, not freed). */
hearth_status hearth_image_alloc(hearth_image *img, size_t width, size_t height, int channels,
                                 hearth_pixtype type, hearth_err *err);
void hearth_image_free(hearth_image *img); /* frees data, zeroes img; accepts a zeroed image */
size_t hearth_image_bytes(const hearth_image *img);

/* Limits applied to untrusted image files. */
#define HEARTH_IMAGE_MAX_DIM 16384
/* and at most this many bytes of decoded pixels (a tiny palette PNG can
 * declare gigabytes of RGBA) */
#define HEARTH_IMAGE_MAX_BYTES ((size_t)1 << 29)

/* What a caller expects of an image file. The readers check it against the
 * file's header before allocating any pixels, so a small file declaring a
 * huge image costs nothing. A zeroed struct (or NULL) expects nothing. */
typedef struct hearth_image_expect {
  size_t width, height; /* the size the image must have; 0: any */
  int channels;         /* channels as read (after PNG expansion); 0: any */
  size_t max_pixels;    /* at most width * height pixels; 0: only HEARTH_IMAGE_MAX_DIM */
  int header_only;      /* fill width, height, channels and type; data stays NULL */
  const char *why;      /* appended to a size error, e.g. "(the colour camera of
                           rig.json)"; NULL: nothing */
} hearth_image_expect;

/* PNG: reads 8- or 16-bit gray, gray+alpha, RGB or RGBA (palette and low
 * bit depths are expanded to 8-bit). Writes U8 or U16 images, 1-4 channels,
 * atomically. `name` names the data in messages; read_mem copies what it
 * needs (data may be freed after the call). */
hearth_status hearth_png_read(const char *path, hearth_image *img, hearth_err *err);
/* The same, refusing what does not meet want (NULL: anything) before
 * allocating: HEARTH_E_SIZE, HEARTH_E_UNSUPPORTED (channels) or
 * HEARTH_E_LIMIT (max_pixels), naming path. */
hearth_status hearth_png_read_expect(const char *path, const hearth_image_expect *want,
                                     hearth_image *img, hearth_err *err);
hearth_status hearth_png_read_mem(const void *data, size_t size, const char *name,
                                  hearth_image *img, hearth_err *err);
hearth_status hearth_png_write(const char *path, const hearth_image *img, hearth_err *err);
/* Encode to memory (*out malloc'ed, the caller frees it). */
hearth_status hearth_png_encode(const hearth_image *img, uint8_t **out, size_t *size,
                                hearth_err *err);
/* The same pixels in a file that is cheaper to make where rows repeat (an
 * image enlarged by repeating pixels, flat backgrounds): a row equal to the
 * one above it is stored UP-filtered, every other row as hearth_png_write
 * stores it (SUB), so the bytes differ from hearth_png_write's there. For
 * diagnostic pictures; measurement outputs keep hearth_png_write. */
hearth_status hearth_png_write_picture(const char *path, const hearth_image *img, hearth_err *err);
hearth_status hearth_png_encode_picture(const hearth_image *img, uint8_t **out, size_t *size,
                                        hearth_err *err);

/* Animated PNG (APNG): n_frames RGB U8 frames of width x height, stored
 * back to back in `frames` (top row first), each shown for
 * delay_num / delay_den seconds, looping forever. The first frame is also
 * the default image, so a plain PNG reader shows it. Rows are unfiltered
 * and stored uncompressed (quick to write, frame-sized chunks). */
hearth_status hearth_apng_write(const char *path, const uint8_t *frames, size_t width,
                                size_t height, size_t n_frames, unsigned delay_num,
                                unsigned delay_den, hearth_err *err);
/* The same file in memory (*out malloc'ed, the caller frees). */
hearth_status hearth_apng_encode(const uint8_t *frames, size_t width, size_t height,
                                 size_t n_frames, unsigned delay_num, unsigned delay_den,
                                 uint8_t **out, size_t *size, hearth_err *err);

/* JPEG (8-bit gray or RGB; U8 images). quality 1..100. Writes atomically. */
hearth_status hearth_jpeg_read(const char *path, hearth_image *img, hearth_err *err);
/* The image at half its size (sides rounded up), decoded by libjpeg's
 * scaled inverse DCT: about two thirds of the full decode's work, for
 * pictures shown halved. Not the pixels of halving hearth_jpeg_read's. */
hearth_status hearth_jpeg_read_half(const char *path, hearth_image *img, hearth_err *err);
hearth_status hearth_jpeg_read_expect(const char *path, const hearth_image_expect *want,
                                      hearth_image *img, hearth_err *err);
/* Every step-th pixel of every step-th row (step >= 1): an image of
 * ceil(width / step) x ceil(height / step) whose pixel (x, y) is the full
 * decode's pixel (x * step, y * step), bit for bit, decoded a row at a time
 * so that only the kept pixels are held. want applies to the file's own
 * size. */
hearth_status hearth_jpeg_read_grid(const char *path, const hearth_image_expect *want, size_t step,
                                    hearth_image *img, hearth_err *err);
hearth_status hearth_jpeg_read_grid_mem(const void *data, size_t size, const char *name,
                                        size_t step, hearth_image *img, hearth_err *err);
/* A window of that grid: window = {x0, y0, w, h} (grid pixels, within the
 * grid, else HEARTH_E_ARG), an image of w x h whose pixel (x, y) is the
 * grid's (x0 + x, y0 + y). Every row is still decoded (the whole file is
 * checked); only the window's pixels are kept. */
hearth_status hearth_jpeg_read_grid_window(const char *path, const hearth_image_expect *want,
                                           size_t step, const size_t window[4], hearth_image *img,
                                           hearth_err *err);
hearth_status hearth_jpeg_read_grid_window_mem(const void *data, size_t size, const char *name,
                                               size_t step, const size_t window[4],
                                               hearth_image *img, hearth_err *err);
hearth_status hearth_jpeg_read_mem(const void *data, size_t size, const char *name,
                                   hearth_image *img, hearth_err *err);
/* Luma only (1 channel): the stored Y plane of a colour JPEG, decoded
 * without chroma or colour conversion (fast; for detection). */
hearth_status hearth_jpeg_read_gray(const char *path, hearth_image *img, hearth_err *err);
hearth_status hearth_jpeg_read_gray_expect(const char *path, const hearth_image_expect *want,
                                           hearth_image *img, hearth_err *err);
hearth_status hearth_jpeg_write(const char *path, const hearth_image *img, int quality,
                                hearth_err *err);

/* Turbo colour map (Google's 2019 polynomial approximation of the published
 * table). t is clamped to [0, 1]. */
void hearth_turbo(double t, uint8_t rgb[3]);
/* Colour a float temperature image (1 channel) with Turbo over [lo, hi] degC
 * (lo < hi; values outside are clamped) into a new RGB U8 image. NaN pixels
 * get nan_rgb (NULL: black). */
hearth_status hearth_turbo_image(const hearth_image *temps, double lo, double hi,
                                 const uint8_t nan_rgb[3], hearth_image *rgb, hearth_err *err);

/* Drawing on RGB(A) U8 images in place, clipped to the image; coordinates
 * in pixels (pixel centres at integers). */
void hearth_draw_line(hearth_image *img, double x0, double y0, double x1, double y1,
                      const uint8_t rgb[3], int thickness);
void hearth_draw_circle(hearth_image *img, double cx, double cy, double r, const uint8_t rgb[3]);
/* Resample a U8 image into a new width x height image (for thumbnails),
 * per axis: the area average when shrinking, linear interpolation between
 * pixel centres when enlarging. */
hearth_status hearth_image_resize(const hearth_image *src, size_t width, size_t height,
                                  hearth_image *dst, hearth_err *err);
/* Copy src into dst with its top-left at (x, y), clipped to dst: U8 images
 * with the same channel count, gray into RGB(A), or RGB into RGBA (alpha
 * kept); other combinations do nothing. */
void hearth_image_blit(hearth_image *dst, const hearth_image *src, size_t x, size_t y);
/* Write text with a built-in 5x7 pixel font, each font pixel scale x scale
 * image pixels (scale >= 1), the top-left of the first glyph at (x, y). */
void hearth_draw_text(hearth_image *img, size_t x, size_t y, const char *text, const uint8_t rgb[3],
                      int scale);

#ifdef __cplusplus
}
#endif
#endif
