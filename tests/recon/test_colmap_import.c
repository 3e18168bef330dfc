/* COLMAP import: the same model written by the test in text and binary form
 * reads to identical poses (byte-identical JSON), known poses and
 * intrinsics come back (inverse computed here independently), camera model
 * mapping, unsupported models, sparse ids, an unregistered image, truncated
 * and malformed files with the place of the error, the cameras document,
 * and the similarity alignment of pose sets. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "hearth/recon.h"
#include "recon/colmap_fixture.h"
#include "recon/recon_release.h"
#include "test_util.h"

static char g_dir[1024];

static const char *tpath(const char *name) {
  static char buf[8][1200];
  static int k;
  k = (k + 1) % 8;
  snprintf(buf[k], sizeof buf[k], "%s/%s", g_dir, name);
  return buf[k];
}

static int same_file(const char *a, const char *b) {
  size_t na, nb;
  char *x = test_slurp(a, &na), *y = test_slurp(b, &nb);
  int same = x && y && na == nb && !memcmp(x, y, na);
  free(x);
  free(y);
  return same;
}

static void write_text_file(const char *path, const char *text) {
  FILE *f = fopen(path, "wb");
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

static const fx_image *fx_find(uint32_t id) {
  for (size_t i = 0; i < FX_N_IMAGES; i++)
    if (k_fx_images[i].id == id) return &k_fx_images[i];
  return NULL;
}

/* ---- the two forms agree and give the known numbers ------------------------------ */
static void check_model(const hearth_colmap_model *m) {
  CHECK(m->n_cameras == 3 && m->n_images == 4 && m->n_points == 3);
  if (m->n_cameras != 3 || m->n_images != 4 || m->n_points != 3) return;
  /* sorted by id, sparse ids kept */
  CHECK(m->cameras[0].id == 3 && m->cameras[1].id == 7 && m->cameras[2].id == 12);
  CHECK(m->images[0].id == 2 && m->images[3].id == 40);
  CHECK(m->points[0].id == 77 && m->points[2].id == 1003);
  CHECK(hearth_colmap_find_camera(m, 7) == &m->cameras[1]);
  CHECK(hearth_colmap_find_camera(m, 4) == NULL);
  CHECK(hearth_colmap_find_image(m, 9) == &m->images[2]);
  CHECK(hearth_colmap_find_image(m, 3) == NULL);
  /* poses: T_world_from_cam = (R^T, -R^T t) with R from the axis-angle the
   * quaternion was made from (Rodrigues, not the library's quaternion code) */
  for (size_t i = 0; i < m->n_images; i++) {
    const hearth_colmap_image *im = &m->images[i];
    const fx_image *want = fx_find(im->id);
    CHECK(want != NULL);
    if (!want) continue;
    double n = sqrt(want->axis[0] * want->axis[0] + want->axis[1] * want->axis[1] +
                    want->axis[2] * want->axis[2]);
    double w[3] = {want->axis[0] / n * want->angle, want->axis[1] / n * want->angle,
                   want->axis[2] / n * want->angle};
    double R[9];
    hearth_rotvec_to_matrix(w, R);
    for (int r = 0; r < 3; r++) {
      double c = 0;
      for (int k = 0; k < 3; k++) {
        CHECK_NEAR(im->T_world_from_cam.R[r * 3 + k], R[k * 3 + r], 1e-12);
        c -= R[k * 3 + r] * want->t[k];
      }
      CHECK_NEAR(im->T_world_from_cam.t[r], c, 1e-12);
    }
    CHECK(!strcmp(im->name, want->name));
    CHECK(im->camera_id == want->camera);
    CHECK(im->n_points2d == (size_t)want->n_points);
    CHECK(im->n_observations == (size_t)want->n_points / 2);
  }
  /* intrinsics: COLMAP's principal point minus half a pixel */
  const hearth_camera *pin = &m->cameras[0].camera, *sr = &m->cameras[1].camera,
                      *cv = &m->cameras[2].camera;
  CHECK(pin->width == 1920 && pin->height == 1080);
  CHECK(pin->fx == 1500.25 && pin->fy == 1490.5 && pin->cx == 960.0 && pin->cy == 540.0);
  for (int k = 0; k < 5; k++) CHECK(pin->dist[k] == 0);
  CHECK(sr->width == 640 && sr->fx == 1200 && sr->fy == 1200 && sr->cx == 320.0 &&
        sr->cy == 239.75);
  CHECK(sr->dist[0] == -0.0123 && sr->dist[1] == 0 && sr->dist[4] == 0);
  CHECK(cv->fx == 1510 && cv->fy == 1509 && cv->cx == 955.25 && cv->cy == 540.625);
  CHECK(cv->dist[0] == 0.1 && cv->dist[1] == -0.05 && cv->dist[2] == 0.001 &&
        cv->dist[3] == -0.002 && cv->dist[4] == 0);
  CHECK(m->points[0].track_length == 1 && m->points[2].track_length == 3);
  CHECK(m->points[1].rgb[0] == 255 && m->points[1].rgb[2] == 7 && m->points[1].error == 0.5);
}

