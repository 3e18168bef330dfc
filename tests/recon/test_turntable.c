/* The embedded pose route: turntable geometry and joint point-to-plane ICP
 * on a small virtual-rig release, checked against the rig's true colour
 * poses after the best similarity; bad input (a missing depth map, an
 * empty cut-out) named in the error.
 *
 * With arguments ROOT INSTANCE [mesh] it only estimates that instance's
 * poses of an existing release and prints the errors, and with `mesh` also
 * the surface errors of the mesh fused with them (bench/recon_turntable.sh;
 * RECON_TT_VERBOSE=1 prints every view). */
#include <jansson.h>
#include <sys/wait.h>
#include "hearth/dataset.h"
#include "hearth/image.h"
#include "hearth/npy.h"
#include "hearth/recon.h"
#include "hearth/recon_geom.h"
#include "../test_util.h"
#include "recon/mesh_distance.h"
#include "recon/true_visibility.h"

/* the options, as the bench's environment changes them */
static void env_opts(hearth_turntable_opts *o) {
  hearth_turntable_opts_default(o);
  o->quiet = 1;
  if (getenv("RECON_TT_ITERS")) o->iterations = atoi(getenv("RECON_TT_ITERS"));
  if (getenv("RECON_TT_PRIOR")) o->azimuth_prior = atof(getenv("RECON_TT_PRIOR"));
  if (getenv("RECON_TT_NO_ENCODER")) o->ignore_encoder = 1;
  if (getenv("RECON_TT_COLOUR")) o->colour_weight = atof(getenv("RECON_TT_COLOUR"));
  if (getenv("RECON_TT_ENCODER")) o->encoder_prior = atof(getenv("RECON_TT_ENCODER"));
  if (getenv("RECON_TT_COLOUR_ALL")) o->colour_with_encoder = 1;
  if (getenv("RECON_TT_AIM")) o->aim_prior = atof(getenv("RECON_TT_AIM"));
  if (getenv("RECON_TT_AIM_TOL")) o->aim_depth_tol = atof(getenv("RECON_TT_AIM_TOL"));
  if (getenv("RECON_TT_AIM_SIDE")) o->aim_side_m = atof(getenv("RECON_TT_AIM_SIDE"));
  if (getenv("RECON_TT_AIM_H")) o->aim_height_tol = atof(getenv("RECON_TT_AIM_H"));
  if (getenv("RECON_TT_AIM_RING")) o->aim_per_ring = atoi(getenv("RECON_TT_AIM_RING"));
  if (getenv("RECON_TT_RING")) o->ring_tilt_prior = atof(getenv("RECON_TT_RING"));
  if (getenv("RECON_TT_ROLL")) o->roll_prior = atof(getenv("RECON_TT_ROLL"));
  if (getenv("RECON_TT_WALL")) o->wall_prior = atof(getenv("RECON_TT_WALL"));
}

/* estimate, align to the truth, print; -1 if the estimate failed. With
 * via_recon, the estimate is hearth_recon_run's (poses and report only):
 * the poses read back from recon/poses_rgb.json, beside recon/report.json;
 * lev (may be NULL): how the views were levelled */
typedef struct levelling {
  size_t ring_plane, free_ring; /* on their ring's plane; rings started from others */
  size_t wall, wall_check;      /* levelled by the backdrop; seeing it and the table */
  double wall_tilt_deg;         /* the backdrop's departure from vertical, measured */
} levelling;

