/* PNG reading through libpng, with a faster path of our own for the plain
 * layouts; writing with our own DEFLATE encoder and libdeflate's checksums (see
 * the encoder below).
 *
 * libpng reports errors by longjmp. Each setjmp lives in a small function
 * whose only locals are set before setjmp and never changed afterwards; all
 * state that changes during decoding (buffers, the image, the message) sits
 * in a context struct owned by the caller's frame, so nothing is
 * indeterminate after the jump and the caller frees everything in one place. */
#include <ctype.h>
#include <libdeflate.h>
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "hearth/image.h"
#include "io_deflate.h"
#include "io_png.h"
#include "io_internal.h"

/* files larger than this are refused before decoding */
#define PNG_MAX_FILE_BYTES ((size_t)1 << 30)
/* and ancillary chunks (text, ICC profiles) larger than this, even unpacked */
#define PNG_MAX_CHUNK_BYTES ((png_alloc_size_t)8 << 20)

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
  char msg[512];        /* libpng's error text */
  char warn[256];       /* its first warning, which often explains the error */
  hearth_status status; /* set by our own checks inside the decode */
  hearth_image img;
  png_bytep *rows;
  const hearth_image_expect *want; /* NULL: any image */
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
  /* an ancillary chunk (text, profile) is buffered whole: a header claiming
     gigabytes must not allocate them */
  png_set_chunk_malloc_max(png, PNG_MAX_CHUNK_BYTES);
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
  hearth_pixtype type = out_depth == 16 ? HEARTH_PIX_U16 : HEARTH_PIX_U8;
  if ((r->status = hearth_image_expect_check(r->want, w, h, channels, r->msg, sizeof r->msg)))
    return 2;
  if (r->want && r->want->header_only) {
    r->img = (hearth_image){w, h, channels, type, NULL};
    return 0;
  }
  if ((r->status = hearth_image_bytes_check(w, h, channels, (int)type, r->msg, sizeof r->msg)))
    return 2;
  hearth_err aerr;
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

/* ---- the plain path ------------------------------------------------------------ */

/* The fast path takes only files that libpng decodes without a transform
 * and without a warning: IHDR first, 8- or 16-bit gray, gray + alpha, RGB or
 * RGBA, not interlaced; then only consecutive IDATs, pHYs, tIME and small
 * tEXt chunks, and IEND; every CRC right; IDATs no longer than libpng
 * allows; one zlib stream (a 32 KiB window, or a smaller one that the whole
 * image fits in) that fills the image exactly with the last IDAT byte. It
 * inflates with libdeflate (whole buffer, checking the Adler-32) and undoes the row
 * filters itself, which gives libpng's pixels exactly: both follow the
 * PNG specification's integer arithmetic. Anything else, and every image
 * that the caller's expectations or the limits refuse, goes to libpng, so
 * errors and their messages are libpng's. */

static uint32_t get_be32(const uint8_t *p) {
  return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* SUB undone in place for 2 or 4 bytes a pixel: each byte plus the one
   bpp before it, modulo 256, so a running sum per byte lane. Sixteen bytes
   at a time where SSE2 is there: the sums within the block by doubling
   shifts, then the last pixel of the block before added to every pixel;
   returns where the scalar loop goes on. */
static size_t unsub_vec(uint8_t *cur, size_t rb, size_t bpp) {
  size_t i = 0;
#if defined(__SSE2__)
  if (bpp == 2 || bpp == 4) {
    __m128i carry = _mm_setzero_si128();
    for (; i + 16 <= rb; i += 16) {
      __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(cur + i));
      if (bpp == 2) v = _mm_add_epi8(v, _mm_slli_si128(v, 2));
      v = _mm_add_epi8(v, _mm_slli_si128(v, 4));
      v = _mm_add_epi8(v, _mm_slli_si128(v, 8));
      v = _mm_add_epi8(v, carry);
      _mm_storeu_si128((__m128i *)(void *)(cur + i), v);
      /* the block's last pixel in every pixel's place */
      carry = bpp == 2 ? _mm_shuffle_epi32(_mm_shufflehi_epi16(v, 0xff), 0xff)
                       : _mm_shuffle_epi32(v, 0xff);
    }
  }
#else
  (void)cur, (void)rb, (void)bpp;
#endif
  return i;
}

