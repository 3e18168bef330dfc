/* Animated PNG writing (the APNG extension: acTL, fcTL, fdAT chunks) with
 * the PNG encoder's chunk writer and stored deflate blocks.
 *
 * Layout: signature, IHDR (8-bit RGB), acTL (frame count, endless loop),
 * then per frame an fcTL (full-size region at 0, 0, no dispose, no blend)
 * and the frame's zlib stream, in IDAT for the first frame (the default
 * image) and in fdAT after it; IEND. Sequence numbers count fcTL and fdAT
 * chunks from 0. Each frame's stream is the zlib header 78 01, its rows
 * with filter byte 0 as stored blocks, and their Adler-32; every stream
 * has the same length, as it depends only on the frame size. */
#include <stdlib.h>
#include <string.h>
#include <zlib.h>
#include "hearth/image.h"
#include "io_deflate.h"
#include "io_png.h"

/* per frame: its unfiltered rows and their zlib stream */
typedef struct apng_scratch {
  size_t row, raw_n; /* bytes of one row with its filter byte; of all rows */
  uint8_t *raw, *z;  /* raw_n; hearth_deflate_bound(raw_n) + 6 */
} apng_scratch;

/* frame `rgb` as a zlib stream in s->z; returns its length */
static size_t frame_stream(apng_scratch *s, const uint8_t *rgb, size_t height) {
  for (size_t y = 0; y < height; y++) {
    s->raw[y * s->row] = 0; /* filter: none */
    memcpy(s->raw + y * s->row + 1, rgb + y * (s->row - 1), s->row - 1);
  }
  s->z[0] = 0x78, s->z[1] = 0x01;
  size_t k = 2 + hearth_deflate_stored(s->raw, s->raw_n, 1, s->z + 2);
  hearth_png_put32(s->z + k, (uint32_t)adler32_z(adler32_z(0L, Z_NULL, 0), s->raw, s->raw_n));
  return k + 4;
}

static hearth_status apng_encode(const char *name, const uint8_t *frames, size_t width,
                                 size_t height, size_t n_frames, unsigned delay_num,
                                 unsigned delay_den, uint8_t **out, size_t *size, hearth_err *err) {
  *out = NULL;
  *size = 0;
  if (!frames || n_frames < 1)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: no frames to write", name);
  if (width < 1 || height < 1 || width > 0x7fffffffu || height > 0x7fffffffu)
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: frame size %zux%zu cannot be stored in PNG",
                          name, width, height);
  /* sequence numbers (2 per frame after the first) stay below 2^31 */
  if (n_frames > 0x3fffffffu)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %zu frames: at most %u fit an APNG", name,
                          n_frames, 0x3fffffffu);
  if (delay_num > 65535 || delay_den > 65535)
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: frame delay %u/%u: both parts must be 0..65535",
                          name, delay_num, delay_den);
  /* sizes: a frame, its rows with filter bytes, its stream's room */
  apng_scratch s = {0};
  size_t frame_bytes, zcap;
  if (!hearth_mul_size(width, 3, &s.row) || !hearth_mul_size(s.row, height, &frame_bytes) ||
      !hearth_mul_size(s.row + 1, height, &s.raw_n) || s.raw_n > (size_t)-1 / 2)
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: frame size %zux%zu overflows", name, width,
                          height);
  s.row += 1;
  zcap = hearth_deflate_bound(s.raw_n) + 6;
  s.raw = malloc(s.raw_n);
  s.z = malloc(zcap);
  if (!s.raw || !s.z) {
    free(s.raw), free(s.z);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: video too large", name);
  }
  /* every frame's stream has the first one's length; the file: signature,
   * IHDR, acTL, per frame fcTL and IDAT or fdAT (4 bytes more for the
   * sequence number), IEND */
  size_t zn = frame_stream(&s, frames, height), total = 0;
  uint8_t *buf = NULL;
  if (hearth_mul_size(n_frames, (12 + 26) + (12 + 4 + zn), &total) && total <= (size_t)-1 - 100) {
    total += 8 + 25 + 20 - 4 + 12;
    buf = malloc(total);
  }
  if (!buf) {
    free(s.raw), free(s.z);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: video too large", name);
  }
  uint8_t *o = buf;
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  memcpy(o, sig, 8);
  o += 8;
  uint8_t ihdr[13] = {0};
  hearth_png_put32(ihdr, (uint32_t)width);
  hearth_png_put32(ihdr + 4, (uint32_t)height);
  ihdr[8] = 8, ihdr[9] = 2; /* 8-bit RGB; methods 0, no interlace */
  o = hearth_png_put_chunk(o, "IHDR", ihdr, 13, NULL, 0, NULL, 0);
  uint8_t actl[8];
  hearth_png_put32(actl, (uint32_t)n_frames);
  hearth_png_put32(actl + 4, 0); /* plays: endless */
  o = hearth_png_put_chunk(o, "acTL", actl, 8, NULL, 0, NULL, 0);
  uint32_t seq = 0;
  for (size_t f = 0; f < n_frames; f++) {
    uint8_t fctl[26] = {0};
    hearth_png_put32(fctl, seq++);
    hearth_png_put32(fctl + 4, (uint32_t)width);
    hearth_png_put32(fctl + 8, (uint32_t)height);
    /* x, y offsets 0; the delay; dispose and blend ops 0 */
    fctl[20] = (uint8_t)(delay_num >> 8), fctl[21] = (uint8_t)delay_num;
    fctl[22] = (uint8_t)(delay_den >> 8), fctl[23] = (uint8_t)delay_den;
    o = hearth_png_put_chunk(o, "fcTL", fctl, 26, NULL, 0, NULL, 0);
    if (f > 0) frame_stream(&s, frames + f * frame_bytes, height);
    if (f == 0) {
      o = hearth_png_put_chunk(o, "IDAT", s.z, zn, NULL, 0, NULL, 0);
    } else {
      uint8_t sq[4];
      hearth_png_put32(sq, seq++);
      o = hearth_png_put_chunk(o, "fdAT", sq, 4, s.z, zn, NULL, 0);
    }
  }
  o = hearth_png_put_chunk(o, "IEND", NULL, 0, NULL, 0, NULL, 0);
  free(s.raw), free(s.z);
  *out = buf;
  *size = (size_t)(o - buf); /* == total */
  return HEARTH_OK;
}

hearth_status hearth_apng_encode(const uint8_t *frames, size_t width, size_t height,
                                 size_t n_frames, unsigned delay_num, unsigned delay_den,
                                 uint8_t **out, size_t *size, hearth_err *err) {
  return apng_encode("<memory>", frames, width, height, n_frames, delay_num, delay_den, out, size,
                     err);
}

hearth_status hearth_apng_write(const char *path, const uint8_t *frames, size_t width,
                                size_t height, size_t n_frames, unsigned delay_num,
                                unsigned delay_den, hearth_err *err) {
  uint8_t *buf;
  size_t n;
  hearth_status s =
      apng_encode(path, frames, width, height, n_frames, delay_num, delay_den, &buf, &n, err);
  if (s) return s;
  s = hearth_write_file_atomic(path, buf, n, err);
  free(buf);
  return s;
}
