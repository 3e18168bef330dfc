/* In-memory images: allocation limits, resampling (constants stay constant,
 * box averages in closed form), blitting, line/circle geometry, the bitmap
 * font and the Turbo colour map. */
#include <math.h>
#include "hearth/image.h"
#include "test_util.h"

static const uint8_t k_white[3] = {255, 255, 255};

static uint8_t *px(const hearth_image *img, size_t x, size_t y) {
  return (uint8_t *)img->data + (y * img->width + x) * (size_t)img->channels;
}

static size_t count_set(const hearth_image *img) {
  size_t n = 0;
  for (size_t y = 0; y < img->height; y++)
    for (size_t x = 0; x < img->width; x++)
      if (px(img, x, y)[0]) n++;
  return n;
}

static void clear(hearth_image *img) { memset(img->data, 0, hearth_image_bytes(img)); }

static void test_alloc(void) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 7, 5, 3, HEARTH_PIX_U16, &err), &err);
  CHECK(hearth_image_bytes(&img) == 7 * 5 * 3 * 2);
  hearth_image_free(&img);
  CHECK(img.data == NULL);
  hearth_image_free(&img); /* a zeroed image is fine */
  CHECK(hearth_image_alloc(&img, SIZE_MAX / 2, 3, 1, HEARTH_PIX_U8, &err) == HEARTH_E_NOMEM);
  CHECK(hearth_image_alloc(&img, (size_t)1 << 32, (size_t)1 << 31, 4, HEARTH_PIX_F32, &err) ==
        HEARTH_E_NOMEM);
  CHECK(img.data == NULL);
  CHECK(hearth_image_alloc(&img, 0, 3, 1, HEARTH_PIX_U8, &err) == HEARTH_E_ARG);
  CHECK(hearth_image_alloc(&img, 3, 3, 5, HEARTH_PIX_U8, &err) == HEARTH_E_ARG);
  CHECK(hearth_image_alloc(&img, 3, 3, 1, (hearth_pixtype)3, &err) == HEARTH_E_ARG);
}

static void test_resize(void) {
  hearth_err err = {0};
  hearth_image src, dst;
  /* a constant image stays constant whatever the factors */
  CHECK_OK(hearth_image_alloc(&src, 37, 29, 3, HEARTH_PIX_U8, &err), &err);
  for (size_t i = 0; i < hearth_image_bytes(&src); i++)
    ((uint8_t *)src.data)[i] = (uint8_t)(i % 3 == 0 ? 201 : i % 3 == 1 ? 7 : 255);
  size_t sizes[5][2] = {{10, 7}, {37, 29}, {80, 61}, {1, 1}, {100, 3}};
  for (int k = 0; k < 5; k++) {
    CHECK_OK(hearth_image_resize(&src, sizes[k][0], sizes[k][1], &dst, &err), &err);
    CHECK(dst.width == sizes[k][0] && dst.height == sizes[k][1] && dst.channels == 3);
    int ok = 1;
    for (size_t i = 0; i < hearth_image_bytes(&dst); i++) {
      uint8_t want = (uint8_t)(i % 3 == 0 ? 201 : i % 3 == 1 ? 7 : 255);
      if (((uint8_t *)dst.data)[i] != want) ok = 0;
    }
    CHECK_MSG(ok, "resize to %zux%zu changed a constant image", sizes[k][0], sizes[k][1]);
    hearth_image_free(&dst);
  }
  hearth_image_free(&src);

  /* halving averages 2x2 blocks: block (i, j) holds 4 values with a known mean */
  CHECK_OK(hearth_image_alloc(&src, 8, 6, 1, HEARTH_PIX_U8, &err), &err);
  for (size_t y = 0; y < 6; y++)
    for (size_t x = 0; x < 8; x++) px(&src, x, y)[0] = (uint8_t)(10 * x + 20 * y);
  CHECK_OK(hearth_image_resize(&src, 4, 3, &dst, &err), &err);
  for (size_t j = 0; j < 3; j++)
    for (size_t i = 0; i < 4; i++) {
      /* mean of 10x+20y over x in {2i, 2i+1}, y in {2j, 2j+1} */
      double mean = 10 * (2.0 * i + 0.5) + 20 * (2.0 * j + 0.5);
      CHECK_NEAR(px(&dst, i, j)[0], mean, 0.5);
    }
  hearth_image_free(&dst);
  /* enlarging a linear ramp keeps it monotone and within the input range */
  CHECK_OK(hearth_image_resize(&src, 31, 6, &dst, &err), &err);
  for (size_t x = 1; x < 31; x++) CHECK(px(&dst, x, 0)[0] >= px(&dst, x - 1, 0)[0]);
  CHECK(px(&dst, 0, 0)[0] == 0 && px(&dst, 30, 0)[0] == 70);
  hearth_image_free(&dst);
  hearth_image_free(&src);

  CHECK_OK(hearth_image_alloc(&src, 4, 4, 1, HEARTH_PIX_U16, &err), &err);
  CHECK(hearth_image_resize(&src, 2, 2, &dst, &err) == HEARTH_E_ARG);
  hearth_image_free(&src);
}

