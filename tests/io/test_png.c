/* PNG: round trips for every supported layout, decoding of hand-built files
 * (an encoder written here from the PNG specification with stored deflate
 * blocks, independent of libpng), byte order checked against raw libpng,
 * and rejection of damaged files with the name in the message. */
#include <dirent.h>
#include <png.h>
#include <stdint.h>
#include "hearth/image.h"
#include "io/io_png.h"
#include "test_util.h"

/* ---- a tiny independent PNG writer (stored deflate, no filtering) -------- */

typedef struct bytes {
  uint8_t *p;
  size_t n, cap;
} bytes;

static void put(bytes *b, const void *src, size_t n) {
  if (b->n + n > b->cap) {
    b->cap = (b->n + n) * 2 + 64;
    b->p = realloc(b->p, b->cap);
  }
  memcpy(b->p + b->n, src, n);
  b->n += n;
}
static void put_be32(bytes *b, uint32_t v) {
  uint8_t x[4] = {(uint8_t)(v >> 24), (uint8_t)(v >> 16), (uint8_t)(v >> 8), (uint8_t)v};
  put(b, x, 4);
}

static uint32_t crc32_bytes(const uint8_t *p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

static void put_chunk(bytes *b, const char *type, const uint8_t *data, size_t n) {
  put_be32(b, (uint32_t)n);
  size_t start = b->n;
  put(b, type, 4);
  if (n) put(b, data, n);
  put_be32(b, crc32_bytes(b->p + start, n + 4));
}

/* raw: h rows, each a filter byte (0) followed by the row bytes */
static bytes make_png(uint32_t w, uint32_t h, int depth, int ctype, const uint8_t *raw,
                      size_t raw_n, const uint8_t *plte, size_t plte_n, const uint8_t *trns,
                      size_t trns_n) {
  bytes b = {0};
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  put(&b, sig, 8);
  uint8_t ihdr[13] = {(uint8_t)(w >> 24),
                      (uint8_t)(w >> 16),
                      (uint8_t)(w >> 8),
                      (uint8_t)w,
                      (uint8_t)(h >> 24),
                      (uint8_t)(h >> 16),
                      (uint8_t)(h >> 8),
                      (uint8_t)h,
                      (uint8_t)depth,
                      (uint8_t)ctype,
                      0,
                      0,
                      0};
  put_chunk(&b, "IHDR", ihdr, 13);
  if (plte) put_chunk(&b, "PLTE", plte, plte_n);
  if (trns) put_chunk(&b, "tRNS", trns, trns_n);
  /* zlib: header, stored blocks of <= 65535 bytes, adler32 */
  bytes z = {0};
  uint8_t zh[2] = {0x78, 0x01};
  put(&z, zh, 2);
  size_t off = 0;
  do {
    size_t len = raw_n - off > 65535 ? 65535 : raw_n - off;
    uint8_t bh[5] = {(uint8_t)(off + len == raw_n), (uint8_t)len, (uint8_t)(len >> 8),
                     (uint8_t)~len, (uint8_t)(~len >> 8)};
    put(&z, bh, 5);
    put(&z, raw + off, len);
    off += len;
  } while (off < raw_n);
  uint32_t a = 1, s2 = 0;
  for (size_t i = 0; i < raw_n; i++) {
    a = (a + raw[i]) % 65521;
    s2 = (s2 + a) % 65521;
  }
  put_be32(&z, (s2 << 16) | a);
  put_chunk(&b, "IDAT", z.p, z.n);
  free(z.p);
  put_chunk(&b, "IEND", NULL, 0);
  return b;
}

/* ---- helpers -------------------------------------------------------------------- */

static void fill_random(hearth_image *img, uint64_t seed) {
  hearth_rng r;
  hearth_rng_seed(&r, seed);
  uint8_t *p = img->data;
  for (size_t i = 0; i < hearth_image_bytes(img); i++) p[i] = (uint8_t)hearth_rng_u64(&r);
}

static int same_image(const hearth_image *a, const hearth_image *b) {
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         a->type == b->type && a->data && b->data &&
         memcmp(a->data, b->data, hearth_image_bytes(a)) == 0;
}

/* 1 if dir holds no file whose name contains ".tmp-" */
static int no_temp_files(const char *dir) {
  DIR *d = opendir(dir);
  if (!d) return 1;
  struct dirent *e;
  int ok = 1;
  while ((e = readdir(d)) != NULL)
    if (strstr(e->d_name, ".tmp-")) ok = 0;
  closedir(d);
  return ok;
}

static void write_bytes(const char *path, const void *p, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) exit(2);
  fwrite(p, 1, n, f);
  fclose(f);
}

