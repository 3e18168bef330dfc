/* In-memory images: allocation, resampling, blitting and simple drawing
 * (lines, circles, a built-in 5x7 bitmap font) for overlays and contact
 * sheets. Pixel (i, j) covers [i, i+1) x [j, j+1); its centre is at
 * (i + 0.5, j + 0.5) for resampling, while drawing coordinates name pixel
 * centres directly (x = 3 is column 3). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"

/* ---- allocation ------------------------------------------------------------ */

static int valid_type(hearth_pixtype t) {
  return t == HEARTH_PIX_U8 || t == HEARTH_PIX_U16 || t == HEARTH_PIX_F32;
}

hearth_status hearth_image_alloc(hearth_image *img, size_t width, size_t height, int channels,
                                 hearth_pixtype type, hearth_err *err) {
  memset(img, 0, sizeof *img);
  if (width == 0 || height == 0)
    return hearth_err_set(err, HEARTH_E_ARG, "image: size %zux%zu: both sides must be >= 1", width,
                          height);
  if (channels < 1 || channels > 4)
    return hearth_err_set(err, HEARTH_E_ARG, "image: %d channels: expected 1..4", channels);
  if (!valid_type(type))
    return hearth_err_set(err, HEARTH_E_ARG, "image: pixel type %d: expected 1, 2 or 4 bytes",
                          (int)type);
  size_t n, bytes;
  if (!hearth_mul_size(width, height, &n) || !hearth_mul_size(n, (size_t)channels, &n) ||
      !hearth_mul_size(n, (size_t)type, &bytes))
    return hearth_err_set(err, HEARTH_E_NOMEM, "image: %zux%zux%d size overflows", width, height,
                          channels);
  void *data = calloc(bytes, 1);
  if (!data) return hearth_err_set(err, HEARTH_E_NOMEM, "image: cannot allocate %zu bytes", bytes);
  img->width = width;
  img->height = height;
  img->channels = channels;
  img->type = type;
  img->data = data;
  return HEARTH_OK;
}

hearth_status hearth_image_bytes_check(size_t w, size_t h, int channels, int sample_bytes,
                                       char *msg, size_t msgsz) {
  size_t n;
  if (hearth_mul_size(w, h, &n) && hearth_mul_size(n, (size_t)channels, &n) &&
      hearth_mul_size(n, (size_t)sample_bytes, &n) && n <= HEARTH_IMAGE_MAX_BYTES)
    return HEARTH_OK;
  snprintf(
      msg, msgsz,
      "image of %zux%zu pixels x %d channel(s) x %d byte(s) exceeds the limit of %zu MiB decoded",
      w, h, channels, sample_bytes, HEARTH_IMAGE_MAX_BYTES >> 20);
  return HEARTH_E_LIMIT;
}

hearth_status hearth_image_expect_check(const hearth_image_expect *want, size_t w, size_t h,
                                        int channels, char *msg, size_t msgsz) {
  if (!want) return HEARTH_OK;
  if ((want->width && w != want->width) || (want->height && h != want->height)) {
    snprintf(msg, msgsz, "image is %zux%zu, expected %zux%zu%s%s", w, h,
             want->width ? want->width : w, want->height ? want->height : h, want->why ? " " : "",
             want->why ? want->why : "");
    return HEARTH_E_SIZE;
  }
  if (want->channels && channels != want->channels) {
    snprintf(msg, msgsz, "image has %d channel(s), expected %d", channels, want->channels);
    return HEARTH_E_UNSUPPORTED;
  }
  size_t px;
  if (want->max_pixels && (!hearth_mul_size(w, h, &px) || px > want->max_pixels)) {
    snprintf(msg, msgsz, "image is %zux%zu, more than the limit of %zu pixels", w, h,
             want->max_pixels);
    return HEARTH_E_LIMIT;
  }
  return HEARTH_OK;
}

void hearth_image_free(hearth_image *img) {
  if (!img) return;
  free(img->data);
  memset(img, 0, sizeof *img);
}

size_t hearth_image_bytes(const hearth_image *img) {
  size_t n;
  if (!img || img->channels < 1 || !valid_type(img->type)) return 0;
  if (!hearth_mul_size(img->width, img->height, &n) ||
      !hearth_mul_size(n, (size_t)img->channels, &n) || !hearth_mul_size(n, (size_t)img->type, &n))
    return 0;
  return n;
}