static int run_release(const char *root, const char *instance, hearth_pose_alignment *al,
                       double *tilt_max_deg, double *icp_rms_mm, hearth_poses *keep, levelling *lev,
                       int via_recon) {
  *tilt_max_deg = 0;
  hearth_err err = {0};
  hearth_turntable_opts o;
  env_opts(&o);
  hearth_poses est, gt;
  hearth_turntable_result res;
  hearth_status s;
  if (via_recon) {
    hearth_recon_job job;
    hearth_recon_job_default(&job);
    job.root = root;
    job.instance = instance;
    job.poses = o;
    job.no_mesh = 1;
    job.force = 1;
    job.quiet = 1;
    hearth_recon_summary sum;
    s = hearth_recon_run(&job, &sum, &err);
    if (!s) {
      res = sum.poses;
      memset(&sum.poses, 0, sizeof sum.poses);
      s = hearth_poses_read(sum.poses_path, &est, &err);
      if (s) hearth_turntable_result_free(&res);
      hearth_recon_summary_free(&sum);
    }
  } else {
    s = hearth_recon_turntable(root, instance, NULL, 0, &o, &est, &res, &err);
  }
  CHECK_OK(s, &err);
  if (s) return -1;
  char path[1200];
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, instance);
  CHECK_OK(hearth_poses_read(path, &gt, &err), &err);
  CHECK_OK(hearth_poses_align(&est, &gt, al, &err), &err);
  if (getenv("RECON_TT_SAVE"))
    CHECK_OK(hearth_poses_write(getenv("RECON_TT_SAVE"), &est, &err), &err);
  *icp_rms_mm = res.icp_rms_mm;
  if (lev) {
    lev->ring_plane = res.n_ring_plane_views;
    lev->free_ring = res.n_free_ring_views;
    lev->wall = res.n_wall_views;
    lev->wall_check = res.n_wall_check_views;
    lev->wall_tilt_deg = res.wall_tilt_deg;
  }
  /* the tilt: each camera's up (the axis in its frame) taken to the true
   * world by its true pose; all must agree with their mean direction */
  double u[3] = {0, 0, 0}, (*ups)[3] = calloc(est.n ? est.n : 1, sizeof *ups);
  for (size_t i = 0; ups && i < est.n; i++) {
    const hearth_view_pose *g = hearth_poses_find(&gt, est.views[i].state, est.views[i].view);
    if (!g) continue;
    const double *n = &est.views[i].T_world_from_cam.R[6]; /* up in camera i */
    hearth_rigid_rotate(&g->T_world_from_cam, n, ups[i]);
    for (int a = 0; a < 3; a++) u[a] += ups[i][a];
  }
  double lu = hearth_norm3(u);
  for (size_t i = 0; ups && i < est.n; i++) {
    double t = acos(fmin(1.0, hearth_dot3(ups[i], u) / lu)) * 57.29577951308232;
    if (t > *tilt_max_deg) *tilt_max_deg = t;
  }
  free(ups);
  printf(
      "%s: %zu views (%zu encoder, %zu colour, %zu ring plane, %zu free ring), %zu pairs, ICP rms %.3f -> %.3f mm (median %.3f), %.1f s; "
      "scale %.5f, rotation median %.3f max %.3f deg, centre median %.2f rms %.2f max %.2f mm\n",
      instance, res.n_views, res.n_encoder_views, res.n_colour_views, res.n_ring_plane_views,
      res.n_free_ring_views, res.n_pairs, res.icp_rms_start_mm, res.icp_rms_mm, res.icp_median_mm,
      res.seconds, al->ref_from_est.s, al->rot_median_deg, al->rot_max_deg, al->pos_median * 1e3,
      al->pos_rms * 1e3, al->pos_max * 1e3);
  if (getenv("RECON_TT_VERBOSE"))
    for (size_t i = 0; i < res.n_views; i++) {
      const hearth_turntable_view *v = &res.views[i];
      const hearth_view_pose *g = hearth_poses_find(&gt, v->state, v->view);
      double R[9], c[3], ce[3], e[3];
      hearth_mat3_mul(al->ref_from_est.T.R, est.views[i].T_world_from_cam.R, R);
      for (int a = 0; a < 3; a++) ce[a] = est.views[i].T_world_from_cam.t[a];
      hearth_rigid_rotate(&al->ref_from_est.T, ce, c);
      for (int a = 0; a < 3; a++)
        e[a] = al->ref_from_est.s * c[a] + al->ref_from_est.T.t[a] - g->T_world_from_cam.t[a];
      double ez[3] = {0, 0, 1}, up_al[3], up_gt[3], up_est[3], Rt[9];
      hearth_rigid_rotate(&al->ref_from_est.T, ez, up_al);
      hearth_mat3_transpose(g->T_world_from_cam.R, Rt);
      for (int a = 0; a < 3; a++) {
        up_gt[a] = Rt[3 * a] * up_al[0] + Rt[3 * a + 1] * up_al[1] + Rt[3 * a + 2] * up_al[2];
        up_est[a] = est.views[i].T_world_from_cam.R[6 + a];
      }
      printf("  tilt err %.3f deg; ", acos(fmin(1.0, hearth_dot3(up_gt, up_est))) * 57.29578);
      /* signed error about the axis: R_gt^T R (in world: R R_gt^T) */
      double Rg_t[9], Rd[9], w[3];
      hearth_mat3_transpose(g->T_world_from_cam.R, Rg_t);
      hearth_mat3_mul(R, Rg_t, Rd);
      hearth_matrix_to_rotvec(Rd, w);
      printf("  yaw %.3f;", hearth_dot3(w, up_al) * 57.29578);
      /* the centre's error along the true camera's horizontal forward and
       * side, and up */
      double fw[3], sdw[3], ef = 0, es = 0, eu = hearth_dot3(e, up_al);
      for (int a = 0; a < 3; a++) fw[a] = g->T_world_from_cam.R[3 * a + 2];
      double fu = hearth_dot3(fw, up_al);
      for (int a = 0; a < 3; a++) fw[a] -= fu * up_al[a];
      double lf = hearth_norm3(fw);
      if (lf > 0) {
        for (int a = 0; a < 3; a++) fw[a] /= lf;
        hearth_cross3(up_al, fw, sdw);
        ef = hearth_dot3(e, fw);
        es = hearth_dot3(e, sdw);
      }
      printf("  err rot %.3f deg pos %.2f mm (forward %.2f side %.2f up %.2f)\n",
             hearth_rotation_angle_between(R, g->T_world_from_cam.R) * 57.29578,
             hearth_norm3(e) * 1e3, ef * 1e3, es * 1e3, eu * 1e3);
      printf(
          "  %s/%s: %zu points, plane %zu (rms %.2f mm), height %.3f m, elevation %.2f deg, "
          "%zu pairs, %zu matches, rms %.3f mm, d_azimuth %.2f deg\n",
          v->state, v->view, v->n_points, v->n_plane, v->plane_rms_mm, v->height_m,
          v->elevation_deg, v->n_pairs, v->n_matches, v->icp_rms_mm, v->d_azimuth_deg);
    }
  hearth_turntable_result_free(&res);
  if (keep) *keep = est;
  else hearth_poses_free(&est);
  hearth_poses_free(&gt);
  return 0;
}

/* bench: the mesh fused with the estimated poses, taken to the truth's
 * frame by the poses' best similarity, against the true mesh */