static void test_blit(void) {
  hearth_err err = {0};
  hearth_image dst, g;
  CHECK_OK(hearth_image_alloc(&dst, 10, 8, 3, HEARTH_PIX_U8, &err), &err);
  CHECK_OK(hearth_image_alloc(&g, 4, 4, 1, HEARTH_PIX_U8, &err), &err);
  for (size_t i = 0; i < 16; i++) ((uint8_t *)g.data)[i] = (uint8_t)(i + 1);
  /* gray into RGB, partly outside on the right and bottom */
  hearth_image_blit(&dst, &g, 8, 6);
  CHECK(px(&dst, 8, 6)[0] == 1 && px(&dst, 8, 6)[1] == 1 && px(&dst, 8, 6)[2] == 1);
  CHECK(px(&dst, 9, 7)[2] == 6);
  CHECK(px(&dst, 7, 6)[0] == 0 && px(&dst, 8, 5)[0] == 0);
  size_t nz = 0;
  for (size_t i = 0; i < hearth_image_bytes(&dst); i++) nz += ((uint8_t *)dst.data)[i] != 0;
  CHECK(nz == 4 * 3);
  hearth_image_blit(&dst, &g, 100, 100); /* entirely outside: nothing, no crash */
  hearth_image_free(&g);
  hearth_image_free(&dst);
}

static void test_lines(void) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 40, 30, 3, HEARTH_PIX_U8, &err), &err);
  uint8_t red[3] = {255, 0, 0};
  /* endpoints are drawn; a horizontal thin line covers exactly its pixels */
  hearth_draw_line(&img, 3, 5, 20, 5, red, 1);
  CHECK(count_set(&img) == 18);
  CHECK(px(&img, 3, 5)[0] == 255 && px(&img, 20, 5)[0] == 255 && px(&img, 3, 5)[1] == 0);
  CHECK(px(&img, 2, 5)[0] == 0 && px(&img, 21, 5)[0] == 0);
  clear(&img);
  /* a diagonal: both endpoints, one pixel per column */
  hearth_draw_line(&img, 2, 3, 17, 11, red, 1);
  CHECK(px(&img, 2, 3)[0] && px(&img, 17, 11)[0]);
  CHECK(count_set(&img) == 16);
  clear(&img);
  /* thickness 3 horizontal: three rows, round caps extend 1 pixel */
  hearth_draw_line(&img, 10, 10, 20, 10, red, 3);
  CHECK(px(&img, 15, 9)[0] && px(&img, 15, 10)[0] && px(&img, 15, 11)[0]);
  CHECK(!px(&img, 15, 8)[0] && !px(&img, 15, 12)[0]);
  CHECK(px(&img, 9, 10)[0] && !px(&img, 8, 10)[0]);
  clear(&img);
  /* clipped: a line from far outside crosses the full width of row 7 */
  hearth_draw_line(&img, -1e7, 7, 1e7, 7, red, 1);
  CHECK(count_set(&img) == 40);
  clear(&img);
  /* entirely outside, or not finite: nothing drawn */
  hearth_draw_line(&img, -50, -5, 100, -5, red, 1);
  hearth_draw_line(&img, 45, 0, 45, 29, red, 2);
  hearth_draw_line(&img, NAN, 0, 10, 10, red, 1);
  CHECK(count_set(&img) == 0);
  hearth_image_free(&img);
}

