/* The JSON documents of a release: write -> read round trips with exact
 * doubles, deterministic bytes, the plate layout in closed form, and for
 * every reader a set of broken documents whose errors must name the file
 * and the JSON path. Broken documents are made here by editing a valid one
 * with jansson (an independent JSON implementation of the edit). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <stdint.h>
#include <unistd.h>

#include "hearth/dataset.h"
#include "test_util.h"

static const char *g_dir;

static const char *tpath(const char *name) {
  static char buf[8][1024];
  static int k = 0;
  k = (k + 1) % 8;
  snprintf(buf[k], sizeof buf[k], "%s/%s", g_dir, name);
  return buf[k];
}

static void spit(const char *path, const char *text) {
  FILE *f = fopen(path, "wb");
  if (!f) {
    fprintf(stderr, "cannot write %s\n", path);
    exit(2);
  }
  fputs(text, f);
  fclose(f);
}

static int same_bytes(const char *a, const char *b) {
  size_t la, lb;
  char *x = test_slurp(a, &la), *y = test_slurp(b, &lb);
  int same = x && y && la == lb && memcmp(x, y, la) == 0;
  free(x);
  free(y);
  return same;
}

/* ---- sample documents ------------------------------------------------------------ */

static hearth_camera cam(int w, int h, double f, double k1) {
  hearth_camera c;
  memset(&c, 0, sizeof c);
  c.width = w;
  c.height = h;
  c.fx = f;
  c.fy = f * (1.0 + 1.0 / 3000.0);
  c.cx = (w - 1) / 2.0 + 1.0 / 3.0;
  c.cy = (h - 1) / 2.0 - 0.1;
  c.dist[0] = k1;
  c.dist[1] = -k1 / 7.0;
  c.dist[2] = 1e-17;
  c.dist[3] = -2.5e-4;
  c.dist[4] = 0.0;
  return c;
}

static hearth_rigid rigid(double a, double b, double c, double tx) {
  hearth_rigid T;
  double w[3] = {a, b, c};
  hearth_rotvec_to_matrix(w, T.R);
  T.t[0] = tx;
  T.t[1] = -tx / 3.0;
  T.t[2] = 0.1 + tx * tx;
  return T;
}

static hearth_rig sample_rig(void) {
  hearth_rig r;
  r.rgb = cam(1920, 1080, 1380.123456789, 0.07);
  r.thermal = cam(256, 192, 221.7, -0.31);
  r.depth = cam(640, 576, 504.2, 0.0);
  r.T_thermal_from_rgb = rigid(0.01, -0.02, 0.003, 0.0421);
  r.T_depth_from_rgb = rigid(0.1, 0.0, 0.0, -0.032);
  r.thermal_rms_px = 0.123456789012345;
  r.stereo_rms_px = 1.0 / 3.0;
  return r;
}

static int cam_eq(const hearth_camera *a, const hearth_camera *b) {
  int eq = a->width == b->width && a->height == b->height && a->fx == b->fx && a->fy == b->fy &&
           a->cx == b->cx && a->cy == b->cy;
  for (int i = 0; i < 5; i++) eq = eq && a->dist[i] == b->dist[i];
  return eq;
}

static int rigid_eq(const hearth_rigid *a, const hearth_rigid *b) {
  int eq = 1;
  for (int i = 0; i < 9; i++) eq = eq && a->R[i] == b->R[i];
  for (int i = 0; i < 3; i++) eq = eq && a->t[i] == b->t[i];
  return eq;
}

static hearth_manifest sample_manifest(void) {
  hearth_manifest m;
  memset(&m, 0, sizeof m);
  snprintf(m.instance, sizeof m.instance, "cup_03");
  snprintf(m.state, sizeof m.state, "hot");
  m.n_views = 30;
  m.views = calloc(m.n_views, sizeof *m.views);
  for (size_t i = 0; i < m.n_views; i++) {
    hearth_view_files *f = &m.views[i];
    snprintf(f->view, sizeof f->view, "v%02zu", i);
    f->elevation_index = (int)(i / 10);
    f->azimuth_index = (int)(i % 10);
    snprintf(f->rgb, sizeof f->rgb, "rgb/v%02zu.jpg", i);
    snprintf(f->cutout, sizeof f->cutout, "cutout/v%02zu.png", i);
    snprintf(f->depth, sizeof f->depth, "depth/v%02zu.png", i);
    snprintf(f->depth_intrinsics, sizeof f->depth_intrinsics, "depth/v%02zu.json", i);
    snprintf(f->thermal, sizeof f->thermal, "thermal/v%02zu.csv", i);
  }
  return m;
}

static hearth_poses sample_poses(void) {
  hearth_poses p;
  p.n = 6;
  p.views = calloc(p.n, sizeof *p.views);
  for (size_t i = 0; i < p.n; i++) {
    snprintf(p.views[i].state, sizeof p.views[i].state, "%s", i < 3 ? "hot" : "iced");
    snprintf(p.views[i].view, sizeof p.views[i].view, "v%02zu", i % 3);
    p.views[i].T_world_from_cam =
        rigid(0.3 * (double)i, 1.0 - 0.2 * (double)i, 0.7, 0.5 + 0.1 * (double)i);
  }
  return p;
}