static void bench_mesh(const char *root, const char *instance, const hearth_pose_alignment *al,
                       hearth_poses *est) {
  hearth_err err = {0};
  char rel[600], path[1400];
  snprintf(rel, sizeof rel, "bench_poses_%s.json", instance);
  snprintf(path, sizeof path, "%s/%s", root, rel);
  CHECK_OK(hearth_poses_write(path, est, &err), &err);
  hearth_recon_tsdf_opts go;
  hearth_recon_tsdf_opts_default(&go);
  go.poses = rel;
  const char *vox = getenv("RECON_TT_VOXEL");
  if (vox) go.voxel_m = atof(vox);
  go.target_triangles = 40000;
  hearth_mesh m, gt;
  CHECK_OK(hearth_recon_tsdf(root, instance, NULL, 0, &go, &m, &err), &err);
  for (size_t i = 0; i < m.n_vertices; i++) {
    double x[3], y[3];
    for (int a = 0; a < 3; a++) x[a] = m.positions[3 * i + a];
    hearth_rigid_rotate(&al->ref_from_est.T, x, y);
    for (int a = 0; a < 3; a++)
      m.positions[3 * i + a] = (float)(al->ref_from_est.s * y[a] + al->ref_from_est.T.t[a]);
  }
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/mesh.glb", root, instance);
  CHECK_OK(hearth_glb_read(path, NULL, &gt, &err), &err);
  double ra, rb, ma, mb, rv = 0, mv = 0;
  mesh_to_mesh(&m, &gt, &ra, &ma);
  mesh_to_mesh(&gt, &m, &rb, &mb);
  /* true->recon again over the true vertices some depth view sees */
  uint8_t *vis = malloc(gt.n_vertices + 1);
  long nvis = vis ? true_visible_vertices(root, instance, &gt, vis) : -1;
  if (nvis > 0) mesh_to_mesh_sel(&gt, vis, &m, &rv, &mv);
  free(vis);
  printf(
      "%s: mesh (turntable poses, voxel %.1f mm) %zu triangles; RMS recon->true %.3f mm "
      "(max %.2f), true->recon %.3f mm (max %.2f), visible true->recon %.3f mm (max %.2f, "
      "%ld of %zu true vertices)\n",
      instance, go.voxel_m * 1e3, m.n_triangles, ra * 1e3, ma * 1e3, rb * 1e3, mb * 1e3, rv * 1e3,
      mv * 1e3, nvis, gt.n_vertices);
  hearth_mesh_free(&m);
  hearth_mesh_free(&gt);
}

static void run_cmd_expect(const char *cmd, int want_rc, const char *want) {
  char out[8192] = "";
  FILE *f = popen(cmd, "r");
  size_t n = f ? fread(out, 1, sizeof out - 1, f) : 0;
  out[n] = 0;
  int st = f ? pclose(f) : -1;
  int rc = st >= 0 && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  CHECK_MSG(rc == want_rc && (!want || strstr(out, want)), "%s: rc %d: %s", cmd, rc, out);
}