/* undo row y's filter in place: cur the row (rb bytes after its filter
   byte f), prev the row above already undone (NULL for the first row) */
static int unfilter_row(uint8_t f, uint8_t *cur, const uint8_t *prev, size_t rb, size_t bpp) {
  switch (f) {
    case 0: return 1;
    case 1: {
      size_t i = unsub_vec(cur, rb, bpp);
      for (i = i > bpp ? i : bpp; i < rb; i++) cur[i] = (uint8_t)(cur[i] + cur[i - bpp]);
      return 1;
    }
    case 2:
      if (prev)
        for (size_t i = 0; i < rb; i++) cur[i] = (uint8_t)(cur[i] + prev[i]);
      return 1;
    case 3:
      for (size_t i = 0; i < rb; i++) {
        unsigned a = i >= bpp ? cur[i - bpp] : 0u, b = prev ? prev[i] : 0u;
        cur[i] = (uint8_t)(cur[i] + ((a + b) >> 1));
      }
      return 1;
    case 4:
      for (size_t i = 0; i < rb; i++) {
        int a = i >= bpp ? cur[i - bpp] : 0, b = prev ? prev[i] : 0,
            c = (i >= bpp && prev) ? prev[i - bpp] : 0;
        int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
        int pred = (pa <= pb && pa <= pc) ? a : pb <= pc ? b : c;
        cur[i] = (uint8_t)(cur[i] + pred);
      }
      return 1;
    default: return 0;
  }
}

