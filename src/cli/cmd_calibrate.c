/* hearth calibrate ROOT: thermal intrinsics and RGB-thermal stereo. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/calib.h"

static const char *k_help =
    "usage: hearth calibrate ROOT [--detect [--no-overlays]] [--max-iterations N]\n"
    "                             [--outlier-factor F] [--outlier-min PX]\n"
    "                             [--no-perspective-correction] [--quiet]\n"
    "\n"
    "From ROOT/calibration/detections.json (run `hearth detect` first, or pass\n"
    "--detect to run it in the same process with its default options) and the\n"
    "factory colour/depth calibration ROOT/calibration/factory.json:\n"
    "  1. thermal intrinsics + 5-parameter distortion from the thermal-only frames\n"
    "     (Zhang's closed form, then Levenberg-Marquardt over all poses);\n"
    "  2. T_thermal_from_rgb from the stereo pairs with both intrinsics fixed.\n"
    "Frames whose residual exceeds F x the median (and PX pixels) are rejected and\n"
    "the solve repeated. Writes calibration/rig.json, calibration/rig_opencv.yaml\n"
    "(cv2.FileStorage) and calibration/calibration_report.json (per-frame RMS).\n"
    "\n"
    "  --detect             detect the plate first (as `hearth detect ROOT`)\n"
    "  --no-overlays        with --detect: skip the overlay images\n"
    "  --max-iterations N   Levenberg-Marquardt iterations (default 100)\n"
    "  --outlier-factor F   default 2.5\n"
    "  --outlier-min PX     default 0.01\n"
    "  --no-perspective-correction\n"
    "                       use the detected centroids as they are (by default each\n"
    "                       centroid is moved to the projected hole centre using the\n"
    "                       estimated pose, removing the perspective bias of circles)\n"
    "  --quiet              summary line only\n";

int hearth_cmd_calibrate(int argc, char **argv) {
  const char *root = NULL;
  int quiet = 0, detect = 0, overlays = 1;
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  for (int i = 1; i < argc; i++) {
    const char *v;
    int r;
    long n;
    double f;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if (!strcmp(argv[i], "--quiet")) {
      quiet = 1;
    } else if (!strcmp(argv[i], "--detect")) {
      detect = 1;
    } else if (!strcmp(argv[i], "--no-overlays")) {
      overlays = 0;
    } else if (!strcmp(argv[i], "--no-perspective-correction")) {
      o.perspective_correction = 0;
    } else if ((r = cli_opt(argc, argv, &i, "--max-iterations", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 100000, &n)) goto bad;
      o.max_iterations = (int)n;
    } else if ((r = cli_opt(argc, argv, &i, "--outlier-factor", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &f) || !(f > 1)) goto bad;
      o.outlier_factor = f;
    } else if ((r = cli_opt(argc, argv, &i, "--outlier-min", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &f) || !(f > 0)) goto bad;
      o.outlier_min_px = f;
    } else if (cli_root_arg("calibrate", argv[i], &root, k_help)) {
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth calibrate: option '%s' needs a value\n", argv[i]);
    return 2;
  bad:;
    char optbuf[64];
    fprintf(stderr, "hearth calibrate: bad value '%s' for %s\n", v, cli_opt_name(argv, i, v, optbuf, sizeof optbuf));
    return 2;
  }
  if (!root) return cli_missing_root("calibrate", k_help);
  hearth_err err = {0};
  if (!overlays && !detect) {
    fprintf(stderr, "hearth calibrate: --no-overlays only applies with --detect\n");
    return 2;
  }
  if (detect) {
    hearth_detect_job run;
    hearth_detect_job_default(&run);
    run.overlays = overlays;
    run.quiet = 1;
    hearth_detections d = {0, NULL};
    if (hearth_calib_detect_release(root, &run, &d, &err)) return cli_fail("calibrate", &err);
    size_t found = 0;
    for (size_t i = 0; i < d.n; i++) found += (size_t)d.frames[i].found;
    printf("detect: plate found in %zu of %zu frames; calibration/detections.json written\n", found, d.n);
    hearth_detections_free(&d);
  }
  hearth_calib_report rep;
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