static hearth_detections sample_detections(void) {
  hearth_detections d = {0}; /* zeroed target: the paper's plate */
  d.n = 3;
  d.frames = calloc(d.n, sizeof *d.frames);
  for (size_t k = 0; k < d.n; k++) {
    hearth_detection *f = &d.frames[k];
    snprintf(f->frame, sizeof f->frame, "%s", k == 0 ? "f000" : "p003");
    snprintf(f->camera, sizeof f->camera, "%s", k == 2 ? "rgb" : "thermal");
    f->found = k != 2;
    if (f->found) {
      for (int i = 0; i < HEARTH_PLATE_HOLES; i++) {
        f->centres[i][0] = 20.0 + i * 2.1 + 1.0 / (double)(k + 3);
        f->centres[i][1] = 191.0 - i * 1.7;
      }
    } else {
      snprintf(f->reason, sizeof f->reason, "only 61 holes visible");
    }
  }
  return d;
}

/* ---- round trips -------------------------------------------------------------------- */

static void test_round_trips(void) {
  hearth_err err = {0};

  hearth_rig rig = sample_rig(), rig2;
  CHECK_OK(hearth_rig_write(tpath("rig.json"), &rig, &err), &err);
  CHECK_OK(hearth_rig_read(tpath("rig.json"), &rig2, &err), &err);
  CHECK(cam_eq(&rig.rgb, &rig2.rgb) && cam_eq(&rig.thermal, &rig2.thermal) &&
        cam_eq(&rig.depth, &rig2.depth));
  CHECK(rigid_eq(&rig.T_thermal_from_rgb, &rig2.T_thermal_from_rgb));
  CHECK(rigid_eq(&rig.T_depth_from_rgb, &rig2.T_depth_from_rgb));
  CHECK(rig.thermal_rms_px == rig2.thermal_rms_px && rig.stereo_rms_px == rig2.stereo_rms_px);
  /* the same document twice gives the same bytes */
  CHECK_OK(hearth_rig_write(tpath("rig_again.json"), &rig2, &err), &err);
  CHECK(same_bytes(tpath("rig.json"), tpath("rig_again.json")));
  /* keys in the spec's order, 2-space indent, short numbers stay short */
  char *text = test_slurp(tpath("rig.json"), NULL);
  CHECK(text && strncmp(text, "{\n  \"rgb\": {\n    \"width\": 1920,", 30) == 0);
  const char *order[] = {"\"rgb\"",
                         "\"thermal\"",
                         "\"depth\"",
                         "\"T_thermal_from_rgb\"",
                         "\"T_depth_from_rgb\"",
                         "\"thermal_rms_px\"",
                         "\"stereo_rms_px\""};
  const char *prev = text;
  for (int i = 0; i < 7 && text; i++) {
    const char *at = strstr(text, order[i]);
    CHECK_MSG(at && at >= prev, "key %s out of order", order[i]);
    if (at) prev = at;
  }
  CHECK(text && strstr(text, "\"width\": 256,"));
  CHECK(text && strstr(text, "0.07,"));
  free(text);

  hearth_factory_calib fac = {rig.rgb, rig.depth, rig.T_depth_from_rgb}, fac2;
  CHECK_OK(hearth_factory_write(tpath("factory.json"), &fac, &err), &err);
  CHECK_OK(hearth_factory_read(tpath("factory.json"), &fac2, &err), &err);
  CHECK(cam_eq(&fac.rgb, &fac2.rgb) && cam_eq(&fac.depth, &fac2.depth) &&
        rigid_eq(&fac.T_depth_from_rgb, &fac2.T_depth_from_rgb));

  hearth_depth_intrinsics di = {cam(640, 576, 503.9, 0.02), rigid(-0.002, 0.1, 0.0, -0.032)}, di2;
  CHECK_OK(hearth_depth_intrinsics_write(tpath("v00.json"), &di, &err), &err);
  CHECK_OK(hearth_depth_intrinsics_read(tpath("v00.json"), &di2, &err), &err);
  CHECK(cam_eq(&di.depth, &di2.depth) && rigid_eq(&di.T_depth_from_rgb, &di2.T_depth_from_rgb));

  hearth_manifest m = sample_manifest(), m2;
  m.views[1].has_time = 1; /* the optional view time */
  m.views[1].time_s = 12.5;
  m.views[1].has_turntable = 1; /* the optional encoder angle */
  m.views[1].turntable_deg = -123.456;
  CHECK_OK(hearth_manifest_write(tpath("manifest.json"), &m, &err), &err);
  CHECK_OK(hearth_manifest_read(tpath("manifest.json"), &m2, &err), &err);
  CHECK(m2.n_views == m.n_views && !strcmp(m2.instance, "cup_03") && !strcmp(m2.state, "hot"));
  for (size_t i = 0; i < m.n_views && i < m2.n_views; i++)
    CHECK(memcmp(&m.views[i], &m2.views[i], sizeof m.views[i]) == 0);
  hearth_manifest_free(&m2);
  hearth_manifest_free(&m2); /* free is idempotent */

  hearth_poses p = sample_poses(), p2;
  CHECK_OK(hearth_poses_write(tpath("poses_rgb.json"), &p, &err), &err);
  CHECK_OK(hearth_poses_read(tpath("poses_rgb.json"), &p2, &err), &err);
  CHECK(p2.n == p.n);
  for (size_t i = 0; i < p.n && i < p2.n; i++) {
    CHECK(!strcmp(p.views[i].state, p2.views[i].state));
    CHECK(!strcmp(p.views[i].view, p2.views[i].view));
    CHECK(rigid_eq(&p.views[i].T_world_from_cam, &p2.views[i].T_world_from_cam));
  }
  const hearth_view_pose *q = hearth_poses_find(&p2, "iced", "v01");
  CHECK(q && q == &p2.views[4]);
  CHECK(hearth_poses_find(&p2, "warm", "v01") == NULL);
  text = test_slurp(tpath("poses_rgb.json"), NULL);
  CHECK(text && strstr(text, "\"convention\": \"T_world_from_cam, OpenCV camera axes\""));
  CHECK(text && strstr(text, "\"units\": \"m\""));
  free(text);
  hearth_poses_free(&p2);

  hearth_detections d = sample_detections(), d2;
  CHECK_OK(hearth_detections_write(tpath("detections.json"), &d, &err), &err);
  CHECK_OK(hearth_detections_read(tpath("detections.json"), &d2, &err), &err);
  CHECK(d2.n == d.n);
  for (size_t k = 0; k < d.n && k < d2.n; k++) {
    CHECK(!strcmp(d.frames[k].frame, d2.frames[k].frame));
    CHECK(!strcmp(d.frames[k].camera, d2.frames[k].camera));
    CHECK(d.frames[k].found == d2.frames[k].found);
    CHECK(!strcmp(d.frames[k].reason, d2.frames[k].reason));
    CHECK(memcmp(d.frames[k].centres, d2.frames[k].centres, sizeof d.frames[k].centres) == 0);
  }
  hearth_detections_free(&d2);

  hearth_scale_doc sc = {0.9734123456789, 28, 0.8}, sc2;
  CHECK_OK(hearth_scale_doc_write(tpath("scale.json"), &sc, &err), &err);
  CHECK_OK(hearth_scale_doc_read(tpath("scale.json"), &sc2, &err), &err);
  CHECK(sc.scale == sc2.scale && sc.views_used == sc2.views_used &&
        sc.residual_median_mm == sc2.residual_median_mm);
  /* the contract only fixes "scale": the statistics may be absent */
  const char *minimal = "{\"scale\": 2.5, \"note\": \"free\"}";
  CHECK_OK(hearth_scale_doc_parse(minimal, strlen(minimal), "mem", &sc2, &err), &err);
  CHECK(sc2.scale == 2.5 && sc2.views_used == 0);

  hearth_instance_doc in, in2;
  memset(&in, 0, sizeof in);
  snprintf(in.id, sizeof in.id, "electric_kettle_07");
  snprintf(in.category, sizeof in.category, "electric_kettle");
  in.n_states = 3;
  snprintf(in.states[0], HEARTH_NAME_MAX, "neutral");
  snprintf(in.states[1], HEARTH_NAME_MAX, "hot");
  snprintf(in.states[2], HEARTH_NAME_MAX, "used");
  snprintf(in.notes, sizeof in.notes, "steel, \"quoted\"\nsecond line \xc3\xa9");
  CHECK_OK(hearth_instance_write(tpath("instance.json"), &in, &err), &err);
  CHECK_OK(hearth_instance_read(tpath("instance.json"), &in2, &err), &err);
  CHECK(memcmp(&in, &in2, sizeof in) == 0);

  hearth_release_doc rel, rel2;
  memset(&rel, 0, sizeof rel);
  snprintf(rel.name, sizeof rel.name, "hearth-synthetic");
  snprintf(rel.version, sizeof rel.version, "1.0.0");
  snprintf(rel.software_version, sizeof rel.software_version, "0.1.0");
  char ids[3][HEARTH_NAME_MAX] = {"cup_03", "pot_01", "orange_12"};
  rel.n_instances = 3;
  rel.instances = ids;
  CHECK_OK(hearth_release_write(tpath("release.json"), &rel, &err), &err);
  CHECK_OK(hearth_release_read(tpath("release.json"), &rel2, &err), &err);
  CHECK(rel2.n_instances == 3 && !strcmp(rel2.name, rel.name) &&
        !strcmp(rel2.version, rel.version) && !strcmp(rel2.software_version, "0.1.0"));
  for (size_t i = 0; i < 3 && i < rel2.n_instances; i++) CHECK(!strcmp(rel2.instances[i], ids[i]));
  hearth_release_free(&rel2);

  hearth_manifest_free(&m);
  hearth_poses_free(&p);
  hearth_detections_free(&d);
}