/* ---- tests ------------------------------------------------------------------------ */

static void test_round_trips(const char *dir) {
  hearth_err err = {0};
  /* one band of rows, and several (the encoder deflates 64-row bands in
     parallel and joins them into one stream) */
  for (int t = 0; t < 4; t++) {
    hearth_pixtype type = t & 1 ? HEARTH_PIX_U16 : HEARTH_PIX_U8;
    size_t h = t < 2 ? 23 : 200;
    for (int c = 1; c <= 4; c++) {
      hearth_image img, back, back2;
      CHECK_OK(hearth_image_alloc(&img, 37, h, c, type, &err), &err);
      fill_random(&img, (uint64_t)(10 * t + c));
      char path[1024];
      snprintf(path, sizeof path, "%s/rt_%d_%d_%zu.png", dir, (int)type, c, h);
      CHECK_OK(hearth_png_write(path, &img, &err), &err);
      CHECK_OK(hearth_png_read(path, &back, &err), &err);
      CHECK_MSG(same_image(&img, &back), "type %d channels %d", (int)type, c);
      /* memory encoding: same bytes as the file, deterministic, decodable */
      uint8_t *enc = NULL, *enc2 = NULL, *file = NULL;
      size_t n = 0, n2 = 0, fn = 0;
      CHECK_OK(hearth_png_encode(&img, &enc, &n, &err), &err);
      /* the same bytes with another thread count */
      setenv("HEARTH_THREADS", c % 2 ? "1" : "3", 1);
      CHECK_OK(hearth_png_encode(&img, &enc2, &n2, &err), &err);
      unsetenv("HEARTH_THREADS");
      CHECK_OK(hearth_read_file(path, 1 << 24, &file, &fn, &err), &err);
      CHECK(n == n2 && n == fn && memcmp(enc, enc2, n) == 0 && memcmp(enc, file, n) == 0);
      CHECK_OK(hearth_png_read_mem(enc, n, "mem", &back2, &err), &err);
      CHECK(same_image(&img, &back2));
      free(enc);
      free(enc2);
      free(file);
      hearth_image_free(&img);
      hearth_image_free(&back);
      hearth_image_free(&back2);
    }
  }
  CHECK(no_temp_files(dir));
}

/* pictures (hearth_png_write_picture): rows that repeat the row above are
 * stored UP-filtered; libpng and our reader both see the same pixels, the
 * file is smaller than hearth_png_write's for an image whose rows repeat in
 * threes, and an image without repeated rows gets hearth_png_write's bytes */