/* 1: the file decoded into *img; 0: not taken here (nothing allocated) */
static int png_fast_decode(const uint8_t *d, size_t size, const hearth_image_expect *want,
                           hearth_image *img) {
  static const char k_ihdr[4] = {'I', 'H', 'D', 'R'};
  if (size < 8 + 25 || get_be32(d + 8) != 13 || memcmp(d + 12, k_ihdr, 4) != 0) return 0;
  if (libdeflate_crc32(0, d + 12, 17) != get_be32(d + 29)) return 0;
  const uint8_t *ih = d + 16;
  uint32_t w = get_be32(ih), h = get_be32(ih + 4);
  int depth = ih[8], ctype = ih[9];
  if (ih[10] != 0 || ih[11] != 0 || ih[12] != 0) return 0; /* methods, no interlace */
  if (depth != 8 && depth != 16) return 0;
  int channels = ctype == 0 ? 1 : ctype == 4 ? 2 : ctype == 2 ? 3 : ctype == 6 ? 4 : 0;
  if (!channels || w == 0 || h == 0 || w > HEARTH_IMAGE_MAX_DIM || h > HEARTH_IMAGE_MAX_DIM)
    return 0;
  size_t bpp = (size_t)channels * (size_t)(depth / 8), rb = (size_t)w * bpp;
  size_t raw = (rb + 1) * (size_t)h;
  if (raw / 1100 > size + 4096) return 0;
  char msg[512];
  if (hearth_image_expect_check(want, w, h, channels, msg, sizeof msg) != HEARTH_OK) return 0;
  if (want && want->header_only) return 0;
  if (hearth_image_bytes_check(w, h, channels, depth / 8, msg, sizeof msg) != HEARTH_OK) return 0;
  /* an IDAT chunk's data may exceed the filtered rows by the stored blocks'
     overhead (libpng refuses more: a bound no larger than libpng's own) */
  size_t idat_max = raw + 6 + 5 * (raw / 32566 + 1);
  /* the chunks: where the IDAT run starts and ends, its data's total */
  size_t pos = 33, idat_first = 0, idat_end = 0, idat_bytes = 0, n_idat = 0;
  int idat_done = 0, iend = 0;
  while (!iend) {
    if (size - pos < 12) return 0;
    uint32_t len = get_be32(d + pos);
    const uint8_t *type = d + pos + 4;
    if (len > 0x7fffffffu || size - pos - 12 < len) return 0;
    if (libdeflate_crc32(0, type, (size_t)len + 4) != get_be32(d + pos + 8 + len)) return 0;
    if (!memcmp(type, "IDAT", 4)) {
      if (idat_done || len > idat_max) return 0;
      if (!n_idat) idat_first = pos;
      idat_end = pos + 12 + len;
      idat_bytes += len;
      n_idat++;
    } else {
      if (n_idat) idat_done = 1;
      if (!memcmp(type, "IEND", 4)) {
        if (len != 0 || !n_idat) return 0;
        iend = 1;
      } else if (memcmp(type, "pHYs", 4) && memcmp(type, "tIME", 4) &&
                 (memcmp(type, "tEXt", 4) || len > 65536)) {
        return 0;
      }
    }
    pos += 12 + (size_t)len;
  }
  const uint8_t *z = d + idat_first + 8;
  uint8_t *joined = NULL;
  if (n_idat > 1) {
    if (!(joined = malloc(idat_bytes ? idat_bytes : 1))) return 0;
    size_t k = 0;
    for (size_t p = idat_first; p < idat_end;) {
      uint32_t len = get_be32(d + p);
      memcpy(joined + k, d + p + 8, len);
      k += len;
      p += 12 + (size_t)len;
    }
    z = joined;
  }
  int ok = 0;
  uint8_t *buf = NULL;
  struct libdeflate_decompressor *dec = NULL;
  /* deflate, no preset dictionary; a window smaller than 32 KiB (libpng
     writes one for small images) only where the image fits in it, so that
     no distance can reach past it (zlib would refuse that, libdeflate not) */
  if (idat_bytes < 2 || (z[0] & 0x0f) != 8 || (z[0] >> 4) > 7 || (z[1] & 0x20)) goto out;
  if ((z[0] >> 4) < 7 && raw > (size_t)1 << ((z[0] >> 4) + 8)) goto out;
  hearth_err aerr;
  if (!(buf = malloc(raw)) || !(dec = libdeflate_alloc_decompressor())) goto out;
  size_t used_in = 0;
  if (libdeflate_zlib_decompress_ex(dec, z, idat_bytes, buf, raw, &used_in, NULL) !=
          LIBDEFLATE_SUCCESS ||
      used_in != idat_bytes)
    goto out;
  if (hearth_image_alloc(img, w, h, channels, depth == 16 ? HEARTH_PIX_U16 : HEARTH_PIX_U8,
                         &aerr) != HEARTH_OK)
    goto out;
  uint8_t *px = img->data;
  for (size_t y = 0; y < h; y++) {
    uint8_t *cur = px + y * rb;
    memcpy(cur, buf + y * (rb + 1) + 1, rb);
    if (!unfilter_row(buf[y * (rb + 1)], cur, y ? cur - rb : NULL, rb, bpp)) {
      hearth_image_free(img);
      goto out;
    }
  }
  /* 16-bit samples are big-endian in the file and native in memory */
  if (depth == 16 && host_is_little_endian()) {
    size_t n = rb * (size_t)h / 2;
    uint16_t *q = img->data;
    for (size_t i = 0; i < n; i++) q[i] = (uint16_t)(q[i] << 8 | q[i] >> 8);
  }
  ok = 1;
out:
  libdeflate_free_decompressor(dec);
  free(buf);
  free(joined);
  if (!ok) memset(img, 0, sizeof *img);
  return ok;
}

static hearth_status png_read_mem(const void *data, size_t size, const char *name,
                                  const hearth_image_expect *want, hearth_image *img,
                                  hearth_err *err) {
  if (!name) name = "<memory>";
  memset(img, 0, sizeof *img);
  if (!data && size) return hearth_err_set(err, HEARTH_E_ARG, "%s: no data", name);
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || memcmp(data, sig, 8) != 0)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: not a PNG file (bad signature)", name);
  if (png_fast_decode(data, size, want, img)) return HEARTH_OK;
  return hearth_png_read_mem_libpng(data, size, name, want, img, err);
}

