/* Pinhole camera with 5-parameter Brown-Conrady or 8-parameter rational
 * distortion (OpenCV order). */
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "hearth/camera.h"

/* the lens models: coefficient count and stable name, by enum value */
static const struct {
  int n_coeffs;
  const char *name;
} k_lens[] = {{5, "brown5"}, {8, "rational8"}};

int hearth_lens_n_coeffs(hearth_lens_model m) {
  return (unsigned)m < sizeof k_lens / sizeof k_lens[0] ? k_lens[m].n_coeffs : 0;
}

const char *hearth_lens_name(hearth_lens_model m) {
  return (unsigned)m < sizeof k_lens / sizeof k_lens[0] ? k_lens[m].name : "unknown";
}

int hearth_lens_from_name(const char *name) {
  for (size_t i = 0; name && i < sizeof k_lens / sizeof k_lens[0]; i++)
    if (!strcmp(name, k_lens[i].name)) return (int)i;
  return -1;
}

void hearth_camera_K(const hearth_camera *cam, double K[9]) {
  K[0] = cam->fx;
  K[1] = 0.0;
  K[2] = cam->cx;
  K[3] = 0.0;
  K[4] = cam->fy;
  K[5] = cam->cy;
  K[6] = 0.0;
  K[7] = 0.0;
  K[8] = 1.0;
}

void hearth_distort(const double dist[5], double x, double y, double *xd, double *yd, double J[4]) {
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  hearth_distort_xy(dist, x, y, xd, yd);
  if (J) {
    double x2 = x * x, y2 = y * y, xy = x * y, r2 = x2 + y2;
    double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    /* d radial / d r2 */
    double dr = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    J[0] = radial + 2.0 * x2 * dr + 2.0 * p1 * y + 6.0 * p2 * x;
    J[1] = 2.0 * xy * dr + 2.0 * p1 * x + 2.0 * p2 * y;
    J[2] = J[1];
    J[3] = radial + 2.0 * y2 * dr + 6.0 * p1 * y + 2.0 * p2 * x;
  }
}

/* The rational model: N / D radial term, (N, D, dN/dr2, dD/dr2) into q */
static void rational_terms(const double d[8], double r2, double q[4]) {
  q[0] = 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  q[1] = 1.0 + r2 * (d[5] + r2 * (d[6] + r2 * d[7]));
  q[2] = d[0] + r2 * (2.0 * d[1] + 3.0 * d[4] * r2);
  q[3] = d[5] + r2 * (2.0 * d[6] + 3.0 * d[7] * r2);
}

void hearth_camera_distort(const hearth_camera *cam, double x, double y, double *xd, double *yd,
                           double J[4]) {
  if (cam->model != HEARTH_LENS_RATIONAL8) {
    hearth_distort(cam->dist, x, y, xd, yd, J);
    return;
  }
  const double *d = cam->dist;
  const double p1 = d[2], p2 = d[3];
  double x2 = x * x, y2 = y * y, xy = x * y, r2 = x2 + y2, q[4];
  rational_terms(d, r2, q);
  double radial = q[0] / q[1];
  *xd = x * radial + 2.0 * p1 * xy + p2 * (r2 + 2.0 * x2);
  *yd = y * radial + p1 * (r2 + 2.0 * y2) + 2.0 * p2 * xy;
  if (J) {
    double dr = (q[2] * q[1] - q[0] * q[3]) / (q[1] * q[1]); /* d radial / d r2 */
    J[0] = radial + 2.0 * x2 * dr + 2.0 * p1 * y + 6.0 * p2 * x;
    J[1] = 2.0 * xy * dr + 2.0 * p1 * x + 2.0 * p2 * y;
    J[2] = J[1];
    J[3] = radial + 2.0 * y2 * dr + 6.0 * p1 * y + 2.0 * p2 * x;
  }
}

