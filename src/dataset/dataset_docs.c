/* The JSON documents of a release tree (docs/dataset.md): rig.json,
 * calibration/factory.json, depth/vNN.json, scale.json, instance.json,
 * release.json, plus names and the plate layout. manifest, poses and
 * detections live in dataset_views.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/dataset.h"
#include "dataset/dataset_json.h"
#include "dataset/dataset_internal.h"

/* ---- names ------------------------------------------------------------------------ */

const char *const hearth_categories[18] =
    {"sponge",       "eraser",     "bottled_drink", "tissue",          "headset", "storage_bag",
     "glasses_case", "smartphone", "canned_drink",  "mouse",           "pillow",  "wallet",
     "cup",          "pot",        "cushion",       "electric_kettle", "orange",  "laptop"};

int hearth_category_valid(const char *name) {
  if (!name) return 0;
  for (int i = 0; i < 18; i++)
    if (strcmp(name, hearth_categories[i]) == 0) return 1;
  return 0;
}

int hearth_state_valid(const char *name) {
  static const char *const states[] = {"neutral", "hot", "warm", "iced", "used"};
  if (!name) return 0;
  for (size_t i = 0; i < sizeof states / sizeof states[0]; i++)
    if (strcmp(name, states[i]) == 0) return 1;
  return 0;
}

int hearth_instance_id_valid(const char *id) {
  if (!id) return 0;
  size_t n = strlen(id);
  if (n == 0 || n >= HEARTH_NAME_MAX) return 0;
  const char *us = strrchr(id, '_');
  if (!us) return 0;
  size_t digits = n - (size_t)(us + 1 - id);
  if (digits < 2 || digits > 4) return 0;
  for (const char *p = us + 1; *p; p++)
    if (*p < '0' || *p > '9') return 0;
  char cat[HEARTH_NAME_MAX];
  size_t cl = (size_t)(us - id);
  memcpy(cat, id, cl);
  cat[cl] = 0;
  return hearth_category_valid(cat);
}

/* ---- the calibration plate --------------------------------------------------------- */

void hearth_plate_hole(int i, double xyz[3]) {
  if (i < 0 || i >= HEARTH_PLATE_HOLES) {
    xyz[0] = xyz[1] = xyz[2] = NAN;
    return;
  }
  /* rows alternate 11 (even r) and 10 (odd r) holes: 21 per pair of rows */
  int r = 2 * (i / 21), c = i % 21;
  if (c >= 11) {
    r += 1;
    c -= 11;
  }
  xyz[0] = HEARTH_PLATE_PITCH_M * c + ((r & 1) ? 0.5 * HEARTH_PLATE_PITCH_M : 0.0);
  xyz[1] = HEARTH_PLATE_ROW_STEP_M * r;
  xyz[2] = 0.0;
}

/* ---- rig.json ---------------------------------------------------------------------- */

static hearth_status get_nonneg(hj_ctx *c, const json_t *obj, const char *key, double *out) {
  hearth_status s = hj_get_number(c, obj, key, out);
  if (s) return s;
  if (*out < 0) {
    size_t m = hj_push_key(c, key);
    s = hj_fail(c, HEARTH_E_RANGE, "expected a number >= 0, found %.17g", *out);
    hj_pop(c, m);
  }
  return s;
}

/* the colour and depth cameras keep the 5-parameter model (only the
 * thermal calibration chooses a wide-angle model); key NULL: the camera
 * fields sit at the top level */
static hearth_status brown5_only(hj_ctx *c, const char *key, const hearth_camera *cam) {
  if (cam->model == HEARTH_LENS_BROWN5) return HEARTH_OK;
  size_t m = key ? hj_push_key(c, key) : 0;
  size_t m2 = hj_push_key(c, "dist");
  hearth_status s = hj_fail(c, HEARTH_E_UNSUPPORTED,
                            "8 coefficients (the rational model) are only supported for the "
                            "thermal camera; expected 5 (k1 k2 p1 p2 k3)");
  hj_pop(c, key ? m : m2);
  return s;
}

/* the keys a rig.json with the stereo calibration has beyond a
 * thermal-only one */
static const char *const k_stereo_keys[] = {"rgb", "depth", "T_thermal_from_rgb",
                                            "T_depth_from_rgb", "stereo_rms_px"};