hearth_status hearth_png_read_mem_libpng(const void *data, size_t size, const char *name,
                                         const hearth_image_expect *want, hearth_image *img,
                                         hearth_err *err) {
  if (!name) name = "<memory>";
  memset(img, 0, sizeof *img);
  if (!data && size) return hearth_err_set(err, HEARTH_E_ARG, "%s: no data", name);
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || memcmp(data, sig, 8) != 0)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: not a PNG file (bad signature)", name);
  /* libpng allocates a chunk's declared length before reading it: a chunk
     that claims more bytes than the file has left is refused here */
  for (size_t pos = 8; size - pos >= 8;) {
    const uint8_t *c = (const uint8_t *)data + pos;
    uint32_t len = get_be32(c);
    if (len > 0x7fffffffu || size - pos - 8 < len)
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: chunk '%c%c%c%c' at byte %zu claims %u bytes, the file has %zu "
                            "left (truncated?)",
                            name, isprint(c[4]) ? c[4] : '?', isprint(c[5]) ? c[5] : '?',
                            isprint(c[6]) ? c[6] : '?', isprint(c[7]) ? c[7] : '?', pos,
                            (unsigned)len, size - pos - 8);
    if (!memcmp(c + 4, "IEND", 4)) break;
    pos += 12 + (size_t)len;
    if (pos > size) break;
  }
  png_reader r;
  memset(&r, 0, sizeof r);
  r.data = data;
  r.size = size;
  r.want = want;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, on_png_error, on_png_warning);
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
      if (r.warn[0]) return hearth_err_set(err, s, "%s: invalid PNG: %s (%s)", name, r.msg, r.warn);
      return hearth_err_set(err, s, "%s: invalid PNG: %s", name, r.msg);
    }
    return hearth_err_set(err, r.status, "%s: %s", name, r.msg);
  }
  *img = r.img;
  return HEARTH_OK;
}

hearth_status hearth_png_read_mem(const void *data, size_t size, const char *name,
                                  hearth_image *img, hearth_err *err) {
  return png_read_mem(data, size, name, NULL, img, err);
}

hearth_status hearth_png_read_expect(const char *path, const hearth_image_expect *want,
                                     hearth_image *img, hearth_err *err) {
  memset(img, 0, sizeof *img);
  uint8_t *buf;
  size_t n;
  hearth_status s = hearth_read_file(path, PNG_MAX_FILE_BYTES, &buf, &n, err);
  if (s) return s;
  s = png_read_mem(buf, n, path, want, img, err);
  free(buf);
  return s;
}

hearth_status hearth_png_read(const char *path, hearth_image *img, hearth_err *err) {
  return hearth_png_read_expect(path, NULL, img, err);
}

/* ---- writing ------------------------------------------------------------------ */

static hearth_status check_writable(const hearth_image *img, const char *name, hearth_err *err) {
  if (!img || !img->data) return hearth_err_set(err, HEARTH_E_ARG, "%s: no image to write", name);
  if (img->type != HEARTH_PIX_U8 && img->type != HEARTH_PIX_U16)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "%s: PNG stores U8 or U16 pixels, not %d-byte samples", name,
                          (int)img->type);
  if (img->channels < 1 || img->channels > 4)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: %d channels: expected 1..4", name, img->channels);
  if (img->width < 1 || img->height < 1 || img->width > 0x7fffffffu || img->height > 0x7fffffffu)
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: image size %zux%zu cannot be stored in PNG",
                          name, img->width, img->height);
  if (hearth_image_bytes(img) == 0)
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: image size overflows", name);
  return HEARTH_OK;
}

/* The encoder is our own (libpng only reads): rows are SUB-filtered and
 * deflated in bands of PNG_BAND_ROWS rows, in parallel, each band a raw
 * deflate piece of its own (io_deflate.c: run-length matching, one
 * dynamic-Huffman block) ended with a sync flush, the last with the final
 * block; concatenated behind a zlib header and followed by the Adler-32 of
 * all filtered bytes (combined band by band) they form the one zlib stream
 * of the IDAT chunks. The picture variants store a row equal to the one
 * above it UP-filtered instead (all zeros: a few matches). Run-length matching only looks one byte back, so the
 * bands lose little against one stream. The bands are fixed, so the bytes
 * do not depend on the thread count. Speed over size: textures are encoded
 * on every build; a noisy 1024x1024 RGB texture encodes about 4x faster
 * than with OpenCV (zlib level 3, the same size) and twice as fast as with
 * zlib's own run-length mode, which this encoder replaced
 * (bench/png_vs_opencv.py). */
#define PNG_BAND_ROWS 64

