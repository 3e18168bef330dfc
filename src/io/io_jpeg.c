/* JPEG reading and writing through libjpeg(-turbo).
 *
 * libjpeg's default error handler exits the process; ours formats the
 * message and longjmps back. Warnings (premature end of data, corrupt
 * entropy data) are treated as errors: a damaged file is never accepted.
 * As in io_png.c, setjmp sits in a small function whose changing state lives
 * in a context struct owned by the caller. */
#include <errno.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
/* jpeglib.h needs size_t and FILE declared first */
#include <stdio.h>
#include <jpeglib.h>
#include "hearth/image.h"
#include "io_internal.h"

#define JPEG_MAX_FILE_BYTES ((size_t)1 << 30)

typedef struct jpeg_errmgr {
  struct jpeg_error_mgr pub;
  jmp_buf jump;
  char msg[JMSG_LENGTH_MAX + 64];
} jpeg_errmgr;

static void on_jpeg_error(j_common_ptr cinfo) {
  jpeg_errmgr *e = (jpeg_errmgr *)cinfo->err;
  if (!e->msg[0]) (*cinfo->err->format_message)(cinfo, e->msg);
  longjmp(e->jump, 1);
}

static void on_jpeg_message(j_common_ptr cinfo, int level) {
  /* level -1 is a warning about damaged data: fail like an error; trace
   * messages (level >= 0) are ignored */
  if (level < 0) on_jpeg_error(cinfo);
}

static void init_errmgr(jpeg_errmgr *e) {
  memset(e, 0, sizeof *e);
  jpeg_std_error(&e->pub);
  e->pub.error_exit = on_jpeg_error;
  e->pub.emit_message = on_jpeg_message;
}

/* ---- reading ------------------------------------------------------------------ */

typedef struct jpeg_reader {
  struct jpeg_decompress_struct cinfo;
  jpeg_errmgr jerr;
  const uint8_t *data;
  size_t size;
  hearth_status status; /* our own check failures */
  char msg[256];
  int want_gray;                   /* decode to luma only (Y of a YCbCr file) */
  int half;                        /* decode at half the size (libjpeg's scaled IDCT) */
  size_t step;                     /* > 1: keep every step-th pixel and row (grid) */
  const size_t *win;               /* NULL, or the grid's window {x0, y0, w, h} kept */
  JSAMPROW line;                   /* with step > 1: one full decoded row */
  const hearth_image_expect *want; /* NULL: any image */
  hearth_image img;
} jpeg_reader;

