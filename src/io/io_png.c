/* PNG reading and writing through libpng.
 *
 * libpng reports errors by longjmp. Each setjmp lives in a small function
 * whose only locals are set before setjmp and never changed afterwards; all
 * state that changes during decoding (buffers, the image, the message) sits
 * in a context struct owned by the caller's frame, so nothing is
 * indeterminate after the jump and the caller frees everything in one place. */
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>
#include "hearth/image.h"

/* files larger than this are refused before decoding */
#define PNG_MAX_FILE_BYTES ((size_t)1 << 30)

static int host_is_little_endian(void) {
  const uint16_t one = 1;
  uint8_t b;
  memcpy(&b, &one, 1);
  return b == 1;
}

/* ---- reading ------------------------------------------------------------------ */

typedef struct png_reader {
  const uint8_t *data;
  size_t size, pos;
  char msg[512];       /* libpng's error text */
  char warn[256];      /* its first warning, which often explains the error */
  hearth_status status; /* set by our own checks inside the decode */
  hearth_image img;
  png_bytep *rows;
} png_reader;

static void on_png_error(png_structp png, png_const_charp msg) {
  png_reader *r = png_get_error_ptr(png);
  if (r && !r->msg[0]) snprintf(r->msg, sizeof r->msg, "%s", msg ? msg : "libpng error");
  png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg) {
  /* warnings (unknown profiles, ancillary chunk CRCs) do not affect pixels,
   * but the first is kept: libpng reports a limit as a warning followed by a
   * generic error */
  png_reader *r = png_get_error_ptr(png);
  if (r && !r->warn[0]) snprintf(r->warn, sizeof r->warn, "%s", msg ? msg : "");
}

static void on_png_write_warning(png_structp png, png_const_charp msg) {
  (void)png;
  (void)msg;
}

static void read_from_mem(png_structp png, png_bytep out, png_size_t n) {
  png_reader *r = png_get_io_ptr(png);
  if (n > r->size - r->pos) png_error(png, "file is truncated");
  memcpy(out, r->data + r->pos, n);
  r->pos += n;
}

/* Decode into r->img. Returns 0 on success, 1 after a libpng error (r->msg)
 * and 2 after one of our own checks (r->status, r->msg). */
static int png_decode(png_structp png, png_infop info, png_reader *r) {
  if (setjmp(png_jmpbuf(png))) return 1;
  png_set_read_fn(png, r, read_from_mem);
  png_set_user_limits(png, HEARTH_IMAGE_MAX_DIM, HEARTH_IMAGE_MAX_DIM);
  png_read_info(png, info);
  png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  int depth = png_get_bit_depth(png, info), ctype = png_get_color_type(png, info);
  /* palette and sub-byte gray become 8-bit; tRNS becomes an alpha channel */
  if (ctype == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (ctype == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  /* 16-bit samples are big-endian in the file and native in memory */
  if (depth == 16 && host_is_little_endian()) png_set_swap(png);
  /* the row size as stored, before any expansion */
  size_t file_rowbytes = ((size_t)w * (size_t)png_get_channels(png, info) * (size_t)depth + 7) / 8;
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  int channels = png_get_channels(png, info);
  int out_depth = png_get_bit_depth(png, info);
  if (channels < 1 || channels > 4 || (out_depth != 8 && out_depth != 16)) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg,
             "%d channels of %d bits after expansion: expected 1..4 of 8 or 16", channels,
             out_depth);
    return 2;
  }
  if (w == 0 || h == 0 || w > HEARTH_IMAGE_MAX_DIM || h > HEARTH_IMAGE_MAX_DIM) {
    r->status = HEARTH_E_LIMIT;
    snprintf(r->msg, sizeof r->msg, "size %ux%u exceeds the limit of %d per side", (unsigned)w,
             (unsigned)h, HEARTH_IMAGE_MAX_DIM);
    return 2;
  }
  /* deflate expands at most ~1032:1, so a small file claiming a huge image
   * is truncated: refuse it before allocating the pixels */
  size_t raw = (file_rowbytes + 1) * (size_t)h;
  if (raw / 1100 > r->size + 4096) {
    r->status = HEARTH_E_PARSE;
    snprintf(r->msg, sizeof r->msg,
             "size %ux%u needs %zu bytes of pixel data, more than %zu file bytes can hold "
             "(truncated?)",
             (unsigned)w, (unsigned)h, raw, r->size);
    return 2;
  }
  hearth_err aerr;
  hearth_pixtype type = out_depth == 16 ? HEARTH_PIX_U16 : HEARTH_PIX_U8;
  if (hearth_image_alloc(&r->img, w, h, channels, type, &aerr) != HEARTH_OK) {
    r->status = aerr.status;
    snprintf(r->msg, sizeof r->msg, "%s", aerr.msg);
    return 2;
  }
  size_t stride = (size_t)w * (size_t)channels * (size_t)type;
  if (png_get_rowbytes(png, info) != stride) {
    r->status = HEARTH_E_UNSUPPORTED;
    snprintf(r->msg, sizeof r->msg, "unexpected row size %zu (expected %zu)",
             (size_t)png_get_rowbytes(png, info), stride);
    return 2;
  }
  r->rows = hearth_alloc_array(h, sizeof *r->rows);
  if (!r->rows) {
    r->status = HEARTH_E_NOMEM;
    snprintf(r->msg, sizeof r->msg, "cannot allocate row pointers");
    return 2;
  }
  for (png_uint_32 y = 0; y < h; y++) r->rows[y] = (png_bytep)r->img.data + (size_t)y * stride;
  png_read_image(png, r->rows);
  /* read through IEND so a file cut after the pixel data is still an error */
  png_read_end(png, NULL);
  return 0;
}

