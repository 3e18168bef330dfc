/* Pixels at a crease against a closed form: a cool floor (z = 0, x in
 * [0, 50] mm) meets a hot wall (x = 0, z in [0, 50] mm) along the y axis,
 * both seen at 45 degrees by one camera whose lens blurs each pixel with
 * its 8 neighbours (a 3 x 3 box). A pixel beside the crease mixes the
 * wall's temperature into the floor's: with crease_deg 0 the floor's
 * texels there read up to several degC hot; with crease_deg 60 those
 * pixels are dropped as silhouette pixels are, and every observed floor
 * texel reads the floor, while the floor stays observed away from it. */
#include "hearth/hearth.h"
#include "test_util.h"

#define RES 256
#define T_FLOOR 30.0
#define T_WALL 80.0
#define T_ROOM 22.0
#define SIDE 0.05

/* the floor's quad (u in [0.05, 0.45]) and the wall's (u in [0.55, 0.95]),
   v along y; both facing the camera (+z, +x) */
static void crease_mesh(hearth_mesh *m, hearth_err *err) {
  CHECK_OK(hearth_mesh_alloc(m, 8, 4, 1, err), err);
  const float h = 0.03f, s = (float)SIDE;
  const float P[8][3] = {{0, -h, 0}, {s, -h, 0}, {s, h, 0}, {0, h, 0},
                         {0, -h, 0}, {0, h, 0},  {0, h, s}, {0, -h, s}};
  const float UV[8][2] = {{0.45f, 0.05f}, {0.05f, 0.05f}, {0.05f, 0.95f}, {0.45f, 0.95f},
                          {0.55f, 0.05f}, {0.55f, 0.95f}, {0.95f, 0.95f}, {0.95f, 0.05f}};
  const uint32_t I[12] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  memcpy(m->positions, P, sizeof P);
  memcpy(m->uvs, UV, sizeof UV);
  memcpy(m->indices, I, sizeof I);
}

/* the scene along the ray o + t d: the nearer of floor and wall, else the
   room */
static double scene(const double o[3], const double d[3]) {
  double best = INFINITY, val = T_ROOM;
  if (d[2] < 0) {
    double t = -o[2] / d[2], x = o[0] + t * d[0], y = o[1] + t * d[1];
    if (x >= 0 && x <= SIDE && fabs(y) <= 0.03 && t < best) best = t, val = T_FLOOR;
  }
  if (d[0] < 0) {
    double t = -o[0] / d[0], z = o[2] + t * d[2], y = o[1] + t * d[1];
    if (z >= 0 && z <= SIDE && fabs(y) <= 0.03 && t < best) best = t, val = T_WALL;
  }
  return val;
}

/* max |observed - T_FLOOR| over the observed floor texels (u < 0.5) and
   their count, those more than 3 mm from the crease in *n_far */
static double floor_error(const hearth_map_result *r, size_t *n, size_t *n_far) {
  double mx = 0;
  *n = *n_far = 0;
  for (size_t q = 0; q < (size_t)RES * RES; q++) {
    double u = ((double)(q % RES) + 0.5) / RES;
    if (u >= 0.5 || r->mask[q] != HEARTH_TEXEL_OBSERVED) continue;
    double x = (0.45 - u) / 0.4 * SIDE, e = fabs(r->observed[q] - T_FLOOR);
    (*n)++;
    if (x > 0.003) (*n_far)++;
    if (e > mx) mx = e;
  }
  return mx;
}

int main(void) {
  hearth_err err = {0};
  hearth_mesh m = {0};
  crease_mesh(&m, &err);
  hearth_camera cam = {320, 240, 900.0, 900.0, 159.5, 119.5, {0, 0, 0, 0, 0}};
  /* at (0.15, 0, 0.15) looking at (0.012, 0, 0.012): camera z along
     (-1, 0, -1) / sqrt 2, x along world -y, y = z cross x */
  hearth_rigid T = {{0, -0.7071067811865476, -0.7071067811865476, -1, 0, 0, 0, 0.7071067811865476,
                     -0.7071067811865476},
                    {0.15, 0, 0.15}};
  hearth_image sharp, img;
  CHECK_OK(hearth_image_alloc(&sharp, 320, 240, 1, HEARTH_PIX_F32, &err), &err);
  CHECK_OK(hearth_image_alloc(&img, 320, 240, 1, HEARTH_PIX_F32, &err), &err);
  float *ps = sharp.data, *pb = img.data;
  for (int v = 0; v < 240; v++)
    for (int u = 0; u < 320; u++) {
      double d[3], w[3];
      hearth_camera_ray(&cam, u, v, d);
      hearth_rigid_rotate(&T, d, w);
      ps[v * 320 + u] = (float)scene(T.t, w);
    }
  for (int v = 0; v < 240; v++)
    for (int u = 0; u < 320; u++) {
      double s = 0;
      int k = 0;
      for (int dv = -1; dv <= 1; dv++)
        for (int du = -1; du <= 1; du++) {
          int x = u + du, y = v + dv;
          if (x < 0 || y < 0 || x >= 320 || y >= 240) continue;
          s += ps[y * 320 + x];
          k++;
        }
      pb[v * 320 + u] = (float)(s / k);
    }
  hearth_map_view view = {&img, T, 0.0, 0};
  hearth_map_opts o;
  hearth_map_opts_default(&o);
  o.resolution = RES;
  o.threads = 1;
  o.fusion = HEARTH_FUSE_ROBUST;
  hearth_map_result r0, r60;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, &view, 1, &o, &r0, &err), &err);
  o.crease_deg = 60.0;
  CHECK_OK(hearth_map_views(&m, NULL, &cam, &view, 1, &o, &r60, &err), &err);
  size_t n0, f0, n60, f60;
  double e0 = floor_error(&r0, &n0, &f0), e60 = floor_error(&r60, &n60, &f60);
  printf(
      "crease: floor max |error| %.2f degC over %zu texels without the crease rule, %.3f over "
      "%zu with it (%zu and %zu more than 3 mm from the crease)\n",
      e0, n0, e60, n60, f0, f60);
  /* without the rule the wall's heat reaches the floor's texels */
  CHECK_MSG(e0 > 5.0 && n0 > 1000, "without the rule: %.2f degC over %zu texels", e0, n0);
  CHECK_MSG(e60 < 0.01 && n60 > 1000, "with it: %.3f degC over %zu texels", e60, n60);
  /* only the crease's neighbourhood is lost */
  CHECK_MSG(f60 == f0, "%zu of %zu floor texels away from the crease", f60, f0);
  hearth_map_result_free(&r0);
  hearth_map_result_free(&r60);
  hearth_image_free(&sharp);
  hearth_image_free(&img);
  hearth_mesh_free(&m);
  return g_test_failures;
}