static hearth_status rig_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_rig r;
  memset(&r, 0, sizeof r);
  hearth_status s;
  int stereo = 0;
  for (size_t i = 0; i < sizeof k_stereo_keys / sizeof k_stereo_keys[0]; i++)
    stereo |= json_object_get(root, k_stereo_keys[i]) != NULL;
  if (!stereo) {
    /* thermal-only (hearth calibrate --thermal-only): the thermal camera
     * and its RMS, nothing else */
    if ((s = hj_get_camera(c, root, "thermal", &r.thermal))) return s;
    if ((s = get_nonneg(c, root, "thermal_rms_px", &r.thermal_rms_px))) return s;
    r.thermal_only = 1;
    *(hearth_rig *)out = r;
    return HEARTH_OK;
  }
  if ((s = hj_get_camera(c, root, "rgb", &r.rgb)) || (s = brown5_only(c, "rgb", &r.rgb))) return s;
  if ((s = hj_get_camera(c, root, "thermal", &r.thermal))) return s;
  if ((s = hj_get_camera(c, root, "depth", &r.depth)) || (s = brown5_only(c, "depth", &r.depth)))
    return s;
  if ((s = hj_get_rigid(c, root, "T_thermal_from_rgb", &r.T_thermal_from_rgb))) return s;
  if ((s = hj_get_rigid(c, root, "T_depth_from_rgb", &r.T_depth_from_rgb))) return s;
  if ((s = get_nonneg(c, root, "thermal_rms_px", &r.thermal_rms_px))) return s;
  if ((s = get_nonneg(c, root, "stereo_rms_px", &r.stereo_rms_px))) return s;
  *(hearth_rig *)out = r;
  return HEARTH_OK;
}

hearth_status hearth_rig_parse(const char *text, size_t len, const char *name, hearth_rig *rig,
                               hearth_err *err) {
  return hr_parse_doc(text, len, name, rig_from_json, rig, err);
}

hearth_status hearth_rig_read(const char *path, hearth_rig *rig, hearth_err *err) {
  return hr_read_doc(path, rig_from_json, rig, err);
}

static hearth_status rig_validate(const char *text, size_t len, const char *name, hearth_err *err) {
  hearth_rig r;
  return hearth_rig_parse(text, len, name, &r, err);
}

hearth_status hearth_rig_require_stereo(const hearth_rig *rig, const char *path, const char *stage,
                                        hearth_err *err) {
  if (!rig->thermal_only) return HEARTH_OK;
  return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                        "%s: a thermal-only rig (hearth calibrate --thermal-only) has no colour "
                        "camera and no T_thermal_from_rgb, which %s needs; calibrate with the "
                        "stereo pairs and factory.json",
                        path ? path : "rig.json", stage ? stage : "this stage");
}

hearth_status hearth_rig_write(const char *path, const hearth_rig *rig, hearth_err *err) {
  json_t *o = json_object();
  if (rig->thermal_only) {
    int ok = hj_set(o, "thermal", hj_camera_new(&rig->thermal)) &&
             hj_set(o, "thermal_rms_px", hj_real(rig->thermal_rms_px));
    if (!ok) {
      json_decref(o);
      o = NULL;
    }
    return hj_write_doc(path, o, rig_validate, err);
  }
  int ok = hj_set(o, "rgb", hj_camera_new(&rig->rgb)) &&
           hj_set(o, "thermal", hj_camera_new(&rig->thermal)) &&
           hj_set(o, "depth", hj_camera_new(&rig->depth)) &&
           hj_set(o, "T_thermal_from_rgb", hj_rigid_new(&rig->T_thermal_from_rgb)) &&
           hj_set(o, "T_depth_from_rgb", hj_rigid_new(&rig->T_depth_from_rgb)) &&
           hj_set(o, "thermal_rms_px", hj_real(rig->thermal_rms_px)) &&
           hj_set(o, "stereo_rms_px", hj_real(rig->stereo_rms_px));
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, rig_validate, err);
}

/* ---- calibration/factory.json ----------------------------------------------------- */

