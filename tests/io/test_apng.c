/* Animated PNG: the chunk sequence (IHDR, acTL, fcTL + IDAT, fcTL + fdAT
 * ..., IEND) with valid CRCs and sequence numbers, every frame decoded back
 * by libpng (the file itself shows frame 0; frame k is rebuilt as a plain
 * PNG from its fdAT data), multi-block frames, the exact bytes of a fixed
 * input, and rejected arguments. */
#include <stdint.h>
#include <zlib.h>
#include "hearth/image.h"
#include "test_util.h"

static uint32_t be32(const uint8_t *p) {
  return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void put_be32(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)(v >> 24), p[1] = (uint8_t)(v >> 16), p[2] = (uint8_t)(v >> 8), p[3] = (uint8_t)v;
}

/* frame f, pixel (x, y), channel c of the test input */
static uint8_t pixel(int f, size_t x, size_t y, int c) {
  return (uint8_t)(f * 71 + (int)(x * 3 + y * 29) + c * 101 + (int)((x * y) >> 2));
}

static uint8_t *make_frames(size_t w, size_t h, int n) {
  uint8_t *p = malloc(w * h * 3 * (size_t)n);
  for (int f = 0; f < n; f++)
    for (size_t y = 0; y < h; y++)
      for (size_t x = 0; x < w; x++)
        for (int c = 0; c < 3; c++) p[(((size_t)f * h + y) * w + x) * 3 + c] = pixel(f, x, y, c);
  return p;
}

/* a plain PNG of signature, the APNG's IHDR, one IDAT and IEND */
static uint8_t *plain_png(const uint8_t *ihdr_chunk, const uint8_t *data, size_t n, size_t *out_n) {
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  static const uint8_t iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  uint8_t *p = malloc(8 + 25 + 12 + n + 12), *o = p;
  memcpy(o, sig, 8), o += 8;
  memcpy(o, ihdr_chunk, 25), o += 25;
  put_be32(o, (uint32_t)n);
  memcpy(o + 4, "IDAT", 4);
  memcpy(o + 8, data, n);
  put_be32(o + 8 + n, (uint32_t)crc32(crc32(0, Z_NULL, 0), o + 4, (uInt)(n + 4)));
  o += 12 + n;
  memcpy(o, iend, 12), o += 12;
  *out_n = (size_t)(o - p);
  return p;
}

static int same_pixels(const hearth_image *im, size_t w, size_t h, int f) {
  if (im->width != w || im->height != h || im->channels != 3 || im->type != HEARTH_PIX_U8) return 0;
  const uint8_t *d = im->data;
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++)
      for (int c = 0; c < 3; c++)
        if (d[(y * w + x) * 3 + c] != pixel(f, x, y, c)) return 0;
  return 1;
}

/* walk the chunks, check their order, CRCs, sequence numbers and fields,
 * and decode every frame */
static void check_file(const uint8_t *p, size_t n, size_t w, size_t h, int frames) {
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  CHECK(n > 8 && memcmp(p, sig, 8) == 0);
  size_t at = 8;
  int chunks = 0, fctl = 0, fdat = 0, idat = 0, iend = 0, bad_crc = 0, bad_seq = 0, bad_frame = 0;
  uint32_t seq = 0;
  const uint8_t *ihdr = NULL;
  while (at + 12 <= n && !iend) {
    uint32_t len = be32(p + at);
    if (at + 12 + len > n) break;
    const uint8_t *type = p + at + 4, *data = p + at + 8;
    if (be32(data + len) != (uint32_t)crc32(crc32(0, Z_NULL, 0), type, len + 4)) bad_crc++;
    if (chunks == 0) {
      CHECK(memcmp(type, "IHDR", 4) == 0 && len == 13);
      CHECK(be32(data) == w && be32(data + 4) == h && data[8] == 8 && data[9] == 2);
      CHECK(data[10] == 0 && data[11] == 0 && data[12] == 0);
      ihdr = p + at;
    } else if (chunks == 1) {
      CHECK(memcmp(type, "acTL", 4) == 0 && len == 8);
      CHECK(be32(data) == (uint32_t)frames && be32(data + 4) == 0);
    } else if (memcmp(type, "fcTL", 4) == 0) {
      CHECK(len == 26);
      if (be32(data) != seq++) bad_seq++;
      CHECK(be32(data + 4) == w && be32(data + 8) == h && be32(data + 12) == 0 &&
            be32(data + 16) == 0);
      CHECK(data[20] == 0 && data[21] == 1 && data[22] == 0 && data[23] == 10 && data[24] == 0 &&
            data[25] == 0);
      fctl++;
    } else if (memcmp(type, "IDAT", 4) == 0) {
      CHECK(fctl == 1 && fdat == 0);
      idat++;
    } else if (memcmp(type, "fdAT", 4) == 0) {
      CHECK(fctl == fdat + 2 && len > 4);
      if (be32(data) != seq++) bad_seq++;
      size_t pn;
      uint8_t *png = plain_png(ihdr, data + 4, len - 4, &pn);
      hearth_image im = {0};
      hearth_err err = {0};
      if (hearth_png_read_mem(png, pn, "frame", &im, &err) || !same_pixels(&im, w, h, fdat + 1))
        bad_frame++;
      hearth_image_free(&im);
      free(png);
      fdat++;
    } else if (memcmp(type, "IEND", 4) == 0) {
      CHECK(len == 0);
      iend = 1;
    } else {
      CHECK_MSG(0, "unexpected chunk %.4s", (const char *)type);
    }
    at += 12 + len;
    chunks++;
  }
  CHECK(iend && at == n);
  CHECK(idat == 1 && fctl == frames && fdat == frames - 1);
  CHECK(bad_crc == 0 && bad_seq == 0 && bad_frame == 0);
  /* a plain PNG reader sees frame 0 */
  hearth_image im = {0};
  hearth_err err = {0};
  CHECK_OK(hearth_png_read_mem(p, n, "apng", &im, &err), &err);
  CHECK(same_pixels(&im, w, h, 0));
  hearth_image_free(&im);
}