static void test_pictures(const char *dir) {
  hearth_err err = {0};
  for (int t = 0; t < 2; t++) {
    hearth_pixtype type = t ? HEARTH_PIX_U16 : HEARTH_PIX_U8;
    for (int c = 1; c <= 4; c++) {
      hearth_image img, plain, back, ref;
      CHECK_OK(hearth_image_alloc(&img, 41, 150, c, type, &err), &err);
      CHECK_OK(hearth_image_alloc(&plain, 41, 150, c, type, &err), &err);
      fill_random(&img, (uint64_t)(100 + 10 * t + c));
      fill_random(&plain, (uint64_t)(200 + 10 * t + c));
      size_t stride = hearth_image_bytes(&img) / img.height;
      uint8_t *p = img.data;
      for (size_t y = 0; y < img.height; y++)
        if (y % 3) memcpy(p + y * stride, p + (y - 1) * stride, stride);
      char path[1024];
      snprintf(path, sizeof path, "%s/pic_%d_%d.png", dir, (int)type, c);
      CHECK_OK(hearth_png_write_picture(path, &img, &err), &err);
      CHECK_OK(hearth_png_read(path, &back, &err), &err);
      CHECK_MSG(same_image(&img, &back), "picture: type %d channels %d", (int)type, c);
      uint8_t *file = NULL, *enc = NULL, *a = NULL, *b = NULL;
      size_t fn = 0, n = 0, na = 0, nb = 0;
      CHECK_OK(hearth_read_file(path, 1 << 24, &file, &fn, &err), &err);
      CHECK_OK(hearth_png_read_mem_libpng(file, fn, "pic.png", NULL, &ref, &err), &err);
      CHECK_MSG(same_image(&img, &ref), "picture, libpng: type %d channels %d", (int)type, c);
      CHECK_OK(hearth_png_encode(&img, &enc, &n, &err), &err);
      CHECK_MSG(fn < n / 2, "picture %zu bytes, plain %zu", fn, n);
      CHECK_OK(hearth_png_encode_picture(&plain, &a, &na, &err), &err);
      CHECK_OK(hearth_png_encode(&plain, &b, &nb, &err), &err);
      CHECK(na == nb && memcmp(a, b, na) == 0);
      free(file);
      free(enc);
      free(a);
      free(b);
      hearth_image_free(&img);
      hearth_image_free(&plain);
      hearth_image_free(&back);
      hearth_image_free(&ref);
    }
  }
  CHECK(no_temp_files(dir));
}

/* 16-bit gray over the full range; the file must hold big-endian samples,
 * checked with plain libpng (no transforms) */
static void test_u16_full_range(const char *dir) {
  hearth_err err = {0};
  hearth_image img, back;
  CHECK_OK(hearth_image_alloc(&img, 256, 3, 1, HEARTH_PIX_U16, &err), &err);
  uint16_t *p = img.data;
  for (size_t i = 0; i < 768; i++) p[i] = (uint16_t)(i * 257 + (i / 256) * 13);
  p[0] = 0;
  p[1] = 65535;
  p[2] = 0x0102;
  char path[1024];
  snprintf(path, sizeof path, "%s/u16.png", dir);
  CHECK_OK(hearth_png_write(path, &img, &err), &err);
  CHECK_OK(hearth_png_read(path, &back, &err), &err);
  CHECK(same_image(&img, &back));
  CHECK(back.data && ((uint16_t *)back.data)[1] == 65535 && ((uint16_t *)back.data)[0] == 0);

  FILE *f = fopen(path, "rb");
  CHECK(f != NULL);
  if (f) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    png_init_io(png, f);
    png_read_info(png, info);
    CHECK(png_get_bit_depth(png, info) == 16);
    CHECK(png_get_color_type(png, info) == PNG_COLOR_TYPE_GRAY);
    CHECK(png_get_image_width(png, info) == 256 && png_get_image_height(png, info) == 3);
    uint8_t row[512];
    png_read_row(png, row, NULL);
    CHECK(row[0] == 0 && row[1] == 0);
    CHECK(row[2] == 0xff && row[3] == 0xff);
    CHECK(row[4] == 0x01 && row[5] == 0x02);
    CHECK(row[6] == (uint8_t)(p[3] >> 8) && row[7] == (uint8_t)p[3]);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
  }
  hearth_image_free(&img);
  hearth_image_free(&back);
}

