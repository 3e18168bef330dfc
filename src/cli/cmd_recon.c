/* hearth recon: camera poses (and geometry) of an instance, by the embedded
 * turntable route (`hearth recon ROOT`), by running COLMAP over it
 * (`--poses colmap`) or by importing a sparse model COLMAP made
 * (`hearth recon import-colmap MODEL_DIR ...`). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/recon.h"
#include "hearth/recon_geom.h"

static const char *const k_states[] = {"neutral", "hot", "warm", "iced", "used", NULL};

static const char *k_import_about =
    "Reads a COLMAP sparse model (cameras, images, points3D; binary .bin files when\n"
    "all three are there, else text .txt) and writes its registered images as hearth\n"
    "poses (T_world_from_cam, OpenCV camera axes, in the model's frame and scale) and\n"
    "their cameras beside them in <FILE without .json>_cameras.json (principal points\n"
    "moved from COLMAP's pixel convention to hearth's: cx - 0.5, cy - 0.5).\n"
    "A view is named by its image file's stem (neutral/v07.jpg -> v07); its state is\n"
    "the first folder of the image name when that is a state, else --state.\n"
    "Camera models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, and\n"
    "FULL_OPENCV with k4 = k5 = k6 = 0; fisheye and other models are refused.\n";

static int cmd_import(int argc, char **argv) {
  const char *out = NULL, *root = NULL, *instance = NULL;
  int state = 0, force = 0;
  const cli_opt opts[] = {
      CLI_STR("--out", "FILE.json", &out, "poses file to write",
              .def = "ROOT/instances/ID/recon/poses_rgb.json with --root and --instance"),
      CLI_CHOICE("--state", &state, k_states, NULL,
                 "state of images whose name has no state folder"),
      CLI_STR("--root", "ROOT", &root, "release root: check the poses against an instance's views"),
      CLI_STR("--instance", "ID", &instance, "the instance (with --root)"),
      CLI_FLAG("--force", &force, 1, "replace an existing recon/poses_rgb.json (with --root)"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth recon import-colmap",
                           .args = "MODEL_DIR",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_import_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  if (!root != !instance) return cli_usage_error(&cmd, "--root and --instance go together");
  if (!out && !root)
    return cli_usage_error(&cmd, "--out FILE.json is required (or --root and --instance)");
  char out_buf[4096], cam_path[4096];
  if (!out) {
    if (snprintf(out_buf, sizeof out_buf, "%s/instances/%s/recon/poses_rgb.json", root, instance) >=
        (int)sizeof out_buf)
      return cli_usage_error(&cmd, "--root: path too long");
    out = out_buf;
    if (hearth_path_exists(out) && !force) {
      fprintf(stderr,
              "hearth recon import-colmap: %s exists (poses in the frame of the "
              "reconstruction beside it); --force replaces it\n",
              out);
      return 1;
    }
  }
  if (hearth_recon_cameras_path(out, cam_path, sizeof cam_path))
    return cli_usage_error(&cmd, "--out: path too long");
  hearth_err err = {0};
  hearth_colmap_model m;
  hearth_status s = hearth_colmap_read(args.v[0], &m, &err);
  if (s) return cli_fail("recon import-colmap", &err);
  hearth_poses poses;
  hearth_recon_cameras cams;
  s = hearth_colmap_to_poses(&m, k_states[state], &poses, &cams, &err);
  hearth_recon_coverage cov = {0};
  if (!s && root) s = hearth_recon_match_instance(root, instance, &poses, &cov, &err);
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", out);
  char *slash = strrchr(dir, '/');
  if (!s && slash && slash != dir) {
    *slash = 0;
    s = hearth_mkdirs(dir, &err);
  }
  if (!s) s = hearth_poses_write(out, &poses, &err);
  if (!s) s = hearth_recon_cameras_write(cam_path, &cams, &err);
  if (!s) {
    printf("import-colmap %s (%s): %zu camera(s), %zu image(s), %zu point(s) -> %s, %s\n",
           args.v[0], m.format == HEARTH_COLMAP_BINARY ? "binary" : "text", m.n_cameras, m.n_images,
           m.n_points, out, cam_path);
    if (root) {
      printf("%s: %zu of %zu views have a pose", instance, cov.n_views - cov.n_missing,
             cov.n_views);
      for (size_t i = 0; i < cov.n_missing && i < HEARTH_RECON_MISSING_LISTED; i++)
        printf("%s%s", i ? ", " : "; without: ", cov.missing[i]);
      printf("%s\n", cov.n_missing > HEARTH_RECON_MISSING_LISTED ? ", ..." : "");
    }
  }
  hearth_poses_free(&poses);
  hearth_recon_cameras_free(&cams);
  hearth_colmap_model_free(&m);
  return s ? cli_fail("recon import-colmap", &err) : 0;
}

static const char *k_about =
    "Camera poses (and geometry) of an instance's colour views.\n"
    "--poses turntable (default, no outside tool): each depth map's turntable plane fixes\n"
    "its camera's tilt and height; the turntable geometry (azimuth index x --azimuth-step,\n"
    "plus --ring-shift per elevation index) starts the angle about the axis; joint\n"
    "point-to-plane ICP on the cut-out depth of all views of all states refines the angles\n"
    "and horizontal positions. A state whose manifest records the turntable's encoder\n"
    "angle (turntable_deg) per view has its angles held to it; --colour W adds, to the\n"
    "states without it, a photometric term (each view's band-passed grey against its\n"
    "neighbours').\n"
    "Writes recon/poses_rgb.json (metres, +z up the axis, the\n"
    "turntable top at z = 0), recon/poses_rgb_cameras.json (the factory colour camera),\n"
    "recon/mesh_geometry.glb (the depth maps fused with those poses; no UVs),\n"
    "recon/mesh.glb (that mesh with a UV atlas of its own: normal-clustered disc charts,\n"
    "LSCM, packed with gutters; no texture, map --rgb bakes it) and recon/report.json\n"
    "(views, ICP residuals, the aim point, per-view plane and match figures, chart\n"
    "stretch and packing).\n"
    "--poses colmap runs COLMAP (Debian's `colmap`, CPU only): feature_extractor with the\n"
    "cut-outs as masks and one camera shared by all views, exhaustive_matcher and mapper\n"
    "over every view of every state, then imports the model with the most registered\n"
    "views into recon/poses_rgb.json (and recon/poses_rgb_cameras.json, the cameras).\n"
    "Views COLMAP could not register get no pose. Each step's output is logged in the\n"
    "workspace, which a failure keeps for inspection.\n";

static const char *k_tail =
    "Import a model made elsewhere: hearth recon import-colmap MODEL_DIR --out FILE.json\n"
    "(see hearth recon import-colmap --help).\n";

/* the embedded route over one instance */
static int run_turntable(const char *root, const char *instance, const hearth_recon_job *base) {
  hearth_recon_job job = *base;
  job.root = root;
  job.instance = instance;
  hearth_recon_summary sum;
  hearth_err err = {0};
  if (hearth_recon_run(&job, &sum, &err)) return cli_fail("recon", &err);
  const hearth_turntable_result *r = &sum.poses;
  printf("recon %s: %zu views, %zu pairs, ICP rms %.3f -> %.3f mm (median %.3f), %.1f s -> %s\n",
         instance, r->n_views, r->n_pairs, r->icp_rms_start_mm, r->icp_rms_mm, r->icp_median_mm,
         r->seconds, sum.poses_path);
  for (size_t i = 0; i < r->n_aim_states; i++) {
    const hearth_turntable_aim_state *a = &r->aim_states[i];
    printf("recon %s/%s: aimed at (%.4f, %.4f, %.4f) m on the axis", instance, a->state,
           a->point_m[0], a->point_m[1], a->point_m[2]);
    if (isfinite(a->sigma_along_m) && isfinite(a->sigma_across_m))
      printf(", sigma %.2f mm along it, %.2f mm across", 1e3 * a->sigma_along_m,
             1e3 * a->sigma_across_m);
    printf("\n");
  }
  if (!job.no_mesh) {
    printf("recon %s: mesh %zu vertices, %zu triangles -> %s\n", instance, sum.mesh_vertices,
           sum.mesh_triangles, sum.mesh_path);
    printf("recon %s: atlas %zu charts, L2 stretch %.4f (max %.3f), packing %.3f -> %s\n", instance,
           sum.atlas.n_charts, sum.atlas.stretch_l2, sum.atlas.stretch_l2_max,
           sum.atlas.packing_efficiency, sum.atlas_path);
  }
  hearth_recon_summary_free(&sum);
  return 0;
}

