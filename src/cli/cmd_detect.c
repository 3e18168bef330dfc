/* hearth detect ROOT: plate hole centres in the calibration captures. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/calib.h"

static const char *k_about =
    "Finds the hole centres of the calibration target (ROOT/calibration/target.json;\n"
    "absent: the paper's 84-hole plate) in every capture under\n"
    "ROOT/calibration/captures (thermal/fNNN.csv of any size, stereo/pNNN_rgb.jpg +\n"
    "pNNN_thermal.csv). Holes bright or dark in either camera. Colour: blobs at\n"
    "half size. Thermal: per-frame percentile clip, 8-bit, upsampled, blob\n"
    "detection, then an intensity-weighted centroid on the raw matrix (never\n"
    "altered), in native pixels. Centres are ordered by the target's lattice, the\n"
    "same hole index in every frame and camera (a symmetric target by the image,\n"
    "docs/dataset.md); partial, blurred, ambiguous or missing targets are reported\n"
    "and marked found=false.\n"
    "\n"
    "A root without captures/stereo is thermal-only: every file of\n"
    "ROOT/calibration/captures/thermal (sorted by name) is a frame, a CSV matrix or\n"
    "an 8-/16-bit PNG or TIFF image (recognised from its content), its frame name\n"
    "the file name without extension; holes may be brighter or darker than the\n"
    "plate. All frames must have one size.\n"
    "\n"
    "Writes ROOT/calibration/detections.json and overlay images\n"
    "ROOT/calibration/overlays/<frame>_<camera>.png (centres joined row by row).\n";

void cli_detect_opts(hearth_detect_job *run, cli_opt out[CLI_DETECT_OPTS]) {
  const cli_opt t[CLI_DETECT_OPTS] = {
      CLI_FLAG("--no-overlays", &run->overlays, 0, "skip the overlay images"),
      CLI_INT("--threads", "N", &run->threads, 1, 1024, "worker threads",
              .def = "HEARTH_THREADS or all cores"),
      CLI_INT("--upsample", "N", &run->detect.upsample, 1, 8,
              "thermal upsampling for blob detection (1..8)"),
      CLI_NUM("--max-blur", "F", &run->detect.max_blur_frac, 0, CLI_INF,
              "reject frames whose edge spread exceeds F hole radii", .flags = CLI_LO_OPEN),
      CLI_END,
  };
  memcpy(out, t, sizeof t);
}

int hearth_cmd_detect(int argc, char **argv) {
  hearth_detect_job run;
  hearth_detect_job_default(&run);
  cli_opt detect_opts[CLI_DETECT_OPTS];
  cli_detect_opts(&run, detect_opts);
  const cli_opt opts[] = {
      CLI_GROUP(NULL, detect_opts, NULL),
      CLI_FLAG("--quiet", &run.quiet, 1, "no per-frame lines"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth detect",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
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
