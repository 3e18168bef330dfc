/* JPEG: quality of a round trip (PSNR on a smooth image), gray layout,
 * deterministic output, and rejection of truncated or damaged files and of
 * invalid writes with the file named and no file left behind. */
#include <dirent.h>
#include <math.h>
#include "hearth/image.h"
#include "test_util.h"

static double psnr_u8(const hearth_image *a, const hearth_image *b) {
  size_t n = hearth_image_bytes(a);
  const uint8_t *p = a->data, *q = b->data;
  double se = 0;
  for (size_t i = 0; i < n; i++) se += (double)(p[i] - q[i]) * (p[i] - q[i]);
  if (se == 0) return 99.0;
  return 10.0 * log10(255.0 * 255.0 / (se / (double)n));
}

/* smooth colour field: slow sinusoids, no edges */
static void smooth_image(hearth_image *img) {
  uint8_t *p = img->data;
  int nc = img->channels;
  for (size_t y = 0; y < img->height; y++)
    for (size_t x = 0; x < img->width; x++)
      for (int c = 0; c < nc; c++) {
        double v = 128 + 90 * sin(0.05 * (double)x + 1.3 * c) * cos(0.037 * (double)y - 0.4 * c);
        p[(y * img->width + x) * nc + c] = (uint8_t)lround(v);
      }
}

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

static void test_round_trip(const char *dir) {
  hearth_err err = {0};
  for (int c = 1; c <= 3; c += 2) {
    hearth_image img, back;
    CHECK_OK(hearth_image_alloc(&img, 160, 120, c, HEARTH_PIX_U8, &err), &err);
    smooth_image(&img);
    char path[1024];
    snprintf(path, sizeof path, "%s/smooth%d.jpg", dir, c);
    CHECK_OK(hearth_jpeg_write(path, &img, 95, &err), &err);
    CHECK_OK(hearth_jpeg_read(path, &back, &err), &err);
    CHECK(back.width == 160 && back.height == 120 && back.channels == c &&
          back.type == HEARTH_PIX_U8);
    if (back.data && back.width == 160 && back.channels == c) {
      double q = psnr_u8(&img, &back);
      printf("jpeg q95 %d channel(s): PSNR %.2f dB\n", c, q);
      CHECK_MSG(q > 35.0, "PSNR %.2f", q);
      /* a low quality loses more: the quality setting takes effect */
      char low[1024];
      snprintf(low, sizeof low, "%s/smooth%d_q10.jpg", dir, c);
      hearth_image back_low;
      CHECK_OK(hearth_jpeg_write(low, &img, 10, &err), &err);
      CHECK_OK(hearth_jpeg_read(low, &back_low, &err), &err);
      if (back_low.data) CHECK(psnr_u8(&img, &back_low) < q - 3);
      hearth_image_free(&back_low);
    }
    /* same input, same bytes */
    char again[1024];
    snprintf(again, sizeof again, "%s/smooth%d_again.jpg", dir, c);
    CHECK_OK(hearth_jpeg_write(again, &img, 95, &err), &err);
    uint8_t *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    CHECK_OK(hearth_read_file(path, 1 << 24, &a, &na, &err), &err);
    CHECK_OK(hearth_read_file(again, 1 << 24, &b, &nb, &err), &err);
    CHECK(na == nb && na > 0 && memcmp(a, b, na) == 0);
    /* the memory reader sees the same pixels */
    hearth_image mem;
    CHECK_OK(hearth_jpeg_read_mem(a, na, "mem.jpg", &mem, &err), &err);
    CHECK(mem.data && back.data && memcmp(mem.data, back.data, hearth_image_bytes(&back)) == 0);
    hearth_image_free(&mem);
    free(a);
    free(b);
    hearth_image_free(&img);
    hearth_image_free(&back);
  }
  CHECK(no_temp_files(dir));
}

static void expect_fail(const void *p, size_t n, const char *name) {
  hearth_err err = {0};
  hearth_image img;
  hearth_status s = hearth_jpeg_read_mem(p, n, name, &img, &err);
  CHECK_MSG(s != HEARTH_OK, "%s accepted", name);
  CHECK_MSG(strstr(err.msg, name) != NULL, "message '%s' lacks the name", err.msg);
  CHECK(img.data == NULL);
}

