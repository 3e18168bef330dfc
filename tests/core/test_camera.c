/* Camera projection, Jacobians and undistortion over whole images. */
#include <math.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "test_util.h"

typedef struct lens {
  const char *name;
  hearth_camera cam;
} lens;

static const lens LENSES[] = {
    /* a strongly distorted thermal lens */
    {"thermal", {256, 192, 275.0, 276.0, 127.8, 96.3, {-0.35, 0.15, 0.002, 0.002, -0.02}}},
    /* barrel k1 with pincushion k2/k3 and tangential terms */
    {"mixed", {640, 576, 504.0, 505.0, 321.5, 290.0, {-0.28, 0.32, -0.0015, 0.001, -0.09}}},
    /* mild RGB lens */
    {"rgb", {1920, 1080, 1380.0, 1378.0, 958.2, 541.7, {0.09, -0.21, 0.0005, -0.0003, 0.11}}},
    /* pincushion */
    {"pincushion", {800, 600, 600.0, 600.0, 400.0, 300.0, {0.12, 0.05, 0.0, 0.0, 0.01}}},
    /* no distortion */
    {"pinhole", {320, 240, 300.0, 310.0, 159.5, 119.5, {0, 0, 0, 0, 0}}},
};
#define NLENS (sizeof LENSES / sizeof LENSES[0])

/* reprojection error of an undistorted pixel, computed from project() */
static double reproject_err(const hearth_camera *cam, double u, double v, const double xy[2]) {
  double X[3] = {xy[0], xy[1], 1.0}, uv[2];
  if (!hearth_camera_project(cam, X, uv, NULL)) return INFINITY;
  return hypot(uv[0] - u, uv[1] - v);
}