hearth_status hearth_png_read_mem(const void *data, size_t size, const char *name,
                                  hearth_image *img, hearth_err *err) {
  if (!name) name = "<memory>";
  memset(img, 0, sizeof *img);
  if (!data && size) return hearth_err_set(err, HEARTH_E_ARG, "%s: no data", name);
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || memcmp(data, sig, 8) != 0)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: not a PNG file (bad signature)", name);
  png_reader r;
  memset(&r, 0, sizeof r);
  r.data = data;
  r.size = size;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, on_png_error,
                                           on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!png || !info) {
    png_destroy_read_struct(png ? &png : NULL, NULL, NULL);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot create PNG decoder", name);
  }
  int rc = png_decode(png, info, &r);
  png_destroy_read_struct(&png, &info, NULL);
  free(r.rows);
  if (rc != 0) {
    hearth_image_free(&r.img);
    if (rc == 1) {
      /* a libpng failure: limits and allocation show up as their own status */
      hearth_status s = HEARTH_E_PARSE;
      if (strstr(r.msg, "limit") || strstr(r.warn, "limit")) s = HEARTH_E_LIMIT;
      else if (strstr(r.msg, "memory")) s = HEARTH_E_NOMEM;
      if (r.warn[0])
        return hearth_err_set(err, s, "%s: invalid PNG: %s (%s)", name, r.msg, r.warn);
      return hearth_err_set(err, s, "%s: invalid PNG: %s", name, r.msg);
    }
    return hearth_err_set(err, r.status, "%s: %s", name, r.msg);
  }
  *img = r.img;
  return HEARTH_OK;
}

hearth_status hearth_png_read(const char *path, hearth_image *img, hearth_err *err) {
  memset(img, 0, sizeof *img);
  uint8_t *buf;
  size_t n;
  hearth_status s = hearth_read_file(path, PNG_MAX_FILE_BYTES, &buf, &n, err);
  if (s) return s;
  s = hearth_png_read_mem(buf, n, path, img, err);
  free(buf);
  return s;
}

/* ---- writing ------------------------------------------------------------------ */

/* where encoded bytes go: a FILE (atomic writer) or a growing buffer */
typedef struct png_sink {
  FILE *fp;
  uint8_t *buf;
  size_t len, cap;
  char msg[512];
  png_bytep *rows;
} png_sink;

static void write_to_sink(png_structp png, png_bytep data, png_size_t n) {
  png_sink *k = png_get_io_ptr(png);
  if (k->fp) {
    if (fwrite(data, 1, n, k->fp) != n) png_error(png, "write failed");
    return;
  }
  if (n > k->cap - k->len) {
    size_t cap = k->cap ? k->cap : 65536;
    while (n > cap - k->len) {
      if (cap > SIZE_MAX / 2) png_error(png, "encoded size overflows");
      cap *= 2;
    }
    uint8_t *nb = realloc(k->buf, cap);
    if (!nb) png_error(png, "out of memory");
    k->buf = nb;
    k->cap = cap;
  }
  memcpy(k->buf + k->len, data, n);
  k->len += n;
}

