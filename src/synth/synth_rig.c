/* The virtual rig's cameras: its own Brown-Conrady lens (forward model and
 * inversion, written independently of the pipeline's camera code) and the
 * rig parameters drawn from a seed in the ranges of the paper's hardware
 * (Orbbec Femto Bolt colour + depth, HIKMICRO Mini2 thermal). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "synth/synth_rig.h"

#define DEG (3.14159265358979323846 / 180.0)

void synth_lens_distort(const double d[5], double x, double y, double *xd, double *yd) {
  double r2 = x * x + y * y;
  double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  *xd = x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x);
  *yd = y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y;
}

/* OpenCV's rational model (k1 k2 p1 p2 k3 k4 k5 k6): the radial factor is
 * a ratio of two cubics in r^2 */
static void rational_distort(const double d[8], double x, double y, double *xd, double *yd) {
  double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  double radial =
      (1.0 + d[0] * r2 + d[1] * r4 + d[4] * r6) / (1.0 + d[5] * r2 + d[6] * r4 + d[7] * r6);
  *xd = x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x);
  *yd = y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y;
}

void synth_lens_distort_cam(const hearth_camera *c, double x, double y, double *xd, double *yd) {
  if (c->model == HEARTH_LENS_RATIONAL8) rational_distort(c->dist, x, y, xd, yd);
  else synth_lens_distort(c->dist, x, y, xd, yd);
}

int synth_lens_project(const hearth_camera *c, const double X[3], double uv[2]) {
  if (!(X[2] > 0.0)) return 0;
  double xd, yd;
  synth_lens_distort_cam(c, X[0] / X[2], X[1] / X[2], &xd, &yd);
  uv[0] = c->fx * xd + c->cx;
  uv[1] = c->fy * yd + c->cy;
  return 1;
}

/* distortion and its 2x2 Jacobian, for the Newton inversion; the rational
 * model's by central differences (kept apart from the pipeline's
 * analytic Jacobian) */
static void lens_jac5(const double d[5], double x, double y, double f[2], double J[4]);
static void lens_jac(const hearth_camera *c, double x, double y, double f[2], double J[4]) {
  if (c->model != HEARTH_LENS_RATIONAL8) {
    lens_jac5(c->dist, x, y, f, J);
    return;
  }
  const double h = 1e-7;
  double a[2], b[2];
  rational_distort(c->dist, x, y, &f[0], &f[1]);
  rational_distort(c->dist, x + h, y, &a[0], &a[1]);
  rational_distort(c->dist, x - h, y, &b[0], &b[1]);
  J[0] = (a[0] - b[0]) / (2 * h);
  J[2] = (a[1] - b[1]) / (2 * h);
  rational_distort(c->dist, x, y + h, &a[0], &a[1]);
  rational_distort(c->dist, x, y - h, &b[0], &b[1]);
  J[1] = (a[0] - b[0]) / (2 * h);
  J[3] = (a[1] - b[1]) / (2 * h);
}

static void lens_jac5(const double d[5], double x, double y, double f[2], double J[4]) {
  double r2 = x * x + y * y;
  double radial = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  double drad = d[0] + r2 * (2.0 * d[1] + 3.0 * d[4] * r2); /* d radial / d r2 */
  f[0] = x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x);
  f[1] = y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y;
  J[0] = radial + 2.0 * x * x * drad + 2.0 * d[2] * y + 6.0 * d[3] * x;
  J[1] = 2.0 * x * y * drad + 2.0 * d[2] * x + 2.0 * d[3] * y;
  J[2] = 2.0 * x * y * drad + 2.0 * d[2] * x + 2.0 * d[3] * y;
  J[3] = radial + 2.0 * y * y * drad + 6.0 * d[2] * y + 2.0 * d[3] * x;
}

double synth_lens_unproject(const hearth_camera *c, double u, double v, double xy[2]) {
  double tx = (u - c->cx) / c->fx, ty = (v - c->cy) / c->fy;
  /* start from the distorted point, then damped-free Newton; lenses in the
   * rig's ranges are monotonic over the image so this converges quickly */
  double x = tx, y = ty, f[2], J[4];
  for (int it = 0; it < 40; it++) {
    lens_jac(c, x, y, f, J);
    double ex = tx - f[0], ey = ty - f[1];
    double det = J[0] * J[3] - J[1] * J[2];
    if (fabs(det) < 1e-12) break;
    double dx = (J[3] * ex - J[1] * ey) / det, dy = (J[0] * ey - J[2] * ex) / det;
    x += dx;
    y += dy;
    if (fabs(dx) + fabs(dy) < 1e-15) break;
  }
  lens_jac(c, x, y, f, J);
  xy[0] = x;
  xy[1] = y;
  return hypot((f[0] - tx) * c->fx, (f[1] - ty) * c->fy);
}