static void test_circle(void) {
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 41, 41, 3, HEARTH_PIX_U8, &err), &err);
  hearth_draw_circle(&img, 20, 20, 10, k_white);
  CHECK(px(&img, 30, 20)[0] && px(&img, 10, 20)[0] && px(&img, 20, 30)[0] && px(&img, 20, 10)[0]);
  CHECK(!px(&img, 20, 20)[0] && !px(&img, 31, 20)[0] && !px(&img, 25, 20)[0]);
  /* every drawn pixel lies on the ring; the ring has no gaps (each pixel
   * has two 8-neighbours on it) and about the 4 sqrt(2) r pixels an
   * 8-connected ring needs */
  size_t n = 0;
  for (size_t y = 1; y < 40; y++)
    for (size_t x = 1; x < 40; x++)
      if (px(&img, x, y)[0]) {
        double d = hypot((double)x - 20, (double)y - 20);
        CHECK(fabs(d - 10) <= 0.5 + 1e-9);
        int nb = 0;
        for (int dy = -1; dy <= 1; dy++)
          for (int dx = -1; dx <= 1; dx++)
            if ((dx || dy) && px(&img, x + dx, y + dy)[0]) nb++;
        CHECK(nb >= 2);
        n++;
      }
  CHECK(n >= 52);
  clear(&img);
  /* clipped at the border */
  hearth_draw_circle(&img, 0, 0, 5, k_white);
  CHECK(px(&img, 5, 0)[0] && px(&img, 0, 5)[0]);
  hearth_draw_circle(&img, 1e9, 1e9, 3, k_white);
  hearth_image_free(&img);
}

/* the ink of one character drawn at (1, 1), scale s, into a 5s x 7s mask */
static void glyph_mask(const char *text, int s, uint8_t *mask, size_t *ink, int *outside) {
  hearth_err err = {0};
  hearth_image img;
  size_t w = 5 * (size_t)s, h = 7 * (size_t)s;
  if (hearth_image_alloc(&img, w + 2 + 8 * (size_t)s, h + 2 + 8 * (size_t)s, 3, HEARTH_PIX_U8,
                         &err))
    exit(2);
  hearth_draw_text(&img, 1, 1, text, k_white, s);
  *ink = 0;
  *outside = 0;
  for (size_t y = 0; y < img.height; y++)
    for (size_t x = 0; x < img.width; x++) {
      int on = px(&img, x, y)[0] != 0;
      int in = x >= 1 && y >= 1 && x < 1 + w && y < 1 + h;
      if (in) {
        mask[(y - 1) * w + (x - 1)] = (uint8_t)on;
        *ink += (size_t)on;
      } else if (on) {
        *outside = 1;
      }
    }
  hearth_image_free(&img);
}

static void test_text(void) {
  const char *req = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ.,:-_/%()=+";
  size_t nreq = strlen(req);
  uint8_t masks[64][35], qmask[35];
  size_t ink, qink;
  int outside;
  glyph_mask("?", 1, qmask, &qink, &outside);
  CHECK(qink > 0);
  for (size_t i = 0; i < nreq; i++) {
    char s[2] = {req[i], 0};
    glyph_mask(s, 1, masks[i], &ink, &outside);
    CHECK_MSG(ink > 0 && !outside, "glyph '%c': ink %zu outside %d", req[i], ink, outside);
    CHECK_MSG(memcmp(masks[i], qmask, 35) != 0, "glyph '%c' is missing", req[i]);
  }
  /* all glyphs differ from one another */
  for (size_t i = 0; i < nreq; i++)
    for (size_t j = i + 1; j < nreq; j++)
      CHECK_MSG(memcmp(masks[i], masks[j], 35) != 0, "'%c' and '%c' look the same", req[i], req[j]);
  /* lower case is drawn as upper case; space draws nothing */
  uint8_t m[35];
  glyph_mask("k", 1, m, &ink, &outside);
  CHECK(memcmp(m, masks[strchr(req, 'K') - req], 35) == 0);
  glyph_mask(" ", 1, m, &ink, &outside);
  CHECK(ink == 0);
  /* scale 3 is the same glyph with 3x3 blocks */
  uint8_t big[15 * 21];
  size_t ink3;
  glyph_mask("R", 3, big, &ink3, &outside);
  size_t r = strchr(req, 'R') - req;
  size_t ink1 = 0;
  for (int i = 0; i < 35; i++) ink1 += masks[r][i];
  CHECK(ink3 == 9 * ink1 && !outside);
  for (size_t y = 0; y < 21; y++)
    for (size_t x = 0; x < 15; x++) CHECK(big[y * 15 + x] == masks[r][(y / 3) * 5 + x / 3]);
  /* the degree sign (UTF-8) has its own glyph */
  glyph_mask("\xc2\xb0", 1, m, &ink, &outside);
  CHECK(ink > 0 && memcmp(m, qmask, 35) != 0);

  /* a string advances 6 pixels per character and is clipped at the edge */
  hearth_err err = {0};
  hearth_image img;
  CHECK_OK(hearth_image_alloc(&img, 20, 10, 3, HEARTH_PIX_U8, &err), &err);
  hearth_draw_text(&img, 0, 0, "11", k_white, 1);
  CHECK(px(&img, 2, 0)[0] && px(&img, 8, 0)[0] && !px(&img, 5, 0)[0]);
  clear(&img);
  hearth_draw_text(&img, 15, 5, "TEMP 36.6 C", k_white, 2);
  CHECK(count_set(&img) > 0);
  hearth_image_free(&img);
}