static void test_bad_inputs(const char *dir) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 64, 48, 3, HEARTH_PIX_U8, &err), &err);
  smooth_image(&img);
  char path[1024];
  snprintf(path, sizeof path, "%s/ok.jpg", dir);
  CHECK_OK(hearth_jpeg_write(path, &img, 90, &err), &err);
  hearth_image_free(&img);
  uint8_t *data = NULL;
  size_t n = 0;
  CHECK_OK(hearth_read_file(path, 1 << 24, &data, &n, &err), &err);
  if (!data) return;

  expect_fail(data, 0, "empty.jpg");
  expect_fail("\x89PNG\r\n\x1a\n", 8, "png.jpg");
  /* cut in the header, in the entropy data, and just before EOI */
  size_t cuts[4] = {4, 100, n / 2, n - 2};
  for (int i = 0; i < 4; i++) {
    char name[64];
    snprintf(name, sizeof name, "cut%zu.jpg", cuts[i]);
    expect_fail(data, cuts[i], name);
  }
  /* an end-of-image marker in the middle of the entropy data (after SOS) */
  size_t sos = 0;
  for (size_t i = 2; i + 4 < n && !sos; i++)
    if (data[i] == 0xFF && data[i + 1] == 0xDA)
      sos = i + 2 + ((size_t)data[i + 2] << 8 | data[i + 3]);
  CHECK(sos > 0 && sos + 16 < n);
  uint8_t *bad = malloc(n);
  memcpy(bad, data, n);
  size_t mid = sos + (n - sos) / 2;
  bad[mid] = 0xFF;
  bad[mid + 1] = 0xD9;
  expect_fail(bad, n, "eoi.jpg");
  /* a corrupt frame header: zero height */
  memcpy(bad, data, n);
  for (size_t i = 0; i + 8 < n; i++)
    if (bad[i] == 0xFF && bad[i + 1] == 0xC0) {
      bad[i + 5] = 0;
      bad[i + 6] = 0;
      break;
    }
  expect_fail(bad, n, "zeroheight.jpg");
  free(bad);

  snprintf(path, sizeof path, "%s/trunc.jpg", dir);
  write_bytes(path, data, n / 2);
  hearth_status s = hearth_jpeg_read(path, &img, &err);
  CHECK(s != HEARTH_OK && strstr(err.msg, path) != NULL);
  free(data);
}

static void test_bad_writes(const char *dir) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 16, 16, 3, HEARTH_PIX_U8, &err), &err);
  char path[1024];
  snprintf(path, sizeof path, "%s/missing/dir/x.jpg", dir);
  hearth_status s = hearth_jpeg_write(path, &img, 90, &err);
  CHECK(s == HEARTH_E_IO && strstr(err.msg, path) != NULL);
  CHECK(!hearth_path_exists(path));
  snprintf(path, sizeof path, "%s/q0.jpg", dir);
  s = hearth_jpeg_write(path, &img, 0, &err);
  CHECK(s == HEARTH_E_RANGE && strstr(err.msg, path) != NULL);
  CHECK(!hearth_path_exists(path));
  s = hearth_jpeg_write(path, &img, 101, &err);
  CHECK(s == HEARTH_E_RANGE);
  hearth_image_free(&img);
  CHECK_OK(hearth_image_alloc(&img, 16, 16, 4, HEARTH_PIX_U8, &err), &err);
  snprintf(path, sizeof path, "%s/rgba.jpg", dir);
  s = hearth_jpeg_write(path, &img, 90, &err);
  CHECK(s == HEARTH_E_UNSUPPORTED && strstr(err.msg, path) != NULL);
  CHECK(!hearth_path_exists(path));
  hearth_image_free(&img);
  CHECK(no_temp_files(dir));
}

/* the size a caller expects is checked from the header, and the error
 * names the file */
static void test_expect(const char *dir) {
  hearth_err err = {0};
  hearth_image img = {0}, back = {0};
  char path[1200];
  snprintf(path, sizeof path, "%s/expect.jpg", dir);
  CHECK_OK(hearth_image_alloc(&img, 64, 48, 3, HEARTH_PIX_U8, &err), &err);
  CHECK_OK(hearth_jpeg_write(path, &img, 90, &err), &err);
  hearth_image_free(&img);
  hearth_image_expect rig = {1920, 1080, 3, 0, 0, "(the colour camera of rig.json)"};
  CHECK(hearth_jpeg_read_expect(path, &rig, &back, &err) == HEARTH_E_SIZE && !back.data);
  CHECK_MSG(strstr(err.msg,
                   "expect.jpg: image is 64x48, expected 1920x1080 (the colour camera "
                   "of rig.json)"),
            "%s", err.msg);
  CHECK(hearth_jpeg_read_gray_expect(path, &rig, &back, &err) == HEARTH_E_SIZE);
  hearth_image_expect ok = {64, 48, 3, 0, 0, NULL};
  CHECK_OK(hearth_jpeg_read_expect(path, &ok, &back, &err), &err);
  CHECK(back.data && back.channels == 3);
  hearth_image_free(&back);
  hearth_image_expect head = {.header_only = 1};
  CHECK_OK(hearth_jpeg_read_expect(path, &head, &back, &err), &err);
  CHECK(!back.data && back.width == 64 && back.height == 48 && back.channels == 3);
}

/* hearth_jpeg_read_half: sides rounded up, and close to the written image
 * halved by 2 x 2 means (the last odd column and row their own) */