/* ---- resampling -------------------------------------------------------------- */

/* the taps of one output sample along one axis: source indices
 * [first, first + count) with weights summing to 1 */
typedef struct taps {
  size_t first, count, woff; /* woff: offset into the shared weight array */
} taps;

/* Build the taps of every output sample for src -> dst samples along an
 * axis. Shrinking averages the covered source area (box filter with
 * fractional edge weights); enlarging interpolates linearly between the two
 * nearest source centres (clamped at the borders). Returns 0 on allocation
 * failure. */
static int build_taps(size_t src, size_t dst, taps **out_t, double **out_w) {
  taps *t = hearth_alloc_array(dst, sizeof *t);
  size_t per = dst < src ? (src + dst - 1) / dst + 2 : 2;
  double *w = hearth_alloc_array(dst, per * sizeof *w);
  if (!t || !w) {
    free(t);
    free(w);
    return 0;
  }
  size_t off = 0;
  double scale = (double)src / (double)dst;
  for (size_t o = 0; o < dst; o++) {
    t[o].woff = off;
    if (dst < src) {
      /* area average over [a, b) in source pixels */
      double a = (double)o * scale, b = (double)(o + 1) * scale;
      size_t i0 = (size_t)floor(a), i1 = (size_t)ceil(b);
      if (i1 > src) i1 = src;
      if (i0 >= i1) i0 = i1 - 1;
      t[o].first = i0;
      t[o].count = i1 - i0;
      for (size_t i = i0; i < i1; i++) {
        double lo = fmax(a, (double)i), hi = fmin(b, (double)(i + 1));
        w[off++] = (hi > lo ? hi - lo : 0.0) / scale;
      }
    } else {
      /* centre-aligned linear interpolation */
      double x = ((double)o + 0.5) * scale - 0.5;
      if (x < 0) x = 0;
      if (x > (double)(src - 1)) x = (double)(src - 1);
      size_t i0 = (size_t)floor(x);
      double f = x - (double)i0;
      if (i0 + 1 >= src) {
        t[o].first = src - 1;
        t[o].count = 1;
        w[off++] = 1.0;
      } else {
        t[o].first = i0;
        t[o].count = 2;
        w[off++] = 1.0 - f;
        w[off++] = f;
      }
    }
  }
  *out_t = t;
  *out_w = w;
  return 1;
}

hearth_status hearth_image_resize(const hearth_image *src, size_t width, size_t height,
                                  hearth_image *dst, hearth_err *err) {
  memset(dst, 0, sizeof *dst);
  if (!src || !src->data || src->type != HEARTH_PIX_U8 || src->channels < 1 || src->channels > 4)
    return hearth_err_set(err, HEARTH_E_ARG, "resize: expected a U8 image with 1..4 channels");
  if (width == 0 || height == 0)
    return hearth_err_set(err, HEARTH_E_ARG, "resize: target size %zux%zu must be >= 1x1", width,
                          height);
  hearth_status s = hearth_image_alloc(dst, width, height, src->channels, HEARTH_PIX_U8, err);
  if (s) return s;
  size_t nc = (size_t)src->channels;
  taps *tx = NULL, *ty = NULL;
  double *wx = NULL, *wy = NULL, *tmp = NULL;
  size_t tmp_n = 0;
  int ok = build_taps(src->width, width, &tx, &wx) && build_taps(src->height, height, &ty, &wy) &&
           hearth_mul_size(src->height, width, &tmp_n) && hearth_mul_size(tmp_n, nc, &tmp_n) &&
           (tmp = hearth_alloc_array(tmp_n, sizeof *tmp)) != NULL;
  if (!ok) {
    free(tx);
    free(wx);
    free(ty);
    free(wy);
    hearth_image_free(dst);
    return hearth_err_set(err, HEARTH_E_NOMEM, "resize: cannot allocate scratch for %zux%zu", width,
                          height);
  }
  /* horizontal pass into a double buffer, then the vertical pass */
  const uint8_t *in = src->data;
  for (size_t y = 0; y < src->height; y++) {
    const uint8_t *row = in + y * src->width * nc;
    double *trow = tmp + y * width * nc;
    for (size_t x = 0; x < width; x++) {
      for (size_t c = 0; c < nc; c++) {
        double acc = 0;
        for (size_t k = 0; k < tx[x].count; k++)
          acc += wx[tx[x].woff + k] * row[(tx[x].first + k) * nc + c];
        trow[x * nc + c] = acc;
      }
    }
  }
  uint8_t *out = dst->data;
  for (size_t y = 0; y < height; y++) {
    for (size_t x = 0; x < width * nc; x++) {
      double acc = 0;
      for (size_t k = 0; k < ty[y].count; k++)
        acc += wy[ty[y].woff + k] * tmp[(ty[y].first + k) * width * nc + x];
      long v = lround(acc);
      out[y * width * nc + x] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
    }
  }
  free(tx);
  free(wx);
  free(ty);
  free(wy);
  free(tmp);
  return HEARTH_OK;
}