static hearth_status factory_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_factory_calib f;
  memset(&f, 0, sizeof f);
  hearth_status s;
  if ((s = hj_get_camera(c, root, "rgb", &f.rgb)) || (s = brown5_only(c, "rgb", &f.rgb))) return s;
  if ((s = hj_get_camera(c, root, "depth", &f.depth)) || (s = brown5_only(c, "depth", &f.depth)))
    return s;
  if ((s = hj_get_rigid(c, root, "T_depth_from_rgb", &f.T_depth_from_rgb))) return s;
  *(hearth_factory_calib *)out = f;
  return HEARTH_OK;
}

hearth_status hearth_factory_parse(const char *text, size_t len, const char *name,
                                   hearth_factory_calib *f, hearth_err *err) {
  return hr_parse_doc(text, len, name, factory_from_json, f, err);
}

hearth_status hearth_factory_read(const char *path, hearth_factory_calib *f, hearth_err *err) {
  return hr_read_doc(path, factory_from_json, f, err);
}

static hearth_status factory_validate(const char *text, size_t len, const char *name,
                                      hearth_err *err) {
  hearth_factory_calib f;
  return hearth_factory_parse(text, len, name, &f, err);
}

hearth_status hearth_factory_write(const char *path, const hearth_factory_calib *f,
                                   hearth_err *err) {
  json_t *o = json_object();
  int ok = hj_set(o, "rgb", hj_camera_new(&f->rgb)) &&
           hj_set(o, "depth", hj_camera_new(&f->depth)) &&
           hj_set(o, "T_depth_from_rgb", hj_rigid_new(&f->T_depth_from_rgb));
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, factory_validate, err);
}

/* ---- depth/vNN.json ---------------------------------------------------------------- */

static hearth_status depth_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_depth_intrinsics d;
  memset(&d, 0, sizeof d);
  hearth_status s;
  /* the camera fields sit at the top level, beside T_depth_from_rgb */
  if ((s = hj_camera(c, root, &d.depth)) || (s = brown5_only(c, NULL, &d.depth))) return s;
  if ((s = hj_get_rigid(c, root, "T_depth_from_rgb", &d.T_depth_from_rgb))) return s;
  *(hearth_depth_intrinsics *)out = d;
  return HEARTH_OK;
}

hearth_status hearth_depth_intrinsics_parse(const char *text, size_t len, const char *name,
                                            hearth_depth_intrinsics *d, hearth_err *err) {
  return hr_parse_doc(text, len, name, depth_from_json, d, err);
}

hearth_status hearth_depth_intrinsics_read(const char *path, hearth_depth_intrinsics *d,
                                           hearth_err *err) {
  return hr_read_doc(path, depth_from_json, d, err);
}

static hearth_status depth_validate(const char *text, size_t len, const char *name,
                                    hearth_err *err) {
  hearth_depth_intrinsics d;
  return hearth_depth_intrinsics_parse(text, len, name, &d, err);
}

hearth_status hearth_depth_intrinsics_write(const char *path, const hearth_depth_intrinsics *d,
                                            hearth_err *err) {
  json_t *o = hj_camera_new(&d->depth);
  if (o && !hj_set(o, "T_depth_from_rgb", hj_rigid_new(&d->T_depth_from_rgb))) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, depth_validate, err);
}

/* ---- scale.json ----------------------------------------------------------------------- */

static hearth_status scale_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_scale_doc d = {0, 0, 0};
  hearth_status s;
  if ((s = hj_get_number(c, root, "scale", &d.scale))) return s;
  if (!(d.scale > 0)) {
    size_t m = hj_push_key(c, "scale");
    s = hj_fail(c, HEARTH_E_RANGE, "expected a number > 0, found %.17g", d.scale);
    hj_pop(c, m);
    return s;
  }
  /* the contract fixes only "scale"; the statistics are optional (0 when absent) */
  if (json_object_get(root, "views_used") &&
      (s = hj_get_int(c, root, "views_used", 0, 1 << 30, &d.views_used)))
    return s;
  if (json_object_get(root, "residual_median_mm") &&
      (s = get_nonneg(c, root, "residual_median_mm", &d.residual_median_mm)))
    return s;
  *(hearth_scale_doc *)out = d;
  return HEARTH_OK;
}

hearth_status hearth_scale_doc_parse(const char *text, size_t len, const char *name,
                                     hearth_scale_doc *s, hearth_err *err) {
  return hr_parse_doc(text, len, name, scale_from_json, s, err);
}

hearth_status hearth_scale_doc_read(const char *path, hearth_scale_doc *s, hearth_err *err) {
  return hr_read_doc(path, scale_from_json, s, err);
}

