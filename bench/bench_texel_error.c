/* One state of a built virtual-rig release, texel by texel, for finding
 * where the worst errors sit (bench/texel_error.py reads the output): the
 * truth through surface correspondence (hearth_truth_match_state: apparent
 * temperature, distance to the matched true point, seen within 60
 * degrees, viewing conditions) and each texel's surface point and face
 * normal on derived/mesh.glb, at the map's resolution. Writes
 * OUT_DIR/{apparent,dist,away,conditions,surface}.npy.
 * usage: bench_texel_error ROOT INSTANCE STATE OUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "hearth/hearth.h"

static int put(const char *dir, const char *name, hearth_npy_dtype t, int nd, const size_t *sh,
               const void *data, hearth_err *err) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s.npy", dir, name);
  return hearth_npy_write(path, t, nd, sh, data, err) != HEARTH_OK;
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: bench_texel_error ROOT INSTANCE STATE OUT_DIR\n");
    return 2;
  }
  const char *root = argv[1], *inst = argv[2], *state = argv[3], *out = argv[4];
  hearth_err err = {0};
  char path[4096];
  hearth_npy mask = {0};
  snprintf(path, sizeof path, "%s/instances/%s/derived/%s/mask.npy", root, inst, state);
  if (hearth_npy_read(path, &mask, &err) || mask.ndim != 2) {
    fprintf(stderr, "bench_texel_error: %s\n", err.msg[0] ? err.msg : path);
    return 1;
  }
  const size_t R = mask.shape[0], n = R * R;
  hearth_npy_free(&mask);
  hearth_truth_match tm;
  if (hearth_truth_match_state(root, inst, state, R, NULL, &tm, &err)) {
    fprintf(stderr, "bench_texel_error: %s\n", err.msg);
    return 1;
  }
  hearth_mesh m = {0};
  hearth_glb_read_opts go = {.require_uvs = 1};
  snprintf(path, sizeof path, "%s/instances/%s/derived/mesh.glb", root, inst);
  uint32_t *tri = malloc(n * sizeof *tri);
  float *bary = malloc(3 * n * sizeof *bary), *surf = malloc(6 * n * sizeof *surf);
  int rc = !tri || !bary || !surf || !tm.t_apparent || hearth_glb_read(path, &go, &m, &err) ||
           hearth_uv_rasterize(&m, R, tri, bary, &err);
  /* per texel: point (3) and unit face normal (3), NaN off the surface */
  for (size_t q = 0; !rc && q < n; q++) {
    float *o = surf + 6 * q;
    if (tri[q] == UINT32_MAX) {
      for (int k = 0; k < 6; k++) o[k] = NAN;
      continue;
    }
    const uint32_t *f = m.indices + 3 * (size_t)tri[q];
    const float *v[3];
    for (int c = 0; c < 3; c++) v[c] = m.positions + 3 * (size_t)f[c];
    for (int a = 0; a < 3; a++)
      o[a] = bary[3 * q] * v[0][a] + bary[3 * q + 1] * v[1][a] + bary[3 * q + 2] * v[2][a];
    double e1[3], e2[3];
    for (int a = 0; a < 3; a++) e1[a] = v[1][a] - v[0][a], e2[a] = v[2][a] - v[0][a];
    double nr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0]};
    double l = sqrt(nr[0] * nr[0] + nr[1] * nr[1] + nr[2] * nr[2]);
    for (int a = 0; a < 3; a++) o[3 + a] = l > 0 ? (float)(nr[a] / l) : NAN;
  }
  const size_t s2[2] = {R, R}, s3[3] = {R, R, 3}, s6[3] = {R, R, 6};
  if (!rc)
    rc = put(out, "apparent", HEARTH_NPY_F32, 2, s2, tm.t_apparent, &err) ||
         put(out, "dist", HEARTH_NPY_F32, 2, s2, tm.dist_m, &err) ||
         put(out, "away", HEARTH_NPY_U8, 2, s2, tm.away, &err) ||
         (tm.conditions && put(out, "conditions", HEARTH_NPY_F32, 3, s3, tm.conditions, &err)) ||
         put(out, "surface", HEARTH_NPY_F32, 3, s6, surf, &err);
  if (rc) fprintf(stderr, "bench_texel_error: %s\n", err.msg[0] ? err.msg : "no apparent truth");
  else printf("%s/%s: %zu x %zu texels -> %s\n", inst, state, R, R, out);
  free(tri), free(bary), free(surf);
  hearth_mesh_free(&m);
  hearth_truth_match_free(&tm);
  return rc;
}
