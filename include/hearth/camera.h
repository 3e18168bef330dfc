/* hearth/camera.h - area core (src/core/core_camera.c): the pinhole camera
 * with 5-parameter Brown-Conrady distortion or OpenCV's 8-parameter
 * rational model, in OpenCV's conventions. A camera is a plain value;
 * nothing here allocates.
 *
 * Camera axes: +x right, +y down, +z forward. Pixel (0,0) is the centre of
 * the top-left pixel. Distortion order [k1, k2, p1, p2, k3]:
 *   x = X/Z, y = Y/Z, r2 = x^2 + y^2
 *   radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3
 *   xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2)
 *   yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y
 *   u = fx xd + cx,  v = fy yd + cy
 * The rational model (HEARTH_LENS_RATIONAL8, OpenCV's CALIB_RATIONAL_MODEL)
 * has order [k1, k2, p1, p2, k3, k4, k5, k6] and divides the radial term:
 *   radial = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
 * See docs/conventions.md. */
#ifndef HEARTH_CAMERA_H
#define HEARTH_CAMERA_H

#include <stddef.h>
#include "hearth/geom.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Lens models; a zeroed camera is HEARTH_LENS_BROWN5. */
typedef enum hearth_lens_model {
  HEARTH_LENS_BROWN5 = 0,   /* k1 k2 p1 p2 k3 (dist[5..7] unused, kept 0) */
  HEARTH_LENS_RATIONAL8 = 1 /* k1 k2 p1 p2 k3 k4 k5 k6 */
} hearth_lens_model;
/* Number of coefficients of a model (5 or 8), its stable name ("brown5",
 * "rational8") and the model of a name (-1 if unknown). */
int hearth_lens_n_coeffs(hearth_lens_model m);
const char *hearth_lens_name(hearth_lens_model m);
int hearth_lens_from_name(const char *name);

typedef struct hearth_camera {
  int width, height;       /* pixels */
  double fx, fy, cx, cy;   /* pixels */
  double dist[8];          /* k1 k2 p1 p2 k3 [k4 k5 k6] */
  hearth_lens_model model; /* which of dist is used */
} hearth_camera;

/* Jacobians filled by hearth_camera_project when the pointers are non-NULL
 * (row-major, 2 rows): */
typedef struct hearth_project_jac {
  double d_point[6]; /* d(u,v) / d(X,Y,Z) in the camera frame */
  double d_intr[8];  /* d(u,v) / d(fx, fy, cx, cy) */
  double d_dist[10]; /* d(u,v) / d(k1, k2, p1, p2, k3) */
  double d_rat[6];   /* d(u,v) / d(k4, k5, k6); rational model only */
} hearth_project_jac;

/* The distortion polynomial above, (x, y) -> (xd, yd), inline for loops
 * over many points; hearth_distort is the same with the Jacobian. */
static inline void hearth_distort_xy(const double dist[5], double x, double y, double *xd,
                                     double *yd) {
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  double x2 = x * x, y2 = y * y, xy = x * y, r2 = x2 + y2;
  double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * radial + 2.0 * p1 * xy + p2 * (r2 + 2.0 * x2);
  *yd = y * radial + p1 * (r2 + 2.0 * y2) + 2.0 * p2 * xy;
}

/* The same polynomial in float, for loops that only need pixel-level
 * accuracy (about 1e-7 relative) and vectorise in float: dist as floats. */
static inline void hearth_distort_xyf(const float dist[5], float x, float y, float *xd, float *yd) {
  const float k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  float x2 = x * x, y2 = y * y, xy = x * y, r2 = x2 + y2;
  float radial = 1.0f + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * radial + 2.0f * p1 * xy + p2 * (r2 + 2.0f * x2);
  *yd = y * radial + p1 * (r2 + 2.0f * y2) + 2.0f * p2 * xy;
}

/* Distort normalised coordinates (x, y) -> (xd, yd), optionally with the
 * 2x2 Jacobian d(xd,yd)/d(x,y) (row-major). */
void hearth_distort(const double dist[5], double x, double y, double *xd, double *yd, double J[4]);
/* The same for the camera's own model (5-parameter: hearth_distort). */
void hearth_camera_distort(const hearth_camera *cam, double x, double y, double *xd, double *yd,
                           double J[4]);

/* Project a point in the camera frame to pixels. Returns 0 if Z <= 0
 * (u, v untouched), 1 otherwise. */
int hearth_camera_project(const hearth_camera *cam, const double Xc[3], double uv[2],
                          hearth_project_jac *jac);

/* Undistort a pixel to normalised ideal coordinates (x, y) such that
 * project((x, y, 1)) == (u, v). Newton's method on the distortion model with
 * a fixed-point start; converges to 1e-10 px over the whole image for
 * realistic lenses. Returns the final residual in pixels (or a negative value
 * if the iteration diverged). */
double hearth_camera_undistort(const hearth_camera *cam, double u, double v, double xy[2]);

/* The unit ray direction (camera frame) through pixel (u, v). Returns the
 * undistortion residual as above. */
double hearth_camera_ray(const hearth_camera *cam, double u, double v, double dir[3]);

/* Unit ray directions (camera frame, 3 floats each, row-major, into the
 * caller's dirs of 3 * ceil(width / stride) * ceil(height / stride) floats)
 * through the
 * pixels (x * stride, y * stride), x < ceil(width / stride), y < ceil(height /
 * stride): hearth_camera_ray for a whole grid, faster (each solve starts
 * where its neighbours' roots point). A pixel that cannot be undistorted to
 * within HEARTH_GRID_MAX_RESIDUAL pixels (outside the invertible part of the
 * lens model) gets NaN; returns how many did. */
#define HEARTH_GRID_MAX_RESIDUAL 1e-6
size_t hearth_camera_ray_grid(const hearth_camera *cam, size_t stride, float *dirs);

/* K as a row-major 3x3. */
void hearth_camera_K(const hearth_camera *cam, double K[9]);

#ifdef __cplusplus
}
#endif
#endif
