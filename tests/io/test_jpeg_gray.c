/* hearth_jpeg_read_gray: the Y plane must match the luma of the full RGB
 * decode (0.299/0.587/0.114) to within the chroma round trip, a gray JPEG
 * must come back unchanged in layout, and damaged files must fail with the
 * path named. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"
#include "test_util.h"

static void test_luma_matches_rgb(const char *dir) {
  char path[1200];
  snprintf(path, sizeof path, "%s/plate.jpg", dir);
  hearth_image img = {0}, rgb = {0}, y = {0};
  hearth_err err = {0};
  /* coloured smooth pattern with dark discs, like a plate under tinted light */
  size_t w = 203, h = 117;
  CHECK_OK(hearth_image_alloc(&img, w, h, 3, HEARTH_PIX_U8, &err), &err);
  uint8_t *p = img.data;
  for (size_t j = 0; j < h; j++)
    for (size_t i = 0; i < w; i++) {
      double dark = hypot(fmod((double)i, 40.0) - 20, fmod((double)j, 40.0) - 20) < 8 ? 0.25 : 1.0;
      p[3 * (j * w + i) + 0] = (uint8_t)(dark * (180 + 60 * sin(i * 0.03)));
      p[3 * (j * w + i) + 1] = (uint8_t)(dark * (200 + 40 * cos(j * 0.05)));
      p[3 * (j * w + i) + 2] = (uint8_t)(dark * 150);
    }
  CHECK_OK(hearth_jpeg_write(path, &img, 95, &err), &err);
  CHECK_OK(hearth_jpeg_read(path, &rgb, &err), &err);
  CHECK_OK(hearth_jpeg_read_gray(path, &y, &err), &err);
  CHECK(y.channels == 1 && y.type == HEARTH_PIX_U8 && y.width == w && y.height == h);
  if (y.data && rgb.data && y.width == w && y.height == h) {
    const uint8_t *q = rgb.data, *g = y.data;
    double se = 0, mx = 0;
    for (size_t k = 0; k < w * h; k++) {
      double l = 0.299 * q[3 * k] + 0.587 * q[3 * k + 1] + 0.114 * q[3 * k + 2];
      double d = fabs(l - g[k]);
      se += d * d;
      mx = fmax(mx, d);
    }
    double rms = sqrt(se / (double)(w * h));
    fprintf(stderr, "luma plane vs RGB luma: RMS %.3f, max %.2f levels\n", rms, mx);
    /* the RGB decode rounds each channel and upsamples chroma: about a level */
    CHECK_MSG(rms < 0.5 && mx < 2, "RMS %.3f, max %.2f", rms, mx);
  }
  hearth_image_free(&img);
  hearth_image_free(&rgb);
  hearth_image_free(&y);
}

static void test_luma_errors(const char *dir) {
  char path[1200], bad[1200];
  hearth_err err = {0};
  hearth_image img = {0}, y = {0};
  snprintf(path, sizeof path, "%s/gray.jpg", dir);
  CHECK_OK(hearth_image_alloc(&img, 64, 48, 1, HEARTH_PIX_U8, &err), &err);
  for (size_t k = 0; k < 64 * 48; k++) ((uint8_t *)img.data)[k] = (uint8_t)(k * 7);
  CHECK_OK(hearth_jpeg_write(path, &img, 90, &err), &err);
  CHECK_OK(hearth_jpeg_read_gray(path, &y, &err), &err);
  CHECK(y.width == 64 && y.height == 48 && y.channels == 1);
  hearth_image_free(&y);
  hearth_image_free(&img);
  /* truncated: half the bytes */
  uint8_t *buf;
  size_t n;
  CHECK_OK(hearth_read_file(path, 1 << 20, &buf, &n, &err), &err);
  snprintf(bad, sizeof bad, "%s/cut.jpg", dir);
  FILE *fp = fopen(bad, "wb");
  CHECK(fp != NULL);
  if (fp) {
    fwrite(buf, 1, n / 2, fp);
    fclose(fp);
  }
  free(buf);
  CHECK(hearth_jpeg_read_gray(bad, &y, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, bad) != NULL, "message: %s", err.msg);
  CHECK(y.data == NULL);
  /* not a JPEG at all */
  snprintf(bad, sizeof bad, "%s/text.jpg", dir);
  fp = fopen(bad, "wb");
  CHECK(fp != NULL);
  if (fp) {
    fputs("hello", fp);
    fclose(fp);
  }
  CHECK(hearth_jpeg_read_gray(bad, &y, &err) == HEARTH_E_PARSE);
  CHECK_MSG(strstr(err.msg, bad) != NULL && strstr(err.msg, "not a JPEG"), "message: %s", err.msg);
  /* missing file */
  snprintf(bad, sizeof bad, "%s/none.jpg", dir);
  CHECK(hearth_jpeg_read_gray(bad, &y, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, bad) != NULL, "message: %s", err.msg);
}

int main(void) {
  const char *dir = test_tmpdir("io_jpeg_gray");
  char d[1024];
  snprintf(d, sizeof d, "%s", dir);
  test_luma_matches_rgb(d);
  test_luma_errors(d);
  TEST_MAIN_END();
}