/* awkward doubles survive a write/read bit for bit */
static void test_exact_numbers(void) {
  hearth_err err = {0};
  double vals[] = {0.1,
                   1.0 / 3.0,
                   2.0 / 3.0,
                   1e-300,
                   4.9e-324,
                   1.7976931348623157e308,
                   123456789.123456789,
                   -0.0,
                   5e-324 * 3,
                   0.30000000000000004,
                   1e22,
                   1e21};
  size_t n = sizeof vals / sizeof vals[0];
  hearth_detections d = {0};
  d.n = 1;
  d.frames = calloc(1, sizeof *d.frames);
  snprintf(d.frames[0].frame, HEARTH_NAME_MAX, "f001");
  snprintf(d.frames[0].camera, 16, "rgb");
  d.frames[0].found = 1;
  for (int i = 0; i < HEARTH_PLATE_HOLES; i++) {
    d.frames[0].centres[i][0] = vals[(size_t)i % n] * (i % 2 ? -1 : 1);
    d.frames[0].centres[i][1] = vals[(size_t)(i + 5) % n] / 7.0;
  }
  hearth_detections d2;
  CHECK_OK(hearth_detections_write(tpath("exact.json"), &d, &err), &err);
  CHECK_OK(hearth_detections_read(tpath("exact.json"), &d2, &err), &err);
  if (d2.n == 1) {
    for (int i = 0; i < HEARTH_PLATE_HOLES; i++)
      for (int k = 0; k < 2; k++)
        CHECK_MSG(memcmp(&d.frames[0].centres[i][k], &d2.frames[0].centres[i][k], sizeof(double)) ==
                      0,
                  "centre %d/%d: %.17g became %.17g", i, k, d.frames[0].centres[i][k],
                  d2.frames[0].centres[i][k]);
  }
  char *text = test_slurp(tpath("exact.json"), NULL);
  /* shortest forms, not %.17g noise */
  CHECK(text && strstr(text, "[0.1, "));
  free(text);
  hearth_detections_free(&d);
  hearth_detections_free(&d2);
}

