/* Thermal calibration frames in any of the formats cameras export: a
 * temperature CSV, or an 8-/16-bit PNG or TIFF image (recognised from the
 * first bytes, never the file name), read into one F32 plane; and the
 * TIFF writer the virtual rig and the tests make such frames with. TIFF
 * goes through libtiff with per-handle error handlers (no global state). */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <tiffio.h>
#include "hearth/thermal.h"

#define FRAME_MAX_FILE_BYTES ((size_t)1 << 28)

const char *hearth_frame_kind_name(hearth_frame_kind k) {
  static const char *const names[] = {"csv", "png8", "png16", "tiff8", "tiff16"};
  return (unsigned)k < sizeof names / sizeof names[0] ? names[k] : "unknown";
}

/* ---- images to one plane ------------------------------------------------------ */
/* U8/U16 image (1..4 channels) -> F32 plane: grey as stored, colour as the
 * mean of R, G and B (a grey palette saved as RGB), alpha ignored */
static hearth_status plane_from_image(const hearth_image *img, const char *name, hearth_image *out,
                                      hearth_err *err) {
  hearth_status st = hearth_image_alloc(out, img->width, img->height, 1, HEARTH_PIX_F32, err);
  if (st) return st;
  size_t n = img->width * img->height, ch = (size_t)img->channels;
  size_t colour = ch >= 3 ? 3 : 1;
  float *o = out->data;
  for (size_t i = 0; i < n; i++) {
    double s = 0;
    for (size_t k = 0; k < colour; k++)
      s += img->type == HEARTH_PIX_U16 ? ((const uint16_t *)img->data)[i * ch + k]
                                       : ((const uint8_t *)img->data)[i * ch + k];
    o[i] = (float)(s / (double)colour);
  }
  (void)name;
  return HEARTH_OK;
}

/* ---- TIFF from memory ----------------------------------------------------------- */
typedef struct tiff_mem {
  const uint8_t *data;
  size_t size, pos;
  char msg[256]; /* libtiff's first error */
} tiff_mem;

static tmsize_t tm_read(thandle_t h, void *buf, tmsize_t n) {
  tiff_mem *m = (tiff_mem *)h;
  if (n < 0) return 0;
  size_t left = m->pos < m->size ? m->size - m->pos : 0, k = (size_t)n < left ? (size_t)n : left;
  memcpy(buf, m->data + m->pos, k);
  m->pos += k;
  return (tmsize_t)k;
}
static tmsize_t tm_write(thandle_t h, void *buf, tmsize_t n) {
  (void)h, (void)buf, (void)n;
  return 0;
}
static toff_t tm_seek(thandle_t h, toff_t off, int whence) {
  tiff_mem *m = (tiff_mem *)h;
  uint64_t base = whence == SEEK_CUR ? m->pos : whence == SEEK_END ? m->size : 0;
  uint64_t p = base + off;
  if (p > ((uint64_t)1 << 40)) return (toff_t)-1;
  m->pos = (size_t)p;
  return p;
}
static int tm_close(thandle_t h) {
  (void)h;
  return 0;
}
static toff_t tm_size(thandle_t h) { return ((tiff_mem *)h)->size; }
static int tm_map(thandle_t h, void **base, toff_t *size) {
  (void)h, (void)base, (void)size;
  return 0;
}
static void tm_unmap(thandle_t h, void *base, toff_t size) { (void)h, (void)base, (void)size; }

static int tm_error(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap) {
  (void)tif;
  tiff_mem *m = user;
  if (!m->msg[0]) {
    char b[200];
    vsnprintf(b, sizeof b, fmt, ap);
    snprintf(m->msg, sizeof m->msg, "%s%s%s", module ? module : "", module ? ": " : "", b);
  }
  return 1;
}
static int tm_warning(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap) {
  (void)tif, (void)user, (void)module, (void)fmt, (void)ap;
  return 1; /* warnings (unknown tags and the like) are not errors */
}