static void test_release(void) {
  const char *dir = test_tmpdir("recon_turntable");
  char root[1100], cmd[4096], path[1400];
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "%s synth --out '%s' --categories cup --states neutral --views 10 --no-calibration "
           "--draft-rgb --texture 256 --map-res 64 --recon none --quiet",
           HEARTH_EXE, root);
  CHECK(system(cmd) == 0);
  /* --recon none: no stand-in */
  snprintf(path, sizeof path, "%s/instances/cup_01/recon", root);
  CHECK(!hearth_path_exists(path));
  hearth_pose_alignment al;
  double tilt, icp;
  if (run_release(root, "cup_01", &al, &tilt, &icp, NULL, NULL, 0) == 0) {
    /* the table plane fixes each camera's tilt: within 0.05 degrees of the
     * truth; the depth is metric: the best similarity's scale is 1 */
    CHECK_MSG(tilt < 0.05, "tilt %g deg", tilt);
    CHECK_MSG(fabs(al.ref_from_est.s - 1.0) < 0.005, "scale %g", al.ref_from_est.s);
    /* registered: the residual is the depth noise (0.6 mm + 0.8 mm/m a map) */
    CHECK_MSG(icp < 1.2, "ICP rms %g mm", icp);
    /* the encoder's angles (turntable_deg, 0.05 degrees of error) hold
     * the angle about the axis that the cup's depth barely fixes: the
     * issue's 0.2 degrees and 2 mm (depth alone: about 1 degree, 5 mm) */
    CHECK_MSG(al.rot_median_deg < 0.2 && al.rot_max_deg < 0.3 && al.pos_median < 0.002,
              "rotation median %g max %g deg, centre %g m", al.rot_median_deg, al.rot_max_deg,
              al.pos_median);
    /* no view is left where it started (0.37 mm measured) */
    CHECK_MSG(al.pos_max < 0.0015, "centre max %g m", al.pos_max);
  }
  {
    /* without the encoder (and with the photometric term asked for):
     * every view gets the photometric term */
    hearth_err e2 = {0};
    hearth_turntable_opts o;
    hearth_turntable_opts_default(&o);
    o.quiet = 1;
    o.ignore_encoder = 1;
    o.colour_weight = 1e-2;
    hearth_poses est;
    hearth_turntable_result res;
    CHECK_OK(hearth_recon_turntable(root, "cup_01", NULL, 0, &o, &est, &res, &e2), &e2);
    CHECK_MSG(res.n_encoder_views == 0 && res.n_colour_views == 10, "%zu encoder, %zu colour",
              res.n_encoder_views, res.n_colour_views);
    hearth_turntable_result_free(&res);
    hearth_poses_free(&est);
  }
  /* hearth recon ROOT: refuses another tool's recon/mesh.glb without
   * --force, then removes it and writes poses, cameras, mesh and report */
  snprintf(cmd, sizeof cmd, "mkdir -p '%s' && echo x > '%s/mesh.glb'", path, path);
  CHECK(system(cmd) == 0);
  snprintf(cmd, sizeof cmd, "'%s' recon '%s' --quiet 2>&1", HEARTH_EXE, root);
  run_cmd_expect(cmd, 1, "--force");
  snprintf(cmd, sizeof cmd,
           "'%s' recon '%s' --quiet --force --triangles 4000 --wall 1 --roll 1 --ring-tilt 0 "
           "2>&1",
           HEARTH_EXE, root);
  run_cmd_expect(cmd, 0, "10 views");
  static const char *const k_files[] = {"poses_rgb.json", "poses_rgb_cameras.json",
                                        "mesh_geometry.glb", "report.json"};
  for (int i = 0; i < 4; i++) {
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/%s", root, k_files[i]);
    CHECK_MSG(hearth_path_exists(path), "%s", path);
  }
  /* the other tool's mesh.glb is replaced by the mesh with its own atlas */
  hearth_err err = {0};
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/mesh.glb", root);
  {
    hearth_glb_read_opts ro;
    hearth_glb_read_opts_default(&ro);
    ro.require_uvs = 1;
    hearth_mesh am;
    CHECK_OK(hearth_glb_read(path, &ro, &am, &err), &err);
    CHECK(am.uvs != NULL && am.n_triangles > 1000 && am.n_triangles <= 4000);
    hearth_mesh_free(&am);
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/report.json", root);
    char *rep = test_slurp(path, NULL);
    CHECK(rep && strstr(rep, "\"atlas\": {\"charts\": ") && strstr(rep, "\"stretch_l2\": "));
    free(rep);
  }
  hearth_poses p;
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/poses_rgb.json", root);
  CHECK_OK(hearth_poses_read(path, &p, &err), &err);
  CHECK(p.n == 10);
  hearth_poses_free(&p);
  hearth_recon_cameras cams;
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/poses_rgb_cameras.json", root);
  CHECK_OK(hearth_recon_cameras_read(path, &cams, &err), &err);
  CHECK(cams.n_views == 10 && cams.n_cameras == 1);
  hearth_recon_cameras_free(&cams);
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/report.json", root);
  char *rep = test_slurp(path, NULL);
  CHECK(rep && strstr(rep, "\"icp_rms_mm\"") && strstr(rep, "\"per_view\""));
  CHECK(rep && strstr(rep, "\"open_loops\": ") && strstr(rep, "\"open_edges\": "));
  free(rep);
  /* hearth validate reads the openings against mesh_geometry.glb's: a
     report that counts others is refused, naming the member */
  snprintf(cmd, sizeof cmd, "'%s' validate '%s' --raw-only 2>&1", HEARTH_EXE, root);
  run_cmd_expect(cmd, 0, "0 problem(s)");
  snprintf(cmd, sizeof cmd,
           "cp '%s' '%s/report.json' && sed -i 's/\"open_loops\": [0-9]*/\"open_loops\": 999/' "
           "'%s'",
           path, dir, path);
  CHECK(system(cmd) == 0);
  snprintf(cmd, sizeof cmd, "'%s' validate '%s' --raw-only 2>&1", HEARTH_EXE, root);
  run_cmd_expect(cmd, 1, "mesh.open_loops: 999, but mesh_geometry.glb has");
  snprintf(cmd, sizeof cmd, "cp '%s/report.json' '%s'", dir, path);
  CHECK(system(cmd) == 0);

  /* the reconstructed release maps: scale, transfer, bake and map run on
     hearth's own mesh and atlas (the true rig stands in for calibration) */
  snprintf(cmd, sizeof cmd,
           "cp '%s/ground_truth/rig.json' '%s/calibration/rig.json' && "
           "'%s' build '%s' --resolution 64 --threads 2 >/dev/null 2>&1",
           root, root, HEARTH_EXE, root);
  CHECK(system(cmd) == 0);
  {
    hearth_npy mask = {0};
    snprintf(path, sizeof path, "%s/instances/cup_01/derived/neutral/mask.npy", root);
    CHECK_OK(hearth_npy_read(path, &mask, &err), &err);
    size_t n = mask.ndim == 2 ? mask.shape[0] * mask.shape[1] : 0, on = 0;
    for (size_t i = 0; mask.data && mask.dtype == HEARTH_NPY_U8 && i < n; i++)
      on += ((const uint8_t *)mask.data)[i] != 0;
    /* the observed texels of a cup seen from 10 views */
    CHECK_MSG(n == 64 * 64 && on > n / 10, "mask: %zu of %zu texels observed", on, n);
    hearth_npy_free(&mask);
    snprintf(path, sizeof path, "%s/instances/cup_01/derived/rgb_texture.png", root);
    CHECK(hearth_path_exists(path));
  }

  /* bad input names the file: a missing depth map, an empty cut-out */
  snprintf(cmd, sizeof cmd, "mv '%s/instances/cup_01/raw/neutral/depth/v03.png' '%s/v03.png'", root,
           dir);
  CHECK(system(cmd) == 0);
  hearth_poses est;
  hearth_status s = hearth_recon_turntable(root, "cup_01", NULL, 0, NULL, &est, NULL, &err);
  CHECK_MSG(s == HEARTH_E_NOT_FOUND && strstr(err.msg, "depth/v03.png") &&
                strstr(err.msg, "no depth map"),
            "%s", err.msg);
  snprintf(cmd, sizeof cmd, "mv '%s/v03.png' '%s/instances/cup_01/raw/neutral/depth/v03.png'", dir,
           root);
  CHECK(system(cmd) == 0);
  hearth_image cut = {0};
  snprintf(path, sizeof path, "%s/instances/cup_01/raw/neutral/cutout/v06.png", root);
  CHECK_OK(hearth_png_read(path, &cut, &err), &err);
  memset(cut.data, 0, cut.width * cut.height * (size_t)cut.channels);
  CHECK_OK(hearth_png_write(path, &cut, &err), &err);
  hearth_image_free(&cut);
  s = hearth_recon_turntable(root, "cup_01", NULL, 0, NULL, &est, NULL, &err);
  CHECK_MSG(s == HEARTH_E_INCONSISTENT && strstr(err.msg, "cutout/v06.png") &&
                strstr(err.msg, "empty"),
            "%s", err.msg);
}