/* ---- plate ----------------------------------------------------------------------------- */

static void test_plate(void) {
  /* independent enumeration: rows r = 0..7, 11 holes on even rows, 10 on odd */
  int i = 0, counts[HEARTH_PLATE_ROWS] = {0};
  for (int r = 0; r < 8; r++) {
    int cols = (r % 2 == 0) ? 11 : 10;
    for (int c = 0; c < cols; c++, i++) {
      double xyz[3];
      hearth_plate_hole(i, xyz);
      CHECK_NEAR(xyz[0], 0.012 * c + (r % 2 ? 0.006 : 0.0), 1e-15);
      CHECK_NEAR(xyz[1], 0.0103923 * r, 1e-15);
      CHECK(xyz[2] == 0.0);
      int row = (int)lround(xyz[1] / 0.0103923);
      if (row >= 0 && row < 8) counts[row]++;
    }
  }
  CHECK(i == HEARTH_PLATE_HOLES && i == 84);
  for (int r = 0; r < 8; r++) CHECK(counts[r] == (r % 2 ? 10 : 11));
  double h[3];
  hearth_plate_hole(11, h);
  CHECK_NEAR(h[0], 0.006, 1e-15);
  CHECK_NEAR(h[1], 0.0103923, 1e-15);
  hearth_plate_hole(0, h);
  CHECK(h[0] == 0 && h[1] == 0 && h[2] == 0);
  hearth_plate_hole(83, h);
  CHECK_NEAR(h[0], 0.006 + 9 * 0.012, 1e-15);
  CHECK_NEAR(h[1], 7 * 0.0103923, 1e-15);
  hearth_plate_hole(84, h);
  CHECK(isnan(h[0]));
  hearth_plate_hole(-1, h);
  CHECK(isnan(h[0]));
  /* neighbours are one pitch apart along a row and one pitch apart across rows
   * (an equilateral lattice: sqrt(6^2 + 10.3923^2) = 12 mm) */
  double a[3], b[3];
  hearth_plate_hole(0, a);
  hearth_plate_hole(11, b);
  CHECK_NEAR(hypot(b[0] - a[0], b[1] - a[1]), 0.012, 1e-6);
}

static void test_names(void) {
  const char *cats[18] = {"sponge",       "eraser",      "bottled_drink", "tissue",
                          "headset",      "storage_bag", "glasses_case",  "smartphone",
                          "canned_drink", "mouse",       "pillow",        "wallet",
                          "cup",          "pot",         "cushion",       "electric_kettle",
                          "orange",       "laptop"};
  for (int i = 0; i < 18; i++) {
    CHECK(hearth_category_valid(cats[i]));
    int seen = 0;
    for (int j = 0; j < 18; j++) seen += !strcmp(hearth_categories[j], cats[i]);
    CHECK_MSG(seen == 1, "%s listed %d times", cats[i], seen);
  }
  CHECK(!hearth_category_valid("mug") && !hearth_category_valid("") &&
        !hearth_category_valid("Cup") && !hearth_category_valid(NULL));
  const char *states[] = {"neutral", "hot", "warm", "iced", "used"};
  for (int i = 0; i < 5; i++) CHECK(hearth_state_valid(states[i]));
  CHECK(!hearth_state_valid("cold") && !hearth_state_valid("HOT") && !hearth_state_valid(""));
  CHECK(hearth_instance_id_valid("cup_03") && hearth_instance_id_valid("bottled_drink_12"));
  CHECK(!hearth_instance_id_valid("cup_3") && !hearth_instance_id_valid("mug_03") &&
        !hearth_instance_id_valid("cup03") && !hearth_instance_id_valid("cup_0a") &&
        !hearth_instance_id_valid("cup_"));
}

/* ---- broken documents ------------------------------------------------------------------ */

/* navigate "a.b[3][1]" to the parent container and the last step */
static json_t *walk(json_t *root, const char *path, char *last_key, size_t *last_index,
                    int *last_is_index) {
  json_t *cur = root, *parent = NULL;
  const char *p = path;
  while (*p) {
    parent = cur;
    if (*p == '[') {
      size_t idx = strtoul(p + 1, (char **)&p, 10);
      p++; /* ']' */
      *last_is_index = 1;
      *last_index = idx;
      if (*p == '.') p++;
      if (*p) cur = json_array_get(cur, idx);
    } else {
      size_t n = strcspn(p, ".[");
      memcpy(last_key, p, n);
      last_key[n] = 0;
      *last_is_index = 0;
      p += n;
      if (*p == '.') p++;
      if (*p) cur = json_object_get(cur, last_key);
    }
    if (!cur) return NULL;
  }
  return parent;
}

typedef struct bad_case {
  const char *set;   /* JSON path to replace */
  const char *value; /* JSON text of the new value; NULL deletes */
  hearth_status want;
  const char *where; /* must appear in the message */
  const char *what;  /* must appear in the message */
} bad_case;