int main(void) {
  /* closed form: pinhole projection */
  {
    hearth_camera c = {640, 480, 500, 510, 320, 240, {0, 0, 0, 0, 0}};
    double X[3] = {0.2, -0.1, 2.0}, uv[2] = {-7, -7};
    CHECK(hearth_camera_project(&c, X, uv, NULL) == 1);
    CHECK_NEAR(uv[0], 500 * 0.1 + 320, 1e-12);
    CHECK_NEAR(uv[1], 510 * -0.05 + 240, 1e-12);
    double K[9];
    hearth_camera_K(&c, K);
    CHECK(K[0] == 500 && K[2] == 320 && K[4] == 510 && K[5] == 240 && K[8] == 1 && K[3] == 0);
    /* Z <= 0 is rejected and leaves uv untouched */
    double Xb[3] = {0.1, 0.1, 0.0};
    uv[0] = uv[1] = -7;
    CHECK(hearth_camera_project(&c, Xb, uv, NULL) == 0);
    Xb[2] = -1.0;
    CHECK(hearth_camera_project(&c, Xb, uv, NULL) == 0);
    Xb[2] = NAN;
    CHECK(hearth_camera_project(&c, Xb, uv, NULL) == 0);
    CHECK(uv[0] == -7 && uv[1] == -7);
    /* principal point ray is +z */
    double dir[3];
    CHECK(hearth_camera_ray(&c, 320, 240, dir) >= 0);
    CHECK_NEAR(dir[0], 0, 1e-15);
    CHECK_NEAR(dir[1], 0, 1e-15);
    CHECK_NEAR(dir[2], 1, 1e-15);
  }
  /* closed form: radial-only distortion of a point on the x axis */
  {
    double d[5] = {-0.3, 0.1, 0, 0, 0.02}, xd, yd;
    hearth_distort(d, 0.5, 0.0, &xd, &yd, NULL);
    double r2 = 0.25;
    CHECK_NEAR(xd, 0.5 * (1 - 0.3 * r2 + 0.1 * r2 * r2 + 0.02 * r2 * r2 * r2), 1e-15);
    CHECK_NEAR(yd, 0.0, 1e-15);
    /* tangential only: xd = x + 2 p1 x y + p2 (r2 + 2 x^2) */
    double t[5] = {0, 0, 0.01, -0.02, 0};
    hearth_distort(t, 0.3, -0.2, &xd, &yd, NULL);
    CHECK_NEAR(xd, 0.3 + 2 * 0.01 * 0.3 * -0.2 + -0.02 * (0.13 + 2 * 0.09), 1e-15);
    CHECK_NEAR(yd, -0.2 + 0.01 * (0.13 + 2 * 0.04) + 2 * -0.02 * 0.3 * -0.2, 1e-15);
  }

  /* a lens folding over inside the image: the grid marks with NaN exactly
     the pixels hearth_camera_ray cannot undistort to within the grid's
     residual bound */
  {
    hearth_camera fold = {64, 48, 40.0, 40.0, 31.5, 23.5, {-0.9, 0.0, 0.0, 0.0, 0.0}};
    float *g = malloc(64 * 48 * 3 * sizeof *g);
    size_t nfail = hearth_camera_ray_grid(&fold, 1, g), nref = 0, agree = 0;
    for (size_t p = 0; p < 64 * 48; p++) {
      double dir[3];
      double res = hearth_camera_ray(&fold, (double)(p % 64), (double)(p / 64), dir);
      int bad = !(res >= 0 && res <= HEARTH_GRID_MAX_RESIDUAL);
      nref += bad;
      agree += bad == (isnan(g[3 * p]) != 0);
    }
    CHECK(nfail > 0 && nfail == nref && agree == 64 * 48);
    free(g);
  }

  hearth_rng rng;
  hearth_rng_seed(&rng, 7);
  for (size_t li = 0; li < NLENS; li++) {
    const hearth_camera *cam = &LENSES[li].cam;
    /* undistort on a dense grid: every pixel corner (half-integers from
     * -0.5 to W-0.5), every pixel centre on the border, plus the corners */
    double worst = 0.0, worst_reported = 0.0;
    long count = 0, failures = 0;
    int step = cam->width > 1000 ? 3 : 1; /* every 3rd corner on the largest image */
    for (int r = 0;; r += step) {
      if (r > cam->height) r = cam->height;
      for (int c = 0;; c += step) {
        if (c > cam->width) c = cam->width;
        double u = c - 0.5, v = r - 0.5, xy[2];
        double res = hearth_camera_undistort(cam, u, v, xy);
        double e = reproject_err(cam, u, v, xy);
        if (!(res >= 0) || !(e <= 1e-10)) failures++;
        worst = fmax(worst, e);
        worst_reported = fmax(worst_reported, res);
        count++;
        if (c == cam->width) break;
      }
      if (r == cam->height) break;
    }
    for (int c = 0; c < cam->width; c++) {
      for (int side = 0; side < 2; side++) {
        double u = c, v = side ? cam->height - 1 : 0, xy[2];
        double res = hearth_camera_undistort(cam, u, v, xy);
        double e = reproject_err(cam, u, v, xy);
        if (!(res >= 0) || !(e <= 1e-10)) failures++;
        worst = fmax(worst, e);
        count++;
      }
    }
    for (int r = 0; r < cam->height; r++) {
      for (int side = 0; side < 2; side++) {
        double u = side ? cam->width - 1 : 0, v = r, xy[2];
        double res = hearth_camera_undistort(cam, u, v, xy);
        double e = reproject_err(cam, u, v, xy);
        if (!(res >= 0) || !(e <= 1e-10)) failures++;
        worst = fmax(worst, e);
        count++;
      }
    }
    printf("%-10s undistort: %ld points, max reprojection residual %.3g px (reported %.3g)\n",
           LENSES[li].name, count, worst, worst_reported);
    CHECK_MSG(failures == 0, "%s: %ld of %ld points above 1e-10 px", LENSES[li].name, failures,
              count);

    /* ray is unit and projects back to the pixel */
    for (int i = 0; i < 500; i++) {
      double u = hearth_rng_range(&rng, -0.5, cam->width - 0.5);
      double v = hearth_rng_range(&rng, -0.5, cam->height - 0.5), dir[3], uv[2];
      CHECK(hearth_camera_ray(cam, u, v, dir) >= 0);
      CHECK_NEAR(hearth_norm3(dir), 1.0, 1e-15);
      CHECK(dir[2] > 0);
      double X[3] = {dir[0] * 3.7, dir[1] * 3.7, dir[2] * 3.7};
      CHECK(hearth_camera_project(cam, X, uv, NULL));
      CHECK(hypot(uv[0] - u, uv[1] - v) < 1e-9);
    }

    /* the grid form: the same rays as hearth_camera_ray, pixel by pixel, for
       strides 1 and 3 (float directions: within 1e-7) */
    for (size_t st = 1; st <= 3; st += 2) {
      size_t gw = ((size_t)cam->width + st - 1) / st, gh = ((size_t)cam->height + st - 1) / st;
      float *g = malloc(gw * gh * 3 * sizeof *g);
      CHECK(hearth_camera_ray_grid(cam, st, g) == 0);
      double gworst = 0;
      for (size_t y = 0; y < gh; y++)
        for (size_t x = 0; x < gw; x++) {
          double dir[3];
          CHECK(hearth_camera_ray(cam, (double)(x * st), (double)(y * st), dir) >= 0);
          for (int k = 0; k < 3; k++) gworst = fmax(gworst, fabs(g[3 * (y * gw + x) + k] - dir[k]));
        }
      CHECK_MSG(gworst < 1e-7, "%s: grid rays differ by %.3g", LENSES[li].name, gworst);
      free(g);
    }

    /* analytic Jacobians vs central differences at random in-image points */
    double worst_rel = 0.0;
    for (int i = 0; i < 300; i++) {
      double u = hearth_rng_range(&rng, 0, cam->width - 1);
      double v = hearth_rng_range(&rng, 0, cam->height - 1), xy[2];
      CHECK(hearth_camera_undistort(cam, u, v, xy) >= 0);
      double Z = hearth_rng_range(&rng, 0.3, 3.0);
      double X[3] = {xy[0] * Z, xy[1] * Z, Z}, uv[2];
      hearth_project_jac J;
      CHECK(hearth_camera_project(cam, X, uv, &J));
      CHECK(hypot(uv[0] - u, uv[1] - v) < 1e-9);
      /* parameters: X(3), fx fy cx cy, dist(5); u, v are linear in the
       * intrinsics and distortion coefficients, so large steps are exact
       * there up to rounding; the point needs a small step. Differences are
       * judged relative to the largest entry of that block row (the
       * Jacobian's scale), so exact zeros are not judged against noise. */
      double gscale[3][2];
      for (int k = 0; k < 2; k++) {
        gscale[0][k] = gscale[1][k] = gscale[2][k] = 0.0;
        for (int q = 0; q < 3; q++) gscale[0][k] = fmax(gscale[0][k], fabs(J.d_point[k * 3 + q]));
        for (int q = 0; q < 4; q++) gscale[1][k] = fmax(gscale[1][k], fabs(J.d_intr[k * 4 + q]));
        for (int q = 0; q < 5; q++) gscale[2][k] = fmax(gscale[2][k], fabs(J.d_dist[k * 5 + q]));
      }
      for (int p = 0; p < 12; p++) {
        int g = p < 3 ? 0 : p < 7 ? 1 : 2;
        hearth_camera cp = *cam, cm = *cam;
        double Xp[3] = {X[0], X[1], X[2]}, Xm[3] = {X[0], X[1], X[2]};
        double h, an[2];
        if (p < 3) {
          h = 1e-5 * Z;
          Xp[p] += h;
          Xm[p] -= h;
          an[0] = J.d_point[p];
          an[1] = J.d_point[3 + p];
        } else if (p < 7) {
          double *fp[4] = {&cp.fx, &cp.fy, &cp.cx, &cp.cy};
          double *fm[4] = {&cm.fx, &cm.fy, &cm.cx, &cm.cy};
          h = 1e-2;
          *fp[p - 3] += h;
          *fm[p - 3] -= h;
          an[0] = J.d_intr[p - 3];
          an[1] = J.d_intr[4 + p - 3];
        } else {
          h = 1e-3;
          cp.dist[p - 7] += h;
          cm.dist[p - 7] -= h;
          an[0] = J.d_dist[p - 7];
          an[1] = J.d_dist[5 + p - 7];
        }
        double up[2], um[2];
        hearth_camera_project(&cp, Xp, up, NULL);
        hearth_camera_project(&cm, Xm, um, NULL);
        for (int k = 0; k < 2; k++) {
          double fd = (up[k] - um[k]) / (2 * h);
          double rel = fabs(fd - an[k]) / fmax(fmax(fabs(an[k]), gscale[g][k]), 1e-300);
          worst_rel = fmax(worst_rel, rel);
          CHECK_MSG(rel < 1e-6, "%s: param %d row %d analytic %.12g fd %.12g", LENSES[li].name, p,
                    k, an[k], fd);
        }
      }
      /* the 2x2 distortion Jacobian */
      double xd, yd, D[4];
      hearth_distort(cam->dist, xy[0], xy[1], &xd, &yd, D);
      for (int k = 0; k < 2; k++) {
        double h = 1e-7, a1, b1, a2, b2;
        hearth_distort(cam->dist, xy[0] + (k == 0) * h, xy[1] + (k == 1) * h, &a1, &b1, NULL);
        hearth_distort(cam->dist, xy[0] - (k == 0) * h, xy[1] - (k == 1) * h, &a2, &b2, NULL);
        CHECK(fabs((a1 - a2) / (2 * h) - D[k]) < 1e-7);
        CHECK(fabs((b1 - b2) / (2 * h) - D[2 + k]) < 1e-7);
      }
    }
    printf("%-10s jacobians: worst relative difference to central FD %.3g\n", LENSES[li].name,
           worst_rel);
  }

  /* a pixel far outside the valid region of a strongly barrel lens (beyond
   * where r * radial(r) folds over) is reported, not silently wrong */
  {
    hearth_camera c = {256, 192, 275, 275, 128, 96, {-0.35, 0.0, 0, 0, 0}};
    /* max of r (1 - 0.35 r^2) is at r = 1/sqrt(1.05) ~ 0.976, value ~0.65 */
    double xy[2] = {123, 456};
    double res = hearth_camera_undistort(&c, 128 + 275 * 0.9, 96, xy);
    CHECK(res < 0 || res > 1e-3);
    /* inside the fold, fine */
    res = hearth_camera_undistort(&c, 128 + 275 * 0.6, 96, xy);
    CHECK(res >= 0 && res < 1e-10);
    CHECK(hearth_camera_undistort(&c, NAN, 3, xy) < 0);
  }
  TEST_MAIN_END();
}