static void test_text_and_binary(void) {
  hearth_err err = {0};
  char txt[1200], bin[1200];
  snprintf(txt, sizeof txt, "%s", tpath("text"));
  snprintf(bin, sizeof bin, "%s", tpath("bin"));
  mkdir(txt, 0755);
  mkdir(bin, 0755);
  CHECK(fx_write_text(txt) == 0);
  CHECK(fx_write_binary(bin) == 0);
  hearth_colmap_model mt, mb;
  CHECK_OK(hearth_colmap_read(txt, &mt, &err), &err);
  CHECK(mt.format == HEARTH_COLMAP_TEXT);
  check_model(&mt);
  CHECK_OK(hearth_colmap_read(bin, &mb, &err), &err);
  CHECK(mb.format == HEARTH_COLMAP_BINARY);
  check_model(&mb);

  /* both to poses and cameras documents: the same bytes */
  hearth_poses pt, pb;
  hearth_recon_cameras ct, cb;
  CHECK_OK(hearth_colmap_to_poses(&mt, "iced", &pt, &ct, &err), &err);
  CHECK_OK(hearth_colmap_to_poses(&mb, "iced", &pb, &cb, &err), &err);
  CHECK_OK(hearth_poses_write(tpath("poses_text.json"), &pt, &err), &err);
  CHECK_OK(hearth_poses_write(tpath("poses_bin.json"), &pb, &err), &err);
  CHECK(same_file(tpath("poses_text.json"), tpath("poses_bin.json")));
  char cpt[1200], cpb[1200];
  CHECK(hearth_recon_cameras_path(tpath("poses_text.json"), cpt, sizeof cpt) == HEARTH_OK);
  CHECK(hearth_recon_cameras_path(tpath("poses_bin.json"), cpb, sizeof cpb) == HEARTH_OK);
  CHECK(strstr(cpt, "/poses_text_cameras.json") != NULL);
  CHECK_OK(hearth_recon_cameras_write(cpt, &ct, &err), &err);
  CHECK_OK(hearth_recon_cameras_write(cpb, &cb, &err), &err);
  CHECK(same_file(cpt, cpb));

  /* views: state from the folder, else the default; order neutral, hot, ..., iced */
  CHECK(pt.n == 4);
  if (pt.n == 4) {
    CHECK(!strcmp(pt.views[0].state, "neutral") && !strcmp(pt.views[0].view, "v00"));
    CHECK(!strcmp(pt.views[1].state, "neutral") && !strcmp(pt.views[1].view, "v01"));
    CHECK(!strcmp(pt.views[2].state, "hot") && !strcmp(pt.views[2].view, "v00"));
    CHECK(!strcmp(pt.views[3].state, "iced") && !strcmp(pt.views[3].view, "v07"));
    CHECK(ct.n_views == 4 && ct.views[3].image_id == 40 && ct.views[3].camera_id == 7);
    CHECK(!strcmp(ct.views[2].image, "hot/v00.jpg"));
  }
  /* the poses read back as written (the file is a hearth poses document) */
  hearth_poses back;
  CHECK_OK(hearth_poses_read(tpath("poses_text.json"), &back, &err), &err);
  CHECK(back.n == pt.n);
  hearth_poses_free(&back);

  /* the cameras document reads back to the same cameras */
  hearth_recon_cameras cr;
  CHECK_OK(hearth_recon_cameras_read(cpt, &cr, &err), &err);
  CHECK(cr.n_cameras == 3 && cr.n_views == 4);
  for (size_t i = 0; i < cr.n_cameras && i < ct.n_cameras; i++) {
    CHECK(cr.cameras[i].id == ct.cameras[i].id && cr.cameras[i].model_id == ct.cameras[i].model_id);
    CHECK(!memcmp(&cr.cameras[i].camera, &ct.cameras[i].camera, sizeof cr.cameras[i].camera));
    CHECK(!memcmp(cr.cameras[i].params, ct.cameras[i].params,
                  ct.cameras[i].n_params * sizeof(double)));
  }
  hearth_recon_cameras_free(&cr);
  /* its reader is strict: a view naming a camera not listed */
  char *doc = test_slurp(cpt, NULL);
  char *at = doc ? strstr(doc, "\"colmap_camera_id\": 7,\n      \"colmap_image_id\"") : NULL;
  CHECK(at != NULL);
  if (at) {
    at[20] = '8';
    hearth_status s = hearth_recon_cameras_parse(doc, strlen(doc), "c.json", &cr, &err);
    CHECK(s == HEARTH_E_INCONSISTENT &&
          strstr(err.msg, "c.json: views[3].colmap_camera_id: camera 8"));
  }
  free(doc);

  hearth_poses_free(&pt);
  hearth_poses_free(&pb);
  hearth_recon_cameras_free(&ct);
  hearth_recon_cameras_free(&cb);
  hearth_colmap_model_free(&mt);
  hearth_colmap_model_free(&mb);
  hearth_colmap_model_free(&mb); /* idempotent */
}