/* A phone (flat) at seed 7: the low ring's cameras, 25 mm above the
 * turntable, see it at grazing incidence, mostly beyond the depth
 * camera's range and reach; their depth shows a backdrop or nothing the
 * phone stands on. Those views take their ring's plane instead of failing
 * (`no turntable plane found`) or levelling on the backdrop (tilts of
 * 80 degrees), and the backdrop, a vertical wall, levels them with the
 * rig's tilt axis (before: the ring's plane, the one view's that sees the
 * table at grazing incidence, held them: tilt 1.0 degrees, rotation max
 * 0.96, scale 1.004; now 0.11, 0.14, 1.001). */
static void test_flat_low(void) {
  const char *dir = test_tmpdir("recon_turntable_flat");
  char root[1100], cmd[4096];
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "%s synth --out '%s' --categories smartphone --states neutral --views 10 --seed 7 "
           "--no-calibration --draft-rgb --texture 256 --map-res 64 --recon none --quiet",
           HEARTH_EXE, root);
  CHECK(system(cmd) == 0);
  hearth_pose_alignment al;
  double tilt, icp;
  levelling lev;
  if (run_release(root, "smartphone_01", &al, &tilt, &icp, NULL, &lev, 0) == 0) {
    /* three of the four low views have no table of their own */
    CHECK_MSG(lev.ring_plane >= 3 && lev.ring_plane <= 4, "%zu views on their ring's plane",
              lev.ring_plane);
    /* every camera levelled: its up within 0.4 degrees of the others' */
    CHECK_MSG(tilt < 0.4, "tilt %g deg", tilt);
    CHECK_MSG(al.rot_max_deg < 0.4, "rotation max %g deg", al.rot_max_deg);
    CHECK_MSG(fabs(al.ref_from_est.s - 1.0) < 0.01, "scale %g", al.ref_from_est.s);
  }
}

/* Seed 3's phone: no view of its low ring (10.6 degrees) finds the
 * turntable, so no view there can borrow a plane (before: `no turntable
 * plane found ... nor in any view of its elevation`). The ring starts from
 * the backdrop each view sees (vertical) and the rig's tilt axis from the
 * other rings, and the ICP settles it against them. The backdrop is taken
 * as vertical only because the views with a table show it so: leaning
 * back by 5 degrees (`synth --backdrop-tilt 5`) it is measured as such
 * and levels nothing, and the ring is still reconstructed. */
static void flat_low_ring(double backdrop_tilt_deg, levelling *lev, hearth_pose_alignment *al,
                          double *tilt) {
  char name[64], root[1100], cmd[4096];
  snprintf(name, sizeof name, "recon_turntable_flat_ring_%g", backdrop_tilt_deg);
  const char *dir = test_tmpdir(name);
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "%s synth --out '%s' --categories smartphone --states neutral --views 10 --seed 3 "
           "--no-calibration --draft-rgb --texture 256 --map-res 64 --recon none --quiet "
           "--backdrop-tilt %g",
           HEARTH_EXE, root, backdrop_tilt_deg);
  CHECK(system(cmd) == 0);
  double icp;
  memset(lev, 0, sizeof *lev);
  lev->wall_tilt_deg = NAN;
  al->rot_max_deg = al->pos_max = 1e9;
  CHECK(run_release(root, "smartphone_01", al, tilt, &icp, NULL, lev, 0) == 0);
}

static void test_flat_low_ring(void) {
  hearth_pose_alignment al;
  double tilt;
  levelling lev;
  flat_low_ring(0, &lev, &al, &tilt);
  CHECK_MSG(lev.ring_plane == 0 && lev.free_ring == 4, "%zu views on their ring's plane, %zu free",
            lev.ring_plane, lev.free_ring);
  CHECK_MSG(lev.wall == 4 && lev.wall_check >= 3 && lev.wall_tilt_deg < 0.2,
            "%zu views levelled by the backdrop, %zu checked it: %g deg off vertical", lev.wall,
            lev.wall_check, lev.wall_tilt_deg);
  /* the ring's 4 views levelled within 0.2 degrees (0.02 now) */
  CHECK_MSG(tilt < 0.2, "tilt %g deg", tilt);
  CHECK_MSG(al.rot_max_deg < 0.3, "rotation max %g deg", al.rot_max_deg);
  CHECK_MSG(al.pos_max < 0.0015, "centre max %g mm", al.pos_max * 1e3);
  CHECK_MSG(fabs(al.ref_from_est.s - 1.0) < 0.01, "scale %g", al.ref_from_est.s);

  /* the wall term off (hearth recon --wall 0): nothing is levelled by the
     backdrop, and the ring is still reconstructed */
  setenv("RECON_TT_WALL", "0", 1);
  flat_low_ring(0, &lev, &al, &tilt);
  unsetenv("RECON_TT_WALL");
  CHECK_MSG(lev.wall == 0 && lev.free_ring == 4 && al.rot_max_deg < 5,
            "wall term off: %zu views levelled by the backdrop, rotation max %g deg", lev.wall,
            al.rot_max_deg);

  flat_low_ring(5, &lev, &al, &tilt);
  CHECK_MSG(lev.wall == 0 && lev.wall_check >= 3 && fabs(lev.wall_tilt_deg - 5) < 0.3,
            "leaning backdrop: %zu views levelled by it, %zu checked it: %g deg off vertical",
            lev.wall, lev.wall_check, lev.wall_tilt_deg);
  CHECK_MSG(lev.free_ring == 4 && al.rot_max_deg < 5, "leaning backdrop: rotation max %g deg",
            al.rot_max_deg);
}