int hearth_camera_project(const hearth_camera *cam, const double Xc[3], double uv[2],
                          hearth_project_jac *jac) {
  double Z = Xc[2];
  if (!(Z > 0.0)) return 0;
  double iz = 1.0 / Z, x = Xc[0] * iz, y = Xc[1] * iz, xd, yd, J[4];
  hearth_camera_distort(cam, x, y, &xd, &yd, jac ? J : NULL);
  uv[0] = cam->fx * xd + cam->cx;
  uv[1] = cam->fy * yd + cam->cy;
  if (jac) {
    /* chain: d(u,v)/d(xd,yd) = diag(fx, fy); d(x,y)/dX = [[1/Z,0,-x/Z],[0,1/Z,-y/Z]] */
    double A[4] = {cam->fx * J[0], cam->fx * J[1], cam->fy * J[2], cam->fy * J[3]};
    for (int r = 0; r < 2; r++) {
      jac->d_point[r * 3 + 0] = A[r * 2 + 0] * iz;
      jac->d_point[r * 3 + 1] = A[r * 2 + 1] * iz;
      jac->d_point[r * 3 + 2] = -(A[r * 2 + 0] * x + A[r * 2 + 1] * y) * iz;
    }
    jac->d_intr[0] = xd;
    jac->d_intr[1] = 0.0;
    jac->d_intr[2] = 1.0;
    jac->d_intr[3] = 0.0;
    jac->d_intr[4] = 0.0;
    jac->d_intr[5] = yd;
    jac->d_intr[6] = 0.0;
    jac->d_intr[7] = 1.0;
    double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2, xy = x * y;
    double *dd = jac->d_dist;
    dd[0] = cam->fx * x * r2;
    dd[1] = cam->fx * x * r4;
    dd[2] = cam->fx * 2.0 * xy;
    dd[3] = cam->fx * (r2 + 2.0 * x * x);
    dd[4] = cam->fx * x * r6;
    dd[5] = cam->fy * y * r2;
    dd[6] = cam->fy * y * r4;
    dd[7] = cam->fy * (r2 + 2.0 * y * y);
    dd[8] = cam->fy * 2.0 * xy;
    dd[9] = cam->fy * y * r6;
    if (cam->model == HEARTH_LENS_RATIONAL8) {
      /* k1..k3 act through N / D; k4..k6 through -N r2^k / D^2 */
      double q[4];
      rational_terms(cam->dist, r2, q);
      double iD = 1.0 / q[1], nD2 = q[0] * iD * iD;
      for (int k = 0; k < 10; k++)
        if (k % 5 != 2 && k % 5 != 3) dd[k] *= iD;
      const double rp[3] = {r2, r4, r6};
      for (int k = 0; k < 3; k++) {
        jac->d_rat[k] = -cam->fx * x * nD2 * rp[k];
        jac->d_rat[3 + k] = -cam->fy * y * nD2 * rp[k];
      }
    }
  }
  return 1;
}

/* Pixel residual of a normalised point against the target pixel. */
static double reproj_residual(const hearth_camera *cam, double x, double y, double tu, double tv,
                              double *ex, double *ey) {
  double xd, yd;
  hearth_camera_distort(cam, x, y, &xd, &yd, NULL);
  /* residual in distorted normalised coordinates, scored in pixels */
  *ex = xd - tu;
  *ey = yd - tv;
  double a = cam->fx * *ex, b = cam->fy * *ey;
  return sqrt(a * a + b * b); /* residuals are far from overflow: no hypot */
}

/* Newton from (x, y) towards the ideal point whose distortion is (tu, tv),
 * until the residual is at most tol pixels */
static double undistort_from(const hearth_camera *cam, double tu, double tv, double x, double y,
                             double tol, double xy[2]) {
  double ex, ey;
  double res = reproj_residual(cam, x, y, tu, tv, &ex, &ey);
  for (int it = 0; it < 100 && res > tol; it++) {
    double xd, yd, J[4];
    hearth_camera_distort(cam, x, y, &xd, &yd, J);
    double det = J[0] * J[3] - J[1] * J[2];
    if (!(fabs(det) > 1e-300) || !isfinite(det)) return -1.0;
    double dx = -(J[3] * ex - J[1] * ey) / det;
    double dy = -(-J[2] * ex + J[0] * ey) / det;
    /* step control: never move farther than the current radius + 1 in one
     * step, then halve until the residual decreases */
    double len = sqrt(dx * dx + dy * dy), cap = 1.0 + sqrt(x * x + y * y);
    if (!isfinite(len)) len = hypot(dx, dy);
    if (len > cap) {
      dx *= cap / len;
      dy *= cap / len;
    }
    double lam = 1.0, nres = res, nx = x, ny = y, nex = ex, ney = ey;
    int accepted = 0;
    /* near the floating-point floor a failed full step means no descent
     * is left: a few halvings, not sixty */
    int max_halvings = res < 1e-11 ? 3 : 60;
    for (int h = 0; h < max_halvings; h++) {
      nx = x + lam * dx;
      ny = y + lam * dy;
      nres = reproj_residual(cam, nx, ny, tu, tv, &nex, &ney);
      if (nres < res) {
        accepted = 1;
        break;
      }
      lam *= 0.5;
    }
    if (!accepted) break; /* no descent left: at the floating-point floor */
    x = nx;
    y = ny;
    ex = nex;
    ey = ney;
    res = nres;
  }
  if (!isfinite(res)) return -1.0;
  /* a root where the distortion map folds over (det <= 0) lies outside the
   * region where the lens model is invertible; so does one where the radial
   * factor is not positive (the model has turned the point through the
   * centre: det can be positive again beyond the fold) */
  double xd, yd, J[4], r2 = x * x + y * y;
  hearth_camera_distort(cam, x, y, &xd, &yd, J);
  if (!(J[0] * J[3] - J[1] * J[2] > 0.0)) return -1.0;
  if (cam->model == HEARTH_LENS_RATIONAL8) {
    double q[4];
    rational_terms(cam->dist, r2, q);
    if (!(q[0] > 0.0) || !(q[1] > 0.0)) return -1.0;
  } else if (!(1.0 + r2 * (cam->dist[0] + r2 * (cam->dist[1] + r2 * cam->dist[4])) > 0.0)) {
    return -1.0;
  }
  xy[0] = x;
  xy[1] = y;
  return res;
}