/* ---- camera models ----------------------------------------------------------------- */
static void test_models(void) {
  hearth_err err = {0};
  hearth_camera c;
  static const struct {
    int id;
    const char *name;
    int n;
  } k_table[] = {{0, "SIMPLE_PINHOLE", 3},
                 {1, "PINHOLE", 4},
                 {2, "SIMPLE_RADIAL", 4},
                 {3, "RADIAL", 5},
                 {4, "OPENCV", 8},
                 {5, "OPENCV_FISHEYE", 8},
                 {6, "FULL_OPENCV", 12},
                 {7, "FOV", 5},
                 {8, "SIMPLE_RADIAL_FISHEYE", 4},
                 {9, "RADIAL_FISHEYE", 5},
                 {10, "THIN_PRISM_FISHEYE", 12},
                 {11, "RAD_TAN_THIN_PRISM_FISHEYE", 16}};
  for (size_t i = 0; i < sizeof k_table / sizeof k_table[0]; i++) {
    CHECK(!strcmp(hearth_colmap_model_name(k_table[i].id), k_table[i].name));
    CHECK(hearth_colmap_model_n_params(k_table[i].id) == k_table[i].n);
    CHECK(hearth_colmap_model_id(k_table[i].name) == k_table[i].id);
  }
  CHECK(hearth_colmap_model_name(99) == NULL && hearth_colmap_model_n_params(-2) == -1);
  CHECK(hearth_colmap_model_id("pinhole") == -1);

  double sp[3] = {800, 320.5, 240.5};
  CHECK_OK(hearth_colmap_camera_convert(0, sp, 3, 640, 480, &c, &err), &err);
  CHECK(c.fx == 800 && c.fy == 800 && c.cx == 320 && c.cy == 240);
  double rad[5] = {700, 100, 50, 0.1, -0.01};
  CHECK_OK(hearth_colmap_camera_convert(3, rad, 5, 200, 100, &c, &err), &err);
  CHECK(c.dist[0] == 0.1 && c.dist[1] == -0.01 && c.dist[2] == 0 && c.dist[3] == 0 &&
        c.dist[4] == 0);
  double full[12] = {700, 710, 100, 50, 0.1, -0.01, 0.001, 0.002, 0.003, 0, 0, 0};
  CHECK_OK(hearth_colmap_camera_convert(6, full, 12, 200, 100, &c, &err), &err);
  CHECK(c.fy == 710 && c.dist[2] == 0.001 && c.dist[3] == 0.002 && c.dist[4] == 0.003);
  full[10] = 0.5;
  CHECK(hearth_colmap_camera_convert(6, full, 12, 200, 100, &c, &err) == HEARTH_E_UNSUPPORTED);
  CHECK(strstr(err.msg, "FULL_OPENCV") && strstr(err.msg, "rational"));
  double fish[8] = {700, 700, 100, 50, 0.1, 0, 0, 0};
  CHECK(hearth_colmap_camera_convert(5, fish, 8, 200, 100, &c, &err) == HEARTH_E_UNSUPPORTED);
  CHECK(strstr(err.msg, "OPENCV_FISHEYE"));
  CHECK(hearth_colmap_camera_convert(1, sp, 3, 640, 480, &c, &err) == HEARTH_E_SIZE);
  double neg[3] = {-5, 1, 1};
  CHECK(hearth_colmap_camera_convert(0, neg, 3, 640, 480, &c, &err) == HEARTH_E_RANGE);
  CHECK(hearth_colmap_camera_convert(0, sp, 3, 0, 480, &c, &err) == HEARTH_E_RANGE);
  CHECK(hearth_colmap_camera_convert(0, sp, 3, 70000, 480, &c, &err) == HEARTH_E_RANGE);

  /* in a file: the error names the file, the line and the camera */
  char dir[1200];
  snprintf(dir, sizeof dir, "%s", tpath("fisheye"));
  mkdir(dir, 0755);
  CHECK(fx_write_text(dir) == 0);
  write_text_file(tpath("fisheye/cameras.txt"),
                  "# cameras\n3 PINHOLE 1920 1080 1500 1500 960 540\n"
                  "7 OPENCV_FISHEYE 640 480 500 500 320 240 0.1 0.01 0 0\n"
                  "12 OPENCV 1920 1080 1 1 1 1 0 0 0 0\n");
  hearth_colmap_model m;
  CHECK(hearth_colmap_read(dir, &m, &err) == HEARTH_E_UNSUPPORTED);
  CHECK_MSG(strstr(err.msg, "fisheye/cameras.txt:3: camera 7: model OPENCV_FISHEYE"), "%s",
            err.msg);
  CHECK(m.n_cameras == 0 && m.cameras == NULL);
  write_text_file(tpath("fisheye/cameras.txt"), "5 KANNALA 640 480 1 2 3\n");
  CHECK(hearth_colmap_read(dir, &m, &err) == HEARTH_E_UNSUPPORTED);
  CHECK_MSG(strstr(err.msg, "cameras.txt:1: camera 5: unknown camera model 'KANNALA'"), "%s",
            err.msg);

  /* binary: byte offset, camera id and model */
  fx_buf b;
  b.n = 0;
  fx_put(&b, 1, 8);
  fx_put(&b, 44, 4);
  fx_put(&b, 5, 4);
  fx_put(&b, 640, 8);
  fx_put(&b, 480, 8);
  for (int k = 0; k < 8; k++) fx_putd(&b, k < 2 ? 500 : 0.01);
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_CAMERAS, HEARTH_COLMAP_BINARY, b.data, b.n, "c.bin", &m,
                            &err) == HEARTH_E_UNSUPPORTED);
  CHECK_MSG(strstr(err.msg, "c.bin: byte offset 8: camera 44: model OPENCV_FISHEYE"), "%s",
            err.msg);
  b.data[12] = 200; /* model id 200 */
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_CAMERAS, HEARTH_COLMAP_BINARY, b.data, b.n, "c.bin", &m,
                            &err) == HEARTH_E_UNSUPPORTED);
  CHECK_MSG(strstr(err.msg, "c.bin: byte offset 12: camera 44: unknown camera model id 200"), "%s",
            err.msg);
  hearth_colmap_model_free(&m);
}

