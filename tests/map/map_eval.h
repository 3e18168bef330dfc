/* Shared by mapping tests and benchmarks: map one state of a virtual-rig
 * release with given poses and compare with ground truth. */
#ifndef HEARTH_TEST_MAP_EVAL_H
#define HEARTH_TEST_MAP_EVAL_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/hearth.h"

typedef struct map_eval {
  size_t n_eval; /* observed texels seen >= 10 deg from grazing */
  double median, p95, max_err;
  double coverage;     /* observed / surface */
  size_t cross_island; /* filled texels whose value is not from their island */
  size_t n_filled;
} map_eval;

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static int cmp_pair(const void *a, const void *b) {
  const double *x = a, *y = b;
  if (x[0] != y[0]) return (x[0] > y[0]) - (x[0] < y[0]);
  return (x[1] > y[1]) - (x[1] < y[1]);
}

/* poses_path: thermal poses; rig_path: rig; mesh_path: metric mesh */
static hearth_status map_eval_state(const char *root, const char *inst, const char *state,
                                    const char *mesh_path, const char *poses_path,
                                    const char *rig_path, const hearth_map_opts *opts, map_eval *ev,
                                    hearth_err *err) {
  char path[4096];
  memset(ev, 0, sizeof *ev);
  hearth_rig rig;
  hearth_status s = hearth_rig_read(rig_path, &rig, err);
  if (s) return s;
  hearth_poses poses = {0};
  hearth_manifest man = {0};
  hearth_mesh mesh = {0};
  hearth_npy gt = {0};
  hearth_map_result r = {0};
  hearth_image *imgs = NULL;
  hearth_map_view *views = NULL;
  double *errs = NULL;
  if ((s = hearth_poses_read(poses_path, &poses, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
  if ((s = hearth_manifest_read(path, &man, err))) goto done;
  hearth_glb_read_opts go = {.require_uvs = 1};
  if ((s = hearth_glb_read(mesh_path, &go, &mesh, err))) goto done;
  imgs = calloc(man.n_views, sizeof *imgs);
  views = calloc(man.n_views, sizeof *views);
  for (size_t v = 0; v < man.n_views; v++) {
    snprintf(path, sizeof path, "%s/instances/%s/raw/%s/%s", root, inst, state,
             man.views[v].thermal);
    if ((s = hearth_thermal_read_csv(path, NULL, &imgs[v], err))) goto done;
    const hearth_view_pose *p = hearth_poses_find(&poses, state, man.views[v].view);
    if (!p) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "no pose for %s", man.views[v].view);
      goto done;
    }
    views[v].image = &imgs[v];
    views[v].T_world_from_cam = p->T_world_from_cam;
  }
  if ((s = hearth_map_views(&mesh, NULL, &rig.thermal, views, man.n_views, opts, &r, err)))
    goto done;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/temperature_true.npy", root, inst,
           state);
  if ((s = hearth_npy_read(path, &gt, err))) goto done;
  if (gt.ndim != 2 || gt.shape[0] != r.R || gt.shape[1] != r.R) {
    s = hearth_err_set(err, HEARTH_E_SIZE, "%s: ground truth is not %zux%zu", path, r.R, r.R);
    goto done;
  }
  const float *t = gt.data;
  size_t N = r.R * r.R, n = 0;
  errs = malloc(N * sizeof *errs);
  const float cos_min = (float)sin(10.0 * M_PI / 180.0);
  for (size_t q = 0; q < N; q++)
    if (r.mask[q] == HEARTH_TEXEL_OBSERVED && r.best_cos[q] >= cos_min && !isnan(t[q]))
      errs[n++] = fabs((double)r.observed[q] - (double)t[q]);
  qsort(errs, n, sizeof *errs, cmp_double);
  ev->n_eval = n;
  if (n) {
    ev->median = errs[n / 2];
    ev->p95 = errs[(size_t)(0.95 * (double)(n - 1))];
    ev->max_err = errs[n - 1];
  }
  ev->coverage = r.n_surface ? (double)r.n_observed / (double)r.n_surface : 0;
  ev->n_filled = r.n_filled;
  /* filled texels: their value must be an observed value of their own
     island (the fill copies; checked against the mesh's UV island labels) */
  {
    uint32_t *tri = malloc(N * sizeof *tri), *isl = malloc(mesh.n_triangles * sizeof *isl),
             nisl = 0;
    hearth_uv_rasterize(&mesh, r.R, tri, NULL, NULL);
    hearth_uv_islands(&mesh, isl, &nisl, NULL);
    /* (island, value) pairs of observed texels, sorted, for exact lookups */
    double *key = malloc(2 * N * sizeof *key);
    size_t nk = 0;
    for (size_t q = 0; q < N; q++)
      if (r.mask[q] == HEARTH_TEXEL_OBSERVED) {
        key[2 * nk] = (double)isl[tri[q]];
        key[2 * nk + 1] = (double)r.observed[q];
        nk++;
      }
    qsort(key, nk, 2 * sizeof *key, cmp_pair);
    for (size_t q = 0; q < N; q++) {
      if (r.mask[q] != HEARTH_TEXEL_FILLED) continue;
      double want[2] = {(double)isl[tri[q]], (double)r.filled[q]};
      if (!bsearch(want, key, nk, 2 * sizeof *key, cmp_pair)) ev->cross_island++;
    }
    free(key);
    free(tri);
    free(isl);
  }
done:
  free(errs);
  hearth_map_result_free(&r);
  if (imgs)
    for (size_t v = 0; v < man.n_views; v++) hearth_image_free(&imgs[v]);
  free(imgs);
  free(views);
  hearth_npy_free(&gt);
  hearth_mesh_free(&mesh);
  hearth_manifest_free(&man);
  hearth_poses_free(&poses);
  return s;
}

#endif