typedef struct band_job {
  const hearth_image *img;
  size_t stride, bpp, n_bands;
  uint8_t **out; /* per band: its deflate output */
  size_t *out_len;
  uLong *adler; /* per band: Adler-32 of its filtered bytes */
  size_t *raw_len;
  int *failed;    /* per band */
  int up_repeats; /* a row equal to the one above: UP-filtered (all zero) */
} band_job;

static void encode_bands(void *ctx, size_t b, size_t e, int t) {
  band_job *j = ctx;
  const hearth_image *img = j->img;
  size_t rowb = 1 + j->stride, bpp = j->bpp;
  int swap16 = img->type == HEARTH_PIX_U16 && host_is_little_endian();
  uint8_t *raw = malloc(PNG_BAND_ROWS * rowb);
  (void)t;
  for (size_t band = b; band < e; band++) {
    j->failed[band] = 1;
    if (!raw) continue;
    size_t y0 = band * PNG_BAND_ROWS,
           y1 = y0 + PNG_BAND_ROWS < img->height ? y0 + PNG_BAND_ROWS : img->height;
    for (size_t y = y0; y < y1; y++) {
      const uint8_t *src = (const uint8_t *)img->data + y * j->stride;
      uint8_t *dst = raw + (y - y0) * rowb;
      dst[0] = 1; /* SUB */
      uint8_t *px = dst + 1;
      if (j->up_repeats && y > 0 && !memcmp(src, src - j->stride, j->stride)) {
        dst[0] = 2; /* UP: every difference to the row above is zero */
        memset(px, 0, j->stride);
      } else if (swap16) {
        for (size_t i = 0; i + 1 < j->stride; i += 2) {
          px[i] = src[i + 1];
          px[i + 1] = src[i];
        }
        for (size_t i = j->stride; i-- > bpp;) px[i] = (uint8_t)(px[i] - px[i - bpp]);
      } else {
        /* straight from the source row: no dependence between bytes */
        memcpy(px, src, bpp);
        for (size_t i = bpp; i < j->stride; i++) px[i] = (uint8_t)(src[i] - src[i - bpp]);
      }
    }
    size_t n = (y1 - y0) * rowb;
    j->raw_len[band] = n;
    j->adler[band] = libdeflate_adler32(1, raw, n);
    j->out[band] = malloc(hearth_deflate_bound(n));
    if (j->out[band] &&
        hearth_deflate_rle(raw, n, band + 1 == j->n_bands, j->out[band], &j->out_len[band]))
      j->failed[band] = 0;
  }
  free(raw);
}

void hearth_png_put32(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)(v >> 24);
  p[1] = (uint8_t)(v >> 16);
  p[2] = (uint8_t)(v >> 8);
  p[3] = (uint8_t)v;
}

uint8_t *hearth_png_put_chunk(uint8_t *o, const char type[4], const uint8_t *a, size_t na,
                              const uint8_t *b, size_t nb, const uint8_t *c, size_t nc) {
  hearth_png_put32(o, (uint32_t)(na + nb + nc));
  memcpy(o + 4, type, 4);
  uint32_t crc = libdeflate_crc32(0, o + 4, 4);
  uint8_t *d = o + 8;
  if (na) memcpy(d, a, na), crc = libdeflate_crc32(crc, a, na), d += na;
  if (nb) memcpy(d, b, nb), crc = libdeflate_crc32(crc, b, nb), d += nb;
  if (nc) memcpy(d, c, nc), crc = libdeflate_crc32(crc, c, nc), d += nc;
  hearth_png_put32(d, crc);
  return d + 4;
}

