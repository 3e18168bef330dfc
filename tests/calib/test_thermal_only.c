/* Thermal-only calibration on roots the virtual rig writes (frames as CSV,
 * 8-/16-bit PNG and TIFF of any name): a normal lens is recovered with the
 * 5-parameter model, a strongly distorted wide-angle lens with the rational
 * model (which must predict held-out frames better); OpenCV
 * (/usr/bin/python3, cv2) calibrates the same detected points to the same
 * focal length and undistorts with the YAML as hearth does; bad inputs fail
 * naming the file, exit non-zero and leave no rig.json. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include "calib/calib_internal.h"
#include "hearth/synth.h"
#include "hearth/thermal.h"
#include "test_util.h"

#define NP HEARTH_PLATE_HOLES

static char g_dir[1024];

static int g_width = 256, g_height = 192; /* the next root's frame size */

static void make_root(const char *name, int wide, int n, const char *formats, uint64_t seed,
                      char *root, size_t rs) {
  hearth_synth_thermal_opts o;
  hearth_synth_thermal_opts_default(&o);
  o.width = g_width;
  o.height = g_height;
  snprintf(root, rs, "%s/%s", g_dir, name);
  o.out_root = root;
  o.seed = seed;
  o.n_frames = n;
  o.wide_angle = wide;
  o.formats = formats;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_thermal_only(&o, &err), &err);
}