static void check_size(size_t w, size_t h, int frames) {
  uint8_t *f = make_frames(w, h, frames), *out = NULL;
  size_t n = 0;
  hearth_err err = {0};
  CHECK_OK(hearth_apng_encode(f, w, h, (size_t)frames, 1, 10, &out, &n, &err), &err);
  if (out) check_file(out, n, w, h, frames);
  /* stored blocks: the file's size follows from the frame size */
  size_t raw = h * (1 + 3 * w), blocks = (raw + 65534) / 65535;
  size_t zn = 2 + raw + 5 * blocks + 4;
  CHECK(n == 8 + 25 + 20 + (size_t)frames * (38 + 12 + zn) + (size_t)(frames - 1) * 4 + 12);
  free(out);
  free(f);
}

int main(void) {
  check_size(1, 1, 1);
  check_size(5, 4, 3);
  check_size(1456, 15, 2); /* 65535 filtered bytes: one full stored block */
  check_size(1456, 16, 2); /* 69904: two blocks */
  check_size(200, 110, 3);

  /* the exact bytes of a fixed input (size and CRC-32 of the whole file):
   * the evaluation's videos keep their bytes */
  uint8_t *f = make_frames(48, 16, 4), *out = NULL;
  size_t n = 0;
  hearth_err err = {0};
  CHECK_OK(hearth_apng_encode(f, 48, 16, 4, 1, 10, &out, &n, &err), &err);
  CHECK_MSG(n == 9601 && crc32(crc32(0, Z_NULL, 0), out, (uInt)n) == 0x310b1300u,
            "size %zu crc %08lx", n, crc32(crc32(0, Z_NULL, 0), out, (uInt)n));
  free(out);

  /* the file on disk is the same */
  const char *tmp = getenv("HEARTH_TEST_TMP");
  char path[1200];
  snprintf(path, sizeof path, "%s/test_apng.png", tmp && *tmp ? tmp : "/tmp");
  CHECK_OK(hearth_apng_write(path, f, 48, 16, 4, 1, 10, &err), &err);
  uint8_t *disk = NULL;
  size_t dn = 0;
  CHECK_OK(hearth_read_file(path, 1u << 20, &disk, &dn, &err), &err);
  CHECK(dn == n);
  free(disk);
  remove(path);

  /* rejected arguments, with the name in the message */
  CHECK(hearth_apng_encode(f, 48, 16, 0, 1, 10, &out, &n, &err) == HEARTH_E_ARG && !out);
  CHECK(hearth_apng_encode(NULL, 48, 16, 4, 1, 10, &out, &n, &err) == HEARTH_E_ARG);
  CHECK(hearth_apng_encode(f, 0, 16, 4, 1, 10, &out, &n, &err) == HEARTH_E_SIZE);
  CHECK(hearth_apng_encode(f, 48, 16, 4, 70000, 10, &out, &n, &err) == HEARTH_E_RANGE);
  CHECK(hearth_apng_write("/nonexistent-dir/x.png", f, 48, 16, 4, 1, 10, &err) == HEARTH_E_IO &&
        strstr(err.msg, "/nonexistent-dir/x.png"));
  free(f);
  TEST_MAIN_END();
}