/* files made by the independent writer above */
static void test_handmade_decode(void) {
  hearth_err err = {0};
  hearth_image img;

  /* 16-bit gray, 3x1: big-endian 0x0000 0xffff 0x1234 */
  uint8_t raw16[7] = {0, 0x00, 0x00, 0xff, 0xff, 0x12, 0x34};
  bytes b = make_png(3, 1, 16, 0, raw16, 7, NULL, 0, NULL, 0);
  CHECK_OK(hearth_png_read_mem(b.p, b.n, "g16", &img, &err), &err);
  CHECK(img.type == HEARTH_PIX_U16 && img.channels == 1 && img.width == 3);
  if (img.data) {
    uint16_t *q = img.data;
    CHECK(q[0] == 0 && q[1] == 65535 && q[2] == 0x1234);
  }
  hearth_image_free(&img);
  free(b.p);

  /* 1-bit gray, 10x2: expanded to 0/255 */
  uint8_t raw1[6] = {0, 0xA5, 0x80, 0, 0xFF, 0xC0};
  b = make_png(10, 2, 1, 0, raw1, 6, NULL, 0, NULL, 0);
  CHECK_OK(hearth_png_read_mem(b.p, b.n, "g1", &img, &err), &err);
  CHECK(img.type == HEARTH_PIX_U8 && img.channels == 1 && img.width == 10 && img.height == 2);
  if (img.data) {
    const uint8_t *q = img.data;
    const uint8_t want0[10] = {255, 0, 255, 0, 0, 255, 0, 255, 255, 0};
    CHECK(memcmp(q, want0, 10) == 0);
    for (int i = 0; i < 10; i++) CHECK(q[10 + i] == 255);
  }
  hearth_image_free(&img);
  free(b.p);

  /* 2-bit palette 4x1 with tRNS on entry 1: RGBA */
  uint8_t plte[12] = {10, 20, 30, 40, 50, 60, 70, 80, 90, 200, 210, 220};
  uint8_t trns[2] = {255, 128};
  uint8_t rawp[2] = {0, 0x1B}; /* indices 0 1 2 3 */
  b = make_png(4, 1, 2, 3, rawp, 2, plte, 12, trns, 2);
  CHECK_OK(hearth_png_read_mem(b.p, b.n, "pal", &img, &err), &err);
  CHECK(img.type == HEARTH_PIX_U8 && img.channels == 4 && img.width == 4);
  if (img.data) {
    const uint8_t want[16] = {10, 20, 30, 255, 40,  50,  60,  128,
                              70, 80, 90, 255, 200, 210, 220, 255};
    CHECK(memcmp(img.data, want, 16) == 0);
  }
  hearth_image_free(&img);
  free(b.p);

  /* 8-bit gray+alpha 2x1 */
  uint8_t rawga[5] = {0, 1, 2, 3, 4};
  b = make_png(2, 1, 8, 4, rawga, 5, NULL, 0, NULL, 0);
  CHECK_OK(hearth_png_read_mem(b.p, b.n, "ga", &img, &err), &err);
  CHECK(img.channels == 2 && img.data && memcmp(img.data, rawga + 1, 4) == 0);
  hearth_image_free(&img);
  free(b.p);
}

static void expect_fail(const void *p, size_t n, const char *name, hearth_status want) {
  hearth_err err = {0};
  hearth_image img;
  hearth_status s = hearth_png_read_mem(p, n, name, &img, &err);
  CHECK_MSG(s != HEARTH_OK, "%s accepted", name);
  if (want != HEARTH_OK)
    CHECK_MSG(s == want, "%s: got %s (%s)", name, hearth_status_name(s), err.msg);
  CHECK_MSG(strstr(err.msg, name) != NULL, "message '%s' lacks the name", err.msg);
  CHECK(img.data == NULL && img.width == 0);
}