/* ---- malformed input: the place of the error --------------------------------------- */
static void test_errors(void) {
  hearth_err err = {0};
  hearth_colmap_model m = {0};
  fx_buf cams, ims, pts;
  fx_cameras_bin(&cams);
  fx_images_bin(&ims);
  fx_points_bin(&pts);
  /* every truncation of each binary file fails with a byte offset */
  int all_ok = 1;
  for (size_t cut = 0; cut < ims.n; cut++) {
    hearth_colmap_model_free(&m);
    CHECK_OK(hearth_colmap_parse(HEARTH_COLMAP_CAMERAS, HEARTH_COLMAP_BINARY, cams.data, cams.n,
                                 "cameras.bin", &m, &err),
             &err);
    hearth_status s = hearth_colmap_parse(HEARTH_COLMAP_IMAGES, HEARTH_COLMAP_BINARY, ims.data, cut,
                                          "images.bin", &m, &err);
    if (s != HEARTH_E_PARSE || !strstr(err.msg, "images.bin: byte offset ") || m.n_images) {
      CHECK_MSG(0, "cut at %zu: %s", cut, err.msg);
      all_ok = 0;
      break;
    }
  }
  CHECK(all_ok);
  /* a cut inside image 5's pose names where that field starts */
  size_t image5 = 8 + (4 + 56 + 4 + strlen("neutral/v00.jpg") + 1 + 8 + 4 * 24);
  fx_buf two = ims;
  two.data[0] = 2; /* a count that the bytes left allow */
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_IMAGES, HEARTH_COLMAP_BINARY, two.data, image5 + 20,
                            "images.bin", &m, &err) == HEARTH_E_PARSE);
  char want[160];
  snprintf(want, sizeof want,
           "images.bin: byte offset %zu: truncated: expected the pose of image 5", image5 + 4);
  CHECK_MSG(strstr(err.msg, want), "%s (wanted %s)", err.msg, want);
  CHECK_OK(hearth_colmap_parse(HEARTH_COLMAP_IMAGES, HEARTH_COLMAP_BINARY, ims.data, ims.n,
                               "images.bin", &m, &err),
           &err);
  for (size_t cut = 0; cut < pts.n; cut++) {
    hearth_status s = hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_BINARY, pts.data,
                                          cut, "points3D.bin", &m, &err);
    if (s != HEARTH_E_PARSE || !strstr(err.msg, "points3D.bin: byte offset ")) {
      CHECK_MSG(0, "points cut at %zu: %s", cut, err.msg);
      break;
    }
  }
  /* a huge count is refused before any allocation */
  fx_buf big = pts;
  for (int k = 0; k < 8; k++) big.data[k] = k == 5 ? 1 : 0; /* 2^40 */
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_BINARY, big.data, big.n,
                            "points3D.bin", &m, &err) == HEARTH_E_PARSE);
  CHECK_MSG(strstr(err.msg, "byte offset 0: 1099511627776 3-D points announced"), "%s", err.msg);
  /* trailing bytes */
  fx_buf extra = pts;
  extra.data[extra.n++] = 0;
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_BINARY, extra.data, extra.n,
                            "points3D.bin", &m, &err) == HEARTH_E_PARSE);
  CHECK(strstr(err.msg, "1 bytes after the last record"));
  /* a track naming an image that is not registered */
  fx_buf bad = pts;
  bad.data[8 + 8 + 24 + 3 + 8 + 8] = 3; /* first track element of the first point: image 3 */
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_BINARY, bad.data, bad.n,
                            "points3D.bin", &m, &err) == HEARTH_E_INCONSISTENT);
  CHECK_MSG(strstr(err.msg, "byte offset 59: point 1001: track names image 3"), "%s", err.msg);

  /* text: file and line */
  static const struct {
    const char *text;
    hearth_status status;
    const char *msg;
  } k_images[] = {
      {"# c\n\n2 1 0 0 0 0 0 0 3 neutral/v00.jpg\n\n5 1 0 0 0 0 x 0 3 b.jpg\n\n", HEARTH_E_PARSE,
       "images.txt:5: expected TY of image 5 (a finite decimal number), found 'x'"},
      {"2 1 0 0 0 0 0 0 99 a.jpg\n\n", HEARTH_E_INCONSISTENT,
       "images.txt:1: image 2 (a.jpg): camera 99 is not in the model's cameras"},
      {"2 1 0 0 0 0 0 0 3 a.jpg\n1 2 -1 3 4\n", HEARTH_E_PARSE,
       "images.txt:2: image 2: 2-D point 1: expected its POINT3D_ID"},
      {"2 1 0 0 0 0 0 0 3 a.jpg\n1 2 -2\n", HEARTH_E_PARSE, "images.txt:2: expected POINT3D_ID"},
      {"2 2 0 0 0 0 0 0 3 a.jpg\n\n", HEARTH_E_RANGE, "images.txt:1: image 2: quaternion"},
      {"2 1 0 0 0 0 0 0 3 a.jpg extra\n\n", HEARTH_E_PARSE,
       "images.txt:1: unexpected 'extra' after the image name"},
      {"2 1 0 0 0 0 0 0 3 a.jpg\n\n4 1 0 0 0 0 0 0 3 b.jpg\n\n2 1 0 0 0 0 0 0 3 c.jpg\n\n",
       HEARTH_E_INCONSISTENT, "images.txt:5: duplicate image id 2 (also on line 1)"},
      {"2 1 0 0 0 0 0 0 3 a.jpg\n# a comment where the points belong\n", HEARTH_E_PARSE,
       "images.txt:2: expected the 2-D points of image 2"},
      {"4294967296 1 0 0 0 0 0 0 3 a.jpg\n\n", HEARTH_E_PARSE,
       "images.txt:1: expected an image id"},
      {"2 1 0 0 0 0 0 0 3 a.jpg\n1 2 nan\n", HEARTH_E_PARSE, "images.txt:2"},
      {"2 1e999 0 0 0 0 0 0 3 a.jpg\n\n", HEARTH_E_PARSE, "images.txt:1: expected QW of image 2"},
  };
  for (size_t i = 0; i < sizeof k_images / sizeof k_images[0]; i++) {
    hearth_status s = hearth_colmap_parse(HEARTH_COLMAP_IMAGES, HEARTH_COLMAP_TEXT,
                                          (const uint8_t *)k_images[i].text,
                                          strlen(k_images[i].text), "images.txt", &m, &err);
    CHECK_MSG(s == k_images[i].status && strstr(err.msg, k_images[i].msg), "case %zu: %s: %s", i,
              hearth_status_name(s), err.msg);
    CHECK(m.n_images == 0);
  }
  /* a last image without its points line; blank lines and tabs; CR LF */
  const char *ok = "\n# c\r\n2\t1 0 0 0   0 0 0 3 a.jpg\r\n\r\n\r\n5 1 0 0 0 0 0 0 7 hot/b.jpg";
  CHECK_OK(hearth_colmap_parse(HEARTH_COLMAP_IMAGES, HEARTH_COLMAP_TEXT, (const uint8_t *)ok,
                               strlen(ok), "images.txt", &m, &err),
           &err);
  CHECK(m.n_images == 2 && m.images[1].n_points2d == 0 && !strcmp(m.images[1].name, "hot/b.jpg"));
  const char *pbad = "1 0 0 0 255 0 256 0.1\n";
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_TEXT, (const uint8_t *)pbad,
                            strlen(pbad), "points3D.txt", &m, &err) == HEARTH_E_PARSE);
  CHECK_MSG(strstr(err.msg,
                   "points3D.txt:1: expected B of point 1 (an integer in 0..255), found '256'"),
            "%s", err.msg);
  const char *ptrack = "# p\n1 0 0 0 1 2 3 0.1 2 0 5 0 2\n";
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_TEXT, (const uint8_t *)ptrack,
                            strlen(ptrack), "points3D.txt", &m, &err) == HEARTH_E_INCONSISTENT);
  CHECK_MSG(strstr(err.msg,
                   "points3D.txt:2: point 1: track names 2-D point 0 of image 2, which has 0"),
            "%s", err.msg);
  const char *podd = "1 0 0 0 1 2 3 0.1 2\n";
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_POINTS3D, HEARTH_COLMAP_TEXT, (const uint8_t *)podd,
                            strlen(podd), "points3D.txt", &m, &err) == HEARTH_E_PARSE);
  CHECK(strstr(err.msg, "POINT2D_IDX of track element 0 of point 1"));
  const char *cshort = "1 PINHOLE 10 10 5 5 5\n";
  CHECK(hearth_colmap_parse(HEARTH_COLMAP_CAMERAS, HEARTH_COLMAP_TEXT, (const uint8_t *)cshort,
                            strlen(cshort), "cameras.txt", &m, &err) == HEARTH_E_SIZE);
  CHECK(strstr(err.msg, "cameras.txt:1: camera 1: model PINHOLE takes 4 parameters, found 3"));
  hearth_colmap_model_free(&m);

  /* a folder that is not a model */
  char dir[1200];
  snprintf(dir, sizeof dir, "%s", tpath("half"));
  mkdir(dir, 0755);
  write_text_file(tpath("half/cameras.txt"), "");
  write_text_file(tpath("half/images.txt"), "");
  CHECK(hearth_colmap_read(dir, &m, &err) == HEARTH_E_NOT_FOUND);
  CHECK_MSG(strstr(err.msg, "points3D.txt missing"), "%s", err.msg);
  CHECK(hearth_colmap_read(tpath("none"), &m, &err) == HEARTH_E_NOT_FOUND);
  /* an empty model is a model with no views */
  write_text_file(tpath("half/points3D.txt"), "# none\n");
  CHECK_OK(hearth_colmap_read(dir, &m, &err), &err);
  CHECK(m.n_images == 0);
  hearth_colmap_model_free(&m);
}