/* 0 on success, 1 after a libjpeg error (r->jerr.msg), 2 after our checks. */
static int jpeg_decode(jpeg_reader *r) {
  if (setjmp(r->jerr.jump)) return 1;
  jpeg_create_decompress(&r->cinfo);
  jpeg_mem_src(&r->cinfo, r->data, (unsigned long)r->size);
  jpeg_read_header(&r->cinfo, TRUE);
  size_t w = r->cinfo.image_width, h = r->cinfo.image_height;
  if (w == 0 || h == 0 || w > HEARTH_IMAGE_MAX_DIM || h > HEARTH_IMAGE_MAX_DIM) {
    r->status = HEARTH_E_LIMIT;
    snprintf(r->msg, sizeof r->msg, "size %zux%zu exceeds the limit of %d per side", w, h,
             HEARTH_IMAGE_MAX_DIM);
    return 2;
  }
  if (r->cinfo.data_precision != 8) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg, "%d-bit samples: expected 8-bit JPEG", r->cinfo.data_precision);
    return 2;
  }
  int channels;
  switch (r->cinfo.jpeg_color_space) {
    case JCS_GRAYSCALE:
      r->cinfo.out_color_space = JCS_GRAYSCALE;
      channels = 1;
      break;
    case JCS_YCbCr:
    case JCS_RGB:
      /* libjpeg returns the stored Y plane for grayscale output of a YCbCr
         file, skipping chroma decoding and colour conversion */
      r->cinfo.out_color_space = r->want_gray ? JCS_GRAYSCALE : JCS_RGB;
      channels = r->want_gray ? 1 : 3;
      break;
    default:
      r->status = HEARTH_E_UNSUPPORTED;
      snprintf(r->msg, sizeof r->msg, "colour space %d (CMYK/YCCK?): expected gray or RGB",
               (int)r->cinfo.jpeg_color_space);
      return 2;
  }
  /* entropy coding needs at least about a bit per 8x8 block and component,
   * so a small file claiming a huge image is truncated: refuse it before
   * allocating (the bound is several times looser than the real one) */
  if (w * h / 4096 > r->size + 4096) {
    r->status = HEARTH_E_PARSE;
    snprintf(r->msg, sizeof r->msg,
             "size %zux%zu is more than %zu file bytes can hold (truncated?)", w, h, r->size);
    return 2;
  }
  if ((r->status = hearth_image_expect_check(r->want, w, h, channels, r->msg, sizeof r->msg)))
    return 2;
  if (r->want && r->want->header_only) {
    r->img = (hearth_image){w, h, channels, HEARTH_PIX_U8, NULL};
    return 0;
  }
  if (r->half) {
    /* the 4 x 4 inverse DCT of each 8 x 8 block: sides rounded up */
    r->cinfo.scale_num = 1;
    r->cinfo.scale_denom = 2;
    w = (w + 1) / 2;
    h = (h + 1) / 2;
  }
  if ((r->status = hearth_image_bytes_check(w, h, channels, 1, r->msg, sizeof r->msg))) return 2;
  jpeg_start_decompress(&r->cinfo);
  if ((int)r->cinfo.output_components != channels || r->cinfo.output_width != w ||
      r->cinfo.output_height != h) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg, "unexpected output layout");
    return 2;
  }
  const size_t step = r->step > 1 ? r->step : 1;
  size_t gw = (w + step - 1) / step, gh = (h + step - 1) / step, wx = 0, wy = 0;
  if (r->win) {
    /* a window of the grid: its pixel (x, y) is the grid's (x0 + x, y0 + y) */
    const size_t *g = r->win;
    if (g[2] == 0 || g[3] == 0 || g[0] > gw || g[2] > gw - g[0] || g[1] > gh || g[3] > gh - g[1]) {
      r->status = HEARTH_E_ARG;
      snprintf(r->msg, sizeof r->msg,
               "window %zux%zu at (%zu, %zu) does not lie within the %zux%zu grid", g[2], g[3],
               g[0], g[1], gw, gh);
      return 2;
    }
    wx = g[0], wy = g[1], gw = g[2], gh = g[3];
  }
  hearth_err aerr;
  if (hearth_image_alloc(&r->img, gw, gh, channels, HEARTH_PIX_U8, &aerr) != HEARTH_OK) {
    r->status = aerr.status;
    snprintf(r->msg, sizeof r->msg, "%s", aerr.msg);
    return 2;
  }
  size_t stride = gw * (size_t)channels;
  const int by_line = step > 1 || r->win; /* rows decoded into line, then picked */
  if (by_line && !(r->line = malloc(w * (size_t)channels))) {
    r->status = HEARTH_E_NOMEM;
    snprintf(r->msg, sizeof r->msg, "out of memory for a row");
    return 2;
  }
  while (r->cinfo.output_scanline < r->cinfo.output_height) {
    const size_t y = r->cinfo.output_scanline;
    JSAMPROW row = by_line ? r->line : (JSAMPROW)r->img.data + y * stride;
    int got = jpeg_read_scanlines(&r->cinfo, &row, 1) == 1;
    if (got && by_line && y % step == 0 && y / step >= wy && y / step < wy + gh) {
      uint8_t *dst = (uint8_t *)r->img.data + (y / step - wy) * stride;
      const uint8_t *src = r->line + wx * step * (size_t)channels;
      for (size_t x = 0; x < gw; x++)
        memcpy(dst + x * (size_t)channels, src + x * step * (size_t)channels, (size_t)channels);
    }
    if (!got) {
      r->status = HEARTH_E_PARSE;
      snprintf(r->msg, sizeof r->msg, "image data ends at row %u of %zu",
               (unsigned)r->cinfo.output_scanline, h);
      return 2;
    }
  }
  /* reads up to EOI: missing trailing data raises the premature-end warning */
  jpeg_finish_decompress(&r->cinfo);
  return 0;
}