/* ---- the aim point against the truth --------------------------------------
 * The virtual rig aims each thermal camera at one point c (synth_look_at on
 * the object's box centre, src/synth/synth_release.c) with its x axis level,
 * and turns the object under them; each view's distance to c is jittered by
 * up to 2%. So, from ground_truth/ alone (the true colour poses, the true
 * T_thermal_from_rgb): c is where the thermal optical axes meet (least
 * squares), the turntable axis is the direction normal to every thermal
 * x axis, and c's place in each colour camera's frame is P_i. */
typedef struct aim_truth {
  double c[3], up[3]; /* the truth's frame */
  double P[3];        /* mean of the views' P_i */
  double side_rms;    /* the P_i's spread about P: across the optical axis */
  double depth_rms;   /* and along it */
  double miss_rms;    /* the thermal axes' RMS distance from c */
  size_t n;
} aim_truth;

static int solve3(const double M[9], const double b[3], double x[3]) {
  double det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
               M[2] * (M[3] * M[7] - M[4] * M[6]);
  if (!(fabs(det) > 1e-300)) return 0;
  for (int k = 0; k < 3; k++) {
    double A[9];
    memcpy(A, M, sizeof A);
    for (int r = 0; r < 3; r++) A[3 * r + k] = b[r];
    x[k] = (A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
            A[2] * (A[3] * A[7] - A[4] * A[6])) /
           det;
  }
  return 1;
}

static int aim_truth_of(const char *root, const char *instance, aim_truth *t) {
  memset(t, 0, sizeof *t);
  hearth_err err = {0};
  char path[1200];
  hearth_poses gt;
  hearth_rig rig;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, instance);
  CHECK_OK(hearth_poses_read(path, &gt, &err), &err);
  snprintf(path, sizeof path, "%s/ground_truth/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &rig, &err), &err);
  if (!gt.n) return -1;
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&rig.T_thermal_from_rgb, &T_rgb_from_th);
  hearth_rigid *th = calloc(gt.n, sizeof *th);
  double M[9] = {0}, b[3] = {0};
  for (size_t i = 0; th && i < gt.n; i++) {
    hearth_rigid_compose(&gt.views[i].T_world_from_cam, &T_rgb_from_th, &th[i]);
    const double d[3] = {th[i].R[2], th[i].R[5], th[i].R[8]}, *o = th[i].t;
    for (int r = 0; r < 3; r++)
      for (int c = 0; c < 3; c++) {
        double pr = (r == c) - d[r] * d[c];
        M[3 * r + c] += pr;
        b[r] += pr * o[c];
      }
  }
  int ok = th && solve3(M, b, t->c);
  /* the axis: the cross products of pairs of level x axes, all along it */
  for (size_t i = 0; ok && i < gt.n; i++)
    for (size_t j = i + 1; j < gt.n; j++) {
      const double xi[3] = {th[i].R[0], th[i].R[3], th[i].R[6]};
      const double xj[3] = {th[j].R[0], th[j].R[3], th[j].R[6]};
      const double yi[3] = {th[i].R[1], th[i].R[4], th[i].R[7]};
      double u[3];
      hearth_cross3(xi, xj, u);
      double sg = hearth_dot3(u, yi) < 0 ? 1.0 : -1.0; /* a camera's y points down */
      for (int a = 0; a < 3; a++) t->up[a] += sg * u[a];
    }
  double lu = ok ? hearth_norm3(t->up) : 0;
  ok = ok && lu > 0;
  for (int a = 0; ok && a < 3; a++) t->up[a] /= lu;
  double(*P)[3] = ok ? calloc(gt.n, sizeof *P) : NULL;
  for (size_t i = 0; P && i < gt.n; i++) {
    hearth_rigid T_cam_from_world;
    hearth_rigid_inverse(&gt.views[i].T_world_from_cam, &T_cam_from_world);
    hearth_rigid_apply(&T_cam_from_world, t->c, P[i]);
    for (int a = 0; a < 3; a++) t->P[a] += P[i][a] / (double)gt.n;
    const double d[3] = {th[i].R[2], th[i].R[5], th[i].R[8]};
    double e[3] = {t->c[0] - th[i].t[0], t->c[1] - th[i].t[1], t->c[2] - th[i].t[2]}, f[3];
    hearth_cross3(d, e, f);
    t->miss_rms += hearth_dot3(f, f);
  }
  for (size_t i = 0; P && i < gt.n; i++) {
    double dx = P[i][0] - t->P[0], dy = P[i][1] - t->P[1], dz = P[i][2] - t->P[2];
    t->side_rms += dx * dx + dy * dy;
    t->depth_rms += dz * dz;
  }
  ok = ok && P;
  if (ok) {
    t->n = gt.n;
    t->side_rms = sqrt(t->side_rms / (double)gt.n);
    t->depth_rms = sqrt(t->depth_rms / (double)gt.n);
    t->miss_rms = sqrt(t->miss_rms / (double)gt.n);
  }
  free(P);
  free(th);
  hearth_poses_free(&gt);
  return ok ? 0 : -1;
}