int hearth_cmd_recon(int argc, char **argv) {
  if (argc >= 2 && !strcmp(argv[1], "import-colmap")) return cmd_import(argc - 1, argv + 1);
  static const char *const k_poses[] = {"turntable", "colmap", NULL};
  static const char *const k_intr[] = {"calibration", "estimate", NULL};
  static const int k_intr_values[] = {HEARTH_COLMAP_INTR_CALIBRATION, HEARTH_COLMAP_INTR_ESTIMATE};
  int poses = 0;
  int intr = HEARTH_COLMAP_INTR_CALIBRATION;
  hearth_colmap_job job = {0};
  hearth_recon_job tj;
  hearth_recon_job_default(&tj);
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &job.instance, "the instance",
              .def = "every instance of release.json (turntable)"),
      CLI_CHOICE("--poses", &poses, k_poses, NULL, "where the poses come from", .def = "turntable"),
      CLI_NUM("--azimuth-step", "DEG", &tj.poses.azimuth_step_deg, 1, 180,
              "turntable: degrees between azimuth indices", .def = "36"),
      CLI_NUM("--ring-shift", "DEG", &tj.poses.ring_shift_deg, -180, 180,
              "turntable: azimuth added per elevation index", .def = "12"),
      CLI_FLAG("--clockwise", &tj.poses.direction, -1,
               "turntable: azimuth grows clockwise seen from above"),
      CLI_FLAG("--no-encoder", &tj.poses.ignore_encoder, 1,
               "turntable: leave the manifests' turntable_deg unused"),
      CLI_NUM("--aim", "W", &tj.poses.aim_prior, 0, 100,
              "turntable: weight of the aim term (every camera aimed at one axis point; 0: off)",
              .def = "0.1"),
      CLI_NUM("--wall", "W", &tj.poses.wall_prior, 0, 100,
              "turntable: weight of the backdrop's levelling of views without a table (taken "
              "as vertical where the views with a table show it so; 0: off)",
              .def = "1"),
      CLI_NUM("--roll", "W", &tj.poses.roll_prior, 0, 100,
              "turntable: weight holding those views' up normal to the rig's tilt axis (0: off)",
              .def = "1"),
      CLI_NUM("--ring-tilt", "W", &tj.poses.ring_tilt_prior, 0, 100,
              "turntable: weight holding one up per ring where a view has neither a table nor "
              "a backdrop (rigs without a backdrop)",
              .def = "0: off"),
      CLI_NUM("--colour", "W", &tj.poses.colour_weight, 0, 10,
              "turntable: weight of the photometric term of states without turntable_deg "
              "(about 0.01; experimental)",
              .def = "0: off"),
      CLI_NUM("--voxel", "M", &tj.geometry.voxel_m, 0.0002, 0.05,
              "turntable: TSDF voxel of the mesh (metres)", .def = "0.002"),
      CLI_SIZE("--triangles", "N", &tj.geometry.target_triangles, 0, 10000000,
               "turntable: simplify the mesh to this many triangles (0: not)", .def = "20000"),
      CLI_FLAG("--no-mesh", &tj.no_mesh, 1, "turntable: poses and report only"),
      CLI_CHOICE("--intrinsics", &intr, k_intr, k_intr_values,
                 "colmap: calibration: the colour camera of calibration/rig.json (else "
                 "factory.json), held fixed; estimate: COLMAP's self-calibration"),
      CLI_STR("--out", "FILE.json", &job.out, "colmap: poses file to write",
              .def = "ROOT/instances/ID/recon/poses_rgb.json"),
      CLI_STR("--work", "DIR", &job.work,
              "colmap: keep COLMAP's workspace (database, model, logs) here",
              .def = "a temporary folder, removed after success"),
      CLI_STR("--colmap", "PROGRAM", &job.colmap, "colmap: the COLMAP program",
              .def = "colmap on PATH"),
      CLI_FLAG("--no-masks", &job.no_masks, 1,
               "colmap: features from the whole image, not only the cut-out"),
      CLI_INT("--threads", "N", &job.threads, 1, 1024, "threads to use",
              .def = "HEARTH_THREADS or all cores"),
      CLI_FLAG("--force", &job.force, 1, "replace an existing poses file"),
      CLI_FLAG("--quiet", &job.quiet, 1, "no progress output"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth recon",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts,
                           .tail = k_tail};
  if (argc < 2) return cli_usage_error(&cmd, "missing ROOT (see 'hearth recon --help')");
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  job.root = args.v[0];
  if (poses == 0) {
    tj.force = job.force;
    tj.quiet = job.quiet;
    tj.poses.threads = job.threads;
    if (job.out || job.work || job.colmap || job.no_masks)
      return cli_usage_error(&cmd, "--out, --work, --colmap and --no-masks go with --poses colmap");
    if (job.instance) return run_turntable(job.root, job.instance, &tj);
    char path[4096];
    if (snprintf(path, sizeof path, "%s/release.json", job.root) >= (int)sizeof path)
      return cli_usage_error(&cmd, "ROOT: path too long");
    hearth_release_doc rel;
    hearth_err err = {0};
    if (hearth_release_read(path, &rel, &err)) return cli_fail("recon", &err);
    int out = 0;
    for (size_t i = 0; i < rel.n_instances && !out; i++)
      out = run_turntable(job.root, rel.instances[i], &tj);
    hearth_release_free(&rel);
    return out;
  }
  if (!job.instance) return cli_usage_error(&cmd, "--poses colmap needs --instance ID");
  job.intrinsics = (hearth_colmap_intrinsics)intr;
  hearth_colmap_result res;
  hearth_err err = {0};
  if (hearth_colmap_run(&job, &res, &err)) return cli_fail("recon", &err);
  printf(
      "recon %s: %zu of %zu views registered (%.0f%%), %zu points, %zu model(s); "
      "extract %.1fs, match %.1fs, map %.1fs -> %s\n",
      job.instance, res.n_registered, res.n_views,
      res.n_views ? 100.0 * (double)res.n_registered / (double)res.n_views : 0.0, res.n_points,
      res.n_models, res.seconds[0], res.seconds[1], res.seconds[2], res.out);
  if (res.work[0]) printf("workspace: %s\n", res.work);
  return 0;
}