/* ---- blit ------------------------------------------------------------------ */

void hearth_image_blit(hearth_image *dst, const hearth_image *src, size_t x, size_t y) {
  if (!dst || !src || !dst->data || !src->data) return;
  if (dst->type != HEARTH_PIX_U8 || src->type != HEARTH_PIX_U8) return;
  int sc = src->channels, dc = dst->channels;
  /* same layout, gray into RGB(A), or RGB into RGBA (alpha left as is) */
  int gray_up = sc == 1 && dc >= 3;
  int rgb_up = sc == 3 && dc == 4;
  if (sc != dc && !gray_up && !rgb_up) return;
  if (x >= dst->width || y >= dst->height) return;
  size_t w = src->width < dst->width - x ? src->width : dst->width - x;
  size_t h = src->height < dst->height - y ? src->height : dst->height - y;
  const uint8_t *in = src->data;
  uint8_t *out = dst->data;
  for (size_t j = 0; j < h; j++) {
    const uint8_t *s = in + j * src->width * (size_t)sc;
    uint8_t *d = out + ((y + j) * dst->width + x) * (size_t)dc;
    if (sc == dc) {
      memcpy(d, s, w * (size_t)sc);
      continue;
    }
    for (size_t i = 0; i < w; i++) {
      if (gray_up) {
        d[i * dc] = d[i * dc + 1] = d[i * dc + 2] = s[i];
      } else {
        memcpy(d + i * dc, s + i * 3, 3);
      }
    }
  }
}

/* ---- drawing ------------------------------------------------------------------ */

/* Set pixel (x, y) if inside; RGB(A) gets the colour (alpha opaque), gray
 * images get its luma so overlays on gray images still show. */
static void put_pixel(hearth_image *img, long x, long y, const uint8_t rgb[3]) {
  if (x < 0 || y < 0 || (size_t)x >= img->width || (size_t)y >= img->height) return;
  size_t nc = (size_t)img->channels;
  uint8_t *p = (uint8_t *)img->data + ((size_t)y * img->width + (size_t)x) * nc;
  if (nc >= 3) {
    p[0] = rgb[0];
    p[1] = rgb[1];
    p[2] = rgb[2];
    if (nc == 4) p[3] = 255;
  } else {
    p[0] = (uint8_t)((299 * rgb[0] + 587 * rgb[1] + 114 * rgb[2] + 500) / 1000);
    if (nc == 2) p[1] = 255;
  }
}

static int drawable(const hearth_image *img) {
  return img && img->data && img->type == HEARTH_PIX_U8 && img->channels >= 1 &&
         img->channels <= 4 && img->width > 0 && img->height > 0;
}

/* Clip the segment to the rectangle [lo, hi]^2 (Liang-Barsky). Returns 0 if
 * nothing remains. */
static int clip_segment(double *x0, double *y0, double *x1, double *y1, double xlo, double ylo,
                        double xhi, double yhi) {
  double dx = *x1 - *x0, dy = *y1 - *y0, t0 = 0, t1 = 1;
  double p[4] = {-dx, dx, -dy, dy};
  double q[4] = {*x0 - xlo, xhi - *x0, *y0 - ylo, yhi - *y0};
  for (int i = 0; i < 4; i++) {
    if (p[i] == 0) {
      if (q[i] < 0) return 0;
      continue;
    }
    double r = q[i] / p[i];
    if (p[i] < 0) {
      if (r > t1) return 0;
      if (r > t0) t0 = r;
    } else {
      if (r < t0) return 0;
      if (r < t1) t1 = r;
    }
  }
  double ax = *x0 + t0 * dx, ay = *y0 + t0 * dy;
  double bx = *x0 + t1 * dx, by = *y0 + t1 * dy;
  *x0 = ax;
  *y0 = ay;
  *x1 = bx;
  *y1 = by;
  return 1;
}