static int json_vec3_of(const json_t *o, const char *key, double x[3]) {
  const json_t *a = json_object_get(o, key);
  if (!json_is_array(a) || json_array_size(a) != 3) return 0;
  for (size_t k = 0; k < 3; k++) {
    const json_t *v = json_array_get(a, k);
    if (!json_is_number(v)) return 0;
    x[k] = json_number_value(v);
  }
  return 1;
}

/* recon/report.json's aim point against the truth, after the poses' best
 * similarity al (truth = s R est + t) */
static void check_aim(const char *root, const char *instance, const hearth_pose_alignment *al,
                      size_t n_states, size_t views_per_state) {
  aim_truth tr;
  if (aim_truth_of(root, instance, &tr)) {
    CHECK_MSG(0, "no aim truth");
    return;
  }
  /* the truth is consistent: every thermal axis passes through c */
  CHECK_MSG(tr.miss_rms < 1e-5, "true axes miss c by %g m", tr.miss_rms);
  char path[1200];
  snprintf(path, sizeof path, "%s/instances/%s/recon/report.json", root, instance);
  json_error_t je;
  json_t *rep = json_load_file(path, 0, &je);
  CHECK_MSG(rep != NULL, "%s: %s", path, je.text);
  const json_t *aim = rep ? json_object_get(rep, "aim") : NULL;
  const char *w = getenv("RECON_TT_AIM");
  if (w && !(atof(w) > 0)) { /* the term off: null */
    CHECK_MSG(json_is_null(aim), "aim off, but report.json's aim is not null");
    json_decref(rep);
    return;
  }
  const json_t *states = json_object_get(aim, "states"), *places = json_object_get(aim, "places");
  CHECK_MSG(json_is_array(states) && json_array_size(states) == n_states, "aim.states");
  CHECK_MSG(json_is_array(places) && json_array_size(places) == 1, "aim.places");
  const double s = al->ref_from_est.s;
  /* the axis: +z of the reconstruction, taken to the truth's frame */
  double ax[3], ax_t[3];
  CHECK(json_vec3_of(aim, "axis_direction", ax));
  hearth_rigid_rotate(&al->ref_from_est.T, ax, ax_t);
  double axis_deg = acos(fmin(1.0, hearth_dot3(ax_t, tr.up))) * 57.29577951308232;
  printf(
      "%s: aim truth c (%.4f %.4f %.4f), |P| %.4f m, spread %.3f mm across, %.3f mm (%.2f%%) "
      "along; axis %.3f deg off\n",
      instance, tr.c[0], tr.c[1], tr.c[2], hearth_norm3(tr.P), tr.side_rms * 1e3,
      tr.depth_rms * 1e3, 100 * tr.depth_rms / hearth_norm3(tr.P), axis_deg);
  /* the tilt test's bound (each camera's up within 0.05 degrees) */
  CHECK_MSG(axis_deg < 0.05, "axis %g deg from the truth", axis_deg);
  for (size_t i = 0; json_is_array(states) && i < json_array_size(states); i++) {
    const json_t *st = json_array_get(states, i);
    double C[3], A[3], Ct[3], e[3];
    CHECK(json_vec3_of(st, "point_m", C) && json_vec3_of(st, "axis_m", A));
    CHECK_MSG(json_integer_value(json_object_get(st, "views")) == (json_int_t)views_per_state,
              "aim.states[%zu].views", i);
    hearth_rigid_rotate(&al->ref_from_est.T, C, Ct);
    for (int a = 0; a < 3; a++) e[a] = s * Ct[a] + al->ref_from_est.T.t[a] - tr.c[a];
    double eu = hearth_dot3(e, tr.up), eh2 = hearth_dot3(e, e) - eu * eu;
    double eh = sqrt(fmax(0.0, eh2));
    printf(
        "  %s: aimed at, after the similarity: %.3f mm from the truth (%.3f across the "
        "axis, %.3f along it)\n",
        json_string_value(json_object_get(st, "state")), hearth_norm3(e) * 1e3, eh * 1e3, eu * 1e3);
    /* across the axis every ring sees the point from all sides: as good
     * as the cameras' places (0.27 mm median measured; bound 1 mm). Along
     * it, only the rings' different elevations fix it: a relative offset
     * d of two rings in their cameras' frames (image y) moves it by
     * d / (cos 12 deg - cos 52 deg) = 2.8 d. Measured: d = 0.56 mm between
     * the low and high rings, the point 2.2 mm high; bound 4 mm (d up to
     * 1.4 mm; the pose test lets a camera be 2 mm off) */
    CHECK_MSG(eh < 0.001 && fabs(eu) < 0.004, "aimed-at point %g mm across, %g mm along the axis",
              eh * 1e3, eu * 1e3);
    /* the reported standard deviations (mm). Along the axis the model
     * (docs/dataset.md: the rings' radii free, the rings' distances within
     * the rig's 1.1% spread fixing the height) gives 2.02 mm against errors
     * of 2.19 and 2.22 mm: within 3 sigma. Below 5 mm: the 4 mm bound
     * above on the error itself, and the height prior's 17 mm (15% of the
     * can's top) would show as a sigma far above it. Across, sigma is the
     * place relative to the cameras (0.024 mm), without the cameras' own
     * errors (the 0.18 mm error is 7 sigma): only its size is checked,
     * below the term's own 0.5 mm */
    const json_t *jsa = json_object_get(st, "sigma_along_mm"),
                 *jsc = json_object_get(st, "sigma_across_mm");
    CHECK_MSG(json_is_number(jsa) && json_is_number(jsc), "aim.states[%zu]: sigmas not numbers", i);
    double sa = json_number_value(jsa), sc = json_number_value(jsc);
    printf("  reported sigma %.3f mm along the axis (error %.2f sigma), %.3f mm across (%.2f)\n",
           sa, fabs(eu) * 1e3 / sa, sc, eh * 1e3 / sc);
    CHECK_MSG(sa > 0 && fabs(eu) * 1e3 < 3 * sa, "along the axis: error %g mm, sigma %g mm",
              eu * 1e3, sa);
    CHECK_MSG(sa < 5, "sigma along the axis %g mm", sa);
    CHECK_MSG(sc > 0 && sc < 0.5, "sigma across the axis %g mm", sc);
    CHECK_MSG(A[2] == 0 && A[0] == C[0] && A[1] == C[1], "axis_m is not C on the top");
  }
  const json_t *pl = json_array_get(places, 0);
  double P[3];
  CHECK(json_vec3_of(pl, "camera_m", P));
  double eP[3];
  for (int a = 0; a < 3; a++) eP[a] = s * P[a] - tr.P[a];
  double side = json_number_value(json_object_get(pl, "side_rms_mm")),
         depth = json_number_value(json_object_get(pl, "depth_rms_mm")),
         rel = json_number_value(json_object_get(pl, "depth_rms_rel"));
  printf(
      "  P: %.3f mm from the truth's mean; fitted spread %.3f mm across, %.3f mm (%.2f%%) "
      "along\n",
      hearth_norm3(eP) * 1e3, side, depth, 100 * rel);
  CHECK(json_is_null(json_object_get(pl, "ring")));
  /* P = R^T (C - t): the aimed-at point's error, seen from a camera */
  CHECK_MSG(hearth_norm3(eP) < 0.004, "P %g mm from the truth", hearth_norm3(eP) * 1e3);
  /* the fitted spread: across, no more than the term's 0.5 mm sigma (the
   * truth's 0.03 mm plus the poses' errors); along, the rig's distance
   * jitter, which the depth sees (within a third of the truth's) */
  CHECK_MSG(side < 0.5, "fitted spread across %g mm", side);
  CHECK_MSG(fabs(depth - tr.depth_rms * 1e3) < tr.depth_rms * 1e3 / 3,
            "fitted spread along %g mm, true %g mm", depth, tr.depth_rms * 1e3);
  CHECK_NEAR(rel, depth / 1e3 / hearth_norm3(P), 1e-9);
  json_decref(rep);
}