/* the whole PNG file in a malloc'ed buffer */
static hearth_status png_encode_mem(const hearth_image *img, const char *name, int up_repeats,
                                    uint8_t **out, size_t *size, hearth_err *err) {
  *out = NULL;
  *size = 0;
  size_t bpp = (size_t)img->channels * (size_t)img->type, stride = img->width * bpp;
  size_t nb = (img->height + PNG_BAND_ROWS - 1) / PNG_BAND_ROWS;
  band_job j = {img,
                stride,
                bpp,
                nb,
                calloc(nb, sizeof(uint8_t *)),
                calloc(nb, sizeof(size_t)),
                calloc(nb, sizeof(uLong)),
                calloc(nb, sizeof(size_t)),
                calloc(nb, sizeof(int)),
                up_repeats};
  hearth_status s = HEARTH_OK;
  if (!j.out || !j.out_len || !j.adler || !j.raw_len || !j.failed) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory encoding PNG", name);
    goto done;
  }
  int nt = hearth_default_threads();
  hearth_parallel_chunks(nb, 2, nt, encode_bands, &j);
  size_t total = 8 + 25 + 12 + 2 + 4;
  for (size_t k = 0; k < nb; k++) {
    if (j.failed[k]) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot compress rows %zu.. of the PNG", name,
                         k * PNG_BAND_ROWS);
      goto done;
    }
    total += 12 + j.out_len[k];
  }
  uint8_t *buf = malloc(total), *o = buf;
  if (!buf) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory encoding PNG", name);
    goto done;
  }
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  static const uint8_t ctype[5] = {0, 0, 4, 2, 6};
  memcpy(o, sig, 8);
  o += 8;
  uint8_t ihdr[13];
  hearth_png_put32(ihdr, (uint32_t)img->width);
  hearth_png_put32(ihdr + 4, (uint32_t)img->height);
  ihdr[8] = img->type == HEARTH_PIX_U16 ? 16 : 8;
  ihdr[9] = ctype[img->channels];
  ihdr[10] = ihdr[11] = ihdr[12] = 0; /* deflate, adaptive filtering, no interlace */
  o = hearth_png_put_chunk(o, "IHDR", ihdr, 13, NULL, 0, NULL, 0);
  /* the zlib header (deflate, 32 KiB window, fastest) before the first band,
   * the Adler-32 of the filtered bytes after the last */
  static const uint8_t zhdr[2] = {0x78, 0x01};
  uLong adler = j.adler[0];
  for (size_t k = 1; k < nb; k++) adler = adler32_combine(adler, j.adler[k], (z_off_t)j.raw_len[k]);
  uint8_t ztail[4];
  hearth_png_put32(ztail, (uint32_t)adler);
  for (size_t k = 0; k < nb; k++)
    o = hearth_png_put_chunk(o, "IDAT", k == 0 ? zhdr : NULL, k == 0 ? 2 : 0, j.out[k],
                             j.out_len[k], k + 1 == nb ? ztail : NULL, k + 1 == nb ? 4 : 0);
  o = hearth_png_put_chunk(o, "IEND", NULL, 0, NULL, 0, NULL, 0);
  *out = buf;
  *size = (size_t)(o - buf);
done:
  if (j.out)
    for (size_t k = 0; k < nb; k++) free(j.out[k]);
  free(j.out);
  free(j.out_len);
  free(j.adler);
  free(j.raw_len);
  free(j.failed);
  return s;
}

hearth_status hearth_png_encode(const hearth_image *img, uint8_t **out, size_t *size,
                                hearth_err *err) {
  *out = NULL;
  *size = 0;
  hearth_status s = check_writable(img, "<memory>", err);
  if (s) return s;
  return png_encode_mem(img, "<memory>", 0, out, size, err);
}

hearth_status hearth_png_encode_picture(const hearth_image *img, uint8_t **out, size_t *size,
                                        hearth_err *err) {
  *out = NULL;
  *size = 0;
  hearth_status s = check_writable(img, "<memory>", err);
  if (s) return s;
  return png_encode_mem(img, "<memory>", 1, out, size, err);
}

static hearth_status png_write_file(const char *path, const hearth_image *img, int up_repeats,
                                    hearth_err *err) {
  hearth_status s = check_writable(img, path, err);
  if (s) return s;
  uint8_t *buf;
  size_t n;
  if ((s = png_encode_mem(img, path, up_repeats, &buf, &n, err))) return s;
  s = hearth_write_file_atomic(path, buf, n, err);
  free(buf);
  return s;
}

hearth_status hearth_png_write(const char *path, const hearth_image *img, hearth_err *err) {
  return png_write_file(path, img, 0, err);
}

hearth_status hearth_png_write_picture(const char *path, const hearth_image *img, hearth_err *err) {
  return png_write_file(path, img, 1, err);
}