/* run the tool; returns its exit status, stderr into err_out */
static int run_tool(const char *args, char *err_out, size_t es) {
  char cmd[4096], ep[1100];
  snprintf(ep, sizeof ep, "%s/stderr.txt", g_dir);
  snprintf(cmd, sizeof cmd, "%s %s >/dev/null 2>'%s'", HEARTH_EXE, args, ep);
  int rc = system(cmd);
  char *e = test_slurp(ep, NULL);
  snprintf(err_out, es, "%s", e ? e : "");
  free(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

static int file_exists(const char *root, const char *rel) {
  char p[2048];
  snprintf(p, sizeof p, "%s/%s", root, rel);
  return hearth_path_exists(p);
}

/* detection found >= 90% of the frames and every found frame matches the
 * truth hole by hole (never mis-ordered) */
static void check_detections(const char *root, double tol_px) {
  char p[2048];
  hearth_detections d = {0}, t = {0};
  hearth_err err = {0};
  snprintf(p, sizeof p, "%s/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(p, &d, &err), &err);
  snprintf(p, sizeof p, "%s/ground_truth/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(p, &t, &err), &err);
  CHECK(d.n == t.n);
  size_t found = 0, truth_found = 0;
  double worst = 0;
  for (size_t i = 0; i < d.n && i < t.n; i++) {
    CHECK(!strcmp(d.frames[i].frame, t.frames[i].frame));
    truth_found += (size_t)t.frames[i].found;
    if (!d.frames[i].found) {
      fprintf(stderr, "  %s not found: %s\n", d.frames[i].frame, d.frames[i].reason);
      continue;
    }
    found++;
    for (int k = 0; k < NP; k++)
      worst = fmax(worst, hypot(d.frames[i].centres[k][0] - t.frames[i].centres[k][0],
                                d.frames[i].centres[k][1] - t.frames[i].centres[k][1]));
  }
  fprintf(stderr, "%s: found %zu of %zu (truth %zu), worst centre error %.4f px\n", root, found,
          d.n, truth_found, worst);
  CHECK(10 * found >= 9 * truth_found);
  CHECK_MSG(worst < tol_px, "worst centre error %.4f px", worst);
  hearth_detections_free(&d);
  hearth_detections_free(&t);
}

static json_t *load_report(const char *root) {
  char p[2048];
  snprintf(p, sizeof p, "%s/calibration/calibration_report.json", root);
  json_error_t je;
  json_t *r = json_load_file(p, 0, &je);
  CHECK_MSG(r != NULL, "%s: %s", p, je.text);
  return r;
}

static double rep_num(json_t *r, int model, const char *key) {
  json_t *m = json_array_get(json_object_get(r, "lens_models"), (size_t)model);
  json_t *v = json_object_get(m, key);
  return json_is_number(v) ? json_number_value(v) : NAN;
}

/* the calibrated camera against the truth: intrinsics, and the ray of
 * every 4th pixel (angle between recovered and true rays) */
static void check_camera(const char *root, double tol_f, double tol_c, double tol_ray_px) {
  char p[2048];
  hearth_rig rig, truth;
  hearth_err err = {0};
  snprintf(p, sizeof p, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(p, &rig, &err), &err);
  snprintf(p, sizeof p, "%s/ground_truth/rig.json", root);
  CHECK_OK(hearth_rig_read(p, &truth, &err), &err);
  CHECK(rig.thermal_only && truth.thermal_only);
  const hearth_camera *c = &rig.thermal, *g = &truth.thermal;
  fprintf(stderr, "  fx %.4f (%.4f) fy %.4f (%.4f) cx %.4f (%.4f) cy %.4f (%.4f)\n", c->fx, g->fx,
          c->fy, g->fy, c->cx, g->cx, c->cy, g->cy);
  CHECK(c->width == g->width && c->height == g->height);
  CHECK_NEAR(c->fx, g->fx, tol_f);
  CHECK_NEAR(c->fy, g->fy, tol_f);
  CHECK_NEAR(c->cx, g->cx, tol_c);
  CHECK_NEAR(c->cy, g->cy, tol_c);
  /* rays over the central 80% of the image (the plate's reach) */
  double worst = 0;
  for (int v = g->height / 10; v < g->height * 9 / 10; v += 4)
    for (int u = g->width / 10; u < g->width * 9 / 10; u += 4) {
      double a[3], b[3];
      CHECK(hearth_camera_ray(c, u, v, a) >= 0 && hearth_camera_ray(g, u, v, b) >= 0);
      double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
      worst = fmax(worst, acos(fmin(1.0, dot)) * g->fx);
    }
  fprintf(stderr, "  worst ray error %.4f px (at fx)\n", worst);
  CHECK_MSG(worst < tol_ray_px, "worst ray error %.4f px", worst);
}

/* ---- OpenCV cross-check --------------------------------------------------------------- */
static int have_cv2(void) {
  return system("/usr/bin/python3 -c 'import cv2' >/dev/null 2>&1") == 0;
}

/* the found frames' centres, hearth's own fit of them with `model`
 * (hearth_calib_intrinsics, no outlier rounds or perspective correction),
 * and pixels undistorted through rig.json's camera, for the script */
static void cv_check(const char *root, hearth_lens_model model) {
  if (!have_cv2()) {
    fprintf(stderr, "  (cv2 not available in /usr/bin/python3: OpenCV cross-check skipped)\n");
    return;
  }
  char p[2048];
  hearth_detections d = {0};
  hearth_err err = {0};
  snprintf(p, sizeof p, "%s/calibration/detections.json", root);
  CHECK_OK(hearth_detections_read(p, &d, &err), &err);
  double obj[NP][3];
  calib_plate_points(obj);
  double *img = malloc(sizeof(double) * 2 * NP * (d.n + 1));
  size_t m = 0;
  for (size_t i = 0; i < d.n; i++)
    if (d.frames[i].found) memcpy(img + 2 * NP * m++, d.frames[i].centres, sizeof(double) * 2 * NP);
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  o.lens_model = model;
  o.max_iterations = 500;
  hearth_camera cam;
  double rms;
  CHECK_OK(hearth_calib_intrinsics((const double(*)[3])obj, NP, img, m, 256, 192, &o, &cam, &rms,
                                   NULL, NULL, &err),
           &err);
  /* the points file: obj, then each frame's centres */
  snprintf(p, sizeof p, "%s/cv_points.txt", g_dir);
  FILE *f = fopen(p, "w");
  fprintf(f, "%zu %d %d\n", m, NP, model == HEARTH_LENS_RATIONAL8);
  for (int k = 0; k < NP; k++) fprintf(f, "%.17g %.17g\n", obj[k][0], obj[k][1]);
  for (size_t i = 0; i < m * NP; i++) fprintf(f, "%.17g %.17g\n", img[2 * i], img[2 * i + 1]);
  fclose(f);
  /* pixels through rig.json's camera: (u, v) -> hearth's ideal (x, y) */
  hearth_rig rig;
  snprintf(p, sizeof p, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(p, &rig, &err), &err);
  snprintf(p, sizeof p, "%s/cv_undist.txt", g_dir);
  f = fopen(p, "w");
  for (int v = 10; v < 192; v += 20)
    for (int u = 10; u < 256; u += 20) {
      double xy[2];
      CHECK(hearth_camera_undistort(&rig.thermal, u, v, xy) >= 0);
      fprintf(f, "%d %d %.17g %.17g\n", u, v, xy[0], xy[1]);
    }
  fclose(f);
  char cmd[4096];
  snprintf(cmd, sizeof cmd,
           "/usr/bin/python3 '%s/tests/calib/thermal_only_cv.py' '%s/cv_points.txt' "
           "'%s/calibration/rig_opencv.yaml' '%s/cv_undist.txt' %.17g %.17g %.17g %.17g",
           getenv("HEARTH_SOURCE_DIR"), g_dir, root, g_dir, cam.fx, cam.fy, cam.cx, cam.cy);
  int rc = system(cmd);
  CHECK_MSG(rc == 0, "%s", cmd);
  free(img);
  hearth_detections_free(&d);
}

/* ---- the two lenses -------------------------------------------------------------------- */
static void test_normal_lens(void) {
  char root[1100], e[4096], args[2400];
  make_root("normal", 0, 15,
            "csv,png8,png16,tiff8,tiff16,png8-dark,tiff-lzw,png-rgb,tiff-deflate,tiff-packbits", 3,
            root, sizeof root);
  snprintf(args, sizeof args, "detect --no-overlays '%s'", root);
  CHECK_MSG(run_tool(args, e, sizeof e) == 0, "%s", e);
  check_detections(root, 0.15);
  snprintf(args, sizeof args, "calibrate --thermal-only '%s'", root);
  CHECK_MSG(run_tool(args, e, sizeof e) == 0, "%s", e);
  json_t *r = load_report(root);
  const char *chosen = json_string_value(json_object_get(r, "lens_model"));
  double h5 = rep_num(r, 0, "heldout_rms_px"), h8 = rep_num(r, 1, "heldout_rms_px");
  double t5 = rep_num(r, 0, "train_rms_px"), t8 = rep_num(r, 1, "train_rms_px");
  fprintf(stderr, "normal lens: chosen %s; train %.4f / %.4f, held-out %.4f / %.4f px\n",
          chosen ? chosen : "?", t5, t8, h5, h8);
  CHECK(chosen && !strcmp(chosen, "brown5"));
  CHECK(isfinite(h5) && isfinite(h8) && h5 < 0.1);
  json_decref(r);
  check_camera(root, 0.5, 0.5, 0.1);
  CHECK(file_exists(root, "calibration/rig_opencv.yaml"));
  cv_check(root, HEARTH_LENS_BROWN5);
}

static void test_wide_lens(void) {
  char root[1100], e[4096], args[2400];
  make_root("wide", 1, 20, "png8,tiff16,csv,png16", 5, root, sizeof root);
  snprintf(args, sizeof args, "calibrate --detect --no-overlays --thermal-only '%s'", root);
  CHECK_MSG(run_tool(args, e, sizeof e) == 0, "%s", e);
  check_detections(root, 0.2);
  json_t *r = load_report(root);
  const char *chosen = json_string_value(json_object_get(r, "lens_model"));
  double h5 = rep_num(r, 0, "heldout_rms_px"), h8 = rep_num(r, 1, "heldout_rms_px");
  double t5 = rep_num(r, 0, "train_rms_px"), t8 = rep_num(r, 1, "train_rms_px");
  fprintf(stderr, "wide lens: chosen %s; train %.4f / %.4f, held-out %.4f / %.4f px\n",
          chosen ? chosen : "?", t5, t8, h5, h8);
  CHECK(chosen && !strcmp(chosen, "rational8"));
  CHECK(h8 < 0.9 * h5);
  json_decref(r);
  check_camera(root, 1.0, 1.0, 0.2);
  cv_check(root, HEARTH_LENS_RATIONAL8);
  /* --lens forces a model, and says so */
  snprintf(args, sizeof args, "calibrate --thermal-only --lens brown5 '%s'", root);
  CHECK_MSG(run_tool(args, e, sizeof e) == 0, "%s", e);
  r = load_report(root);
  json_t *lc = json_object_get(r, "lens_choice");
  CHECK(!strcmp(json_string_value(json_object_get(r, "lens_model")), "brown5") &&
        json_is_true(json_object_get(lc, "forced")));
  json_decref(r);
  hearth_rig rig;
  hearth_err err = {0};
  snprintf(args, sizeof args, "%s/calibration/rig.json", root);
  CHECK_OK(hearth_rig_read(args, &rig, &err), &err);
  CHECK(rig.thermal.model == HEARTH_LENS_BROWN5);
  snprintf(args, sizeof args, "calibrate --lens rational8 '%s'", root);
  CHECK(run_tool(args, e, sizeof e) == 2 && strstr(e, "--thermal-only"));
}

/* another sensor size: the size comes from the frames */
static void test_other_size(void) {
  char root[1100], e[4096], args[2400];
  g_width = 384;
  g_height = 288;
  make_root("size384", 0, 10, "png16,csv,tiff8", 4, root, sizeof root);
  g_width = 256;
  g_height = 192;
  snprintf(args, sizeof args, "calibrate --detect --no-overlays --thermal-only '%s'", root);
  CHECK_MSG(run_tool(args, e, sizeof e) == 0, "%s", e);
  check_detections(root, 0.15);
  check_camera(root, 0.5, 0.5, 0.15);
}

/* ---- bad input ------------------------------------------------------------------------- */
/* detect (and calibrate) must fail, naming `needle`, and leave no rig.json */
static void expect_fail(const char *root, const char *needle, int calibrate_only) {
  char e[4096], args[2400];
  if (!calibrate_only) {
    snprintf(args, sizeof args, "detect --no-overlays '%s'", root);
    int rc = run_tool(args, e, sizeof e);
    CHECK_MSG(rc != 0 && strstr(e, needle), "detect %s: rc %d, stderr: %s (want %s)", root, rc, e,
              needle);
  }
  snprintf(args, sizeof args, "calibrate --detect --no-overlays --thermal-only '%s'", root);
  int rc = run_tool(args, e, sizeof e);
  CHECK_MSG(rc != 0 && strstr(e, needle), "calibrate %s: rc %d, stderr: %s (want %s)", root, rc, e,
            needle);
  CHECK(!file_exists(root, "calibration/rig.json"));
  CHECK(!file_exists(root, "calibration/rig_opencv.yaml"));
}

static void truncate_file(const char *path, long keep) {
  char cmd[2400];
  snprintf(cmd, sizeof cmd, "truncate -s %ld '%s'", keep, path);
  CHECK(system(cmd) == 0);
}

static void test_bad_input(void) {
  char root[1100], p[2400];
  hearth_err err = {0};
  /* a corrupt PNG: its data cut short */
  make_root("bad_png", 0, 4, "png8", 9, root, sizeof root);
  snprintf(p, sizeof p, "%s/calibration/captures/thermal/IR_0014.png", root);
  truncate_file(p, 300);
  expect_fail(root, "IR_0014.png", 0);
  /* a corrupt TIFF: the strips cut off */
  make_root("bad_tiff", 0, 4, "tiff8", 9, root, sizeof root);
  snprintf(p, sizeof p, "%s/calibration/captures/thermal/IR_0017.tif", root);
  truncate_file(p, 2000);
  expect_fail(root, "IR_0017.tif", 0);
  /* a frame of another size */
  make_root("bad_size", 0, 4, "csv", 9, root, sizeof root);
  {
    hearth_image img = {0};
    CHECK_OK(hearth_image_alloc(&img, 160, 120, 1, HEARTH_PIX_U8, &err), &err);
    snprintf(p, sizeof p, "%s/calibration/captures/thermal/other.png", root);
    CHECK_OK(hearth_png_write(p, &img, &err), &err);
    hearth_image_free(&img);
  }
  expect_fail(root, "other.png: 160x120", 0);
  /* no thermal frames */
  snprintf(root, sizeof root, "%s/empty", g_dir);
  snprintf(p, sizeof p, "mkdir -p '%s/calibration/captures/thermal'", root);
  CHECK(system(p) == 0);
  expect_fail(root, "no thermal frames", 0);
  /* too few frames with the plate found (3 frames, one flat) */
  make_root("few", 0, 2, "png16", 9, root, sizeof root);
  {
    hearth_image img = {0};
    CHECK_OK(hearth_image_alloc(&img, 256, 192, 1, HEARTH_PIX_U16, &err), &err);
    snprintf(p, sizeof p, "%s/calibration/captures/thermal/flat.png", root);
    CHECK_OK(hearth_png_write(p, &img, &err), &err);
    hearth_image_free(&img);
  }
  expect_fail(root, "found in 2 of 3 thermal frames", 1);
}

/* ---- the frame reader ----------------------------------------------------------------- */
/* every format reads to the values written: 8/16-bit, PNG and each TIFF
 * compression, against the same pixels */
static void test_frame_formats(void) {
  hearth_err err = {0};
  hearth_image a = {0}, b = {0}, f = {0};
  CHECK_OK(hearth_image_alloc(&a, 37, 23, 1, HEARTH_PIX_U16, &err), &err);
  CHECK_OK(hearth_image_alloc(&b, 37, 23, 1, HEARTH_PIX_U8, &err), &err);
  for (size_t i = 0; i < 37 * 23; i++) {
    ((uint16_t *)a.data)[i] = (uint16_t)(i * 977 % 65536);
    ((uint8_t *)b.data)[i] = (uint8_t)(i * 31 % 256);
  }
  char p[2048];
  const hearth_tiff_compression comps[4] = {HEARTH_TIFF_NONE, HEARTH_TIFF_LZW, HEARTH_TIFF_DEFLATE,
                                            HEARTH_TIFF_PACKBITS};
  for (int c = 0; c < 4; c++)
    for (int w = 0; w < 2; w++) {
      const hearth_image *src = w ? &a : &b;
      snprintf(p, sizeof p, "%s/fmt_%d_%d.bin", g_dir, c, w);
      CHECK_OK(hearth_tiff_write(p, src, comps[c], &err), &err);
      hearth_frame_kind k;
      CHECK_OK(hearth_frame_read(p, &f, &k, &err), &err);
      CHECK(k == (w ? HEARTH_FRAME_TIFF16 : HEARTH_FRAME_TIFF8));
      CHECK(f.width == 37 && f.height == 23 && f.type == HEARTH_PIX_F32);
      int same = 1;
      for (size_t i = 0; f.data && i < 37 * 23; i++)
        same &= ((float *)f.data)[i] ==
                (w ? (float)((uint16_t *)a.data)[i] : (float)((uint8_t *)b.data)[i]);
      CHECK_MSG(same, "TIFF compression %d, %d-bit", c, w ? 16 : 8);
      hearth_image_free(&f);
    }
  snprintf(p, sizeof p, "%s/fmt_png16", g_dir);
  CHECK_OK(hearth_png_write(p, &a, &err), &err);
  hearth_frame_kind k;
  CHECK_OK(hearth_frame_read(p, &f, &k, &err), &err);
  CHECK(k == HEARTH_FRAME_PNG16 && f.data && ((float *)f.data)[5] == 5 * 977);
  hearth_image_free(&f);
  /* hand-made TIFFs of the fuzz corpus: big-endian min-is-white reads as
   * displayed (255 - stored), RGB as the mean of its channels */
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (src) {
    snprintf(p, sizeof p, "%s/fuzz/corpus/frame/be_miniswhite.tif", src);
    CHECK_OK(hearth_frame_read(p, &f, &k, &err), &err);
    CHECK(f.width == 4 && f.height == 3 && k == HEARTH_FRAME_TIFF8);
    for (size_t i = 0; f.data && i < 12; i++) CHECK(((float *)f.data)[i] == 255.0f - (float)i);
    hearth_image_free(&f);
    snprintf(p, sizeof p, "%s/fuzz/corpus/frame/rgb8.tif", src);
    CHECK_OK(hearth_frame_read(p, &f, &k, &err), &err);
    CHECK(f.width == 2 && f.height == 2 && f.data && ((float *)f.data)[0] == 20.0f &&
          ((float *)f.data)[3] == 110.0f);
    hearth_image_free(&f);
    snprintf(p, sizeof p, "%s/fuzz/corpus/frame/truncated.tif", src);
    CHECK(hearth_frame_read(p, &f, &k, &err) != HEARTH_OK && !f.data);
    CHECK_MSG(strstr(err.msg, "truncated.tif"), "%s", err.msg);
  }
  /* not an image, not a matrix: the CSV reader's place */
  const char bad[] = "1,2,3\n4,x,6\n";
  CHECK(hearth_frame_read_mem(bad, sizeof bad - 1, "bad.dat", &f, NULL, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, "bad.dat") && strstr(err.msg, "line 2"), "%s", err.msg);
  hearth_image_free(&a);
  hearth_image_free(&b);
}

/* rig.json: a thermal-only rig with the rational model reads back as
 * written, and the stages that need the stereo calibration say why */
static void test_rig_doc(void) {
  hearth_rig rig, back;
  memset(&rig, 0, sizeof rig);
  rig.thermal_only = 1;
  hearth_synth_thermal_opts o;
  hearth_synth_thermal_opts_default(&o);
  o.wide_angle = 1;
  hearth_synth_thermal_camera(&o, &rig.thermal);
  rig.thermal_rms_px = 0.02;
  char p[2048];
  hearth_err err = {0};
  snprintf(p, sizeof p, "%s/rig_only.json", g_dir);
  CHECK_OK(hearth_rig_write(p, &rig, &err), &err);
  CHECK_OK(hearth_rig_read(p, &back, &err), &err);
  CHECK(back.thermal_only && back.thermal.model == HEARTH_LENS_RATIONAL8);
  for (int k = 0; k < 8; k++) CHECK(back.thermal.dist[k] == rig.thermal.dist[k]);
  char *text = test_slurp(p, NULL);
  CHECK(text && !strstr(text, "T_thermal_from_rgb") && !strstr(text, "\"rgb\""));
  free(text);
  /* 6 coefficients, or the rational model for the colour camera: refused
   * with the place */
  static const struct {
    const char *text, *want;
  } bad[] = {
      {"{\"thermal\": {\"width\": 256, \"height\": 192, \"K\": [[200,0,128],[0,200,96],[0,0,1]], "
       "\"dist\": [0,0,0,0,0,0]}, \"thermal_rms_px\": 0.1}",
       "thermal.dist"},
      {"{\"thermal\": {\"width\": 256, \"height\": 192, \"K\": [[200,0,128],[0,200,96],[0,0,1]], "
       "\"dist\": [0,0,0,0,0]}, \"thermal_rms_px\": 0.1, \"stereo_rms_px\": 0.1}",
       "rgb"},
  };
  for (int i = 0; i < 2; i++) {
    hearth_rig r2;
    CHECK(hearth_rig_parse(bad[i].text, strlen(bad[i].text), "bad.json", &r2, &err) != HEARTH_OK);
    CHECK_MSG(strstr(err.msg, "bad.json") && strstr(err.msg, bad[i].want), "%s", err.msg);
  }
  CHECK(hearth_rig_require_stereo(&back, p, "mapping", &err) == HEARTH_E_UNSUPPORTED);
  CHECK_MSG(strstr(err.msg, p) && strstr(err.msg, "T_thermal_from_rgb") &&
                strstr(err.msg, "mapping"),
            "%s", err.msg);
}

/* a release whose rig.json is thermal-only: the stages that need the
 * stereo calibration stop with the reason, naming rig.json */
static void test_pipeline_refuses(const char *thermal_root) {
  char rel[1100], args[2400], e[4096];
  snprintf(rel, sizeof rel, "%s/release", g_dir);
  snprintf(args, sizeof args,
           "synth --out '%s' --views 1 --triangles 200 --texture 16 --map-res 8 "
           "--no-calibration --draft-rgb --quiet",
           rel);
  CHECK_MSG(run_tool(args, e, sizeof e) == 0, "%s", e);
  snprintf(args, sizeof args, "cp '%s/calibration/rig.json' '%s/calibration/rig.json'",
           thermal_root, rel);
  CHECK(system(args) == 0);
  static const char *const stages[] = {"transfer", "map", "refine"};
  for (int i = 0; i < 3; i++) {
    snprintf(args, sizeof args, "%s '%s'", stages[i], rel);
    int rc = run_tool(args, e, sizeof e);
    CHECK_MSG(rc != 0 && strstr(e, "rig.json: a thermal-only rig") &&
                  strstr(e, "T_thermal_from_rgb"),
              "%s: rc %d: %s", stages[i], rc, e);
  }
}

int main(void) {
  snprintf(g_dir, sizeof g_dir, "%s", test_tmpdir("calib_thermal_only"));
  test_frame_formats();
  test_rig_doc();
  test_bad_input();
  test_normal_lens();
  test_wide_lens();
  test_other_size();
  char wide[1100];
  snprintf(wide, sizeof wide, "%s/wide", g_dir);
  test_pipeline_refuses(wide);
  if (g_test_failures) fprintf(stderr, "%d failures\n", g_test_failures);
  return g_test_failures ? 1 : 0;
}