static void test_bad_inputs(const char *dir) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 40, 30, 3, HEARTH_PIX_U8, &err), &err);
  fill_random(&img, 7);
  uint8_t *enc = NULL;
  size_t n = 0;
  CHECK_OK(hearth_png_encode(&img, &enc, &n, &err), &err);
  hearth_image_free(&img);

  expect_fail(enc, 0, "empty.png", HEARTH_E_PARSE);
  expect_fail("GIF89a....", 10, "gif.png", HEARTH_E_PARSE);
  /* truncated at several places, including just before IEND */
  size_t cuts[4] = {8, 20, n / 2, n - 12};
  for (int i = 0; i < 4; i++) {
    char name[64];
    snprintf(name, sizeof name, "cut%zu.png", cuts[i]);
    expect_fail(enc, cuts[i], name, HEARTH_OK);
  }
  /* a flipped byte in the pixel data breaks the IDAT CRC */
  uint8_t *bad = malloc(n);
  memcpy(bad, enc, n);
  bad[n / 2] ^= 0x40;
  expect_fail(bad, n, "flipped.png", HEARTH_OK);
  free(bad);

  /* too large: a valid header claiming 20000 x 4 */
  uint8_t raw[1] = {0};
  bytes big = make_png(20000, 4, 8, 0, raw, 1, NULL, 0, NULL, 0);
  expect_fail(big.p, big.n, "big.png", HEARTH_E_LIMIT);
  free(big.p);
  /* a tiny file claiming 16000 x 16000 is refused before allocating 256 MB */
  bytes huge = make_png(16000, 16000, 8, 0, raw, 1, NULL, 0, NULL, 0);
  expect_fail(huge.p, huge.n, "huge.png", HEARTH_E_PARSE);
  free(huge.p);
  /* a 1-bit palette image with transparency expands 32-fold to RGBA: the
     file's data fits 16384 x 16384, the decoded 1 GiB does not */
  {
    size_t rb = 16384 / 8 + 1, nraw = rb * 16384;
    uint8_t *zeros = calloc(nraw, 1);
    uint8_t plte[3] = {10, 20, 30}, trns[1] = {128};
    bytes pal = make_png(16384, 16384, 1, 3, zeros, nraw, plte, 3, trns, 1);
    free(zeros);
    expect_fail(pal.p, pal.n, "palette.png", HEARTH_E_LIMIT);
    free(pal.p);
  }
  /* rows missing from the data */
  uint8_t rows[4] = {0, 1, 2, 3};
  bytes short_data = make_png(3, 2, 8, 0, rows, 4, NULL, 0, NULL, 0);
  expect_fail(short_data.p, short_data.n, "short.png", HEARTH_OK);
  free(short_data.p);

  /* from a file: the path is named */
  char path[1024];
  snprintf(path, sizeof path, "%s/trunc.png", dir);
  write_bytes(path, enc, n / 3);
  hearth_status s = hearth_png_read(path, &img, &err);
  CHECK(s != HEARTH_OK && strstr(err.msg, path) != NULL);
  snprintf(path, sizeof path, "%s/missing.png", dir);
  s = hearth_png_read(path, &img, &err);
  CHECK(s == HEARTH_E_IO && strstr(err.msg, path) != NULL);
  free(enc);
}

static void test_bad_writes(const char *dir) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 8, 8, 1, HEARTH_PIX_U8, &err), &err);
  char path[1024];
  snprintf(path, sizeof path, "%s/no/such/dir/x.png", dir);
  hearth_status s = hearth_png_write(path, &img, &err);
  CHECK(s == HEARTH_E_IO && strstr(err.msg, path) != NULL);
  CHECK(!hearth_path_exists(path));
  hearth_image_free(&img);

  /* float images are refused before anything is created */
  CHECK_OK(hearth_image_alloc(&img, 8, 8, 1, HEARTH_PIX_F32, &err), &err);
  snprintf(path, sizeof path, "%s/float.png", dir);
  s = hearth_png_write(path, &img, &err);
  CHECK(s == HEARTH_E_UNSUPPORTED && strstr(err.msg, path) != NULL);
  CHECK(!hearth_path_exists(path));
  hearth_image_free(&img);
  CHECK(no_temp_files(dir));
}

/* encode time of a 1024x1024 RGB texture-like image (printed, not asserted) */
static void report_encode_time(void) {
  hearth_err err = {0};
  hearth_image img;
  if (hearth_image_alloc(&img, 1024, 1024, 3, HEARTH_PIX_U8, &err)) return;
  uint8_t *p = img.data;
  hearth_rng r;
  hearth_rng_seed(&r, 3);
  for (size_t y = 0; y < 1024; y++)
    for (size_t x = 0; x < 1024; x++) {
      uint8_t noise = (uint8_t)(hearth_rng_u64(&r) & 7);
      p[3 * (y * 1024 + x)] = (uint8_t)(x / 4 + noise);
      p[3 * (y * 1024 + x) + 1] = (uint8_t)(y / 4 + noise);
      p[3 * (y * 1024 + x) + 2] = (uint8_t)((x + y) / 8);
    }
  uint8_t *enc = NULL;
  size_t n = 0;
  double t0 = hearth_now();
  CHECK_OK(hearth_png_encode(&img, &enc, &n, &err), &err);
  double t1 = hearth_now();
  printf("png encode 1024x1024 RGB: %.1f ms, %zu bytes\n", 1e3 * (t1 - t0), n);
  free(enc);
  hearth_image_free(&img);
}

