/* Issue 19's geometry and pose figures of a virtual-rig release that hearth
 * reconstructed itself (hearth synth --recon none, then hearth build), one
 * line per instance, read from the files the build left: recon/poses_rgb.json
 * against ground_truth/.../poses_rgb.json after the best similarity (its
 * scale, rotation and camera-centre errors), and recon/mesh_geometry.glb
 * through that similarity against the true mesh: RMS and max of recon->true
 * over every vertex, true->recon over every true vertex and over the true
 * vertices some true depth view sees (tests/recon/true_visibility.h), and
 * the openings the mesh keeps (hearth_mesh_open_loops).
 * usage: bench_recon_release ROOT */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/hearth.h"
#include "recon/true_visibility.h"

static int instance(const char *root, const char *id) {
  char path[1400];
  hearth_err err = {0};
  hearth_poses est = {0}, ref = {0};
  hearth_mesh m = {0}, gt = {0};
  uint8_t *vis = NULL;
  int rc = 1;
  snprintf(path, sizeof path, "%s/instances/%s/recon/poses_rgb.json", root, id);
  if (hearth_poses_read(path, &est, &err)) goto done;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, id);
  if (hearth_poses_read(path, &ref, &err)) goto done;
  hearth_pose_alignment a;
  if (hearth_poses_align(&est, &ref, &a, &err)) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/recon/mesh_geometry.glb", root, id);
  if (hearth_glb_read(path, NULL, &m, &err)) goto done;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/mesh.glb", root, id);
  if (hearth_glb_read(path, NULL, &gt, &err)) goto done;
  size_t loops = 0, edges = 0;
  if (hearth_mesh_open_loops(&m, &loops, &edges, &err)) goto done;
  const hearth_similarity *S = &a.ref_from_est;
  for (size_t v = 0; v < m.n_vertices; v++) {
    double x[3], y[3];
    for (int k = 0; k < 3; k++) x[k] = S->s * m.positions[3 * v + k];
    hearth_rigid_apply(&S->T, x, y);
    for (int k = 0; k < 3; k++) m.positions[3 * v + k] = (float)y[k];
  }
  double to_rms, to_max, from_rms, from_max, seen_rms = NAN, seen_max = NAN;
  mesh_to_mesh(&m, &gt, &to_rms, &to_max);
  mesh_to_mesh(&gt, &m, &from_rms, &from_max);
  vis = calloc(gt.n_vertices ? gt.n_vertices : 1, 1);
  long nvis = vis ? true_visible_vertices(root, id, &gt, vis) : -1;
  if (nvis > 0) mesh_to_mesh_sel(&gt, vis, &m, &seen_rms, &seen_max);
  printf(
      "%-20s %5zu/%-5zu %7.4f %6.3f/%6.3f deg %6.2f/%6.2f mm | %6.3f (%5.2f) %6.3f (%5.2f) "
      "%6.3f (%5.2f) mm %5.1f%% | %zu loops, %zu edges\n",
      id, a.n_common, ref.n, S->s, a.rot_median_deg, a.rot_max_deg, 1e3 * a.pos_median,
      1e3 * a.pos_max, 1e3 * to_rms, 1e3 * to_max, 1e3 * from_rms, 1e3 * from_max, 1e3 * seen_rms,
      1e3 * seen_max, gt.n_vertices ? 100.0 * (double)nvis / (double)gt.n_vertices : 0.0, loops,
      edges);
  rc = 0;
done:
  if (rc) fprintf(stderr, "bench_recon_release: %s: %s\n", id, err.msg);
  free(vis);
  hearth_mesh_free(&m);
  hearth_mesh_free(&gt);
  hearth_poses_free(&est);
  hearth_poses_free(&ref);
  return rc;
}

static int cmp_name(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: bench_recon_release ROOT\n");
    return 2;
  }
  char path[1400];
  snprintf(path, sizeof path, "%s/instances", argv[1]);
  DIR *d = opendir(path);
  if (!d) {
    fprintf(stderr, "bench_recon_release: %s: cannot open\n", path);
    return 1;
  }
  char *ids[256];
  size_t n = 0;
  struct dirent *e;
  while ((e = readdir(d)) && n < 256)
    if (e->d_name[0] != '.') ids[n++] = strdup(e->d_name);
  closedir(d);
  qsort(ids, n, sizeof *ids, cmp_name);
  printf("%-20s %11s %7s %17s %17s | %14s %14s %14s %6s | openings\n", "instance", "views", "scale",
         "rot med/max", "centre med/max", "recon->true", "true->recon", "seen->recon", "seen");
  int rc = 0;
  for (size_t i = 0; i < n; i++) {
    rc |= instance(argv[1], ids[i]);
    free(ids[i]);
  }
  return rc;
}