static double luma(const uint8_t c[3]) { return 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]; }

static void test_turbo(void) {
  uint8_t c[3], d[3];
  /* at t = 0 the polynomial is its constant terms: 255 * (0.1357, 0.0914, 0.1067) */
  hearth_turbo(0, c);
  CHECK(c[0] == 35 && c[1] == 23 && c[2] == 27);
  /* the endpoints approximate the published table, (48,18,59) and (122,4,3);
   * the fit is known to be loosest at the ends */
  CHECK(abs(c[0] - 48) <= 35 && abs(c[1] - 18) <= 35 && abs(c[2] - 59) <= 35);
  hearth_turbo(1, c);
  CHECK(abs(c[0] - 122) <= 35 && abs(c[1] - 4) <= 35 && abs(c[2] - 3) <= 35);
  CHECK(c[0] > 3 * c[1] && c[0] > 3 * c[2]); /* dark red */
  /* clamping */
  hearth_turbo(-3, d);
  hearth_turbo(0, c);
  CHECK(memcmp(c, d, 3) == 0);
  hearth_turbo(7, d);
  hearth_turbo(1, c);
  CHECK(memcmp(c, d, 3) == 0);
  /* hues along the map: blue-ish at 0.15, green at 0.5, red/orange at 0.85 */
  hearth_turbo(0.15, c);
  CHECK(c[2] > c[0]);
  hearth_turbo(0.5, c);
  CHECK(c[1] > c[0] && c[1] > c[2]);
  hearth_turbo(0.85, c);
  CHECK(c[0] > c[1] && c[0] > c[2]);
  /* luminance rises to a peak near the middle and falls after it */
  double prev = -1;
  for (int i = 0; i <= 10; i++) {
    hearth_turbo(0.05 * i, c);
    CHECK(luma(c) >= prev - 2);
    prev = luma(c);
  }
  prev = 1e9;
  for (int i = 0; i <= 6; i++) {
    hearth_turbo(0.7 + 0.05 * i, c);
    CHECK(luma(c) <= prev + 2);
    prev = luma(c);
  }

  hearth_err err = {0};
  hearth_image t, rgb;
  CHECK_OK(hearth_image_alloc(&t, 5, 1, 1, HEARTH_PIX_F32, &err), &err);
  float *v = t.data;
  v[0] = 20.0f;
  v[1] = 40.0f;
  v[2] = NAN;
  v[3] = -100.0f;
  v[4] = 30.0f;
  const uint8_t nan_rgb[3] = {1, 2, 3};
  CHECK_OK(hearth_turbo_image(&t, 20, 40, nan_rgb, &rgb, &err), &err);
  CHECK(rgb.channels == 3 && rgb.type == HEARTH_PIX_U8 && rgb.width == 5);
  if (rgb.data) {
    hearth_turbo(0, c);
    CHECK(memcmp(px(&rgb, 0, 0), c, 3) == 0 && memcmp(px(&rgb, 3, 0), c, 3) == 0);
    hearth_turbo(1, c);
    CHECK(memcmp(px(&rgb, 1, 0), c, 3) == 0);
    CHECK(memcmp(px(&rgb, 2, 0), nan_rgb, 3) == 0);
    hearth_turbo(0.5, c);
    for (int k = 0; k < 3; k++) CHECK(abs(px(&rgb, 4, 0)[k] - c[k]) <= 2);
  }
  hearth_image_free(&rgb);
  CHECK(hearth_turbo_image(&t, 40, 20, nan_rgb, &rgb, &err) == HEARTH_E_RANGE);
  CHECK(rgb.data == NULL);
  hearth_image_free(&t);
  CHECK_OK(hearth_image_alloc(&t, 2, 2, 1, HEARTH_PIX_U16, &err), &err);
  CHECK(hearth_turbo_image(&t, 0, 1, nan_rgb, &rgb, &err) == HEARTH_E_ARG);
  hearth_image_free(&t);
}

int main(void) {
  test_alloc();
  test_resize();
  test_blit();
  test_lines();
  test_circle();
  test_text();
  test_turbo();
  TEST_MAIN_END();
}