/* a caller's expectation is checked from the header, before the pixels:
 * a file declaring 16384 x 16384 RGBA16 is refused without 2 GiB */
static void test_expect(const char *dir) {
  hearth_err err = {0};
  hearth_image img = {0}, back = {0};
  char path[1200];
  snprintf(path, sizeof path, "%s/expect.png", dir);
  CHECK_OK(hearth_image_alloc(&img, 40, 30, 1, HEARTH_PIX_U16, &err), &err);
  CHECK_OK(hearth_png_write(path, &img, &err), &err);
  hearth_image_expect ok = {40, 30, 1, 0, 0, NULL};
  CHECK_OK(hearth_png_read_expect(path, &ok, &back, &err), &err);
  CHECK(back.data && back.width == 40);
  hearth_image_free(&back);
  hearth_image_expect size = {64, 30, 0, 0, 0, "(the depth intrinsics)"};
  CHECK(hearth_png_read_expect(path, &size, &back, &err) == HEARTH_E_SIZE && !back.data);
  CHECK_MSG(strstr(err.msg, "expect.png: image is 40x30, expected 64x30 (the depth intrinsics)"),
            "%s", err.msg);
  hearth_image_expect ch = {0, 0, 3, 0, 0, NULL};
  CHECK(hearth_png_read_expect(path, &ch, &back, &err) == HEARTH_E_UNSUPPORTED);
  hearth_image_expect px = {0, 0, 0, 1000, 0, NULL};
  CHECK(hearth_png_read_expect(path, &px, &back, &err) == HEARTH_E_LIMIT);
  CHECK_MSG(strstr(err.msg, "more than the limit of 1000 pixels"), "%s", err.msg);
  hearth_image_expect head = {.header_only = 1};
  CHECK_OK(hearth_png_read_expect(path, &head, &back, &err), &err);
  CHECK(!back.data && back.width == 40 && back.height == 30 && back.channels == 1 &&
        back.type == HEARTH_PIX_U16);
  hearth_image_free(&img);
  /* the huge declaration: header + 2 MB of (invalid) data + IEND */
  bytes b = {0};
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  put(&b, sig, 8);
  const uint8_t ihdr[13] = {0, 0, 0x40, 0, 0, 0, 0x40, 0, 16, 6, 0, 0, 0};
  put_chunk(&b, "IHDR", ihdr, 13);
  uint8_t *zeros = calloc(2000000, 1);
  put_chunk(&b, "IDAT", zeros, 2000000);
  free(zeros);
  put_chunk(&b, "IEND", NULL, 0);
  snprintf(path, sizeof path, "%s/huge.png", dir);
  write_bytes(path, b.p, b.n);
  free(b.p);
  hearth_image_expect depth = {640, 576, 1, 0, 0, NULL};
  double t0 = hearth_now();
  CHECK(hearth_png_read_expect(path, &depth, &back, &err) == HEARTH_E_SIZE && !back.data);
  CHECK_MSG(strstr(err.msg, "image is 16384x16384, expected 640x576"), "%s", err.msg);
  CHECK_MSG(hearth_now() - t0 < 1.0, "took %.2f s", hearth_now() - t0);
  CHECK_OK(hearth_png_read_expect(path, &head, &back, &err), &err);
  CHECK(back.width == 16384 && back.channels == 4 && back.type == HEARTH_PIX_U16 && !back.data);
}

/* ---- files written by libpng with each row filter ------------------------------ */