static hearth_status jpeg_read_mem(const void *data, size_t size, const char *name, int want_gray,
                                   int half, size_t step, const size_t *win,
                                   const hearth_image_expect *want, hearth_image *img,
                                   hearth_err *err) {
  if (!name) name = "<memory>";
  memset(img, 0, sizeof *img);
  if (size < 3 || !data || memcmp(data, "\xff\xd8\xff", 3) != 0)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: not a JPEG file (bad signature)", name);
  if (size > (size_t)(unsigned long)-1)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: too large", name);
  jpeg_reader *r = calloc(1, sizeof *r);
  if (!r) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate decoder", name);
  r->data = data;
  r->size = size;
  r->want_gray = want_gray;
  r->half = half;
  r->step = step;
  r->win = win;
  r->want = want;
  init_errmgr(&r->jerr);
  r->cinfo.err = &r->jerr.pub;
  int rc = jpeg_decode(r);
  /* safe even if creation failed: the struct was zeroed (no memory manager) */
  jpeg_destroy_decompress(&r->cinfo);
  free(r->line);
  hearth_status s = HEARTH_OK;
  if (rc == 1) s = hearth_err_set(err, HEARTH_E_PARSE, "%s: invalid JPEG: %s", name, r->jerr.msg);
  else if (rc == 2) s = hearth_err_set(err, r->status, "%s: %s", name, r->msg);
  if (s) hearth_image_free(&r->img);
  else *img = r->img;
  free(r);
  return s;
}

hearth_status hearth_jpeg_read_mem(const void *data, size_t size, const char *name,
                                   hearth_image *img, hearth_err *err) {
  return jpeg_read_mem(data, size, name, 0, 0, 1, NULL, NULL, img, err);
}

hearth_status hearth_jpeg_read_grid_mem(const void *data, size_t size, const char *name,
                                        size_t step, hearth_image *img, hearth_err *err) {
  return jpeg_read_mem(data, size, name, 0, 0, step, NULL, NULL, img, err);
}

static hearth_status jpeg_read_file(const char *path, int want_gray, int half, size_t step,
                                    const size_t *win, const hearth_image_expect *want,
                                    hearth_image *img, hearth_err *err) {
  memset(img, 0, sizeof *img);
  uint8_t *buf;
  size_t n;
  hearth_status s = hearth_read_file(path, JPEG_MAX_FILE_BYTES, &buf, &n, err);
  if (s) return s;
  s = jpeg_read_mem(buf, n, path, want_gray, half, step, win, want, img, err);
  free(buf);
  return s;
}

hearth_status hearth_jpeg_read(const char *path, hearth_image *img, hearth_err *err) {
  return jpeg_read_file(path, 0, 0, 1, NULL, NULL, img, err);
}

hearth_status hearth_jpeg_read_half(const char *path, hearth_image *img, hearth_err *err) {
  return jpeg_read_file(path, 0, 1, 1, NULL, NULL, img, err);
}

hearth_status hearth_jpeg_read_expect(const char *path, const hearth_image_expect *want,
                                      hearth_image *img, hearth_err *err) {
  return jpeg_read_file(path, 0, 0, 1, NULL, want, img, err);
}

hearth_status hearth_jpeg_read_grid(const char *path, const hearth_image_expect *want, size_t step,
                                    hearth_image *img, hearth_err *err) {
  return jpeg_read_file(path, 0, 0, step, NULL, want, img, err);
}

hearth_status hearth_jpeg_read_grid_window(const char *path, const hearth_image_expect *want,
                                           size_t step, const size_t window[4], hearth_image *img,
                                           hearth_err *err) {
  return jpeg_read_file(path, 0, 0, step, window, want, img, err);
}