typedef hearth_status (*reader_fn)(const char *path, hearth_err *err);

static hearth_status rd_rig(const char *p, hearth_err *e) {
  hearth_rig r;
  return hearth_rig_read(p, &r, e);
}
static hearth_status rd_factory(const char *p, hearth_err *e) {
  hearth_factory_calib f;
  return hearth_factory_read(p, &f, e);
}
static hearth_status rd_depth(const char *p, hearth_err *e) {
  hearth_depth_intrinsics d;
  return hearth_depth_intrinsics_read(p, &d, e);
}
static hearth_status rd_manifest(const char *p, hearth_err *e) {
  hearth_manifest m;
  hearth_status s = hearth_manifest_read(p, &m, e);
  hearth_manifest_free(&m);
  return s;
}
static hearth_status rd_poses(const char *p, hearth_err *e) {
  hearth_poses q;
  hearth_status s = hearth_poses_read(p, &q, e);
  hearth_poses_free(&q);
  return s;
}
static hearth_status rd_detections(const char *p, hearth_err *e) {
  hearth_detections d;
  hearth_status s = hearth_detections_read(p, &d, e);
  hearth_detections_free(&d);
  return s;
}
static hearth_status rd_scale(const char *p, hearth_err *e) {
  hearth_scale_doc s;
  return hearth_scale_doc_read(p, &s, e);
}
static hearth_status rd_instance(const char *p, hearth_err *e) {
  hearth_instance_doc d;
  return hearth_instance_read(p, &d, e);
}
static hearth_status rd_release(const char *p, hearth_err *e) {
  hearth_release_doc d;
  hearth_status s = hearth_release_read(p, &d, e);
  hearth_release_free(&d);
  return s;
}

static void run_bad(const char *label, const char *valid, reader_fn rd, const bad_case *cases,
                    size_t n) {
  hearth_err err = {0};
  CHECK_MSG(rd(tpath(valid), &err) == HEARTH_OK, "%s: valid document refused: %s", label, err.msg);
  for (size_t k = 0; k < n; k++) {
    const bad_case *bc = &cases[k];
    json_error_t je;
    json_t *root = json_load_file(tpath(valid), 0, &je);
    if (!root) {
      CHECK_MSG(0, "%s: cannot reload %s", label, valid);
      return;
    }
    char key[256] = "";
    size_t idx = 0;
    int is_index = 0;
    json_t *parent = walk(root, bc->set, key, &idx, &is_index);
    CHECK_MSG(parent != NULL, "%s: test path %s not in the document", label, bc->set);
    if (!parent) {
      json_decref(root);
      continue;
    }
    json_t *v = bc->value ? json_loads(bc->value, JSON_DECODE_ANY, &je) : NULL;
    CHECK_MSG(!bc->value || v, "%s: bad test value %s", label, bc->value);
    if (is_index) v ? json_array_set_new(parent, idx, v) : json_array_remove(parent, idx);
    else v ? json_object_set_new(parent, key, v) : json_object_del(parent, key);
    char name[128];
    snprintf(name, sizeof name, "bad_%s_%zu.json", label, k);
    const char *path = tpath(name);
    json_dump_file(root, path, JSON_INDENT(1));
    json_decref(root);
    memset(&err, 0, sizeof err);
    hearth_status s = rd(path, &err);
    if (getenv("HEARTH_TEST_VERBOSE")) fprintf(stderr, "  %s\n", err.msg);
    CHECK_MSG(s == bc->want, "%s[%zu] (%s): status %s, want %s: %s", label, k, bc->set,
              hearth_status_name(s), hearth_status_name(bc->want), err.msg);
    CHECK_MSG(strstr(err.msg, path) != NULL, "%s[%zu]: message lacks the file: %s", label, k,
              err.msg);
    CHECK_MSG(strstr(err.msg, bc->where) != NULL, "%s[%zu]: message lacks '%s': %s", label, k,
              bc->where, err.msg);
    CHECK_MSG(strstr(err.msg, bc->what) != NULL, "%s[%zu]: message lacks '%s': %s", label, k,
              bc->what, err.msg);
  }
}

#define N(a) (sizeof(a) / sizeof((a)[0]))