static TIFF *tm_open(tiff_mem *m, const char *mode, const char *name) {
  TIFFOpenOptions *opt = TIFFOpenOptionsAlloc();
  if (!opt) return NULL;
  TIFFOpenOptionsSetErrorHandlerExtR(opt, tm_error, m);
  TIFFOpenOptionsSetWarningHandlerExtR(opt, tm_warning, m);
  TIFFOpenOptionsSetMaxSingleMemAlloc(opt, (tmsize_t)1 << 28);
  TIFF *t = TIFFClientOpenExt(name, mode, (thandle_t)m, tm_read, tm_write, tm_seek, tm_close,
                              tm_size, tm_map, tm_unmap, opt);
  TIFFOpenOptionsFree(opt);
  return t;
}

static hearth_status tiff_fail(tiff_mem *m, hearth_status s, const char *name, const char *what,
                               hearth_err *err) {
  if (m->msg[0]) return hearth_err_set(err, s, "%s: %s (libtiff: %s)", name, what, m->msg);
  return hearth_err_set(err, s, "%s: %s", name, what);
}

/* the first directory: 8- or 16-bit unsigned, grey (1 sample) or colour
 * (3 or 4 samples, interleaved), in strips; the rows as one F32 plane */
static hearth_status tiff_read_mem(const void *data, size_t size, const char *name,
                                   hearth_image *out, int *bits, hearth_err *err) {
  tiff_mem m = {data, size, 0, {0}};
  TIFF *t = tm_open(&m, "rm", name);
  if (!t) return tiff_fail(&m, HEARTH_E_PARSE, name, "not a readable TIFF", err);
  hearth_status st = HEARTH_OK;
  uint32_t w = 0, h = 0;
  uint16_t bps = 0, spp = 1, fmt = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG, photo = 0;
  uint8_t *row = NULL;
  hearth_image img = {0};
  if (!TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &w) || !TIFFGetField(t, TIFFTAG_IMAGELENGTH, &h)) {
    st = tiff_fail(&m, HEARTH_E_PARSE, name, "TIFF without an image size", err);
    goto done;
  }
  TIFFGetFieldDefaulted(t, TIFFTAG_BITSPERSAMPLE, &bps);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLESPERPIXEL, &spp);
  TIFFGetFieldDefaulted(t, TIFFTAG_SAMPLEFORMAT, &fmt);
  TIFFGetFieldDefaulted(t, TIFFTAG_PLANARCONFIG, &planar);
  if (!TIFFGetField(t, TIFFTAG_PHOTOMETRIC, &photo)) photo = PHOTOMETRIC_MINISBLACK;
  if (w < 1 || h < 1 || w > HEARTH_IMAGE_MAX_DIM || h > HEARTH_IMAGE_MAX_DIM) {
    st = hearth_err_set(err, HEARTH_E_LIMIT, "%s: TIFF of %ux%u pixels (1..%d per side)", name,
                        (unsigned)w, (unsigned)h, HEARTH_IMAGE_MAX_DIM);
    goto done;
  }
  if ((bps != 8 && bps != 16) || fmt != SAMPLEFORMAT_UINT) {
    st = hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                        "%s: TIFF with %u-bit samples of format %u; expected 8- or 16-bit "
                        "unsigned integers",
                        name, (unsigned)bps, (unsigned)fmt);
    goto done;
  }
  int grey = photo == PHOTOMETRIC_MINISBLACK || photo == PHOTOMETRIC_MINISWHITE;
  if (!((grey && (spp == 1 || spp == 2)) || (photo == PHOTOMETRIC_RGB && (spp == 3 || spp == 4))) ||
      (spp > 1 && planar != PLANARCONFIG_CONTIG)) {
    st = hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                        "%s: TIFF with photometric %u, %u samples per pixel (planar %u); expected "
                        "grey or RGB, interleaved",
                        name, (unsigned)photo, (unsigned)spp, (unsigned)planar);
    goto done;
  }
  if (TIFFIsTiled(t)) {
    st = hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s: tiled TIFF; expected strips", name);
    goto done;
  }
  tmsize_t line = TIFFScanlineSize(t);
  size_t need = (size_t)w * spp * (bps / 8);
  if (line <= 0 || (size_t)line < need) {
    st = tiff_fail(&m, HEARTH_E_PARSE, name, "TIFF rows shorter than the image width", err);
    goto done;
  }
  if ((st = hearth_image_alloc(&img, w, h, spp, bps == 16 ? HEARTH_PIX_U16 : HEARTH_PIX_U8, err)))
    goto done;
  row = malloc((size_t)line);
  if (!row) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
    goto done;
  }
  for (uint32_t y = 0; y < h; y++) {
    if (TIFFReadScanline(t, row, y, 0) < 0) {
      char what[64];
      snprintf(what, sizeof what, "TIFF row %u cannot be decoded", (unsigned)y);
      st = tiff_fail(&m, HEARTH_E_PARSE, name, what, err);
      goto done;
    }
    memcpy((uint8_t *)img.data + (size_t)y * need, row, need);
  }
  if (photo == PHOTOMETRIC_MINISWHITE) {
    /* as displayed: 0 is white */
    size_t n = (size_t)w * h * spp;
    for (size_t i = 0; i < n; i++) {
      if (bps == 16) ((uint16_t *)img.data)[i] = (uint16_t)(65535 - ((uint16_t *)img.data)[i]);
      else ((uint8_t *)img.data)[i] = (uint8_t)(255 - ((uint8_t *)img.data)[i]);
    }
  }
  st = plane_from_image(&img, name, out, err);
  *bits = bps;
