/* A small test scene for scale and refinement tests: an axis-aligned box
 * mesh (closed, counter-clockwise outward) and an exact analytic ray-box
 * intersection, independent of the Embree ray caster under test. */
#ifndef TEST_REFINE_SCENE_H
#define TEST_REFINE_SCENE_H
#include <math.h>
#include "hearth/hearth.h"

static void scene_box_mesh(hearth_mesh *m, const double lo[3], const double hi[3]) {
  hearth_err err;
  hearth_mesh_alloc(m, 8, 12, 0, &err);
  for (int i = 0; i < 8; i++) {
    m->positions[3 * i] = (float)((i & 1) ? hi[0] : lo[0]);
    m->positions[3 * i + 1] = (float)((i & 2) ? hi[1] : lo[1]);
    m->positions[3 * i + 2] = (float)((i & 4) ? hi[2] : lo[2]);
  }
  /* faces -x +x -y +y -z +z, each two outward CCW triangles */
  static const uint32_t f[12][3] = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5},
                                    {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                    {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
  for (int t = 0; t < 12; t++)
    for (int k = 0; k < 3; k++) m->indices[3 * t + k] = f[t][k];
}

/* nearest positive hit distance of a ray with the box, or INFINITY */
static double scene_ray_box(const double o[3], const double d[3], const double lo[3],
                            const double hi[3]) {
  double t0 = 0, t1 = INFINITY;
  for (int k = 0; k < 3; k++) {
    if (fabs(d[k]) < 1e-15) {
      if (o[k] < lo[k] || o[k] > hi[k]) return INFINITY;
      continue;
    }
    double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
    if (a > b) {
      double t = a;
      a = b;
      b = t;
    }
    if (a > t0) t0 = a;
    if (b < t1) t1 = b;
  }
  return t0 <= t1 && t0 > 0 ? t0 : INFINITY;
}

/* T_world_from_cam of a camera at c looking at target (y roughly down) */
static void scene_look_at(const double c[3], const double target[3], hearth_rigid *T) {
  double z[3] = {target[0] - c[0], target[1] - c[1], target[2] - c[2]}, up[3] = {0, 0, -1}, x[3],
         y[3];
  double l = hearth_norm3(z);
  for (int k = 0; k < 3; k++) z[k] /= l;
  hearth_cross3(z, up, x);
  /* avoid a degenerate up vector */
  if (hearth_norm3(x) < 1e-6) {
    up[0] = 1;
    up[2] = 0;
    hearth_cross3(z, up, x);
  }
  l = hearth_norm3(x);
  for (int k = 0; k < 3; k++) x[k] /= l;
  hearth_cross3(z, x, y);
  for (int r = 0; r < 3; r++) {
    T->R[3 * r] = x[r];
    T->R[3 * r + 1] = y[r];
    T->R[3 * r + 2] = z[r];
    T->t[r] = c[r];
  }
}
/* A start pose: truth moved by a rotation of deg degrees and a translation
 * of mm millimetres, each about a direction drawn from rng. */
static inline hearth_rigid scene_nudged_start(const hearth_rigid *truth, double deg, double mm,
                                              hearth_rng *rng) {
  hearth_pose_nudge n = {{0}, {0}, {0}, {0}};
  double r[3], t[3];
  for (int k = 0; k < 3; k++) {
    r[k] = hearth_rng_normal(rng);
    t[k] = hearth_rng_normal(rng);
  }
  double lr = hearth_norm3(r), lt = hearth_norm3(t);
  for (int k = 0; k < 3; k++) {
    n.d_rot_deg[k] = deg * r[k] / lr;
    n.d_t_mm[k] = mm * t[k] / lt;
  }
  hearth_rigid start = *truth;
  hearth_pose_nudge_apply(&n, &start);
  return start;
}
#endif
