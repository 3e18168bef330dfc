/* A small COLMAP sparse model known in closed form, and the test's own
 * writers of it in COLMAP's text and binary layouts (written from the
 * format description, independently of the library's readers). The text
 * files carry comments, blank lines, CRLF endings and tabs. */
#ifndef HEARTH_TEST_COLMAP_FIXTURE_H
#define HEARTH_TEST_COLMAP_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

typedef struct fx_camera {
  uint32_t id;
  int model; /* COLMAP model id */
  const char *model_name;
  uint64_t width, height;
  int n_params;
  double params[12];
} fx_camera;

typedef struct fx_image {
  uint32_t id;
  double axis[3], angle; /* R_cam_from_world as axis * angle */
  double t[3];           /* t_cam_from_world */
  uint32_t camera;
  const char *name;
  int n_points; /* 2-D points; odd ones observe 3-D point (id 1000 + j) */
} fx_image;

typedef struct fx_point {
  uint64_t id;
  double xyz[3];
  uint8_t rgb[3];
  double error;
  int track_length;
  uint32_t image[3], point2d[3];
} fx_point;

/* sparse ids everywhere; image "neutral/v02.jpg" is not registered */
static const fx_camera k_fx_cameras[] = {
    {3, 1, "PINHOLE", 1920, 1080, 4, {1500.25, 1490.5, 960.5, 540.5}},
    {7, 2, "SIMPLE_RADIAL", 640, 480, 4, {1200.0, 320.5, 240.25, -0.0123}},
    {12, 4, "OPENCV", 1920, 1080, 8, {1510.0, 1509.0, 955.75, 541.125, 0.1, -0.05, 0.001, -0.002}},
};
static const fx_image k_fx_images[] = {
    {2, {0.3, -0.5, 0.8}, 0.7, {0.11, -0.22, 1.5}, 3, "neutral/v00.jpg", 4},
    {5, {1, 0.2, 0.1}, 2.9, {-0.4, 0.05, 2.25}, 3, "neutral/v01.jpg", 0},
    {9, {0, 0, 1}, -1.2, {0.0, 0.3, 0.9}, 12, "hot/v00.jpg", 3},
    {40, {-0.2, 1, 0.4}, 0.001, {1e-3, 2.5e-4, 3.0}, 7, "v07.png", 2},
};
static const fx_point k_fx_points[] = {
    {1001, {0.1, 0.2, 0.3}, {255, 0, 7}, 0.5, 2, {2, 9}, {1, 1}},
    {77, {-1.5, 2.25, 1e-5}, {1, 2, 3}, 1.25, 1, {40}, {1}},
    {1003, {3, 2, 1}, {9, 9, 9}, 0.0, 3, {2, 40, 9}, {3, 0, 2}},
};
#define FX_N_CAMERAS (sizeof k_fx_cameras / sizeof k_fx_cameras[0])
#define FX_N_IMAGES (sizeof k_fx_images / sizeof k_fx_images[0])
#define FX_N_POINTS (sizeof k_fx_points / sizeof k_fx_points[0])

/* q = (cos(a/2), sin(a/2) * axis / |axis|) */
static inline void fx_quat(const fx_image *im, double q[4]) {
  double n =
      sqrt(im->axis[0] * im->axis[0] + im->axis[1] * im->axis[1] + im->axis[2] * im->axis[2]);
  q[0] = cos(im->angle / 2);
  for (int k = 0; k < 3; k++) q[k + 1] = sin(im->angle / 2) * im->axis[k] / n;
}

static inline double fx_px(int j) { return 10.0 + 3.25 * j; }
static inline double fx_py(int j) { return 20.0 + 1.5 * j; }

/* ---- text ---------------------------------------------------------------------- */
/* tabs: one line of points3D.txt separates with a tab, which hearth reads
 * and COLMAP 3.8's reader (single spaces only) does not */
