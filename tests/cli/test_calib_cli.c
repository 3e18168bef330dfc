/* End to end on a small virtual-rig release: `hearth detect` and
 * `hearth calibrate` against the rig's ground truth (detections, thermal
 * intrinsics, stereo transform), plus the commands' usage errors. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/calib.h"
#include "hearth/dataset.h"
#include "hearth/synth.h"
#include "test_util.h"

int main(void) {
  char root[1024], path[4096], log[4096];
  snprintf(root, sizeof root, "%s/rel", test_tmpdir("calib_cli"));
  snprintf(log, sizeof log, "%s.log", root);
  hearth_synth_opts o;
  hearth_synth_opts_default(&o);
  o.ideal = 1; /* closed-form: the clean rig */
  o.seed = 5;
  o.out_root = root;
  o.n_views = 1;
  o.triangles = 1000;
  o.texture_size = 64;
  o.map_resolution = 32;
  o.n_thermal_frames = 10;
  o.n_stereo_pairs = 8;
  o.quiet = 1;
  o.rgb_full_size = 0; /* draft object views; plate frames are always full quality */
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&o, &err), &err);

  CHECK(test_sh("'" HEARTH_EXE "' detect '%s' > '%s' 2>&1", root, log) == 0);
  CHECK(test_sh("'" HEARTH_EXE "' calibrate '%s' >> '%s' 2>&1", root, log) == 0);

  /* detections against the true projected centres */
  hearth_detections d = {0, NULL}, g = {0, NULL};
  snprintf(path, sizeof path, "%s/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(path, &d, &err), &err);
  snprintf(path, sizeof path, "%s/ground_truth/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(path, &g, &err), &err);
  size_t full = 0, found = 0, wrong = 0;
  double se[2] = {0, 0};
  size_t ne[2] = {0, 0};
  for (size_t i = 0; i < g.n; i++) {
    const hearth_detection *t = &g.frames[i], *m = NULL;
    for (size_t k = 0; k < d.n; k++)
      if (!strcmp(d.frames[k].frame, t->frame) && !strcmp(d.frames[k].camera, t->camera))
        m = &d.frames[k];
    CHECK_MSG(m != NULL, "%s %s missing from detections.json", t->frame, t->camera);
    if (!m) continue;
    if (!t->found) {
      CHECK_MSG(!m->found, "%s %s: partial plate accepted", t->frame, t->camera);
      continue;
    }
    full++;
    if (!m->found) continue;
    found++;
    int c = !strcmp(t->camera, "rgb");
    for (int h = 0; h < HEARTH_PLATE_HOLES; h++) {
      double dx = m->centres[h][0] - t->centres[h][0], dy = m->centres[h][1] - t->centres[h][1];
      if (dx * dx + dy * dy > 1.0) wrong++;
      se[c] += dx * dx + dy * dy;
      ne[c]++;
    }
  }
  double rms_t = sqrt(se[0] / (double)(ne[0] ? ne[0] : 1)),
         rms_c = sqrt(se[1] / (double)(ne[1] ? ne[1] : 1));
  fprintf(stderr, "found %zu of %zu full-view frames; centre RMS thermal %.4f px, colour %.4f px\n",
          found, full, rms_t, rms_c);
  CHECK(full > 0 && found * 100 >= full * 98);
  CHECK(wrong == 0);
  CHECK(rms_t <= 0.05);
  CHECK(rms_c <= 0.1);
  hearth_detections_free(&d);
  hearth_detections_free(&g);

  /* the calibrated rig against the true one (fewer frames than the default
   * 27 + 24, so the tolerances are a little wider than the release targets) */
  hearth_rig r, t;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &r, &err), &err);
  snprintf(path, sizeof path, "%s/ground_truth/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &t, &err), &err);
  fprintf(stderr, "fx %.4f%% fy %.4f%% cx %.3f cy %.3f; stereo RMS %.4f px\n",
          100 * (r.thermal.fx / t.thermal.fx - 1), 100 * (r.thermal.fy / t.thermal.fy - 1),
          r.thermal.cx - t.thermal.cx, r.thermal.cy - t.thermal.cy, r.stereo_rms_px);
  CHECK(fabs(r.thermal.fx / t.thermal.fx - 1) < 0.004);
  CHECK(fabs(r.thermal.fy / t.thermal.fy - 1) < 0.004);
  CHECK(fabs(r.thermal.cx - t.thermal.cx) < 1.0 && fabs(r.thermal.cy - t.thermal.cy) < 1.0);
  double ang = hearth_rotation_angle_between(r.T_thermal_from_rgb.R, t.T_thermal_from_rgb.R);
  double dt = 0;
  for (int i = 0; i < 3; i++)
    dt = fmax(dt, fabs(r.T_thermal_from_rgb.t[i] - t.T_thermal_from_rgb.t[i]));
  fprintf(stderr, "stereo: rotation %.4f deg, translation %.3f mm\n", ang * 180 / M_PI, dt * 1000);
  CHECK(ang * 180 / M_PI < 0.1);
  CHECK(dt < 0.001);
  CHECK(r.stereo_rms_px <= 0.3 && r.thermal_rms_px <= 0.3);
  CHECK(r.rgb.fx == t.rgb.fx && r.depth.fx == t.depth.fx);
  snprintf(path, sizeof path, "%s/calibration/overlays/p000_rgb.png", root);
  CHECK(hearth_path_exists(path));

  /* usage and input errors */
  CHECK(test_sh("'" HEARTH_EXE "' detect --help > /dev/null%s%s", "", "") == 0);
  CHECK(test_sh("'" HEARTH_EXE "' calibrate --help > /dev/null%s%s", "", "") == 0);
  CHECK(test_sh("'" HEARTH_EXE "' detect 2> /dev/null%s%s", "", "") == 2);
  CHECK(test_sh("'" HEARTH_EXE "' calibrate --bogus x 2> /dev/null%s%s", "", "") == 2);
  CHECK(test_sh("'" HEARTH_EXE "' detect '%s/nowhere' 2> '%s'", root, log) == 1);
  uint8_t *txt = NULL;
  size_t len = 0;
  CHECK_OK(hearth_read_file(log, 1 << 16, &txt, &len, &err), &err);
  CHECK_MSG(txt && strstr((char *)txt, "nowhere/calibration/captures"), "%s",
            txt ? (char *)txt : "");
  free(txt);
  TEST_MAIN_END();
}
