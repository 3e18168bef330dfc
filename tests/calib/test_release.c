/* The release stages on a small tree the test renders itself: detect and
 * calibrate recover the cameras it used, outputs are readable (rig.json,
 * the OpenCV YAML, overlays), and bad inputs fail naming the file while
 * leaving no output behind. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "calib/calib_internal.h"
#include "calib_test_data.h"
#include "hearth/thermal.h"
#include "test_util.h"

#define NP HEARTH_PLATE_HOLES

/* a small colour camera so the test stays fast */
static void small_rgb(hearth_camera *c) {
  memset(c, 0, sizeof *c);
  c->width = 480;
  c->height = 360;
  c->fx = 400;
  c->fy = 401;
  c->cx = 240.5;
  c->cy = 179;
  c->dist[0] = 0.04;
}

static void write_thermal(const char *path, const hearth_camera *c, const hearth_rigid *T,
                          uint64_t seed) {
  hearth_image img = {0};
  hearth_err err = {0};
  CHECK_OK(hearth_image_alloc(&img, 256, 192, 1, HEARTH_PIX_F32, &err), &err);
  render(c, T, 2, 22.0, 40.0, 0.5, 0.05, seed, img.data);
  CHECK_OK(hearth_thermal_write_csv(path, &img, 2, &err), &err);
  hearth_image_free(&img);
}

static void write_rgb(const char *path, const hearth_camera *c, const hearth_rigid *T,
                      uint64_t seed) {
  hearth_image img = {0};
  hearth_err err = {0};
  size_t n = (size_t)c->width * (size_t)c->height;
  float *f = malloc(sizeof(float) * n);
  render(c, T, 2, 220.0, 20.0, 0.7, 1.0, seed, f);
  CHECK_OK(hearth_image_alloc(&img, (size_t)c->width, (size_t)c->height, 3, HEARTH_PIX_U8, &err),
           &err);
  uint8_t *p = img.data;
  for (size_t i = 0; i < n; i++) {
    double g = f[i] < 0 ? 0 : f[i] > 255 ? 255 : f[i];
    p[3 * i] = p[3 * i + 1] = p[3 * i + 2] = (uint8_t)lround(g);
  }
  CHECK_OK(hearth_jpeg_write(path, &img, 95, &err), &err);
  hearth_image_free(&img);
  free(f);
}

/* root with nf thermal frames and np pairs; returns the true rig pieces */
static void make_release(const char *root, int nf, int np, hearth_camera *th, hearth_camera *rgb,
                         hearth_rigid *Tba) {
  char path[4096];
  td_thermal_cam(th);
  small_rgb(rgb);
  double w[3] = {0.004, -0.01, 0.002};
  hearth_rotvec_to_matrix(w, Tba->R);
  Tba->t[0] = 0.03;
  Tba->t[1] = -0.01;
  Tba->t[2] = 0.002;
  snprintf(path, sizeof path, "%s/calibration/captures/thermal", root);
  hearth_err err = {0};
  CHECK_OK(hearth_mkdirs(path, &err), &err);
  snprintf(path, sizeof path, "%s/calibration/captures/stereo", root);
  CHECK_OK(hearth_mkdirs(path, &err), &err);
  hearth_rng rng;
  hearth_rng_seed(&rng, 77);
  hearth_rigid T[16];
  static double uv[16 * NP * 2];
  CHECK(td_views(&rng, th, nf, 0.7, T, uv) == nf);
  for (int i = 0; i < nf; i++) {
    snprintf(path, sizeof path, "%s/calibration/captures/thermal/f%03d.csv", root, i);
    write_thermal(path, th, &T[i], 300 + (uint64_t)i);
  }
  hearth_rigid Tab;
  hearth_rigid_inverse(Tba, &Tab);
  int k = 0;
  for (int tries = 0; k < np && tries < 1000; tries++) {
    hearth_rigid Tb, Ta;
    if (td_views(&rng, th, 1, 0.5, &Tb, uv) != 1) continue;
    hearth_rigid_compose(&Tab, &Tb, &Ta);
    if (td_project(rgb, &Ta, uv, 20) != NP) continue;
    snprintf(path, sizeof path, "%s/calibration/captures/stereo/p%03d_thermal.csv", root, k);
    write_thermal(path, th, &Tb, 400 + (uint64_t)k);
    snprintf(path, sizeof path, "%s/calibration/captures/stereo/p%03d_rgb.jpg", root, k);
    write_rgb(path, rgb, &Ta, 500 + (uint64_t)k);
    k++;
  }
  CHECK(k == np);
  hearth_factory_calib fc;
  memset(&fc, 0, sizeof fc);
  fc.rgb = *rgb;
  fc.depth = *rgb;
  hearth_rigid_identity(&fc.T_depth_from_rgb);
  snprintf(path, sizeof path, "%s/calibration/factory.json", root);
  CHECK_OK(hearth_factory_write(path, &fc, &err), &err);
}