void hearth_draw_line(hearth_image *img, double x0, double y0, double x1, double y1,
                      const uint8_t rgb[3], int thickness) {
  if (!drawable(img) || !rgb) return;
  if (!isfinite(x0) || !isfinite(y0) || !isfinite(x1) || !isfinite(y1)) return;
  if (thickness < 1) thickness = 1;
  double half = 0.5 * thickness;
  /* only the part near the image matters; this also bounds the work */
  double margin = half + 2;
  if (!clip_segment(&x0, &y0, &x1, &y1, -margin, -margin, (double)img->width - 1 + margin,
                    (double)img->height - 1 + margin))
    return;
  if (thickness == 1) {
    /* one pixel per integer step along the major axis (an 8-connected thin
     * line); the minor coordinate is interpolated, so both endpoints land on
     * their own pixels */
    double dx = x1 - x0, dy = y1 - y0;
    int xmajor = fabs(dx) >= fabs(dy);
    double a0 = xmajor ? x0 : y0, a1 = xmajor ? x1 : y1;
    double b0 = xmajor ? y0 : x0, da = xmajor ? dx : dy, db = xmajor ? dy : dx;
    long ia = (long)floor(a0 + 0.5), ib = (long)floor(a1 + 0.5);
    long step = ib >= ia ? 1 : -1;
    for (long i = ia;; i += step) {
      double t = da != 0 ? ((double)i - a0) / da : 0.0;
      t = t < 0 ? 0 : t > 1 ? 1 : t;
      long j = (long)floor(b0 + t * db + 0.5);
      if (xmajor) put_pixel(img, i, j, rgb);
      else put_pixel(img, j, i, rgb);
      if (i == ib) break;
    }
    return;
  }
  /* thick lines: every pixel centre within thickness/2 of the segment
   * (round caps) */
  double bx0 = fmin(x0, x1) - half, bx1 = fmax(x0, x1) + half;
  double by0 = fmin(y0, y1) - half, by1 = fmax(y0, y1) + half;
  long ix0 = (long)fmax(0, floor(bx0)), ix1 = (long)fmin((double)img->width - 1, ceil(bx1));
  long iy0 = (long)fmax(0, floor(by0)), iy1 = (long)fmin((double)img->height - 1, ceil(by1));
  double dx = x1 - x0, dy = y1 - y0, l2 = dx * dx + dy * dy;
  for (long y = iy0; y <= iy1; y++) {
    for (long x = ix0; x <= ix1; x++) {
      double t = l2 > 0 ? ((x - x0) * dx + (y - y0) * dy) / l2 : 0.0;
      t = t < 0 ? 0 : t > 1 ? 1 : t;
      double ex = x - (x0 + t * dx), ey = y - (y0 + t * dy);
      if (ex * ex + ey * ey <= half * half) put_pixel(img, x, y, rgb);
    }
  }
}

void hearth_draw_circle(hearth_image *img, double cx, double cy, double r, const uint8_t rgb[3]) {
  if (!drawable(img) || !rgb || !isfinite(cx) || !isfinite(cy) || !isfinite(r) || r < 0) return;
  /* a one-pixel ring: pixel centres whose distance to the centre is within
   * half a pixel of r; the loop covers only the clipped bounding box */
  double lo = r - 0.5, hi = r + 0.5;
  double lo2 = lo > 0 ? lo * lo : 0, hi2 = hi * hi;
  double fx0 = fmax(0, floor(cx - hi)), fx1 = fmin((double)img->width - 1, ceil(cx + hi));
  double fy0 = fmax(0, floor(cy - hi)), fy1 = fmin((double)img->height - 1, ceil(cy + hi));
  if (fx0 > fx1 || fy0 > fy1) return;
  for (long y = (long)fy0; y <= (long)fy1; y++) {
    double ddy = y - cy;
    for (long x = (long)fx0; x <= (long)fx1; x++) {
      double ddx = x - cx, d2 = ddx * ddx + ddy * ddy;
      if (d2 >= lo2 && d2 <= hi2) put_pixel(img, x, y, rgb);
    }
  }
}

/* ---- text -------------------------------------------------------------------- */

/* A 5x7 font: each glyph is 7 rows of 5 columns, '#' = ink. Lower-case
 * letters are drawn as upper case; unknown characters as '?'. 0xB0 stands for
 * the degree sign (UTF-8 U+00B0). */