static void test_half(const char *dir) {
  hearth_err err = {0};
  for (int c = 1; c <= 3; c += 2) {
    hearth_image img, half, ref;
    CHECK_OK(hearth_image_alloc(&img, 161, 121, c, HEARTH_PIX_U8, &err), &err);
    smooth_image(&img);
    char path[1024];
    snprintf(path, sizeof path, "%s/half%d.jpg", dir, c);
    CHECK_OK(hearth_jpeg_write(path, &img, 95, &err), &err);
    CHECK_OK(hearth_jpeg_read_half(path, &half, &err), &err);
    CHECK(half.width == 81 && half.height == 61 && half.channels == c);
    CHECK_OK(hearth_image_alloc(&ref, 81, 61, c, HEARTH_PIX_U8, &err), &err);
    const uint8_t *p = img.data;
    uint8_t *q = ref.data;
    for (size_t y = 0; y < 61; y++)
      for (size_t x = 0; x < 81; x++)
        for (int k = 0; k < c; k++) {
          unsigned sum = 0, n = 0;
          for (size_t dy = 0; dy < 2; dy++)
            for (size_t dx = 0; dx < 2; dx++) {
              size_t sx = 2 * x + dx, sy = 2 * y + dy;
              if (sx >= 161 || sy >= 121) continue;
              sum += p[(sy * 161 + sx) * (size_t)c + (size_t)k];
              n++;
            }
          q[(y * 81 + x) * (size_t)c + (size_t)k] = (uint8_t)((sum + n / 2) / n);
        }
    if (half.data && half.width == 81 && half.height == 61 && half.channels == c) {
      double d = psnr_u8(&ref, &half);
      printf("jpeg half %d channel(s): PSNR %.2f dB against 2x2 means\n", c, d);
      CHECK_MSG(d > 35.0, "PSNR %.2f", d);
    }
    hearth_image_free(&img);
    hearth_image_free(&half);
    hearth_image_free(&ref);
  }
}

/* hearth_jpeg_read_grid: every step-th pixel of every step-th row of the
 * full decode, bit for bit (gray and colour, odd sides, so the last column
 * and row of the grid are the image's last kept ones), the size checked
 * against the file's own size, and a truncated file refused by name */
static void test_grid(const char *dir) {
  hearth_err err = {0};
  for (int c = 1; c <= 3; c += 2) {
    hearth_image img, full, grid;
    CHECK_OK(hearth_image_alloc(&img, 161, 121, c, HEARTH_PIX_U8, &err), &err);
    smooth_image(&img);
    uint8_t *p = img.data;
    for (size_t k = 0; k < hearth_image_bytes(&img); k += 7) p[k] ^= 0x5a; /* detail */
    char path[1024];
    snprintf(path, sizeof path, "%s/grid%d.jpg", dir, c);
    CHECK_OK(hearth_jpeg_write(path, &img, 90, &err), &err);
    CHECK_OK(hearth_jpeg_read(path, &full, &err), &err);
    for (size_t st = 1; st <= 5; st++) {
      hearth_image_expect want = {161, 121, 0, 0, 0, NULL};
      CHECK_OK(hearth_jpeg_read_grid(path, &want, st, &grid, &err), &err);
      size_t gw = (161 + st - 1) / st, gh = (121 + st - 1) / st;
      CHECK(grid.width == gw && grid.height == gh && grid.channels == c);
      size_t differ = 0;
      const uint8_t *f = full.data, *g = grid.data;
      for (size_t y = 0; grid.data && y < gh; y++)
        for (size_t x = 0; x < gw; x++)
          differ += memcmp(g + (y * gw + x) * (size_t)c, f + (y * st * 161 + x * st) * (size_t)c,
                           (size_t)c) != 0;
      CHECK_MSG(differ == 0, "step %zu, %d channel(s): %zu pixels differ", st, c, differ);
      hearth_image_free(&grid);
    }
    hearth_image_expect rig = {1920, 1080, 3, 0, 0, "(the colour camera of rig.json)"};
    CHECK(hearth_jpeg_read_grid(path, &rig, 2, &grid, &err) == HEARTH_E_SIZE && !grid.data);
    CHECK_MSG(strstr(err.msg, "image is 161x121, expected 1920x1080") != NULL, "%s", err.msg);
    /* truncated in the middle of its data */
    uint8_t *buf;
    size_t n;
    CHECK_OK(hearth_read_file(path, 1 << 24, &buf, &n, &err), &err);
    char cut[1100];
    snprintf(cut, sizeof cut, "%s/grid_cut%d.jpg", dir, c);
    write_bytes(cut, buf, n / 2);
    free(buf);
    CHECK(hearth_jpeg_read_grid(cut, NULL, 2, &grid, &err) != HEARTH_OK && !grid.data);
    CHECK_MSG(strstr(err.msg, "grid_cut") != NULL, "%s", err.msg);
    hearth_image_free(&img);
    hearth_image_free(&full);
  }
}

int main(void) {
  const char *dir = test_tmpdir("io_jpeg");
  test_grid(dir);
  test_expect(dir);
  test_round_trip(dir);
  test_half(dir);
  test_bad_inputs(dir);
  test_bad_writes(dir);
  TEST_MAIN_END();
}