done:
  free(row);
  hearth_image_free(&img);
  TIFFClose(t);
  return st;
}

/* ---- any frame ----------------------------------------------------------------- */
hearth_status hearth_frame_read_mem(const void *data, size_t size, const char *name,
                                    hearth_image *out, hearth_frame_kind *kind, hearth_err *err) {
  if (!out) return hearth_err_set(err, HEARTH_E_ARG, "frame: out is NULL");
  memset(out, 0, sizeof *out);
  if (!name) name = "(frame)";
  if (!data && size) return hearth_err_set(err, HEARTH_E_ARG, "%s: data is NULL", name);
  const uint8_t *b = data;
  hearth_frame_kind k = HEARTH_FRAME_CSV;
  hearth_status st;
  if (size >= 8 && !memcmp(b, "\x89PNG\r\n\x1a\n", 8)) {
    hearth_image img = {0};
    if ((st = hearth_png_read_mem(data, size, name, &img, err))) return st;
    k = img.type == HEARTH_PIX_U16 ? HEARTH_FRAME_PNG16 : HEARTH_FRAME_PNG8;
    st = plane_from_image(&img, name, out, err);
    hearth_image_free(&img);
  } else if (size >= 4 && (!memcmp(b, "II*\0", 4) || !memcmp(b, "MM\0*", 4) ||
                           !memcmp(b, "II+\0", 4) || !memcmp(b, "MM\0+", 4))) {
    int bits = 8;
    st = tiff_read_mem(data, size, name, out, &bits, err);
    k = bits == 16 ? HEARTH_FRAME_TIFF16 : HEARTH_FRAME_TIFF8;
  } else {
    hearth_csv_opts any = {0, 0};
    st = hearth_thermal_parse_csv(data, size, name, &any, out, err);
  }
  if (st) {
    hearth_image_free(out);
    return st;
  }
  if (kind) *kind = k;
  return HEARTH_OK;
}

hearth_status hearth_frame_read(const char *path, hearth_image *out, hearth_frame_kind *kind,
                                hearth_err *err) {
  if (out) memset(out, 0, sizeof *out);
  if (!path || !out) return hearth_err_set(err, HEARTH_E_ARG, "frame: NULL argument");
  uint8_t *data = NULL;
  size_t size = 0;
  hearth_status st = hearth_read_file(path, FRAME_MAX_FILE_BYTES, &data, &size, err);
  if (st) return st;
  st = hearth_frame_read_mem(data, size, path, out, kind, err);
  free(data);
  return st;
}

/* ---- TIFF writing ----------------------------------------------------------------- */
typedef struct tiff_out {
  uint8_t *data;
  size_t size, cap, pos;
  int failed;
  char msg[256];
} tiff_out;