/* ---- names, duplicates, the unregistered image ------------------------------------------ */
static void test_names(void) {
  hearth_err err = {0};
  char st[HEARTH_NAME_MAX], vw[HEARTH_NAME_MAX];
  CHECK_OK(hearth_colmap_view_of("neutral/v07.jpg", "hot", st, vw, &err), &err);
  CHECK(!strcmp(st, "neutral") && !strcmp(vw, "v07"));
  CHECK_OK(hearth_colmap_view_of("v07.jpg", "hot", st, vw, &err), &err);
  CHECK(!strcmp(st, "hot") && !strcmp(vw, "v07"));
  CHECK_OK(hearth_colmap_view_of("session2/hot/v3", "used", st, vw, &err), &err);
  CHECK(!strcmp(st, "used") && !strcmp(vw, "v3"));
  CHECK_OK(hearth_colmap_view_of("iced/a/b/v_1-x.png", "used", st, vw, &err), &err);
  CHECK(!strcmp(st, "iced") && !strcmp(vw, "v_1-x"));
  CHECK(hearth_colmap_view_of("neutral/v 1.jpg", "hot", st, vw, &err) == HEARTH_E_RANGE);
  CHECK(hearth_colmap_view_of("neutral/.jpg", "hot", st, vw, &err) == HEARTH_E_RANGE);
  CHECK(hearth_colmap_view_of("v1.jpg", "frozen", st, vw, &err) == HEARTH_E_RANGE);

  /* two images that are the same view */
  const char *cams = "1 SIMPLE_PINHOLE 100 100 50 50 50\n";
  const char *ims = "3 1 0 0 0 0 0 0 1 neutral/v00.jpg\n\n8 1 0 0 0 0 0 1 1 neutral/x/v00.png\n\n";
  hearth_colmap_model m = {0};
  CHECK_OK(hearth_colmap_parse(HEARTH_COLMAP_CAMERAS, HEARTH_COLMAP_TEXT, (const uint8_t *)cams,
                               strlen(cams), "cameras.txt", &m, &err),
           &err);
  CHECK_OK(hearth_colmap_parse(HEARTH_COLMAP_IMAGES, HEARTH_COLMAP_TEXT, (const uint8_t *)ims,
                               strlen(ims), "images.txt", &m, &err),
           &err);
  hearth_poses p;
  hearth_recon_cameras c;
  CHECK(hearth_colmap_to_poses(&m, "neutral", &p, &c, &err) == HEARTH_E_INCONSISTENT);
  CHECK_MSG(
      strstr(
          err.msg,
          "images 3 (\"neutral/v00.jpg\") and 8 (\"neutral/x/v00.png\") are both view v00 of state neutral"),
      "%s", err.msg);
  CHECK(p.n == 0 && p.views == NULL && c.n_views == 0);
  hearth_colmap_model_free(&m);

  /* the unregistered image: a two-view instance whose v02 is not in the model */
  char root[1200];
  snprintf(root, sizeof root, "%s", tpath("release"));
  static const char *const states[] = {"neutral", "hot"};
  static const size_t n_views[] = {3, 1};
  rr_write_instance(root, "cup_01", "cup", 2, states, n_views);
  char bin[1200];
  snprintf(bin, sizeof bin, "%s", tpath("bin"));
  CHECK_OK(hearth_colmap_read(bin, &m, &err), &err);
  CHECK_OK(hearth_colmap_to_poses(&m, "neutral", &p, NULL, &err), &err);
  hearth_recon_coverage cov;
  /* v07 (no state folder, default neutral) is not a view of the instance */
  CHECK(hearth_recon_match_instance(root, "cup_01", &p, &cov, &err) == HEARTH_E_INCONSISTENT);
  CHECK_MSG(strstr(err.msg, "state neutral, view v07: cup_01 has no such colour view"), "%s",
            err.msg);
  hearth_poses_free(&p);
  /* without image 40, three of the four views have poses; neutral/v02 is missing */
  m.n_images = 3;
  CHECK_OK(hearth_colmap_to_poses(&m, "neutral", &p, NULL, &err), &err);
  CHECK_OK(hearth_recon_match_instance(root, "cup_01", &p, &cov, &err), &err);
  CHECK(cov.n_views == 4 && cov.n_missing == 1 && !strcmp(cov.missing[0], "neutral/v02"));
  m.n_images = 4;
  hearth_poses_free(&p);
  hearth_colmap_model_free(&m);
}