static hearth_status scale_validate(const char *text, size_t len, const char *name,
                                    hearth_err *err) {
  hearth_scale_doc d;
  return hearth_scale_doc_parse(text, len, name, &d, err);
}

hearth_status hearth_scale_doc_write(const char *path, const hearth_scale_doc *s, hearth_err *err) {
  json_t *o = json_object();
  int ok = hj_set(o, "scale", hj_real(s->scale)) &&
           hj_set(o, "views_used", json_integer(s->views_used)) &&
           hj_set(o, "residual_median_mm", hj_real(s->residual_median_mm));
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, scale_validate, err);
}

/* ---- instance.json ---------------------------------------------------------------------- */

static hearth_status instance_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_instance_doc d;
  memset(&d, 0, sizeof d);
  hearth_status s;
  if ((s = hr_get_checked(c, root, "id", d.id, sizeof d.id, hearth_instance_id_valid,
                          "an instance id <category>_<NN> with one of the 18 categories")))
    return s;
  if ((s = hr_get_checked(c, root, "category", d.category, sizeof d.category, hearth_category_valid,
                          "one of the 18 categories of docs/dataset.md")))
    return s;
  size_t cl = strlen(d.category);
  if (strncmp(d.id, d.category, cl) != 0 || d.id[cl] != '_' || !hearth_instance_id_valid(d.id)) {
    size_t m = hj_push_key(c, "id");
    s = hj_fail(c, HEARTH_E_INCONSISTENT, "\"%s\" does not belong to category \"%s\"", d.id,
                d.category);
    hj_pop(c, m);
    return s;
  }
  json_t *sv;
  if ((s = hj_member(c, root, "states", &sv))) return s;
  size_t m = hj_push_key(c, "states");
  if ((s = hj_array(c, sv, 1, HEARTH_MAX_STATES, &d.n_states))) return s;
  for (size_t i = 0; i < d.n_states; i++) {
    size_t m2 = hj_push_index(c, i);
    if ((s = hj_string(c, json_array_get(sv, i), d.states[i], sizeof d.states[i]))) return s;
    if (!hearth_state_valid(d.states[i]))
      return hj_fail(c, HEARTH_E_RANGE, "expected neutral, hot, warm, iced or used, found \"%s\"",
                     d.states[i]);
    for (size_t j = 0; j < i; j++)
      if (strcmp(d.states[i], d.states[j]) == 0)
        return hj_fail(c, HEARTH_E_INCONSISTENT, "duplicate of states[%zu] (\"%s\")", j,
                       d.states[i]);
    hj_pop(c, m2);
  }
  hj_pop(c, m);
  /* notes are optional free text */
  if (json_object_get(root, "notes") &&
      (s = hj_get_string(c, root, "notes", d.notes, sizeof d.notes)))
    return s;
  *(hearth_instance_doc *)out = d;
  return HEARTH_OK;
}

hearth_status hearth_instance_parse(const char *text, size_t len, const char *name,
                                    hearth_instance_doc *d, hearth_err *err) {
  return hr_parse_doc(text, len, name, instance_from_json, d, err);
}

hearth_status hearth_instance_read(const char *path, hearth_instance_doc *d, hearth_err *err) {
  return hr_read_doc(path, instance_from_json, d, err);
}

hearth_status hearth_instance_load(const char *root, const char *id, hearth_instance_doc *d,
                                   hearth_err *err) {
  char path[4096];
  int n = snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, id);
  if (n < 0 || (size_t)n >= sizeof path)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s/instances/%s: path too long", root, id);
  hearth_status s = hearth_instance_read(path, d, err);
  if (s) return s;
  if (strcmp(d->id, id))
    return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "%s: id: \"%s\", but the directory is instances/%s", path, d->id, id);
  return HEARTH_OK;
}

static hearth_status instance_validate(const char *text, size_t len, const char *name,
                                       hearth_err *err) {
  hearth_instance_doc d;
  return hearth_instance_parse(text, len, name, &d, err);
}

