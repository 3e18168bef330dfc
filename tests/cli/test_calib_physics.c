/* The calibration bench with its physics on (the default synth: a plate of
 * real thickness, a lamp-heated backing, a warming plate, vignetting and
 * fixed-pattern noise in thermal, motion blur and JPEG in colour, a trigger
 * offset between the cameras, the colour camera's rolling shutter, a bowed
 * plate flexing in the hand, holes drilled off their nominal positions, the
 * plate turned every way round): `hearth detect` + `hearth calibrate` must
 * still meet the release targets against the rig's ground truth (thermal
 * focal within 0.2 %, T_thermal_from_rgb within 0.05 deg and 0.5 mm) with a
 * stereo RMS of the paper's order (0.1..0.5 px), the stereo's
 * rolling-shutter model taking the colour rows' motion out of the residual
 * that a rigid plate per pair leaves. */
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
  snprintf(root, sizeof root, "%s/rel", test_tmpdir("calib_physics"));
  snprintf(log, sizeof log, "%s.log", root);
  hearth_synth_opts o;
  hearth_synth_opts_default(&o); /* every effect on */
  o.seed = 1;
  o.out_root = root;
  o.n_views = 1;
  o.triangles = 1000;
  o.texture_size = 64;
  o.map_resolution = 32;
  o.quiet = 1;
  o.rgb_full_size = 0;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&o, &err), &err);

  /* the drawn thickness is given to the pipeline in target.json */
  hearth_target tg;
  snprintf(path, sizeof path, "%s/calibration/target.json", root);
  CHECK_OK(hearth_target_read(path, &tg, &err), &err);
  CHECK_MSG(tg.thickness_m >= 0.003 && tg.thickness_m <= 0.006, "thickness %g", tg.thickness_m);
  CHECK(hearth_target_is_default(&tg));

  CHECK(test_sh("'" HEARTH_EXE "' detect '%s' --no-overlays > '%s' 2>&1", root, log) == 0);
  CHECK(test_sh("'" HEARTH_EXE "' calibrate '%s' --quiet >> '%s' 2>&1", root, log) == 0);
  hearth_rig r, t;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &r, &err), &err);
  snprintf(path, sizeof path, "%s/ground_truth/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &t, &err), &err);
  double ang = hearth_rotation_angle_between(r.T_thermal_from_rgb.R, t.T_thermal_from_rgb.R);
  double dt = 0;
  for (int i = 0; i < 3; i++) {
    double e = r.T_thermal_from_rgb.t[i] - t.T_thermal_from_rgb.t[i];
    dt += e * e;
  }
  dt = sqrt(dt);
  fprintf(stderr,
          "thickness %.2f mm: fx %.4f%% fy %.4f%%; stereo rotation %.4f deg, translation %.3f "
          "mm; RMS thermal %.4f stereo %.4f px\n",
          1000 * tg.thickness_m, 100 * (r.thermal.fx / t.thermal.fx - 1),
          100 * (r.thermal.fy / t.thermal.fy - 1), ang * 180 / M_PI, 1000 * dt, r.thermal_rms_px,
          r.stereo_rms_px);
  CHECK(fabs(r.thermal.fx / t.thermal.fx - 1) < 0.002);
  CHECK(fabs(r.thermal.fy / t.thermal.fy - 1) < 0.002);
  CHECK(ang * 180 / M_PI < 0.05);
  CHECK(dt < 0.0005);
  /* the drilling tolerance (0.04 mm per axis against the nominal lattice
     the pipeline is given) puts the stereo residual at the paper's order
     (0.136 px here; the clean bench: 0.009 px), with the estimates held */
  CHECK_MSG(r.stereo_rms_px >= 0.1 && r.stereo_rms_px < 0.5, "stereo RMS %g", r.stereo_rms_px);
  /* a rigid plate per pair leaves the rows' motion in the residual and in
     the extrinsic */
  CHECK(test_sh("'" HEARTH_EXE "' calibrate '%s' --quiet --no-rolling-shutter >> '%s' 2>&1", root,
                log) == 0);
  hearth_rig r0;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &r0, &err), &err);
  double ang0 = hearth_rotation_angle_between(r0.T_thermal_from_rgb.R, t.T_thermal_from_rgb.R);
  fprintf(stderr, "rigid plate per pair: rotation %.4f deg, stereo RMS %.4f px\n",
          ang0 * 180 / M_PI, r0.stereo_rms_px);
  /* the rows' motion adds to the drilling's residual in quadrature (0.094
     px here) */
  double shear =
      sqrt(fmax(0.0, r0.stereo_rms_px * r0.stereo_rms_px - r.stereo_rms_px * r.stereo_rms_px));
  CHECK_MSG(shear > 0.05, "rigid RMS %g", r0.stereo_rms_px);
  CHECK(ang0 > ang);
  TEST_MAIN_END();
}