static void on_mem_write(png_structp png, png_bytep data, png_size_t n) {
  put(png_get_io_ptr(png), data, n);
}
static void on_mem_flush(png_structp png) { (void)png; }

/* img as a PNG written by libpng: the given row filters (PNG_FILTER_*),
   IDAT chunks of at most idat bytes, a tEXt and a pHYs chunk before them and
   a tIME after them; 16-bit samples stored big-endian as the format wants */
static bytes libpng_encode(const hearth_image *img, int filters, size_t idat, int level) {
  bytes b = {0};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) exit(2);
  png_set_write_fn(png, &b, on_mem_write, on_mem_flush);
  static const int ctype[5] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                               PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
  int depth = img->type == HEARTH_PIX_U16 ? 16 : 8;
  png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, depth,
               ctype[img->channels], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, filters);
  png_set_compression_level(png, level);
  png_set_compression_buffer_size(png, idat);
  png_text t = {PNG_TEXT_COMPRESSION_NONE, "Comment", "filters", 7, 0, NULL, NULL};
  png_set_text(png, info, &t, 1);
  png_set_pHYs(png, info, 2835, 2835, PNG_RESOLUTION_METER);
  png_write_info(png, info);
  uint16_t one = 1;
  uint8_t little;
  memcpy(&little, &one, 1);
  if (depth == 16 && little) png_set_swap(png);
  size_t stride = img->width * (size_t)img->channels * (size_t)img->type;
  for (size_t y = 0; y < img->height; y++)
    png_write_row(png, (png_const_bytep)img->data + y * stride);
  png_time tm = {2026, 12, 1, 12, 0, 0};
  png_set_tIME(png, info, &tm);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return b;
}

/* every layout, each filter alone and libpng's adaptive choice, one IDAT and
   many, random and smooth pixels: the reader (its fast path takes these
   files) gives the pixels written, and so does its libpng route */
static void test_libpng_filters(void) {
  static const int filters[6] = {PNG_FILTER_NONE, PNG_FILTER_SUB,   PNG_FILTER_UP,
                                 PNG_FILTER_AVG,  PNG_FILTER_PAETH, PNG_ALL_FILTERS};
  hearth_err err;
  for (int type = 1; type <= 2; type++)
    for (int ch = 1; ch <= 4; ch++)
      for (int smooth = 0; smooth < 2; smooth++) {
        hearth_image img;
        CHECK_OK(hearth_image_alloc(&img, 37, 23, ch, type == 2 ? HEARTH_PIX_U16 : HEARTH_PIX_U8,
                                    &err),
                 &err);
        fill_random(&img, (uint64_t)(100 + 10 * type + ch));
        if (smooth) {
          /* gradients with a little noise: the predictors' differences matter */
          uint8_t *p = img.data;
          size_t n = hearth_image_bytes(&img);
          for (size_t i = 0; i < n; i++) p[i] = (uint8_t)((i * 7 / 5 + (i / 111) * 3) + (p[i] & 3));
        }
        for (int f = 0; f < 6; f++)
          for (int split = 0; split < 2; split++) {
            bytes b = libpng_encode(&img, filters[f], split ? 64 : 1 << 16, split ? 9 : 6);
            hearth_image got, ref;
            CHECK_OK(hearth_png_read_mem(b.p, b.n, "filters.png", &got, &err), &err);
            CHECK(same_image(&got, &img));
            CHECK_OK(hearth_png_read_mem_libpng(b.p, b.n, "filters.png", NULL, &ref, &err), &err);
            CHECK(same_image(&ref, &img));
            hearth_image_free(&got);
            hearth_image_free(&ref);
            free(b.p);
          }
        hearth_image_free(&img);
      }
}

int main(void) {
  const char *dir = test_tmpdir("io_png");
  test_expect(dir);
  test_round_trips(dir);
  test_pictures(dir);
  test_u16_full_range(dir);
  test_handmade_decode();
  test_libpng_filters();
  test_bad_inputs(dir);
  test_bad_writes(dir);
  report_encode_time();
  TEST_MAIN_END();
}
