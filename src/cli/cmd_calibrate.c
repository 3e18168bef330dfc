/* hearth calibrate ROOT: thermal intrinsics and RGB-thermal stereo. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/calib.h"

static const char *k_about =
    "From ROOT/calibration/detections.json (run `hearth detect` first, or pass\n"
    "--detect to run it in the same process) and the factory colour/depth\n"
    "calibration ROOT/calibration/factory.json:\n"
    "  1. thermal intrinsics + 5-parameter distortion from the thermal-only frames\n"
    "     (Zhang's closed form, then Levenberg-Marquardt over all poses);\n"
    "  2. T_thermal_from_rgb from the stereo pairs with both intrinsics fixed.\n"
    "Frames whose residual exceeds F x the median (and PX pixels) are rejected and\n"
    "the solve repeated. Writes calibration/rig.json, calibration/rig_opencv.yaml\n"
    "(cv2.FileStorage) and calibration/calibration_report.json (per-frame RMS).\n"
    "\n"
    "--thermal-only: a root with only calibration/captures/thermal (CSV, PNG or TIFF\n"
    "frames of any name; no factory.json, no stereo pairs): thermal intrinsics with\n"
    "the 5-parameter model and OpenCV's rational model (k1..k6, p1, p2), compared on\n"
    "held-out frames; the rational model is chosen only when it predicts them at\n"
    "least 10% and 0.005 px better. rig.json then has the thermal camera only.\n";

/* --lens: auto (the held-out rule) or a model by name */
static const char *const k_lens_names[] = {"auto", "brown5", "rational8", NULL};
static const int k_lens_values[] = {-1, HEARTH_LENS_BROWN5, HEARTH_LENS_RATIONAL8};

static void print_thermal_only(const hearth_calib_report *rep, int quiet) {
  const hearth_lens_choice *lc = &rep->lens;
  if (!quiet) {
    printf("thermal frames:\n");
    for (size_t i = 0; i < rep->n_thermal; i++) {
      const hearth_calib_frame_report *f = &rep->thermal[i];
      if (isfinite(f->rms_px))
        printf("  %-12s %-4s %8.4f px  %s\n", f->frame, f->used ? "used" : "-", f->rms_px, f->note);
      else printf("  %-12s %-4s %8s     %s\n", f->frame, f->used ? "used" : "-", "", f->note);
    }
    printf("lens model   train RMS   held-out RMS\n");
    for (int m = 0; m < 2; m++) {
      const hearth_lens_fit *lf = &lc->fit[m];
      printf("  %-9s %8.4f px", hearth_lens_name((hearth_lens_model)m), lf->train_rms_px);
      if (isfinite(lf->heldout_rms_px)) printf("  %8.4f px", lf->heldout_rms_px);
      else printf("  %11s", "-");
      printf("%s\n", (int)lc->chosen == m ? "  <- chosen" : "");
    }
    printf("  %s\n", lc->reason);
    const hearth_camera *t = &rep->rig.thermal;
    printf("thermal %dx%d: fx %.4f fy %.4f cx %.4f cy %.4f dist [", t->width, t->height, t->fx,
           t->fy, t->cx, t->cy);
    for (int k = 0; k < hearth_lens_n_coeffs(t->model); k++)
      printf("%s%.6f", k ? " " : "", t->dist[k]);
    printf("]\n");
  }
  printf(
      "calibrate: thermal-only, %s lens, thermal RMS %.4f px (%.3f s); calibration/rig.json, "
      "rig_opencv.yaml written\n",
      hearth_lens_name(lc->chosen), rep->rig.thermal_rms_px, rep->t_calib_s);
}

