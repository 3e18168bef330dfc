/* Detection and calibration as release-level build stages (hearth_build_release
 * runs them before the instances when calibration/captures/ exists). */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/calib.h"
#include "hearth/release.h"
#include "release/release_internal.h"

/* every capture frame, sorted, so a new or changed frame re-runs detection */
static hearth_status detect_files(void *ctx, const char *root, hearth_build_files *in,
                                  hearth_build_files *out, hearth_err *err) {
  const char *sub[2] = {"thermal", "stereo"};
  hearth_status s = HEARTH_OK;
  for (int j = 0; j < 2 && !s; j++) {
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/calibration/captures/%s", root, sub[j]);
    struct dirent **ents = NULL;
    int n = scandir(dir, &ents, NULL, alphasort);
    for (int i = 0; i < n; i++) {
      if (!s && ents[i]->d_name[0] != '.')
        s = hearth_build_files_add(in, "calibration/captures/%s/%s", sub[j], ents[i]->d_name);
      free(ents[i]);
    }
    free(ents);
  }
  if (!s) s = hearth_build_files_add(out, "calibration/detections.json");
  if (s) return hearth_err_set(err, s, "detect: cannot list calibration/captures");
  return HEARTH_OK;
}

static hearth_status detect_run(void *ctx, const char *root, int threads, hearth_err *err) {
  hearth_detect_job r;
  hearth_detect_job_default(&r);
  r.overlays = *(const int *)ctx;
  r.threads = threads;
  r.quiet = 1;
  hearth_detections d = {0};
  hearth_status s = hearth_calib_detect_release(root, &r, &d, err);
  hearth_detections_free(&d);
  return s;
}

static hearth_status calib_files(void *ctx, const char *root, hearth_build_files *in,
                                 hearth_build_files *out, hearth_err *err) {
  hearth_status s = hearth_build_files_add(in, "calibration/detections.json");
  if (!s) s = hearth_build_files_add(in, "calibration/factory.json");
  if (!s) s = hearth_build_files_add(out, "calibration/rig.json");
  if (!s) s = hearth_build_files_add(out, "calibration/rig_opencv.yaml");
  if (!s) s = hearth_build_files_add(out, "calibration/calibration_report.json");
  if (s) return hearth_err_set(err, s, "calibrate: out of memory");
  return HEARTH_OK;
}

static hearth_status calib_run(void *ctx, const char *root, int threads, hearth_err *err) {
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  hearth_calib_report rep;
  memset(&rep, 0, sizeof rep);
  hearth_status s = hearth_calib_calibrate_release(root, &o, &rep, err);
  if (!s) hearth_calib_report_free(&rep);
  return s;
}

size_t hb_calib_stages(const char *root, int overlays, hearth_build_stage *stages, size_t max) {
  static const int k_overlays_on = 1, k_overlays_off = 0;
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/calibration/captures", root);
  if (max < 2 || !hearth_path_exists(dir)) return 0;
  stages[0] =
      (hearth_build_stage){"detect", overlays ? "defaults overlays=1" : "defaults overlays=0",
                           detect_files, detect_run,
                           (void *)(overlays ? &k_overlays_on : &k_overlays_off)};
  stages[1] = (hearth_build_stage){"calibrate", "defaults", calib_files, calib_run, NULL};
  return 2;
}
