/* Temperature maps on hearth's own reconstruction against the virtual
 * rig's truth, through surface correspondence: each observed texel of a
 * built release's derived/<state>/temperature_observed.npy (no grazing
 * filter: the map keeps no viewing angles) is taken to its surface point
 * on derived/mesh.glb (hearth recon's atlas, scaled), into the truth's
 * frame by the similarity that best maps derived/poses_rgb.json onto the
 * true colour poses, and to the nearest point of the true mesh, whose UV
 * picks the true temperature (ground_truth/.../<state>/temperature_true.npy,
 * or temperature_apparent.npy with WHICH = apparent; nearest texel).
 * usage: bench_recon_map ROOT INSTANCE STATE [WHICH] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/hearth.h"
#include "recon/mesh_distance.h"

static int cmp_d(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static int fail(const hearth_err *e) {
  fprintf(stderr, "bench_recon_map: %s\n", e->msg);
  return 1;
}

int main(int argc, char **argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: bench_recon_map ROOT INSTANCE STATE [true|apparent]\n");
    return 2;
  }
  const char *root = argv[1], *inst = argv[2], *state = argv[3];
  char path[4096];
  hearth_err e = {0};
  hearth_mesh mesh, gt;
  hearth_poses prgb, pgt;
  hearth_npy tt;
  hearth_glb_read_opts go = {.require_uvs = 1};
  snprintf(path, sizeof path, "%s/instances/%s/derived/mesh.glb", root, inst);
  if (hearth_glb_read(path, &go, &mesh, &e)) return fail(&e);
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/mesh.glb", root, inst);
  if (hearth_glb_read(path, &go, &gt, &e)) return fail(&e);
  snprintf(path, sizeof path, "%s/instances/%s/derived/poses_rgb.json", root, inst);
  if (hearth_poses_read(path, &prgb, &e)) return fail(&e);
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, inst);
  if (hearth_poses_read(path, &pgt, &e)) return fail(&e);
  const char *which = argc > 4 ? argv[4] : "true";
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/temperature_%s.npy", root, inst,
           state, which);
  if (hearth_npy_read(path, &tt, &e)) return fail(&e);
  if (tt.ndim != 2 || tt.dtype != HEARTH_NPY_F32) {
    fprintf(stderr, "%s: not a 2-D float map\n", path);
    return 1;
  }
  hearth_npy obs;
  snprintf(path, sizeof path, "%s/instances/%s/derived/%s/temperature_observed.npy", root, inst,
           state);
  if (hearth_npy_read(path, &obs, &e)) return fail(&e);
  if (obs.ndim != 2 || obs.dtype != HEARTH_NPY_F32 || obs.shape[0] != obs.shape[1]) {
    fprintf(stderr, "%s: not a square float map\n", path);
    return 1;
  }
  const size_t R = obs.shape[0];
  const float *O = obs.data;
  hearth_pose_alignment al;
  if (hearth_poses_align(&prgb, &pgt, &al, &e)) return fail(&e);
  uint32_t *tri = malloc(R * R * sizeof *tri);
  float *bary = malloc(3 * R * R * sizeof *bary);
  if (hearth_uv_rasterize(&mesh, R, tri, bary, &e)) return fail(&e);
  tri_grid g;
  tri_grid_build(&g, &gt, 0.004);
  const float *T = tt.data;
  size_t Rg = tt.shape[0];
  double *err = malloc(R * R * sizeof *err), *dist = malloc(R * R * sizeof *dist);
  size_t n = 0;
  for (size_t q = 0; q < R * R; q++) {
    if (isnan(O[q]) || tri[q] == UINT32_MAX) continue;
    double p[3] = {0, 0, 0}, x[3], w[3];
    for (int c = 0; c < 3; c++)
      for (int a = 0; a < 3; a++)
        p[a] +=
            bary[3 * q + c] * mesh.positions[3 * (size_t)mesh.indices[3 * (size_t)tri[q] + c] + a];
    hearth_rigid_apply(&al.ref_from_est.T,
                       (double[3]){al.ref_from_est.s * p[0], al.ref_from_est.s * p[1],
                                   al.ref_from_est.s * p[2]},
                       x);
    uint32_t gtri = 0;
    double cp[3];
    double d = tri_grid_nearest(&g, x, &gtri, cp);
    /* barycentrics of the closest point in the true triangle */
    const uint32_t *f = gt.indices + 3 * (size_t)gtri;
    double v[3][3];
    for (int c = 0; c < 3; c++)
      for (int a = 0; a < 3; a++) v[c][a] = gt.positions[3 * (size_t)f[c] + a];
    double e0[3], e1[3], ep[3];
    for (int a = 0; a < 3; a++)
      e0[a] = v[1][a] - v[0][a], e1[a] = v[2][a] - v[0][a], ep[a] = cp[a] - v[0][a];
    double d00 = dot3(e0, e0), d01 = dot3(e0, e1), d11 = dot3(e1, e1), d20 = dot3(ep, e0),
           d21 = dot3(ep, e1), den = d00 * d11 - d01 * d01;
    w[1] = den > 0 ? (d11 * d20 - d01 * d21) / den : 0;
    w[2] = den > 0 ? (d00 * d21 - d01 * d20) / den : 0;
    w[0] = 1 - w[1] - w[2];
    double u = 0, vv = 0;
    for (int c = 0; c < 3; c++)
      u += w[c] * gt.uvs[2 * (size_t)f[c]], vv += w[c] * gt.uvs[2 * (size_t)f[c] + 1];
    long col = (long)floor(u * (double)Rg), row = (long)floor(vv * (double)Rg);
    if (col < 0 || row < 0 || col >= (long)Rg || row >= (long)Rg) continue;
    float truth = T[(size_t)row * Rg + (size_t)col];
    if (isnan(truth)) continue;
    err[n] = fabs((double)O[q] - truth);
    dist[n++] = d;
  }
  qsort(err, n, sizeof *err, cmp_d);
  qsort(dist, n, sizeof *dist, cmp_d);
  printf(
      "%s %s: poses after similarity: rotation median %.3f deg, centre median %.2f mm; "
      "%zu observed texels (R %zu): |error| median %.3f degC, p95 %.3f, max %.2f; "
      "correspondence distance median %.2f mm, p95 %.2f\n",
      inst, state, al.rot_median_deg, al.pos_median * 1e3, n, R, n ? err[n / 2] : 0,
      n ? err[(size_t)(0.95 * (double)(n - 1))] : 0, n ? err[n - 1] : 0, n ? dist[n / 2] * 1e3 : 0,
      n ? dist[(size_t)(0.95 * (double)(n - 1))] * 1e3 : 0);
  return 0;
}
