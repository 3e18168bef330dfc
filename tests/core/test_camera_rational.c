/* The rational lens model (OpenCV's CALIB_RATIONAL_MODEL): with k4..k6 = 0
 * it is the 5-parameter model bit for bit; its Jacobians match central
 * differences; undistortion inverts projection over a wide-angle image;
 * and a point against OpenCV's published formula evaluated by hand. */
#include <math.h>
#include <string.h>
#include "hearth/camera.h"
#include "test_util.h"

static void wide(hearth_camera *c) {
  static const double d[8] = {2.0, 0.5, 5e-4, -4e-4, 0.0, 2.4, 1.2, 0.05};
  memset(c, 0, sizeof *c);
  c->width = 256;
  c->height = 192;
  c->fx = 154.0;
  c->fy = 154.6;
  c->cx = 128.8;
  c->cy = 94.7;
  memcpy(c->dist, d, sizeof d);
  c->model = HEARTH_LENS_RATIONAL8;
}

static void test_reduces_to_brown5(void) {
  hearth_camera a = {256, 192, 270.0, 271.0, 128.0, 96.0, {-0.3, 0.12, 1e-3, -2e-3, -0.02}};
  hearth_camera b = a;
  b.model = HEARTH_LENS_RATIONAL8;
  int same = 1;
  for (int i = 0; i < 200; i++) {
    double X[3] = {-0.4 + 0.004 * i, 0.3 - 0.003 * i, 1.0}, ua[2], ub[2];
    hearth_project_jac ja, jb;
    hearth_camera_project(&a, X, ua, &ja);
    hearth_camera_project(&b, X, ub, &jb);
    same &= ua[0] == ub[0] && ua[1] == ub[1] && !memcmp(ja.d_dist, jb.d_dist, sizeof ja.d_dist) &&
            !memcmp(ja.d_point, jb.d_point, sizeof ja.d_point);
  }
  CHECK(same);
  CHECK(hearth_lens_n_coeffs(HEARTH_LENS_BROWN5) == 5 &&
        hearth_lens_n_coeffs(HEARTH_LENS_RATIONAL8) == 8);
  CHECK(hearth_lens_from_name("rational8") == HEARTH_LENS_RATIONAL8 &&
        hearth_lens_from_name("fisheye") == -1);
}

/* OpenCV's documented model, term by term, at one point */
static void test_formula(void) {
  hearth_camera c;
  wide(&c);
  double X[3] = {0.45, -0.3, 0.5}, uv[2];
  CHECK(hearth_camera_project(&c, X, uv, NULL));
  double x = 0.9, y = -0.6, r2 = 1.17, r4 = r2 * r2, r6 = r4 * r2;
  double radial = (1 + 2.0 * r2 + 0.5 * r4 + 0.0 * r6) / (1 + 2.4 * r2 + 1.2 * r4 + 0.05 * r6);
  double xd = x * radial + 2 * 5e-4 * x * y + -4e-4 * (r2 + 2 * x * x);
  double yd = y * radial + 5e-4 * (r2 + 2 * y * y) + 2 * -4e-4 * x * y;
  CHECK_NEAR(uv[0], 154.0 * xd + 128.8, 1e-12);
  CHECK_NEAR(uv[1], 154.6 * yd + 94.7, 1e-12);
}

static void test_jacobians(void) {
  hearth_camera c;
  wide(&c);
  double X[3] = {0.31, -0.22, 0.4};
  double uv[2];
  hearth_project_jac J;
  CHECK(hearth_camera_project(&c, X, uv, &J));
  double worst = 0;
  for (int k = 0; k < 8; k++) {
    const double h = 1e-7;
    hearth_camera p = c, m = c;
    p.dist[k] += h;
    m.dist[k] -= h;
    double up[2], um[2];
    hearth_camera_project(&p, X, up, NULL);
    hearth_camera_project(&m, X, um, NULL);
    for (int r = 0; r < 2; r++) {
      double num = (up[r] - um[r]) / (2 * h);
      double an = k < 5 ? J.d_dist[5 * r + k] : J.d_rat[3 * r + k - 5];
      worst = fmax(worst, fabs(num - an) / fmax(1.0, fabs(num)));
    }
  }
  for (int k = 0; k < 3; k++) {
    const double h = 1e-7;
    double Xp[3] = {X[0], X[1], X[2]}, Xm[3] = {X[0], X[1], X[2]}, up[2], um[2];
    Xp[k] += h;
    Xm[k] -= h;
    hearth_camera_project(&c, Xp, up, NULL);
    hearth_camera_project(&c, Xm, um, NULL);
    for (int r = 0; r < 2; r++) {
      double num = (up[r] - um[r]) / (2 * h);
      worst = fmax(worst, fabs(num - J.d_point[3 * r + k]) / fmax(1.0, fabs(num)));
    }
  }
  CHECK_MSG(worst < 1e-6, "worst relative Jacobian error %.3g", worst);
}

static void test_undistort_round_trip(void) {
  hearth_camera c;
  wide(&c);
  double worst = 0;
  int failed = 0;
  for (int v = 0; v < c.height; v += 7)
    for (int u = 0; u < c.width; u += 7) {
      double xy[2], uv[2];
      double res = hearth_camera_undistort(&c, u, v, xy);
      if (res < 0) {
        failed++;
        continue;
      }
      double X[3] = {xy[0], xy[1], 1.0};
      hearth_camera_project(&c, X, uv, NULL);
      worst = fmax(worst, hypot(uv[0] - u, uv[1] - v));
    }
  CHECK_MSG(failed == 0, "%d pixels not undistorted", failed);
  CHECK_MSG(worst < 1e-9, "worst round trip %.3g px", worst);
  /* the corners are far out: about 60 degrees off axis */
  double dir[3];
  CHECK(hearth_camera_ray(&c, 0, 0, dir) >= 0);
  CHECK(acos(dir[2]) * 180 / M_PI > 55);
}

int main(void) {
  test_reduces_to_brown5();
  test_formula();
  test_jacobians();
  test_undistort_round_trip();
  return g_test_failures ? 1 : 0;
}
