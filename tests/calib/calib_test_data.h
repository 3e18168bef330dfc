/* Synthetic plate views for the calibration tests: known cameras, random
 * plausible plate poses, exact projections (the tests' own oracle). */
#ifndef CALIB_TEST_DATA_H
#define CALIB_TEST_DATA_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/calib.h"
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/image.h"

static inline void td_thermal_cam(hearth_camera *c) {
  memset(c, 0, sizeof *c);
  c->width = 256;
  c->height = 192;
  c->fx = 272.5;
  c->fy = 271.0;
  c->cx = 129.3;
  c->cy = 94.1;
  double d[5] = {-0.32, 0.14, 0.0012, -0.0007, -0.03};
  memcpy(c->dist, d, sizeof d);
}

static inline void td_rgb_cam(hearth_camera *c) {
  memset(c, 0, sizeof *c);
  c->width = 1920;
  c->height = 1080;
  c->fx = 1123.0;
  c->fy = 1122.0;
  c->cx = 957.5;
  c->cy = 541.0;
  double d[5] = {0.07, -0.09, 0.0003, -0.0002, 0.03};
  memcpy(c->dist, d, sizeof d);
}

/* the pattern centre in plate coordinates */
static inline void td_pattern_centre(double c[3]) {
  c[0] = 0.060;
  c[1] = 3.5 * HEARTH_PLATE_ROW_STEP_M;
  c[2] = 0;
}

/* a plate pose: pattern centre at (x, y, z) in the camera, tilted by up to
 * max_tilt about a random in-plane axis, rotated in plane by roll */
static inline void td_plate_pose(hearth_rng *rng, double z, double max_tilt, double roll, double x,
                                 double y, hearth_rigid *T) {
  double axis_ang = hearth_rng_range(rng, 0, 2 * M_PI);
  double tilt = hearth_rng_range(rng, 0.3 * max_tilt, max_tilt);
  double wt[3] = {cos(axis_ang) * tilt, sin(axis_ang) * tilt, 0};
  double wr[3] = {0, 0, roll};
  double Rt[9], Rr[9];
  hearth_rotvec_to_matrix(wt, Rt);
  hearth_rotvec_to_matrix(wr, Rr);
  hearth_mat3_mul(Rt, Rr, T->R);
  double pc[3], rp[3];
  td_pattern_centre(pc);
  hearth_rigid_rotate(T, pc, rp);
  T->t[0] = x - rp[0];
  T->t[1] = y - rp[1];
  T->t[2] = z - rp[2];
}

/* project all 84 holes; returns the number inside [margin, size - 1 - margin] */
static inline int td_project(const hearth_camera *c, const hearth_rigid *T, double *uv,
                             double margin) {
  int inside = 0;
  for (int i = 0; i < HEARTH_PLATE_HOLES; i++) {
    double X[3], Xc[3];
    hearth_plate_hole(i, X);
    hearth_rigid_apply(T, X, Xc);
    if (!hearth_camera_project(c, Xc, uv + 2 * i, NULL)) continue;
    if (uv[2 * i] >= margin && uv[2 * i + 1] >= margin && uv[2 * i] <= c->width - 1 - margin &&
        uv[2 * i + 1] <= c->height - 1 - margin)
      inside++;
  }
  return inside;
}

/* n views filling the thermal camera's field, all holes inside */
static inline int td_views(hearth_rng *rng, const hearth_camera *c, int n, double max_tilt,
                           hearth_rigid *T, double *uv) {
  int k = 0, tries = 0;
  while (k < n && tries < 10000) {
    tries++;
    double z = hearth_rng_range(rng, 0.22, 0.40);
    double roll = hearth_rng_range(rng, -0.3, 0.3) + (hearth_rng_uniform(rng) < 0.2 ? M_PI : 0);
    double x = hearth_rng_range(rng, -0.35, 0.35) * z * c->width / (2 * c->fx);
    double y = hearth_rng_range(rng, -0.35, 0.35) * z * c->height / (2 * c->fy);
    td_plate_pose(rng, z, max_tilt, roll, x, y, &T[k]);
    if (td_project(c, &T[k], uv + 2 * HEARTH_PLATE_HOLES * k, 6.0) == HEARTH_PLATE_HOLES) k++;
  }
  return k;
}

/* 1 if plate point (x, y) (metres) is inside a hole */
static inline int in_hole(double x, double y) {
  int r0 = (int)floor(y / HEARTH_PLATE_ROW_STEP_M);
  for (int r = r0; r <= r0 + 1; r++) {
    if (r < 0 || r >= HEARTH_PLATE_ROWS) continue;
    double off = (r & 1) ? 0.006 : 0.0;
    int c = (int)lround((x - off) / HEARTH_PLATE_PITCH_M);
    int nc = (r & 1) ? 10 : 11;
    if (c < 0 || c >= nc) continue;
    double dx = x - (off + HEARTH_PLATE_PITCH_M * c), dy = y - HEARTH_PLATE_ROW_STEP_M * r;
    if (dx * dx + dy * dy < 0.004 * 0.004) return 1;
  }
  return 0;
}

/* render: fraction of each pixel's footprint that sees a hole (ss x ss
 * sub-samples through the lens), then hole/plate levels, blur and noise */
static inline void render(const hearth_camera *c, const hearth_rigid *T, int ss, double plate_v,
                          double hole_v, double blur, double noise, uint64_t seed, float *out) {
  size_t w = (size_t)c->width, h = (size_t)c->height;
  hearth_rigid Ti;
  hearth_rigid_inverse(T, &Ti);
  /* plate plane in camera: n . X = n . t with n = R e3 */
  double n[3] = {T->R[2], T->R[5], T->R[8]}, d = hearth_dot3(n, T->t);
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++) {
      int hits = 0;
      for (int j = 0; j < ss; j++)
        for (int i = 0; i < ss; i++) {
          double u = (double)x + (i + 0.5) / ss - 0.5, v = (double)y + (j + 0.5) / ss - 0.5;
          double dir[3], P[3], Q[3];
          hearth_camera_ray(c, u, v, dir);
          double s = d / hearth_dot3(n, dir);
          for (int k = 0; k < 3; k++) P[k] = s * dir[k];
          hearth_rigid_apply(&Ti, P, Q);
          hits += in_hole(Q[0], Q[1]);
        }
      double f = (double)hits / (ss * ss);
      out[y * w + x] = (float)(plate_v + f * (hole_v - plate_v));
    }
  if (blur > 0) {
    int rad = (int)ceil(3 * blur);
    double k[64], ks = 0;
    for (int i = -rad; i <= rad; i++) ks += k[i + rad] = exp(-0.5 * i * i / (blur * blur));
    float *tmp = malloc(sizeof(float) * w * h);
    for (int pass = 0; pass < 2; pass++) {
      for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++) {
          double s = 0;
          for (int i = -rad; i <= rad; i++) {
            long xx = (long)(pass ? y : x) + i;
            long lim = (long)(pass ? h : w) - 1;
            xx = xx < 0 ? 0 : xx > lim ? lim : xx;
            s += k[i + rad] * (pass ? out[(size_t)xx * w + x] : out[y * w + (size_t)xx]);
          }
          tmp[y * w + x] = (float)(s / ks);
        }
      memcpy(out, tmp, sizeof(float) * w * h);
    }
    free(tmp);
  }
  hearth_rng rng;
  hearth_rng_seed(&rng, seed);
  for (size_t i = 0; i < w * h; i++) out[i] += (float)(noise * hearth_rng_normal(&rng));
}

#endif