int hearth_cmd_calibrate(int argc, char **argv) {
  int quiet = 0, detect = 0, thermal_only = 0, lens = -1;
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  hearth_detect_job run;
  hearth_detect_job_default(&run);
  cli_opt detect_opts[CLI_DETECT_OPTS];
  cli_detect_opts(&run, detect_opts);
  const char *detect_opt = NULL;
  const cli_opt opts[] = {
      CLI_FLAG("--detect", &detect, 1, "detect the plate first (as `hearth detect ROOT`)"),
      CLI_FLAG("--thermal-only", &thermal_only, 1,
               "thermal intrinsics only, from calibration/captures/thermal (see above)"),
      CLI_CHOICE("--lens", &lens, k_lens_names, k_lens_values,
                 "with --thermal-only: the lens model (auto: the held-out rule)",
                 .metavar = "MODEL", .def = "auto"),
      CLI_INT("--max-iterations", "N", &o.max_iterations, 1, 100000,
              "Levenberg-Marquardt iterations"),
      CLI_NUM("--outlier-factor", "F", &o.outlier_factor, 1, CLI_INF,
              "reject frames whose residual exceeds F x the median (and --outlier-min)",
              .flags = CLI_LO_OPEN),
      CLI_NUM("--outlier-min", "PX", &o.outlier_min_px, 0, CLI_INF,
              "residuals below PX pixels are never rejected", .flags = CLI_LO_OPEN),
      CLI_FLAG("--no-perspective-correction", &o.perspective_correction, 0,
               "use the detected centroids as they are (by default each centroid is moved to "
               "the projected hole centre using the estimated pose, removing the perspective "
               "bias of circles)"),
      CLI_FLAG("--no-wall-correction", &o.wall_correction, 0,
               "take each hole as a thin one even when calibration/target.json gives the "
               "plate's thickness_m (by default the centroid of what shows through both "
               "openings is moved to the front opening's projected centre)"),
      CLI_FLAG("--no-rolling-shutter", &o.rolling_shutter, 0,
               "take each colour frame of a stereo pair as read at one instant (by default a "
               "plate velocity per pair is solved when the residuals show the rows were read "
               "while it moved)"),
      CLI_FLAG("--fixed-intrinsics", &o.stereo_intrinsics, 0,
               "hold the thermal intrinsics of the thermal-only frames fixed in the stereo "
               "stage (the paper's; by default they are refined with the extrinsic, the pairs' "
               "plate poses fixed by the colour camera)"),
      CLI_FLAG("--refine-target", &o.target_points, 1,
               "also solve each hole's in-plane offset from the nominal lattice with the "
               "stereo stage (drilling tolerance; the offsets' similarity part held at zero), then "
               "calibrate again from the target as solved; experimental"),
      CLI_FLAG("--quiet", &quiet, 1, "summary line only"),
      CLI_GROUP("with --detect, the options of `hearth detect`", detect_opts, &detect_opt),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth calibrate",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  if (detect_opt && !detect)
    return cli_usage_error(&cmd, "option %s only applies with --detect", detect_opt);
  if (lens >= 0 && !thermal_only)
    return cli_usage_error(&cmd, "option --lens only applies with --thermal-only");
  hearth_err err = {0};
  if (detect) {
    run.quiet = 1;
    hearth_detections d = {0, NULL};
    if (hearth_calib_detect_release(root, &run, &d, &err)) return cli_fail("calibrate", &err);
    size_t found = 0;
    for (size_t i = 0; i < d.n; i++) found += (size_t)d.frames[i].found;
    printf("detect: plate found in %zu of %zu frames; calibration/detections.json written\n", found,
           d.n);
    hearth_detections_free(&d);
  }
  hearth_calib_report rep;
  if (thermal_only) {
    if (hearth_calib_thermal_only_release(root, &o, lens, &rep, &err))
      return cli_fail("calibrate", &err);
    print_thermal_only(&rep, quiet);
    hearth_calib_report_free(&rep);
    return 0;
  }
  if (hearth_calib_calibrate_release(root, &o, &rep, &err)) return cli_fail("calibrate", &err);
  if (!quiet) {
    for (int pass = 0; pass < 2; pass++) {
      size_t n = pass ? rep.n_pairs : rep.n_thermal;
      const hearth_calib_frame_report *f = pass ? rep.pairs : rep.thermal;
      printf("%s\n", pass ? "stereo pairs (RMS over both cameras):" : "thermal frames:");
      for (size_t i = 0; i < n; i++) {
        if (isfinite(f[i].rms_px))
          printf("  %-6s %-4s %8.4f px  %s\n", f[i].frame, f[i].used ? "used" : "-", f[i].rms_px,
                 f[i].note);
        else
          printf("  %-6s %-4s %8s     %s\n", f[i].frame, f[i].used ? "used" : "-", "", f[i].note);
      }
    }
    const hearth_camera *t = &rep.rig.thermal;
    printf("thermal: fx %.4f fy %.4f cx %.4f cy %.4f dist [%.6f %.6f %.6f %.6f %.6f]\n", t->fx,
           t->fy, t->cx, t->cy, t->dist[0], t->dist[1], t->dist[2], t->dist[3], t->dist[4]);
    const double *tt = rep.rig.T_thermal_from_rgb.t;
    printf("T_thermal_from_rgb: t = [%.5f %.5f %.5f] m\n", tt[0], tt[1], tt[2]);
  }
  printf(
      "calibrate: thermal RMS %.4f px, stereo RMS %.4f px (%.3f s); calibration/rig.json, "
      "rig_opencv.yaml written\n",
      rep.rig.thermal_rms_px, rep.rig.stereo_rms_px, rep.t_calib_s);
  hearth_calib_report_free(&rep);
  return 0;
}
