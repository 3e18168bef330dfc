/* Pose error of an estimated poses file against a reference one after the
 * best similarity (hearth_poses_align): how many views the estimate has,
 * the similarity's scale, and the rotation and camera-centre errors left
 * (centre errors in the reference's units and relative to the mean camera
 * distance from the centroid of the reference centres).
 * With --views, one line per common view as well.
 * usage: build/bench_pose_error EST.json REF.json [--views] */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hearth/recon.h"

int main(int argc, char **argv) {
  int per_view = argc == 4 && !strcmp(argv[3], "--views");
  if (argc != 3 && !per_view) {
    fprintf(stderr, "usage: %s EST.json REF.json [--views]\n", argv[0]);
    return 2;
  }
  hearth_err err = {0};
  hearth_poses est, ref;
  if (hearth_poses_read(argv[1], &est, &err) || hearth_poses_read(argv[2], &ref, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  printf("views: %zu of %zu in the reference have an estimated pose (%.1f%%)\n", est.n, ref.n,
         ref.n ? 100.0 * (double)est.n / (double)ref.n : 0.0);
  hearth_pose_alignment a;
  int rc = 0;
  if (hearth_poses_align(&est, &ref, &a, &err)) {
    fprintf(stderr, "alignment: %s\n", err.msg);
    rc = 1;
  } else {
    double c[3] = {0}, spread = 0;
    for (size_t i = 0; i < ref.n; i++)
      for (int k = 0; k < 3; k++) c[k] += ref.views[i].T_world_from_cam.t[k] / (double)ref.n;
    for (size_t i = 0; i < ref.n; i++) {
      double d2 = 0;
      for (int k = 0; k < 3; k++) {
        double d = ref.views[i].T_world_from_cam.t[k] - c[k];
        d2 += d * d;
      }
      spread += sqrt(d2) / (double)ref.n;
    }
    printf("similarity: scale %.6g over %zu common views\n", a.ref_from_est.s, a.n_common);
    printf("rotation error: median %.4f deg, max %.4f deg\n", a.rot_median_deg, a.rot_max_deg);
    printf(
        "centre error: median %.3f mm, rms %.3f mm, max %.3f mm (reference in metres); "
        "median %.4f %% of the mean camera distance %.3f m\n",
        1e3 * a.pos_median, 1e3 * a.pos_rms, 1e3 * a.pos_max,
        spread > 0 ? 100.0 * a.pos_median / spread : 0.0, spread);
    const hearth_similarity *S = &a.ref_from_est;
    for (size_t i = 0; per_view && i < est.n; i++) {
      const hearth_view_pose *e = &est.views[i], *r = hearth_poses_find(&ref, e->state, e->view);
      if (!r) continue;
      double x[3], Ra[9], d2 = 0;
      hearth_rigid_rotate(&S->T, e->T_world_from_cam.t, x);
      for (int k = 0; k < 3; k++) {
        double d = S->s * x[k] + S->T.t[k] - r->T_world_from_cam.t[k];
        d2 += d * d;
      }
      hearth_mat3_mul(S->T.R, e->T_world_from_cam.R, Ra);
      printf("  %s/%s: rotation %.4f deg, centre %.3f mm\n", e->state, e->view,
             hearth_rotation_angle_between(Ra, r->T_world_from_cam.R) * 180.0 / M_PI,
             1e3 * sqrt(d2));
    }
  }
  hearth_poses_free(&est);
  hearth_poses_free(&ref);
  return rc;
}