double hearth_camera_undistort(const hearth_camera *cam, double u, double v, double xy[2]) {
  if (!isfinite(u) || !isfinite(v) || !(cam->fx != 0.0) || !(cam->fy != 0.0)) return -1.0;
  double tu = (u - cam->cx) / cam->fx, tv = (v - cam->cy) / cam->fy;
  /* start at the distorted point itself: for radial models r * radial(r) is
   * monotone on the valid part of the image, and Newton from there stays on
   * the branch that contains the origin */
  return undistort_from(cam, tu, tv, tu, tv, 1e-13, xy);
}

static void unit_ray(const double xy[2], float *dir) {
  double n = sqrt(xy[0] * xy[0] + xy[1] * xy[1] + 1.0);
  dir[0] = (float)(xy[0] / n);
  dir[1] = (float)(xy[1] / n);
  dir[2] = (float)(1.0 / n);
}

size_t hearth_camera_ray_grid(const hearth_camera *cam, size_t stride, float *dirs) {
  if (stride < 1) stride = 1;
  size_t gw = ((size_t)(cam->width > 0 ? cam->width : 0) + stride - 1) / stride;
  size_t gh = ((size_t)(cam->height > 0 ? cam->height : 0) + stride - 1) / stride, failed = 0;
  int ok = isfinite(cam->fx) && isfinite(cam->fy) && cam->fx != 0.0 && cam->fy != 0.0;
  for (size_t gy = 0; gy < gh; gy++) {
    /* along a row each solve starts where the last two roots point (linear
     * extrapolation, a small fraction of a pixel off) and stops at 1e-9 px,
     * far below what a float direction resolves (about 1e-5 px): one Newton
     * step instead of three to five */
    int warm = 0;
    double prev[2] = {0, 0}, step[2] = {0, 0};
    for (size_t gx = 0; gx < gw; gx++) {
      float *d = dirs + 3 * (gy * gw + gx);
      double tu = ((double)(gx * stride) - cam->cx) / cam->fx,
             tv = ((double)(gy * stride) - cam->cy) / cam->fy;
      double xy[2], res = -1.0;
      if (ok && warm == 2)
        res = undistort_from(cam, tu, tv, prev[0] + step[0], prev[1] + step[1], 1e-9, xy);
      if (ok && !(res >= 0.0 && res <= HEARTH_GRID_MAX_RESIDUAL))
        res = undistort_from(cam, tu, tv, tu, tv, 1e-9, xy);
      if (!(res >= 0.0 && res <= HEARTH_GRID_MAX_RESIDUAL)) {
        d[0] = d[1] = d[2] = NAN;
        failed++;
        warm = 0;
        continue;
      }
      unit_ray(xy, d);
      if (warm) {
        step[0] = xy[0] - prev[0];
        step[1] = xy[1] - prev[1];
      }
      prev[0] = xy[0];
      prev[1] = xy[1];
      warm = warm ? 2 : 1;
    }
  }
  return failed;
}

double hearth_camera_ray(const hearth_camera *cam, double u, double v, double dir[3]) {
  double xy[2];
  double res = hearth_camera_undistort(cam, u, v, xy);
  if (res < 0.0) return res;
  double n = sqrt(xy[0] * xy[0] + xy[1] * xy[1] + 1.0);
  dir[0] = xy[0] / n;
  dir[1] = xy[1] / n;
  dir[2] = 1.0 / n;
  return res;
}
