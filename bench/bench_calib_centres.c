/* The hole centres `hearth calibrate` solves from, for the detections of a
 * calibrated root: each found frame's detected centroids (detections.json)
 * corrected for the perspective bias of a hole's image and, with the
 * target's "thickness_m", for the plate's walls (calib_circle_bias), from
 * the frame's plate pose at the calibrated camera (rig.json), two passes,
 * as calibrate corrects the stereo pairs. One JSON document on stdout:
 * {"frames": [{"frame", "camera", "centres": [[u, v], ...]}, ...]}, the
 * frames found in target order (bench/calib_vs_opencv.py compares them
 * with the rig's truth).
 * usage: build/bench_calib_centres ROOT */
#include <stdio.h>
#include <string.h>

#include "calib/calib_internal.h"
#include "hearth/dataset.h"
#include "hearth/core.h"

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s ROOT\n", argv[0]);
    return 2;
  }
  char path[4096];
  hearth_err err = {0};
  hearth_detections dets = {0};
  hearth_rig rig;
  hearth_target tgt = {0}, tdef;
  snprintf(path, sizeof path, "%s/calibration/detections.json", argv[1]);
  if (hearth_detections_read(path, &dets, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  snprintf(path, sizeof path, "%s/calibration/rig.json", argv[1]);
  if (hearth_rig_read(path, &rig, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    hearth_detections_free(&dets);
    return 1;
  }
  snprintf(path, sizeof path, "%s/calibration/target.json", argv[1]);
  if (hearth_path_exists(path) && hearth_target_read(path, &tgt, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    hearth_detections_free(&dets);
    return 1;
  }
  const hearth_target *t = hearth_target_or_default(&tgt, &tdef);
  const size_t nh = hearth_target_holes(t);
  static double obj[HEARTH_TARGET_MAX_HOLES][3], raw[2 * HEARTH_TARGET_MAX_HOLES],
      cor[2 * HEARTH_TARGET_MAX_HOLES], bias[2 * HEARTH_TARGET_MAX_HOLES];
  hearth_target_points(t, obj);
  printf("{\"frames\": [");
  int first = 1;
  for (size_t i = 0; i < dets.n; i++) {
    const hearth_detection *d = &dets.frames[i];
    if (!d->found) continue;
    const hearth_camera *c = strcmp(d->camera, "rgb") ? &rig.thermal : &rig.rgb;
    memcpy(raw, d->centres, sizeof(double) * 2 * nh);
    memcpy(cor, raw, sizeof(double) * 2 * nh);
    for (int pass = 0; pass < 2; pass++) {
      hearth_rigid T;
      hearth_err e2;
      if (hearth_calib_pose(c, (const double(*)[3])obj, nh, cor, &T, NULL, &e2)) break;
      calib_circle_bias(c, &T, (const double(*)[3])obj, nh, 0.5 * t->hole_diameter_m,
                        t->thickness_m, bias);
      for (size_t q = 0; q < 2 * nh; q++) cor[q] = raw[q] - bias[q];
    }
    printf("%s\n  {\"frame\": \"%s\", \"camera\": \"%s\", \"centres\": [", first ? "" : ",",
           d->frame, d->camera);
    for (size_t k = 0; k < nh; k++)
      printf("%s[%.17g, %.17g]", k ? ", " : "", cor[2 * k], cor[2 * k + 1]);
    printf("]}");
    first = 0;
  }
  printf("\n]}\n");
  hearth_detections_free(&dets);
  return 0;
}