/* A can at 10 views per state (both states): the ICP alone lets the
 * cameras "breathe" (each ring drift along its radius, which moves a depth
 * patch along the smooth cylinder and barely changes a point-to-plane
 * distance): scale 0.954 after the best similarity. The aim term ties every
 * camera to the axis point it aims at, which fixes the radii. */
static void test_can_breathing(void) {
  const char *dir = test_tmpdir("recon_turntable_can10");
  char root[1100], cmd[4096];
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "%s synth --out '%s' --categories canned_drink --views 10 --seed 1 "
           "--no-calibration --draft-rgb --texture 256 --map-res 64 --recon none --quiet",
           HEARTH_EXE, root);
  CHECK(system(cmd) == 0);
  hearth_pose_alignment al;
  double tilt, icp;
  if (run_release(root, "canned_drink_01", &al, &tilt, &icp, NULL, NULL, 1) == 0) {
    CHECK_MSG(fabs(al.ref_from_est.s - 1.0) < 0.01, "scale %g", al.ref_from_est.s);
    CHECK_MSG(al.pos_median < 0.002, "centre median %g mm", al.pos_median * 1e3);
    CHECK_MSG(al.rot_median_deg < 0.2, "rotation median %g deg", al.rot_median_deg);
    /* the report's aim point, per state, against the rig's */
    check_aim(root, "canned_drink_01", &al, 2, 10);
    /* hearth validate accepts the release with hearth's recon/ in it */
    snprintf(cmd, sizeof cmd, "'%s' validate '%s' --raw-only 2>&1", HEARTH_EXE, root);
    run_cmd_expect(cmd, 0, "0 problem(s)");
  }
}

int main(int argc, char **argv) {
  if (argc >= 3) {
    hearth_pose_alignment al;
    double tilt, icp;
    hearth_poses est = {0};
    /* ROOT INSTANCE aim STATES VIEWS: through hearth recon, the report's
     * aim point and its sigmas against the truth (a state's VIEWS views) */
    int aim = argc >= 6 && !strcmp(argv[3], "aim");
    int r = run_release(argv[1], argv[2], &al, &tilt, &icp, &est, NULL, aim);
    printf("%s: tilt max %.3f deg\n", argv[2], tilt);
    if (!r && argc >= 4 && !strcmp(argv[3], "mesh")) bench_mesh(argv[1], argv[2], &al, &est);
    if (!r && aim) check_aim(argv[1], argv[2], &al, (size_t)atoi(argv[4]), (size_t)atoi(argv[5]));
    hearth_poses_free(&est);
    return r ? 1 : g_test_failures;
  }
  test_release();
  test_flat_low();
  test_flat_low_ring();
  test_can_breathing();
  return g_test_failures;
}