/* ---- alignment ------------------------------------------------------------------------- */
static void test_align(void) {
  hearth_err err = {0};
  hearth_poses est = {0}, ref = {0};
  est.n = ref.n = 6;
  est.views = calloc(6, sizeof *est.views);
  ref.views = calloc(6, sizeof *ref.views);
  double w_sim[3] = {0.3, -1.1, 0.4};
  hearth_similarity S = {.s = 0.37};
  hearth_rotvec_to_matrix(w_sim, S.T.R);
  S.T.t[0] = 1.5, S.T.t[1] = -0.25, S.T.t[2] = 3;
  for (int i = 0; i < 6; i++) {
    hearth_view_pose *e = &est.views[i], *r = &ref.views[i];
    snprintf(e->state, sizeof e->state, i < 3 ? "neutral" : "hot");
    snprintf(e->view, sizeof e->view, "v%02d", i % 3);
    double w[3] = {0.1 * i, 0.5 - 0.2 * i, 0.05 * i * i};
    hearth_rotvec_to_matrix(w, e->T_world_from_cam.R);
    e->T_world_from_cam.t[0] = cos(i), e->T_world_from_cam.t[1] = sin(2.0 * i),
    e->T_world_from_cam.t[2] = 0.3 * i;
    *r = *e;
    hearth_mat3_mul(S.T.R, e->T_world_from_cam.R, r->T_world_from_cam.R);
    hearth_rigid_apply(&S.T, e->T_world_from_cam.t, r->T_world_from_cam.t);
    for (int k = 0; k < 3; k++)
      r->T_world_from_cam.t[k] = S.s * (r->T_world_from_cam.t[k] - S.T.t[k]) + S.T.t[k];
  }
  /* ref centre = s R c + t */
  hearth_pose_alignment a;
  CHECK_OK(hearth_poses_align(&est, &ref, &a, &err), &err);
  CHECK(a.n_common == 6);
  CHECK_NEAR(a.ref_from_est.s, 0.37, 1e-12);
  for (int k = 0; k < 9; k++) CHECK_NEAR(a.ref_from_est.T.R[k], S.T.R[k], 1e-12);
  for (int k = 0; k < 3; k++) CHECK_NEAR(a.ref_from_est.T.t[k], S.T.t[k], 1e-12);
  CHECK(a.rot_max_deg < 1e-9 && a.pos_max < 1e-12);
  /* one view off by 0.1 in x */
  ref.views[2].T_world_from_cam.t[0] += 0.1;
  CHECK_OK(hearth_poses_align(&est, &ref, &a, &err), &err);
  CHECK(a.pos_max > 0.05 && a.pos_max < 0.1 && a.pos_median < a.pos_max);
  /* fewer than 3 common views; centres on a line */
  est.n = 2;
  CHECK(hearth_poses_align(&est, &ref, &a, &err) == HEARTH_E_NUMERIC);
  est.n = 6;
  for (int i = 0; i < 6; i++) {
    est.views[i].T_world_from_cam.t[0] = i;
    est.views[i].T_world_from_cam.t[1] = 2.0 * i;
    est.views[i].T_world_from_cam.t[2] = 0;
  }
  CHECK(hearth_poses_align(&est, &ref, &a, &err) == HEARTH_E_NUMERIC);
  CHECK(strstr(err.msg, "one line"));
  hearth_poses_free(&est);
  hearth_poses_free(&ref);
}

int main(void) {
  snprintf(g_dir, sizeof g_dir, "%s", test_tmpdir("recon_colmap_import"));
  test_text_and_binary();
  test_models();
  test_errors();
  test_names();
  test_align();
  TEST_MAIN_END();
}