static void test_bad_documents(void) {
  static const bad_case rig[] = {
      {"thermal_rms_px", NULL, HEARTH_E_NOT_FOUND, ": thermal_rms_px:", "missing key"},
      {"thermal", NULL, HEARTH_E_NOT_FOUND, ": thermal:", "missing key"},
      {"rgb.width", "\"1920\"", HEARTH_E_PARSE, "rgb.width", "expected an integer, found a string"},
      {"rgb.width", "0", HEARTH_E_RANGE, "rgb.width", "expected an integer in [1,"},
      {"thermal.dist[4]", "\"NaN\"", HEARTH_E_PARSE, "thermal.dist[4]", "expected a number"},
      {"depth.dist", "[0, 0, 0, 0]", HEARTH_E_SIZE, "depth.dist", "found 4"},
      {"rgb.K[1][0]", "0.5", HEARTH_E_RANGE, "rgb.K[1][0]", "expected 0"},
      {"rgb.K[2][2]", "2", HEARTH_E_RANGE, "rgb.K[2][2]", "expected 1"},
      {"thermal.K[1][1]", "-200.0", HEARTH_E_RANGE, "thermal.K[1][1]", "fy > 0"},
      {"T_thermal_from_rgb.R[0][0]", "1.5", HEARTH_E_RANGE, "T_thermal_from_rgb.R",
       "not a rotation (det="},
      {"T_depth_from_rgb.R", "[[1,0,0],[0,1,0],[0,0,-1]]", HEARTH_E_RANGE, "T_depth_from_rgb.R",
       "det=-1"},
      {"T_depth_from_rgb.t[1]", "null", HEARTH_E_PARSE, "T_depth_from_rgb.t[1]", "found null"},
      {"stereo_rms_px", "-1", HEARTH_E_RANGE, "stereo_rms_px", ">= 0"},
  };
  run_bad("rig", "rig.json", rd_rig, rig, N(rig));

  static const bad_case factory[] = {
      {"depth", NULL, HEARTH_E_NOT_FOUND, ": depth:", "missing key"},
      {"rgb.K", "[[1,0,0],[0,1,0]]", HEARTH_E_SIZE, "rgb.K", "found 2"},
  };
  run_bad("factory", "factory.json", rd_factory, factory, N(factory));

  static const bad_case depth[] = {
      {"K", NULL, HEARTH_E_NOT_FOUND, ": K:", "missing key"},
      {"height", "1e9", HEARTH_E_PARSE, "height", "expected an integer"},
      {"K[0][2]", "\"320\"", HEARTH_E_PARSE, "K[0][2]", "expected a number"},
      {"T_depth_from_rgb.t", "[0, 0]", HEARTH_E_SIZE, "T_depth_from_rgb.t", "found 2"},
      {"T_depth_from_rgb", "[]", HEARTH_E_PARSE, "T_depth_from_rgb", "expected an object"},
  };
  run_bad("depth", "v00.json", rd_depth, depth, N(depth));

  static const bad_case manifest[] = {
      {"views[3].thermal", NULL, HEARTH_E_NOT_FOUND, "views[3].thermal", "missing key"},
      {"views[2].view", "\"v00\"", HEARTH_E_INCONSISTENT, "views[2].view", "duplicate"},
      {"views[1].rgb", "\"../rgb/v01.jpg\"", HEARTH_E_RANGE, "views[1].rgb", "relative path"},
      {"views[1].cutout", "\"/etc/passwd\"", HEARTH_E_RANGE, "views[1].cutout", "relative"},
      {"views[1].depth", "\"depth//v01.png\"", HEARTH_E_RANGE, "views[1].depth", "relative"},
      {"views[4].elevation_index", "-1", HEARTH_E_RANGE, "views[4].elevation_index", "[0,"},
      {"views[4].azimuth_index", "1.5", HEARTH_E_PARSE, "views[4].azimuth_index", "integer"},
      {"views[2].time_s", "-2", HEARTH_E_RANGE, "views[2]", "0..1e6"},
      {"views[2].turntable_deg", "3600.5", HEARTH_E_RANGE, "views[2]", "-3600..3600"},
      {"views[2].turntable_deg", "\"12\"", HEARTH_E_PARSE, "views[2].turntable_deg", "number"},
      {"instance", "\"mug_03\"", HEARTH_E_RANGE, "instance", "18 categories"},
      {"state", "\"boiling\"", HEARTH_E_RANGE, "state", "neutral, hot"},
      {"views", "[]", HEARTH_E_SIZE, "views", "at least 1"},
      {"views[0]", "\"v00\"", HEARTH_E_PARSE, "views[0]", "expected an object"},
      /* two views naming one file: refused at the second, naming both */
      {"views[7].thermal", "\"thermal/v02.csv\"", HEARTH_E_INCONSISTENT, "views[7].thermal",
       "view \"v07\" names \"thermal/v02.csv\", the file of view \"v02\" (views[2].thermal)"},
      {"views[5].rgb", "\"./rgb/./v01.jpg\"", HEARTH_E_INCONSISTENT, "views[5].rgb",
       "the file of view \"v01\" (views[1].rgb)"},
      {"views[3].depth", "\"cutout/v00.png\"", HEARTH_E_INCONSISTENT, "views[3].depth",
       "the file of view \"v00\" (views[0].cutout)"},
  };
  run_bad("manifest", "manifest.json", rd_manifest, manifest, N(manifest));

  static const bad_case poses[] = {
      {"views[1].T_world_from_cam", "[[1,0,0,0],[0,1,0,0],[0,0,1,0]]", HEARTH_E_SIZE,
       "views[1].T_world_from_cam", "expected an array of 4 elements, found 3"},
      {"views[2].T_world_from_cam[2][1]", "\"NaN\"", HEARTH_E_PARSE,
       "views[2].T_world_from_cam[2][1]", "expected a number, found a string"},
      {"views[0].T_world_from_cam[0][0]", "0.9", HEARTH_E_RANGE, "views[0].T_world_from_cam",
       "not a rotation"},
      {"views[0].T_world_from_cam[3][3]", "2", HEARTH_E_RANGE, "views[0].T_world_from_cam[3][3]",
       "last row"},
      {"views[5].view", "\"v01\"", HEARTH_E_INCONSISTENT, "views[5]", "duplicate"},
      {"views[0].state", "\"cold\"", HEARTH_E_RANGE, "views[0].state", "neutral"},
      {"units", "\"mm\"", HEARTH_E_UNSUPPORTED, "units", "expected \"m\""},
      {"convention", NULL, HEARTH_E_NOT_FOUND, "convention", "missing key"},
      {"views[4].T_world_from_cam", NULL, HEARTH_E_NOT_FOUND, "views[4].T_world_from_cam",
       "missing"},
  };
  run_bad("poses", "poses_rgb.json", rd_poses, poses, N(poses));

  static const bad_case det[] = {
      {"frames[0].centres[83]", NULL, HEARTH_E_SIZE, "frames[0].centres",
       "expected an array of 84 elements, found 83"},
      {"frames[1].centres[5][1]", "\"NaN\"", HEARTH_E_PARSE, "frames[1].centres[5][1]",
       "expected a number"},
      {"frames[1].centres[5]", "[1, 2, 3]", HEARTH_E_SIZE, "frames[1].centres[5]", "found 3"},
      {"frames[2].reason", NULL, HEARTH_E_NOT_FOUND, "frames[2].reason", "missing key"},
      {"frames[2].reason", "\"\"", HEARTH_E_RANGE, "frames[2].reason", "non-empty"},
      {"frames[1].found", "1", HEARTH_E_PARSE, "frames[1].found", "true or false"},
      {"frames[0].camera", "\"ir\"", HEARTH_E_RANGE, "frames[0].camera", "\"thermal\" or"},
      {"frames[1].frame", "\"f000\"", HEARTH_E_INCONSISTENT, "frames[1]", "duplicate frame"},
      {"pattern.pitch_m", "0.01", HEARTH_E_UNSUPPORTED, "pattern.pitch_m", "0.012"},
      {"pattern.cols_odd", "11", HEARTH_E_UNSUPPORTED, "pattern.cols_odd", "expected 10"},
      {"pattern", NULL, HEARTH_E_NOT_FOUND, "pattern", "missing key"},
  };
  run_bad("detections", "detections.json", rd_detections, det, N(det));

  static const bad_case scale[] = {
      {"scale", "0", HEARTH_E_RANGE, "scale", "> 0"},
      {"scale", "\"0.97\"", HEARTH_E_PARSE, "scale", "expected a number"},
      {"scale", NULL, HEARTH_E_NOT_FOUND, "scale", "missing key"},
      {"views_used", "-3", HEARTH_E_RANGE, "views_used", "[0,"},
  };
  run_bad("scale", "scale.json", rd_scale, scale, N(scale));

  static const bad_case inst[] = {
      {"id", "\"mug_03\"", HEARTH_E_RANGE, ": id:", "18 categories"},
      {"category", "\"mug\"", HEARTH_E_RANGE, "category", "18 categories"},
      {"category", "\"pot\"", HEARTH_E_INCONSISTENT, ": id:", "category \"pot\""},
      {"states[1]", "\"boiling\"", HEARTH_E_RANGE, "states[1]", "neutral, hot"},
      {"states[2]", "\"hot\"", HEARTH_E_INCONSISTENT, "states[2]", "duplicate of states[1]"},
      {"states", "[]", HEARTH_E_SIZE, "states", "at least 1"},
      {"notes", "7", HEARTH_E_PARSE, "notes", "expected a string"},
  };
  run_bad("instance", "instance.json", rd_instance, inst, N(inst));

  static const bad_case rel[] = {
      {"instances[2]", "\"cup_03\"", HEARTH_E_INCONSISTENT, "instances[2]",
       "duplicate of instances[0]"},
      {"instances[1]", "\"kettle_01\"", HEARTH_E_RANGE, "instances[1]", "18 categories"},
      {"name", "\"\"", HEARTH_E_RANGE, "name", "non-empty"},
      {"software_version", NULL, HEARTH_E_NOT_FOUND, "software_version", "missing key"},
  };
  run_bad("release", "release.json", rd_release, rel, N(rel));
}