static int exists(const char *root, const char *rel) {
  char p[4096];
  snprintf(p, sizeof p, "%s/%s", root, rel);
  return hearth_path_exists(p);
}

int main(void) {
  char root[1024], path[4096];
  snprintf(root, sizeof root, "%s", test_tmpdir("calib_release"));
  hearth_camera th, rgb;
  hearth_rigid Tba;
  make_release(root, 8, 4, &th, &rgb, &Tba);
  hearth_err err = {0};
  hearth_detect_job run;
  hearth_detect_job_default(&run);
  run.threads = 2;
  hearth_detections d = {0, NULL};
  CHECK_OK(hearth_calib_detect_release(root, &run, &d, &err), &err);
  CHECK(d.n == 16);
  for (size_t i = 0; i < d.n; i++)
    CHECK_MSG(d.frames[i].found, "%s %s: %s", d.frames[i].frame, d.frames[i].camera,
              d.frames[i].reason);
  hearth_detections_free(&d);
  /* the file round-trips and overlays exist */
  snprintf(path, sizeof path, "%s/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(path, &d, &err), &err);
  CHECK(d.n == 16 && !strcmp(d.frames[0].frame, "f000") && !strcmp(d.frames[8].frame, "p000"));
  CHECK(!strcmp(d.frames[8].camera, "thermal") && !strcmp(d.frames[9].camera, "rgb"));
  hearth_detections_free(&d);
  CHECK(exists(root, "calibration/overlays/f000_thermal.png"));
  CHECK(exists(root, "calibration/overlays/p003_rgb.png"));

  hearth_calib_report rep;
  CHECK_OK(hearth_calib_calibrate_release(root, NULL, &rep, &err), &err);
  hearth_rig rig;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(path, &rig, &err), &err);
  CHECK_NEAR(rig.thermal.fx / th.fx, 1, 0.005);
  CHECK_NEAR(rig.thermal.fy / th.fy, 1, 0.005);
  CHECK_NEAR(rig.thermal.cx, th.cx, 1.5);
  CHECK_NEAR(rig.thermal.cy, th.cy, 1.5);
  CHECK(rig.thermal.width == 256 && rig.thermal.height == 192);
  CHECK(rig.rgb.fx == rgb.fx && rig.rgb.width == rgb.width);
  double ang = hearth_rotation_angle_between(rig.T_thermal_from_rgb.R, Tba.R) * 180 / M_PI;
  CHECK_MSG(ang < 0.2, "stereo rotation error %g deg", ang);
  for (int i = 0; i < 3; i++) CHECK_NEAR(rig.T_thermal_from_rgb.t[i], Tba.t[i], 0.002);
  CHECK(rig.thermal_rms_px < 0.1 && rig.stereo_rms_px < 0.2);
  CHECK(rep.n_thermal == 8 && rep.n_pairs == 4);
  hearth_calib_report_free(&rep);
  CHECK(exists(root, "calibration/rig_opencv.yaml"));
  CHECK(exists(root, "calibration/calibration_report.json"));
  /* the YAML holds the thermal matrix as written */
  uint8_t *txt = NULL;
  size_t len = 0;
  snprintf(path, sizeof path, "%s/calibration/rig_opencv.yaml", root);
  CHECK_OK(hearth_read_file(path, 1 << 20, &txt, &len, &err), &err);
  CHECK(txt && !strncmp((char *)txt, "%YAML:1.0", 9) &&
        strstr((char *)txt, "thermal_K: !!opencv-matrix"));
  free(txt);

  /* ---- bad inputs ---- */
  /* a pair without its thermal half: error names it, nothing written */
  char bad[1024];
  snprintf(bad, sizeof bad, "%s", test_tmpdir("calib_release_bad"));
  char cmd[4200];
  snprintf(
      cmd, sizeof cmd,
      "cp -r '%s/calibration' '%s/' && rm -rf '%s/calibration/overlays' "
      "'%s/calibration/detections.json' '%s/calibration/rig.json' '%s/calibration/rig_opencv.yaml' "
      "&& rm '%s/calibration/captures/stereo/p002_thermal.csv'",
      root, bad, bad, bad, bad, bad, bad);
  CHECK(system(cmd) == 0);
  CHECK(hearth_calib_detect_release(bad, &run, NULL, &err) == HEARTH_E_NOT_FOUND);
  CHECK_MSG(strstr(err.msg, "p002_thermal.csv") != NULL, "%s", err.msg);
  CHECK(!exists(bad, "calibration/detections.json") && !exists(bad, "calibration/overlays"));
  /* calibrate before detect */
  CHECK(hearth_calib_calibrate_release(bad, NULL, &rep, &err) == HEARTH_E_NOT_FOUND);
  CHECK_MSG(strstr(err.msg, "detections.json") != NULL, "%s", err.msg);
  /* a thermal matrix of the wrong size names the file */
  snprintf(cmd, sizeof cmd,
           "cp '%s/calibration/captures/stereo/p002_rgb.jpg' /dev/null && head -n 100 "
           "'%s/calibration/captures/thermal/f001.csv' > "
           "'%s/calibration/captures/stereo/p002_thermal.csv'",
           bad, bad, bad);
  CHECK(system(cmd) == 0);
  CHECK(hearth_calib_detect_release(bad, &run, NULL, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, "p002_thermal.csv") != NULL, "%s", err.msg);
  CHECK(!exists(bad, "calibration/detections.json"));
  /* a colour image of the wrong size for factory.json names the file */
  snprintf(cmd, sizeof cmd,
           "cp '%s/calibration/captures/thermal/f001.csv' "
           "'%s/calibration/captures/stereo/p002_thermal.csv'",
           bad, bad);
  CHECK(system(cmd) == 0);
  {
    hearth_image small = {0};
    CHECK_OK(hearth_image_alloc(&small, 64, 48, 3, HEARTH_PIX_U8, &err), &err);
    snprintf(path, sizeof path, "%s/calibration/captures/stereo/p001_rgb.jpg", bad);
    CHECK_OK(hearth_jpeg_write(path, &small, 90, &err), &err);
    hearth_image_free(&small);
  }
  CHECK(hearth_calib_detect_release(bad, &run, NULL, &err) == HEARTH_E_SIZE);
  CHECK_MSG(strstr(err.msg, "p001_rgb.jpg") != NULL, "%s", err.msg);
  CHECK(!exists(bad, "calibration/detections.json"));
  /* a plate never found: detection succeeds (frames reported), calibration
   * refuses naming detections.json, and no rig.json appears */
  snprintf(cmd, sizeof cmd,
           "rm -rf '%s/calibration/captures/stereo'/* && mkdir -p '%s/calibration/captures/thermal'",
           bad, bad);
  CHECK(system(cmd) == 0);
  {
    hearth_image flat = {0};
    CHECK_OK(hearth_image_alloc(&flat, 256, 192, 1, HEARTH_PIX_F32, &err), &err);
    float *f = flat.data;
    for (size_t i = 0; i < 256 * 192; i++) f[i] = (float)(21.0 + 0.01 * (double)(i % 7));
    for (int i = 0; i < 8; i++) {
      snprintf(path, sizeof path, "%s/calibration/captures/thermal/f%03d.csv", bad, i);
      CHECK_OK(hearth_thermal_write_csv(path, &flat, 2, &err), &err);
    }
    hearth_image_free(&flat);
  }
  CHECK_OK(hearth_calib_detect_release(bad, &run, &d, &err), &err);
  for (size_t i = 0; i < d.n; i++) CHECK(!d.frames[i].found && d.frames[i].reason[0]);
  hearth_detections_free(&d);
  CHECK(hearth_calib_calibrate_release(bad, NULL, &rep, &err) == HEARTH_E_SIZE);
  CHECK_MSG(strstr(err.msg, "detections.json") != NULL && strstr(err.msg, "0 thermal-only"), "%s",
            err.msg);
  CHECK(!exists(bad, "calibration/rig.json") && !exists(bad, "calibration/rig_opencv.yaml"));
  /* missing factory.json is named */
  snprintf(cmd, sizeof cmd, "rm '%s/calibration/factory.json'", root);
  CHECK(system(cmd) == 0);
  CHECK(hearth_calib_calibrate_release(root, NULL, &rep, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, "factory.json") != NULL, "%s", err.msg);
  /* no captures at all */
  CHECK(hearth_calib_detect_release(test_tmpdir("calib_release_empty"), &run, NULL, &err) ==
        HEARTH_E_NOT_FOUND);
  CHECK_MSG(strstr(err.msg, "captures") != NULL, "%s", err.msg);
  TEST_MAIN_END();
}
