/* hearth detect ROOT: plate hole centres in the calibration captures. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/calib.h"

static const char *k_help =
    "usage: hearth detect ROOT [--no-overlays] [--threads N] [--upsample N]\n"
    "                          [--max-blur F] [--quiet]\n"
    "\n"
    "Finds the 84 hole centres of the calibration plate in every capture under\n"
    "ROOT/calibration/captures (thermal/fNNN.csv, stereo/pNNN_rgb.jpg +\n"
    "pNNN_thermal.csv). Colour: dark blobs. Thermal: per-frame percentile clip,\n"
    "8-bit, upsampled, blob detection, then an intensity-weighted centroid on the\n"
    "raw matrix (never altered), in native pixels. Centres are ordered by the\n"
    "plate's rows (11/10 pattern), the same hole index in every frame and camera;\n"
    "partial, blurred or missing plates are reported and marked found=false.\n"
    "\n"
    "Writes ROOT/calibration/detections.json and overlay images\n"
    "ROOT/calibration/overlays/<frame>_<camera>.png (centres joined row by row).\n"
    "\n"
    "  --no-overlays   skip the overlay images\n"
    "  --threads N     worker threads (default: HEARTH_THREADS or all cores)\n"
    "  --upsample N    thermal upsampling for blob detection (1..8, default 4)\n"
    "  --max-blur F    reject frames whose edge spread exceeds F hole radii (default 0.4)\n"
    "  --quiet         no per-frame lines\n";

int hearth_cmd_detect(int argc, char **argv) {
  const char *root = NULL;
  hearth_detect_job run;
  hearth_detect_job_default(&run);
  for (int i = 1; i < argc; i++) {
    const char *v;
    int r;
    long n;
    double f;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if (!strcmp(argv[i], "--no-overlays")) {
      run.overlays = 0;
    } else if (!strcmp(argv[i], "--quiet")) {
      run.quiet = 1;
    } else if ((r = cli_opt(argc, argv, &i, "--threads", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 1024, &n)) goto bad;
      run.threads = (int)n;
    } else if ((r = cli_opt(argc, argv, &i, "--upsample", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 8, &n)) goto bad;
      run.detect.upsample = (int)n;
    } else if ((r = cli_opt(argc, argv, &i, "--max-blur", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &f) || !(f > 0)) goto bad;
      run.detect.max_blur_frac = f;
    } else if (cli_root_arg("detect", argv[i], &root, k_help)) {
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth detect: option '%s' needs a value\n", argv[i]);
    return 2;
  bad:;
    char optbuf[64];
    fprintf(stderr, "hearth detect: bad value '%s' for %s\n", v, cli_opt_name(argv, i, v, optbuf, sizeof optbuf));
    return 2;
  }
  if (!root) return cli_missing_root("detect", k_help);
  hearth_err err = {0};
  hearth_detections d = {0, NULL};
  double t0 = hearth_now();
  if (hearth_calib_detect_release(root, &run, &d, &err)) return cli_fail("detect", &err);
  double dt = hearth_now() - t0;
  size_t found = 0;
  for (size_t i = 0; i < d.n; i++) {
    found += (size_t)d.frames[i].found;
    if (!run.quiet && !d.frames[i].found)
      printf("  %s %-7s not used: %s\n", d.frames[i].frame, d.frames[i].camera, d.frames[i].reason);
  }
  printf("detect: plate found in %zu of %zu frames (%.2f s); calibration/detections.json written\n",
         found, d.n, dt);
  hearth_detections_free(&d);
  return 0;
}