static void flush_sink(png_structp png) { (void)png; }

static void on_png_write_error(png_structp png, png_const_charp msg) {
  png_sink *k = png_get_error_ptr(png);
  if (k && !k->msg[0]) snprintf(k->msg, sizeof k->msg, "%s", msg ? msg : "libpng error");
  png_longjmp(png, 1);
}

/* Encode img into the sink; returns 0 or 1 after a libpng error (k->msg). */
static int png_encode_to(png_structp png, png_infop info, const hearth_image *img, png_sink *k) {
  if (setjmp(png_jmpbuf(png))) return 1;
  static const int ctypes[5] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
  png_set_write_fn(png, k, write_to_sink, flush_sink);
  /* speed over size (textures are encoded on every build): run-length
   * matching with the SUB filter encodes a 1024x1024 RGB texture several
   * times faster than libpng's defaults (zlib level 6, adaptive filters),
   * and on noisy textures smaller than zlib levels 1-3 with the UP filter
   * (bench/png_vs_opencv.py) */
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height,
               img->type == HEARTH_PIX_U16 ? 16 : 8, ctypes[img->channels], PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  if (img->type == HEARTH_PIX_U16 && host_is_little_endian()) png_set_swap(png);
  size_t stride = img->width * (size_t)img->channels * (size_t)img->type;
  for (size_t y = 0; y < img->height; y++) k->rows[y] = (png_bytep)img->data + y * stride;
  /* libpng copies each row before transforming it, so img is not modified */
  png_write_image(png, k->rows);
  png_write_end(png, NULL);
  return 0;
}

static hearth_status check_writable(const hearth_image *img, const char *name, hearth_err *err) {
  if (!img || !img->data)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: no image to write", name);
  if (img->type != HEARTH_PIX_U8 && img->type != HEARTH_PIX_U16)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "%s: PNG stores U8 or U16 pixels, not %d-byte samples", name,
                          (int)img->type);
  if (img->channels < 1 || img->channels > 4)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: %d channels: expected 1..4", name,
                          img->channels);
  if (img->width < 1 || img->height < 1 || img->width > 0x7fffffffu ||
      img->height > 0x7fffffffu)
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: image size %zux%zu cannot be stored in PNG",
                          name, img->width, img->height);
  if (hearth_image_bytes(img) == 0)
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: image size overflows", name);
  return HEARTH_OK;
}

/* Encode into k (file or memory); on failure k->buf is freed. */
static hearth_status png_encode_sink(const hearth_image *img, const char *name, png_sink *k,
                                     hearth_err *err) {
  k->rows = hearth_alloc_array(img->height, sizeof *k->rows);
  if (!k->rows) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate rows", name);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, k, on_png_write_error,
                                            on_png_write_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!png || !info) {
    png_destroy_write_struct(png ? &png : NULL, NULL);
    free(k->rows);
    k->rows = NULL;
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot create PNG encoder", name);
  }
  int rc = png_encode_to(png, info, img, k);
  png_destroy_write_struct(&png, &info);
  free(k->rows);
  k->rows = NULL;
  if (rc) {
    free(k->buf);
    k->buf = NULL;
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot encode PNG: %s", name, k->msg);
  }
  return HEARTH_OK;
}

hearth_status hearth_png_encode(const hearth_image *img, uint8_t **out, size_t *size,
                                hearth_err *err) {
  *out = NULL;
  *size = 0;
  hearth_status s = check_writable(img, "<memory>", err);
  if (s) return s;
  png_sink k;
  memset(&k, 0, sizeof k);
  s = png_encode_sink(img, "<memory>", &k, err);
  if (s) return s;
  *out = k.buf;
  *size = k.len;
  return HEARTH_OK;
}

hearth_status hearth_png_write(const char *path, const hearth_image *img, hearth_err *err) {
  hearth_status s = check_writable(img, path, err);
  if (s) return s;
  hearth_atomic_file af;
  s = hearth_atomic_open(&af, path, err);
  if (s) return s;
  png_sink k;
  memset(&k, 0, sizeof k);
  k.fp = af.fp;
  s = png_encode_sink(img, path, &k, err);
  if (s) {
    hearth_atomic_abort(&af);
    return s;
  }
  return hearth_atomic_commit(&af, err);
}