static tmsize_t to_read(thandle_t h, void *buf, tmsize_t n) {
  tiff_out *m = (tiff_out *)h;
  if (n < 0) return 0;
  size_t left = m->pos < m->size ? m->size - m->pos : 0, k = (size_t)n < left ? (size_t)n : left;
  memcpy(buf, m->data + m->pos, k);
  m->pos += k;
  return (tmsize_t)k;
}
static tmsize_t to_write(thandle_t h, void *buf, tmsize_t n) {
  tiff_out *m = (tiff_out *)h;
  if (n < 0) return 0;
  size_t end = m->pos + (size_t)n;
  if (end > m->cap) {
    size_t cap = m->cap ? m->cap : 4096;
    while (cap < end) cap *= 2;
    uint8_t *p = realloc(m->data, cap);
    if (!p) {
      m->failed = 1;
      return 0;
    }
    memset(p + m->cap, 0, cap - m->cap);
    m->data = p;
    m->cap = cap;
  }
  memcpy(m->data + m->pos, buf, (size_t)n);
  m->pos = end;
  if (end > m->size) m->size = end;
  return n;
}
static toff_t to_seek(thandle_t h, toff_t off, int whence) {
  tiff_out *m = (tiff_out *)h;
  uint64_t base = whence == SEEK_CUR ? m->pos : whence == SEEK_END ? m->size : 0;
  m->pos = (size_t)(base + off);
  return m->pos;
}
static toff_t to_size(thandle_t h) { return ((tiff_out *)h)->size; }
static int to_error(TIFF *tif, void *user, const char *module, const char *fmt, va_list ap) {
  (void)tif, (void)module;
  tiff_out *m = user;
  if (!m->msg[0]) vsnprintf(m->msg, sizeof m->msg, fmt, ap);
  return 1;
}

hearth_status hearth_tiff_write(const char *path, const hearth_image *img,
                                hearth_tiff_compression comp, hearth_err *err) {
  if (!path || !img || !img->data || img->channels != 1 ||
      (img->type != HEARTH_PIX_U8 && img->type != HEARTH_PIX_U16) || !img->width || !img->height)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: TIFF writes 1-channel U8 or U16 images",
                          path ? path : "(tiff)");
  static const uint16_t k_comp[] = {COMPRESSION_NONE, COMPRESSION_LZW, COMPRESSION_ADOBE_DEFLATE,
                                    COMPRESSION_PACKBITS};
  if ((unsigned)comp >= sizeof k_comp / sizeof k_comp[0])
    return hearth_err_set(err, HEARTH_E_ARG, "%s: unknown TIFF compression %d", path, (int)comp);
  tiff_out m = {0};
  TIFFOpenOptions *opt = TIFFOpenOptionsAlloc();
  if (!opt) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  TIFFOpenOptionsSetErrorHandlerExtR(opt, to_error, &m);
  TIFFOpenOptionsSetWarningHandlerExtR(opt, tm_warning, &m);
  TIFF *t = TIFFClientOpenExt(path, "w", (thandle_t)&m, to_read, to_write, to_seek, tm_close,
                              to_size, tm_map, tm_unmap, opt);
  TIFFOpenOptionsFree(opt);
  if (!t) {
    free(m.data);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot start a TIFF: %s", path, m.msg);
  }
  uint16_t bps = img->type == HEARTH_PIX_U16 ? 16 : 8;
  size_t line = img->width * (bps / 8);
  int ok = TIFFSetField(t, TIFFTAG_IMAGEWIDTH, (uint32_t)img->width) &&
           TIFFSetField(t, TIFFTAG_IMAGELENGTH, (uint32_t)img->height) &&
           TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, bps) &&
           TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, (uint16_t)1) &&
           TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK) &&
           TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG) &&
           TIFFSetField(t, TIFFTAG_COMPRESSION, k_comp[comp]) &&
           TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, (uint32_t)16);
  for (size_t y = 0; ok && y < img->height; y++)
    ok = TIFFWriteScanline(t, (uint8_t *)img->data + y * line, (uint32_t)y, 0) >= 0;
  if (ok) ok = TIFFWriteDirectory(t);
  TIFFClose(t);
  hearth_status st;
  if (!ok || m.failed)
    st = hearth_err_set(err, HEARTH_E_IO, "%s: TIFF encoding failed: %s", path,
                        m.failed ? "out of memory" : m.msg);
  else st = hearth_write_file_atomic(path, m.data, m.size, err);
  free(m.data);
  return st;
}