typedef struct glyph {
  unsigned char c;
  const char *rows;
} glyph;

static const glyph k_font[] = {
    {' ',
     "....."
     "....."
     "....."
     "....."
     "....."
     "....."
     "....."},
    {'0',
     ".###."
     "#...#"
     "#..##"
     "#.#.#"
     "##..#"
     "#...#"
     ".###."},
    {'1',
     "..#.."
     ".##.."
     "..#.."
     "..#.."
     "..#.."
     "..#.."
     ".###."},
    {'2',
     ".###."
     "#...#"
     "....#"
     "...#."
     "..#.."
     ".#..."
     "#####"},
    {'3',
     "#####"
     "...#."
     "..#.."
     "...#."
     "....#"
     "#...#"
     ".###."},
    {'4',
     "...#."
     "..##."
     ".#.#."
     "#..#."
     "#####"
     "...#."
     "...#."},
    {'5',
     "#####"
     "#...."
     "####."
     "....#"
     "....#"
     "#...#"
     ".###."},
    {'6',
     "..##."
     ".#..."
     "#...."
     "####."
     "#...#"
     "#...#"
     ".###."},
    {'7',
     "#####"
     "....#"
     "...#."
     "..#.."
     ".#..."
     ".#..."
     ".#..."},
    {'8',
     ".###."
     "#...#"
     "#...#"
     ".###."
     "#...#"
     "#...#"
     ".###."},
    {'9',
     ".###."
     "#...#"
     "#...#"
     ".####"
     "....#"
     "...#."
     ".##.."},
    {'A',
     ".###."
     "#...#"
     "#...#"
     "#####"
     "#...#"
     "#...#"
     "#...#"},
    {'B',
     "####."
     "#...#"
     "#...#"
     "####."
     "#...#"
     "#...#"
     "####."},
    {'C',
     ".###."
     "#...#"
     "#...."
     "#...."
     "#...."
     "#...#"
     ".###."},
    {'D',
     "###.."
     "#..#."
     "#...#"
     "#...#"
     "#...#"
     "#..#."
     "###.."},
    {'E',
     "#####"
     "#...."
     "#...."
     "####."
     "#...."
     "#...."
     "#####"},
    {'F',
     "#####"
     "#...."
     "#...."
     "####."
     "#...."
     "#...."
     "#...."},
    {'G',
     ".###."
     "#...#"
     "#...."
     "#.###"
     "#...#"
     "#...#"
     ".####"},
    {'H',
     "#...#"
     "#...#"
     "#...#"
     "#####"
     "#...#"
     "#...#"
     "#...#"},
    {'I',
     ".###."
     "..#.."
     "..#.."
     "..#.."
     "..#.."
     "..#.."
     ".###."},
    {'J',
     "..###"
     "...#."
     "...#."
     "...#."
     "...#."
     "#..#."
     ".##.."},
    {'K',
     "#...#"
     "#..#."
     "#.#.."
     "##..."
     "#.#.."
     "#..#."
     "#...#"},
    {'L',
     "#...."
     "#...."
     "#...."
     "#...."
     "#...."
     "#...."
     "#####"},
    {'M',
     "#...#"
     "##.##"
     "#.#.#"
     "#.#.#"
     "#...#"
     "#...#"
     "#...#"},
    {'N',
     "#...#"
     "#...#"
     "##..#"
     "#.#.#"
     "#..##"
     "#...#"
     "#...#"},
    {'O',
     ".###."
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     ".###."},
    {'P',
     "####."
     "#...#"
     "#...#"
     "####."
     "#...."
     "#...."
     "#...."},
    {'Q',
     ".###."
     "#...#"
     "#...#"
     "#...#"
     "#.#.#"
     "#..#."
     ".##.#"},
    {'R',
     "####."
     "#...#"
     "#...#"
     "####."
     "#.#.."
     "#..#."
     "#...#"},
    {'S',
     ".####"
     "#...."
     "#...."
     ".###."
     "....#"
     "....#"
     "####."},
    {'T',
     "#####"
     "..#.."
     "..#.."
     "..#.."
     "..#.."
     "..#.."
     "..#.."},
    {'U',
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     ".###."},
    {'V',
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     "#...#"
     ".#.#."
     "..#.."},
    {'W',
     "#...#"
     "#...#"
     "#...#"
     "#.#.#"
     "#.#.#"
     "#.#.#"
     ".#.#."},
    {'X',
     "#...#"
     "#...#"
     ".#.#."
     "..#.."
     ".#.#."
     "#...#"
     "#...#"},
    {'Y',
     "#...#"
     "#...#"
     ".#.#."
     "..#.."
     "..#.."
     "..#.."
     "..#.."},
    {'Z',
     "#####"
     "....#"
     "...#."
     "..#.."
     ".#..."
     "#...."
     "#####"},
    {'.',
     "....."
     "....."
     "....."
     "....."
     "....."
     ".##.."
     ".##.."},
    {',',
     "....."
     "....."
     "....."
     "....."
     ".##.."
     "..#.."
     ".#..."},
    {':',
     "....."
     ".##.."
     ".##.."
     "....."
     ".##.."
     ".##.."
     "....."},
    {';',
     "....."
     ".##.."
     ".##.."
     "....."
     ".##.."
     "..#.."
     ".#..."},
    {'-',
     "....."
     "....."
     "....."
     "#####"
     "....."
     "....."
     "....."},
    {'_',
     "....."
     "....."
     "....."
     "....."
     "....."
     "....."
     "#####"},
    {'/',
     "....."
     "....#"
     "...#."
     "..#.."
     ".#..."
     "#...."
     "....."},
    {'%',
     "##..."
     "##..#"
     "...#."
     "..#.."
     ".#..."
     "#..##"
     "...##"},
    {'(',
     "...#."
     "..#.."
     ".#..."
     ".#..."
     ".#..."
     "..#.."
     "...#."},
    {')',
     ".#..."
     "..#.."
     "...#."
     "...#."
     "...#."
     "..#.."
     ".#..."},
    {'=',
     "....."
     "....."
     "#####"
     "....."
     "#####"
     "....."
     "....."},
    {'+',
     "....."
     "..#.."
     "..#.."
     "#####"
     "..#.."
     "..#.."
     "....."},
    {'?',
     ".###."
     "#...#"
     "....#"
     "...#."
     "..#.."
     "....."
     "..#.."},
    {0xB0,
     ".##.."
     "#..#."
     "#..#."
     ".##.."
     "....."
     "....."
     "....."},
};