void synth_lens_ray(const hearth_camera *c, double u, double v, double dir[3]) {
  double xy[2];
  synth_lens_unproject(c, u, v, xy);
  double n = sqrt(xy[0] * xy[0] + xy[1] * xy[1] + 1.0);
  dir[0] = xy[0] / n;
  dir[1] = xy[1] / n;
  dir[2] = 1.0 / n;
}

typedef struct table_ctx {
  const hearth_camera *c;
  int ss;
  synth_pixel_warp warp; /* NULL: the model's own pixels */
  const void *warp_ctx;
  float *out;
} table_ctx;

static void table_rows(void *vctx, size_t b, size_t e, int ti) {
  table_ctx *t = vctx;
  size_t W = (size_t)t->c->width, ss = (size_t)t->ss;
  for (size_t y = b; y < e; y++)
    for (size_t x = 0; x < W; x++)
      for (size_t j = 0; j < ss; j++)
        for (size_t i = 0; i < ss; i++) {
          double q[2] = {(double)x + ((double)i + 0.5) / (double)ss - 0.5,
                         (double)y + ((double)j + 0.5) / (double)ss - 0.5},
                 d[3];
          if (t->warp) t->warp(t->warp_ctx, q[0], q[1], q);
          synth_lens_ray(t->c, q[0], q[1], d);
          float *o = t->out + (((y * W + x) * ss + j) * ss + i) * 3;
          o[0] = (float)d[0];
          o[1] = (float)d[1];
          o[2] = (float)d[2];
        }
}

float *synth_ray_table_warped(const hearth_camera *c, int ss, int threads, synth_pixel_warp warp,
                              const void *warp_ctx) {
  size_t n = (size_t)c->width * (size_t)c->height * (size_t)ss * (size_t)ss;
  float *out = hearth_alloc_array(n, 3 * sizeof(float));
  if (!out) return NULL;
  table_ctx t = {c, ss, warp, warp_ctx, out};
  hearth_parallel_for((size_t)c->height, threads, table_rows, &t);
  return out;
}

float *synth_ray_table(const hearth_camera *c, int ss, int threads) {
  return synth_ray_table_warped(c, ss, threads, NULL, NULL);
}

/* R = rotation about axis (unit) by angle */
static void axis_angle(double ax, double ay, double az, double ang, double R[9]) {
  double w[3] = {ax * ang, ay * ang, az * ang};
  hearth_rotvec_to_matrix(w, R);
}

void synth_rig_draw(uint64_t seed, hearth_rig *rig) {
  synth_rig_draw_thermal(seed, 256, 192, 0, rig);
}