/* syntax errors carry jansson's line and column; duplicates are refused */
static void test_syntax(void) {
  hearth_err err = {0};
  struct {
    const char *text;
    const char *what;
  } cases[] = {
      {"{\n  \"scale\": NaN\n}\n", "line 2"},
      {"{\"scale\": 1.0,}", "line 1, column"},
      {"{\"scale\": 1.0, \"scale\": 2.0}", "duplicate"},
      {"[1, 2]", "expected a JSON object"},
      {"", "line"},
      {"{\"scale\": 1e999}", "line 1"},
  };
  for (size_t k = 0; k < N(cases); k++) {
    char name[64];
    snprintf(name, sizeof name, "syntax_%zu.json", k);
    spit(tpath(name), cases[k].text);
    hearth_scale_doc sc;
    memset(&err, 0, sizeof err);
    hearth_status s = hearth_scale_doc_read(tpath(name), &sc, &err);
    CHECK_MSG(s == HEARTH_E_PARSE, "syntax %zu: %s: %s", k, hearth_status_name(s), err.msg);
    CHECK_MSG(strstr(err.msg, tpath(name)) && strstr(err.msg, cases[k].what),
              "syntax %zu: message lacks '%s': %s", k, cases[k].what, err.msg);
  }
  /* parse variants name what the caller calls the text */
  hearth_poses p;
  CHECK(hearth_poses_parse("{\"units\": \"m\"}", 14, "buffer-7", &p, &err) == HEARTH_E_NOT_FOUND);
  CHECK(strstr(err.msg, "buffer-7: convention: missing key") != NULL);
  hearth_poses_free(&p);
  /* missing files are I/O errors naming the file */
  hearth_rig r;
  CHECK(hearth_rig_read(tpath("no_such_rig.json"), &r, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "no_such_rig.json") != NULL);
  /* oversized files are refused before reading (a sparse file costs nothing) */
  int fd = open(tpath("huge.json"), O_CREAT | O_WRONLY | O_TRUNC, 0644);
  CHECK(fd >= 0);
  if (fd >= 0) {
    CHECK(ftruncate(fd, (off_t)65 << 20) == 0);
    close(fd);
    CHECK(hearth_rig_read(tpath("huge.json"), &r, &err) == HEARTH_E_LIMIT);
    CHECK(strstr(err.msg, "huge.json") != NULL);
    unlink(tpath("huge.json"));
  }
}