static const char *glyph_rows(unsigned char c) {
  if (c >= 'a' && c <= 'z') c = (unsigned char)(c - 'a' + 'A');
  for (size_t i = 0; i < sizeof k_font / sizeof k_font[0]; i++)
    if (k_font[i].c == c) return k_font[i].rows;
  return NULL;
}

void hearth_draw_text(hearth_image *img, size_t x, size_t y, const char *text, const uint8_t rgb[3],
                      int scale) {
  if (!drawable(img) || !text || !rgb) return;
  if (scale < 1) scale = 1;
  /* cells are 6x9 font pixels: 5x7 ink plus spacing */
  size_t pen_x = x, pen_y = y, s = (size_t)scale;
  const unsigned char *p = (const unsigned char *)text;
  while (*p) {
    unsigned char c = *p++;
    if (c == '\n') {
      pen_x = x;
      pen_y += 9 * s;
      continue;
    }
    if (c >= 0x80) {
      /* decode just enough UTF-8: U+00B0 is the degree sign, anything else
       * becomes '?' once per code point */
      unsigned char c2 = *p;
      if (c == 0xC2 && c2 == 0xB0) {
        p++;
      } else {
        c = '?';
        while (*p >= 0x80 && *p < 0xC0) p++;
      }
      if (c != '?') c = 0xB0;
    }
    const char *rows = glyph_rows(c);
    if (!rows) rows = glyph_rows('?');
    for (size_t gy = 0; gy < 7; gy++) {
      for (size_t gx = 0; gx < 5; gx++) {
        if (rows[gy * 5 + gx] != '#') continue;
        for (size_t dy = 0; dy < s; dy++) {
          for (size_t dx = 0; dx < s; dx++) {
            size_t px = pen_x + gx * s + dx, py = pen_y + gy * s + dy;
            if (px < img->width && py < img->height) put_pixel(img, (long)px, (long)py, rgb);
          }
        }
      }
    }
    pen_x += 6 * s;
    if (pen_x > img->width) {
      /* the rest of this line is off the image; skip to a newline */
      while (*p && *p != '\n') p++;
    }
  }
}
