/* Which vertices of a release's true mesh some depth view sees, for the
 * recon tests' honest true->recon figure: a vertex counts when, for at
 * least one view of ground_truth/.../poses_rgb.json, it lies in front of
 * the true depth camera (colour pose composed with the factory
 * depth-to-colour extrinsic), projects into the depth image, faces the
 * camera (cosine above vis_min_cos) and the ray from the camera's centre to
 * it meets no other part of the true mesh (Embree). Surfaces no depth view
 * sees (a cup's inner wall under its rim, a kettle's spout inside) cannot
 * be reconstructed from depth and are left out of that figure. */
#ifndef HEARTH_TEST_TRUE_VISIBILITY_H
#define HEARTH_TEST_TRUE_VISIBILITY_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "hearth/dataset.h"
#include "hearth/mesh.h"
#include "recon/mesh_distance.h"

/* a facing cosine below which a view is taken as grazing, not seeing */
#define VIS_MIN_COS 0.1

/* vis[n_vertices] (caller's) set to 1 for the vertices of gt some true
 * depth view of root/instance sees; the count, or -1 on an error */
static long true_visible_vertices(const char *root, const char *instance, const hearth_mesh *gt,
                                  uint8_t *vis) {
  char path[1400];
  hearth_err err = {0};
  hearth_poses gp;
  hearth_factory_calib fac;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, instance);
  if (hearth_poses_read(path, &gp, &err)) return -1;
  snprintf(path, sizeof path, "%s/calibration/factory.json", root);
  if (hearth_factory_read(path, &fac, &err)) {
    hearth_poses_free(&gp);
    return -1;
  }
  hearth_raycaster *rc = NULL;
  if (hearth_raycaster_new(gt, &rc, &err)) {
    hearth_poses_free(&gp);
    return -1;
  }
  /* area-weighted vertex normals (counter-clockwise fronts) */
  double *nrm = calloc(gt->n_vertices * 3 + 1, sizeof *nrm);
  for (size_t t = 0; nrm && t < gt->n_triangles; t++) {
    const uint32_t *f = gt->indices + 3 * t;
    double a[3], b[3], n[3];
    for (int k = 0; k < 3; k++) {
      a[k] = gt->positions[3 * (size_t)f[1] + k] - gt->positions[3 * (size_t)f[0] + k];
      b[k] = gt->positions[3 * (size_t)f[2] + k] - gt->positions[3 * (size_t)f[0] + k];
    }
    n[0] = a[1] * b[2] - a[2] * b[1];
    n[1] = a[2] * b[0] - a[0] * b[2];
    n[2] = a[0] * b[1] - a[1] * b[0];
    for (int c = 0; c < 3; c++)
      for (int k = 0; k < 3; k++) nrm[3 * (size_t)f[c] + k] += n[k];
  }
  hearth_rigid T_rgb_from_depth;
  hearth_rigid_inverse(&fac.T_depth_from_rgb, &T_rgb_from_depth);
  long count = 0;
  memset(vis, 0, gt->n_vertices);
  for (size_t i = 0; nrm && i < gp.n; i++) {
    hearth_rigid T_world_from_depth, T_depth_from_world;
    hearth_rigid_compose(&gp.views[i].T_world_from_cam, &T_rgb_from_depth, &T_world_from_depth);
    hearth_rigid_inverse(&T_world_from_depth, &T_depth_from_world);
    const double *c = T_world_from_depth.t;
    for (size_t v = 0; v < gt->n_vertices; v++) {
      if (vis[v]) continue;
      double p[3], d[3], X[3], uv[2];
      for (int k = 0; k < 3; k++) {
        p[k] = gt->positions[3 * v + k];
        d[k] = p[k] - c[k];
      }
      double ld = sqrt(dot3(d, d)), ln = sqrt(dot3(nrm + 3 * v, nrm + 3 * v));
      if (!(ld > 0) || !(ln > 0) || -dot3(d, nrm + 3 * v) < VIS_MIN_COS * ld * ln) continue;
      hearth_rigid_apply(&T_depth_from_world, p, X);
      if (X[2] <= 0 || !hearth_camera_project(&fac.depth, X, uv, NULL)) continue;
      if (uv[0] < -0.5 || uv[1] < -0.5 || uv[0] > fac.depth.width - 0.5 ||
          uv[1] > fac.depth.height - 0.5)
        continue;
      /* unoccluded up to half a millimetre short of the vertex */
      if (hearth_raycast_any(rc, c, d, 0.0, 1.0 - 5e-4 / ld)) continue;
      vis[v] = 1;
      count++;
    }
  }
  free(nrm);
  hearth_raycaster_free(rc);
  hearth_poses_free(&gp);
  return count;
}

/* RMS and max distance of the vertices of a with sel[v] set to mesh b */
static inline void mesh_to_mesh_sel(const hearth_mesh *a, const uint8_t *sel, const hearth_mesh *b,
                                    double *rms, double *mx) {
  tri_grid g;
  tri_grid_build(&g, b, 0.004);
  double s = 0, m = 0;
  size_t n = 0;
  for (size_t v = 0; v < a->n_vertices; v++) {
    if (!sel[v]) continue;
    double p[3] = {a->positions[3 * v], a->positions[3 * v + 1], a->positions[3 * v + 2]};
    double d = tri_grid_dist(&g, p);
    s += d * d;
    if (d > m) m = d;
    n++;
  }
  *rms = n ? sqrt(s / (double)n) : 0;
  *mx = m;
  tri_grid_free(&g);
}

#endif