static size_t count_entries(const char *dir) {
  DIR *d = opendir(dir);
  size_t n = 0;
  struct dirent *e;
  while (d && (e = readdir(d)) != NULL)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
  if (d) closedir(d);
  return n;
}

/* writers refuse what the readers would refuse, and leave nothing behind */
/* instance.json read from its directory must describe that instance */
static void test_instance_load(void) {
  hearth_err err = {0};
  char dir[1200], path[1300];
  snprintf(dir, sizeof dir, "%s/load/instances/cup_03", g_dir);
  CHECK_OK(hearth_mkdirs(dir, &err), &err);
  hearth_instance_doc in, back;
  memset(&in, 0, sizeof in);
  snprintf(in.id, sizeof in.id, "cup_04");
  snprintf(in.category, sizeof in.category, "cup");
  in.n_states = 1;
  snprintf(in.states[0], HEARTH_NAME_MAX, "hot");
  snprintf(path, sizeof path, "%s/instance.json", dir);
  CHECK_OK(hearth_instance_write(path, &in, &err), &err);
  snprintf(dir, sizeof dir, "%s/load", g_dir);
  CHECK(hearth_instance_load(dir, "cup_03", &back, &err) == HEARTH_E_INCONSISTENT);
  CHECK_MSG(strstr(err.msg,
                   "cup_03/instance.json: id: \"cup_04\", but the directory is "
                   "instances/cup_03"),
            "%s", err.msg);
  snprintf(in.id, sizeof in.id, "cup_03");
  CHECK_OK(hearth_instance_write(path, &in, &err), &err);
  CHECK_OK(hearth_instance_load(dir, "cup_03", &back, &err), &err);
  CHECK(!strcmp(back.id, "cup_03"));
}

static void test_writer_refusals(void) {
  hearth_err err = {0};
  char sub[1100];
  snprintf(sub, sizeof sub, "%s/refuse", g_dir);
  CHECK_OK(hearth_mkdirs(sub, &err), &err);
  char path[1200];

  hearth_rig rig = sample_rig();
  rig.thermal.fx = NAN;
  snprintf(path, sizeof path, "%s/rig.json", sub);
  CHECK(hearth_rig_write(path, &rig, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, "thermal.K[0][0]") && strstr(err.msg, path), "%s", err.msg);

  hearth_poses p = sample_poses();
  p.views[2].T_world_from_cam.R[4] = 3.0;
  snprintf(path, sizeof path, "%s/poses.json", sub);
  CHECK(hearth_poses_write(path, &p, &err) == HEARTH_E_RANGE);
  CHECK_MSG(strstr(err.msg, "views[2].T_world_from_cam") && strstr(err.msg, "not a rotation"), "%s",
            err.msg);
  hearth_poses_free(&p);

  hearth_manifest m = sample_manifest();
  snprintf(m.views[7].view, HEARTH_NAME_MAX, "v03");
  snprintf(path, sizeof path, "%s/manifest.json", sub);
  CHECK(hearth_manifest_write(path, &m, &err) == HEARTH_E_INCONSISTENT);
  CHECK_MSG(strstr(err.msg, "views[7].view"), "%s", err.msg);
  hearth_manifest_free(&m);

  hearth_detections d = sample_detections();
  d.frames[2].reason[0] = 0;
  snprintf(path, sizeof path, "%s/detections.json", sub);
  CHECK(hearth_detections_write(path, &d, &err) == HEARTH_E_RANGE);
  CHECK_MSG(strstr(err.msg, "frames[2].reason"), "%s", err.msg);
  hearth_detections_free(&d);

  hearth_instance_doc in;
  memset(&in, 0, sizeof in);
  snprintf(in.id, sizeof in.id, "cup_01");
  snprintf(in.category, sizeof in.category, "cup");
  in.n_states = 1;
  snprintf(in.states[0], HEARTH_NAME_MAX, "hot");
  snprintf(in.notes, sizeof in.notes, "bad utf-8 \xff");
  snprintf(path, sizeof path, "%s/instance.json", sub);
  CHECK(hearth_instance_write(path, &in, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, "notes"), "%s", err.msg);

  CHECK_MSG(count_entries(sub) == 0, "%zu files left in %s", count_entries(sub), sub);

  /* a failed write over an existing file keeps the old one */
  hearth_scale_doc sc = {1.25, 3, 0.5}, bad = {-1.0, 3, 0.5}, back;
  snprintf(path, sizeof path, "%s/scale.json", sub);
  CHECK_OK(hearth_scale_doc_write(path, &sc, &err), &err);
  CHECK(hearth_scale_doc_write(path, &bad, &err) == HEARTH_E_RANGE);
  CHECK_OK(hearth_scale_doc_read(path, &back, &err), &err);
  CHECK(back.scale == 1.25);
  CHECK(count_entries(sub) == 1);
}

int main(void) {
  g_dir = test_tmpdir("io_release");
  test_instance_load();
  test_round_trips();
  test_exact_numbers();
  test_plate();
  test_names();
  test_bad_documents();
  test_syntax();
  test_writer_refusals();
  TEST_MAIN_END();
}