static inline int fx_write_text_as(const char *dir, int tabs) {
  char p[1024];
  snprintf(p, sizeof p, "%s/cameras.txt", dir);
  FILE *f = fopen(p, "wb");
  if (!f) return -1;
  fprintf(f,
          "# Camera list with one line of data per camera:\n"
          "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n# Number of cameras: 3\n\n");
  for (size_t i = 0; i < FX_N_CAMERAS; i++) {
    const fx_camera *c = &k_fx_cameras[i];
    fprintf(f, "%u %s %llu %llu", (unsigned)c->id, c->model_name, (unsigned long long)c->width,
            (unsigned long long)c->height);
    for (int k = 0; k < c->n_params; k++) fprintf(f, " %.17g", c->params[k]);
    fprintf(f, i == 1 ? "   \n\n   # an indented comment\n" : "\n");
  }
  fclose(f);
  snprintf(p, sizeof p, "%s/images.txt", dir);
  if (!(f = fopen(p, "wb"))) return -1;
  fprintf(f,
          "# Image list with two lines of data per image:\r\n"
          "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\r\n"
          "#   POINTS2D[] as (X, Y, POINT3D_ID)\r\n\r\n");
  for (size_t i = 0; i < FX_N_IMAGES; i++) {
    const fx_image *im = &k_fx_images[i];
    double q[4];
    fx_quat(im, q);
    fprintf(f, "%u %.17g %.17g %.17g %.17g %.17g %.17g %.17g %u %s\r\n", (unsigned)im->id, q[0],
            q[1], q[2], q[3], im->t[0], im->t[1], im->t[2], (unsigned)im->camera, im->name);
    for (int j = 0; j < im->n_points; j++)
      fprintf(f, "%s%.17g %.17g %lld", j ? " " : "", fx_px(j), fx_py(j), j % 2 ? 1000LL + j : -1LL);
    fprintf(f, "\r\n");
    if (i == 1) fprintf(f, "\r\n# between images\r\n\r\n");
  }
  fclose(f);
  snprintf(p, sizeof p, "%s/points3D.txt", dir);
  if (!(f = fopen(p, "wb"))) return -1;
  fprintf(f,
          "# 3D point list with one line of data per point:\n"
          "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n");
  for (size_t i = 0; i < FX_N_POINTS; i++) {
    const fx_point *pt = &k_fx_points[i];
    fprintf(f, "%llu%c%.17g %.17g %.17g %u %u %u %.17g", (unsigned long long)pt->id,
            tabs ? '\t' : ' ', pt->xyz[0], pt->xyz[1], pt->xyz[2], pt->rgb[0], pt->rgb[1],
            pt->rgb[2], pt->error);
    for (int k = 0; k < pt->track_length; k++)
      fprintf(f, " %u %u", (unsigned)pt->image[k], (unsigned)pt->point2d[k]);
    fprintf(f, "\n\n");
  }
  fclose(f);
  return 0;
}

static inline int fx_write_text(const char *dir) { return fx_write_text_as(dir, 1); }

/* ---- binary ---------------------------------------------------------------------- */
typedef struct fx_buf {
  uint8_t data[8192];
  size_t n;
} fx_buf;

static inline void fx_put(fx_buf *b, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; i++) b->data[b->n++] = (uint8_t)(v >> (8 * i));
}
static inline void fx_putd(fx_buf *b, double d) {
  uint64_t u;
  memcpy(&u, &d, sizeof u);
  fx_put(b, u, 8);
}

static inline void fx_cameras_bin(fx_buf *b) {
  b->n = 0;
  fx_put(b, FX_N_CAMERAS, 8);
  for (size_t i = 0; i < FX_N_CAMERAS; i++) {
    const fx_camera *c = &k_fx_cameras[i];
    fx_put(b, c->id, 4);
    fx_put(b, (uint32_t)c->model, 4);
    fx_put(b, c->width, 8);
    fx_put(b, c->height, 8);
    for (int k = 0; k < c->n_params; k++) fx_putd(b, c->params[k]);
  }
}

static inline void fx_images_bin(fx_buf *b) {
  b->n = 0;
  fx_put(b, FX_N_IMAGES, 8);
  for (size_t i = 0; i < FX_N_IMAGES; i++) {
    const fx_image *im = &k_fx_images[i];
    double q[4];
    fx_quat(im, q);
    fx_put(b, im->id, 4);
    for (int k = 0; k < 4; k++) fx_putd(b, q[k]);
    for (int k = 0; k < 3; k++) fx_putd(b, im->t[k]);
    fx_put(b, im->camera, 4);
    size_t n = strlen(im->name) + 1;
    memcpy(b->data + b->n, im->name, n);
    b->n += n;
    fx_put(b, (uint64_t)im->n_points, 8);
    for (int j = 0; j < im->n_points; j++) {
      fx_putd(b, fx_px(j));
      fx_putd(b, fx_py(j));
      fx_put(b, j % 2 ? (uint64_t)(1000 + j) : UINT64_MAX, 8);
    }
  }
}

static inline void fx_points_bin(fx_buf *b) {
  b->n = 0;
  fx_put(b, FX_N_POINTS, 8);
  for (size_t i = 0; i < FX_N_POINTS; i++) {
    const fx_point *pt = &k_fx_points[i];
    fx_put(b, pt->id, 8);
    for (int k = 0; k < 3; k++) fx_putd(b, pt->xyz[k]);
    for (int k = 0; k < 3; k++) fx_put(b, pt->rgb[k], 1);
    fx_putd(b, pt->error);
    fx_put(b, (uint64_t)pt->track_length, 8);
    for (int k = 0; k < pt->track_length; k++) {
      fx_put(b, pt->image[k], 4);
      fx_put(b, pt->point2d[k], 4);
    }
  }
}

static inline int fx_write_file(const char *dir, const char *name, const fx_buf *b, size_t n) {
  char p[1024];
  snprintf(p, sizeof p, "%s/%s", dir, name);
  FILE *f = fopen(p, "wb");
  if (!f) return -1;
  size_t w = fwrite(b->data, 1, n, f);
  fclose(f);
  return w == n ? 0 : -1;
}

static inline int fx_write_binary(const char *dir) {
  fx_buf b;
  fx_cameras_bin(&b);
  if (fx_write_file(dir, "cameras.bin", &b, b.n)) return -1;
  fx_images_bin(&b);
  if (fx_write_file(dir, "images.bin", &b, b.n)) return -1;
  fx_points_bin(&b);
  return fx_write_file(dir, "points3D.bin", &b, b.n);
}

#endif