void synth_rig_draw_thermal(uint64_t seed, int thermal_w, int thermal_h, int wide,
                            hearth_rig *rig) {
  hearth_rng base, r;
  hearth_rng_seed(&base, seed);
  hearth_rng_fork(&base, synth_hash("rig"), &r);
  memset(rig, 0, sizeof *rig);

  /* colour: 1920x1080, fx ~ 1100-1160, small distortion */
  hearth_camera *c = &rig->rgb;
  c->width = 1920;
  c->height = 1080;
  c->fx = hearth_rng_range(&r, 1100.0, 1160.0);
  c->fy = c->fx * (1.0 + hearth_rng_range(&r, -0.002, 0.002));
  c->cx = 959.5 + hearth_rng_range(&r, -8.0, 8.0);
  c->cy = 539.5 + hearth_rng_range(&r, -6.0, 6.0);
  c->dist[0] = hearth_rng_range(&r, 0.05, 0.09);
  c->dist[1] = hearth_rng_range(&r, -0.12, -0.06);
  c->dist[2] = hearth_rng_range(&r, -3e-4, 3e-4);
  c->dist[3] = hearth_rng_range(&r, -3e-4, 3e-4);
  c->dist[4] = hearth_rng_range(&r, 0.02, 0.05);

  /* depth: 640x576 narrow field of view, fx ~ 500 */
  c = &rig->depth;
  c->width = 640;
  c->height = 576;
  c->fx = hearth_rng_range(&r, 495.0, 510.0);
  c->fy = c->fx * (1.0 + hearth_rng_range(&r, -0.002, 0.002));
  c->cx = 319.5 + hearth_rng_range(&r, -4.0, 4.0);
  c->cy = 335.0 + hearth_rng_range(&r, -4.0, 4.0);
  c->dist[0] = hearth_rng_range(&r, 0.02, 0.06);
  c->dist[1] = hearth_rng_range(&r, -0.05, -0.01);
  c->dist[2] = hearth_rng_range(&r, -2e-4, 2e-4);
  c->dist[3] = hearth_rng_range(&r, -2e-4, 2e-4);
  c->dist[4] = hearth_rng_range(&r, 0.0, 0.01);

  /* thermal: 256x192 by default, ~50 degrees across through a barrel lens
   * with real tangential terms; fx chosen so the image edge sees the drawn
   * half angle. Other sizes scale the principal point jitter with the
   * width. The wide-angle lens: ~90 degrees across with strong barrel
   * distortion (still monotonic out to the corners). */
  c = &rig->thermal;
  c->width = thermal_w;
  c->height = thermal_h;
  const double sw = thermal_w / 256.0;
  if (wide) {
    c->dist[0] = hearth_rng_range(&r, -0.40, -0.32);
    c->dist[1] = hearth_rng_range(&r, 0.10, 0.16);
  } else {
    c->dist[0] = hearth_rng_range(&r, -0.35, -0.15);
    c->dist[1] = hearth_rng_range(&r, 0.05, 0.2);
  }
  c->dist[2] = hearth_rng_range(&r, -0.002, 0.002);
  c->dist[3] = hearth_rng_range(&r, -0.002, 0.002);
  c->dist[4] = wide ? hearth_rng_range(&r, -0.005, 0.0) : hearth_rng_range(&r, -0.02, 0.02);
  double fov = wide ? hearth_rng_range(&r, 86.0, 92.0) : hearth_rng_range(&r, 48.5, 51.5);
  double half = 0.5 * fov * DEG, xe = tan(half), x2 = xe * xe;
  double xd_edge = xe * (1.0 + x2 * (c->dist[0] + x2 * (c->dist[1] + x2 * c->dist[4])));
  c->fx = 0.5 * thermal_w / xd_edge;
  c->fy = c->fx * (1.0 + hearth_rng_range(&r, -0.004, 0.004));
  c->cx = 0.5 * (thermal_w - 1) + hearth_rng_range(&r, -2.5 * sw, 2.5 * sw);
  c->cy = 0.5 * (thermal_h - 1) + hearth_rng_range(&r, -2.5 * sw, 2.5 * sw);

  /* thermal from colour: thermal sits ~5 cm above the colour camera with a
   * degree-level misalignment: x_th = R (x_rgb - b) */
  double w[3];
  for (int i = 0; i < 3; i++) w[i] = hearth_rng_range(&r, -1.5, 1.5) * DEG;
  hearth_rotvec_to_matrix(w, rig->T_thermal_from_rgb.R);
  double b[3] = {hearth_rng_range(&r, -0.012, 0.012), hearth_rng_range(&r, -0.060, -0.040),
                 hearth_rng_range(&r, -0.006, 0.006)};
  double Rb[3];
  for (int i = 0; i < 3; i++) {
    Rb[i] = 0;
    for (int k = 0; k < 3; k++) Rb[i] += rig->T_thermal_from_rgb.R[i * 3 + k] * b[k];
    rig->T_thermal_from_rgb.t[i] = -Rb[i];
  }

  /* depth from colour: factory extrinsic, ~32 mm baseline, depth camera
   * tilted ~6 degrees about x as in the Azure-Kinect-style module */
  double Rx[9], Rs[9];
  axis_angle(1, 0, 0, hearth_rng_range(&r, 5.7, 6.3) * DEG, Rx);
  for (int i = 0; i < 3; i++) w[i] = hearth_rng_range(&r, -0.15, 0.15) * DEG;
  hearth_rotvec_to_matrix(w, Rs);
  hearth_mat3_mul(Rs, Rx, rig->T_depth_from_rgb.R);
  rig->T_depth_from_rgb.t[0] = -0.0320 + hearth_rng_range(&r, -0.0005, 0.0005);
  rig->T_depth_from_rgb.t[1] = -0.0021 + hearth_rng_range(&r, -0.0005, 0.0005);
  rig->T_depth_from_rgb.t[2] = 0.0039 + hearth_rng_range(&r, -0.0005, 0.0005);
  rig->thermal_rms_px = 0.0;
  rig->stereo_rms_px = 0.0;
}

void synth_look_at(const double eye[3], const double target[3], hearth_rigid *T) {
  double z[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
  double n = hearth_norm3(z);
  for (int i = 0; i < 3; i++) z[i] /= n;
  const double up[3] = {0, 0, 1};
  double x[3], y[3];
  hearth_cross3(z, up, x);
  n = hearth_norm3(x);
  if (n < 1e-9) { /* looking straight down or up */
    x[0] = 1;
    x[1] = 0;
    x[2] = 0;
  } else {
    for (int i = 0; i < 3; i++) x[i] /= n;
  }
  hearth_cross3(z, x, y);
  /* columns of R_world_from_cam are the camera axes in the world */
  for (int i = 0; i < 3; i++) {
    T->R[i * 3 + 0] = x[i];
    T->R[i * 3 + 1] = y[i];
    T->R[i * 3 + 2] = z[i];
    T->t[i] = eye[i];
  }
}

uint64_t synth_hash(const char *s) {
  uint64_t h = 1469598103934665603ULL;
  for (; *s; s++) {
    h ^= (uint8_t)*s;
    h *= 1099511628211ULL;
  }
  return h;
}