hearth_status hearth_instance_write(const char *path, const hearth_instance_doc *d,
                                    hearth_err *err) {
  if (d->n_states > HEARTH_MAX_STATES)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: not written: %zu states (at most %d)", path,
                          d->n_states, HEARTH_MAX_STATES);
  json_t *o = json_object();
  json_t *st = json_array();
  int ok = o && st;
  for (size_t i = 0; ok && i < d->n_states; i++)
    ok = json_array_append_new(st, hj_str(d->states[i])) == 0;
  ok = ok && hj_set(o, "id", hj_str(d->id)) && hj_set(o, "category", hj_str(d->category)) &&
       hj_set(o, "states", json_incref(st)) && hj_set(o, "notes", hj_str(d->notes));
  json_decref(st);
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, instance_validate, err);
}

/* ---- release.json ------------------------------------------------------------------------- */

#define HR_MAX_INSTANCES 65536

void hearth_release_free(hearth_release_doc *d) {
  if (!d) return;
  free(d->instances);
  d->instances = NULL;
  d->n_instances = 0;
}

static hearth_status release_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_release_doc d;
  memset(&d, 0, sizeof d);
  hearth_status s;
  if ((s = hr_get_nonempty(c, root, "name", d.name, sizeof d.name))) return s;
  if ((s = hr_get_nonempty(c, root, "version", d.version, sizeof d.version))) return s;
  if ((s = hr_get_nonempty(c, root, "software_version", d.software_version,
                           sizeof d.software_version)))
    return s;
  json_t *iv;
  if ((s = hj_member(c, root, "instances", &iv))) return s;
  size_t m = hj_push_key(c, "instances");
  size_t n;
  if ((s = hj_array(c, iv, 0, HR_MAX_INSTANCES, &n))) return s;
  d.instances = hearth_calloc_array(n ? n : 1, sizeof *d.instances);
  if (!d.instances) return hj_fail(c, HEARTH_E_NOMEM, "cannot allocate %zu instances", n);
  for (size_t i = 0; i < n; i++) {
    size_t m2 = hj_push_index(c, i);
    s = hj_string(c, json_array_get(iv, i), d.instances[i], HEARTH_NAME_MAX);
    if (!s && !hearth_instance_id_valid(d.instances[i]))
      s = hj_fail(c, HEARTH_E_RANGE,
                  "expected an instance id <category>_<NN> with one of the 18 categories, "
                  "found \"%s\"",
                  d.instances[i]);
    if (s) {
      free(d.instances);
      return s;
    }
    hj_pop(c, m2);
  }
  size_t first, second;
  if (hr_find_duplicate(n, hr_key_release, &d, &first, &second)) {
    hj_push_index(c, second);
    s = hj_fail(c, HEARTH_E_INCONSISTENT, "duplicate of instances[%zu] (\"%s\")", first,
                d.instances[second]);
    free(d.instances);
    return s;
  }
  hj_pop(c, m);
  d.n_instances = n;
  *(hearth_release_doc *)out = d;
  return HEARTH_OK;
}

void hr_key_release(const void *ctx, size_t i, const char **a, const char **b) {
  const hearth_release_doc *d = ctx;
  *a = d->instances[i];
  *b = NULL;
}

hearth_status hearth_release_parse(const char *text, size_t len, const char *name,
                                   hearth_release_doc *d, hearth_err *err) {
  memset(d, 0, sizeof *d);
  return hr_parse_doc(text, len, name, release_from_json, d, err);
}

hearth_status hearth_release_read(const char *path, hearth_release_doc *d, hearth_err *err) {
  memset(d, 0, sizeof *d);
  return hr_read_doc(path, release_from_json, d, err);
}

static hearth_status release_validate(const char *text, size_t len, const char *name,
                                      hearth_err *err) {
  hearth_release_doc d;
  hearth_status s = hearth_release_parse(text, len, name, &d, err);
  hearth_release_free(&d);
  return s;
}

hearth_status hearth_release_write(const char *path, const hearth_release_doc *d, hearth_err *err) {
  json_t *o = json_object();
  json_t *iv = json_array();
  int ok = o && iv;
  for (size_t i = 0; ok && i < d->n_instances; i++)
    ok = json_array_append_new(iv, hj_str(d->instances[i])) == 0;
  ok = ok && hj_set(o, "name", hj_str(d->name)) && hj_set(o, "version", hj_str(d->version)) &&
       hj_set(o, "software_version", hj_str(d->software_version)) &&
       hj_set(o, "instances", json_incref(iv));
  json_decref(iv);
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, release_validate, err);
}