hearth_status hearth_jpeg_read_grid_window_mem(const void *data, size_t size, const char *name,
                                               size_t step, const size_t window[4],
                                               hearth_image *img, hearth_err *err) {
  return jpeg_read_mem(data, size, name, 0, 0, step, window, NULL, img, err);
}

hearth_status hearth_jpeg_read_gray(const char *path, hearth_image *img, hearth_err *err) {
  return jpeg_read_file(path, 1, 0, 1, NULL, NULL, img, err);
}

hearth_status hearth_jpeg_read_gray_expect(const char *path, const hearth_image_expect *want,
                                           hearth_image *img, hearth_err *err) {
  return jpeg_read_file(path, 1, 0, 1, NULL, want, img, err);
}

/* ---- writing ------------------------------------------------------------------ */

typedef struct jpeg_writer {
  struct jpeg_compress_struct cinfo;
  jpeg_errmgr jerr;
} jpeg_writer;

static int jpeg_encode(jpeg_writer *w, const hearth_image *img, int quality, FILE *fp) {
  if (setjmp(w->jerr.jump)) return 1;
  jpeg_create_compress(&w->cinfo);
  jpeg_stdio_dest(&w->cinfo, fp);
  w->cinfo.image_width = (JDIMENSION)img->width;
  w->cinfo.image_height = (JDIMENSION)img->height;
  if (img->channels == 1) {
    w->cinfo.input_components = 1;
    w->cinfo.in_color_space = JCS_GRAYSCALE;
  } else {
    w->cinfo.input_components = 3;
    w->cinfo.in_color_space = JCS_RGB;
  }
  jpeg_set_defaults(&w->cinfo);
  jpeg_set_quality(&w->cinfo, quality, TRUE);
  jpeg_start_compress(&w->cinfo, TRUE);
  size_t stride = img->width * (size_t)img->channels;
  while (w->cinfo.next_scanline < w->cinfo.image_height) {
    JSAMPROW row = (JSAMPROW)img->data + (size_t)w->cinfo.next_scanline * stride;
    jpeg_write_scanlines(&w->cinfo, &row, 1);
  }
  jpeg_finish_compress(&w->cinfo);
  return 0;
}

hearth_status hearth_jpeg_write(const char *path, const hearth_image *img, int quality,
                                hearth_err *err) {
  if (!img || !img->data) return hearth_err_set(err, HEARTH_E_ARG, "%s: no image to write", path);
  if (img->type != HEARTH_PIX_U8 || (img->channels != 1 && img->channels != 3))
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "%s: JPEG stores U8 gray or RGB, not %d channels of %d bytes", path,
                          img->channels, (int)img->type);
  if (quality < 1 || quality > 100)
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: quality %d: expected 1..100", path, quality);
  if (img->width < 1 || img->height < 1 || img->width > 65500 || img->height > 65500)
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: image size %zux%zu: JPEG allows 1..65500", path,
                          img->width, img->height);
  hearth_atomic_file af;
  hearth_status s = hearth_atomic_open(&af, path, err);
  if (s) return s;
  jpeg_writer *w = calloc(1, sizeof *w);
  if (!w) {
    hearth_atomic_abort(&af);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate encoder", path);
  }
  init_errmgr(&w->jerr);
  w->cinfo.err = &w->jerr.pub;
  errno = 0;
  int rc = jpeg_encode(w, img, quality, af.fp);
  int e = errno;
  jpeg_destroy_compress(&w->cinfo);
  if (rc) {
    /* a failed fwrite shows as libjpeg's "output file write error": the
     * system's reason is added */
    if (e && ferror(af.fp))
      s = hearth_err_set(err, HEARTH_E_IO, "%s: cannot write JPEG: %s (%s)", path, strerror(e),
                         w->jerr.msg);
    else s = hearth_err_set(err, HEARTH_E_IO, "%s: cannot encode JPEG: %s", path, w->jerr.msg);
    free(w);
    hearth_atomic_abort(&af);
    return s;
  }
  free(w);
  return hearth_atomic_commit(&af, err);
}
