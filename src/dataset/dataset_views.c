/* Per-view documents of a release (docs/dataset.md): manifest.json,
 * poses_*.json and detections.json. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/dataset.h"
#include "dataset/dataset_json.h"
#include "dataset/dataset_internal.h"

/* poses cover every state of an instance; detections every capture frame */
#define HR_MAX_POSES ((size_t)HEARTH_MAX_VIEWS * HEARTH_MAX_STATES)
#define HR_MAX_FRAMES ((size_t)HEARTH_MAX_VIEWS * 4)
#define HR_MAX_INDEX 100000

#define HR_CONVENTION "T_world_from_cam, OpenCV camera axes"
#define HR_UNITS "m"

/* ---- manifest.json ------------------------------------------------------------------ */

void hearth_manifest_free(hearth_manifest *m) {
  if (!m) return;
  free(m->views);
  m->views = NULL;
  m->n_views = 0;
}

static void key_manifest(const void *ctx, size_t i, const char **a, const char **b) {
  const hearth_manifest *m = ctx;
  *a = m->views[i].view;
  *b = NULL;
}

/* Read root.key: an array of min..max records of elem_size bytes, each read
 * by one() with the path at ".key[i]". On success *items (caller frees) and
 * *n are set and the path stays at ".key" (its mark in *mk), so the caller
 * can report a duplicate by index before popping. */
typedef hearth_status (*record_fn)(hj_ctx *c, const json_t *v, void *elem);
static hearth_status records_from_json(hj_ctx *c, const json_t *root, const char *key, size_t min,
                                       size_t max, size_t elem_size, const char *what,
                                       record_fn one, void **items, size_t *n, size_t *mk) {
  json_t *arr;
  hearth_status s;
  if ((s = hj_member(c, root, key, &arr))) return s;
  *mk = hj_push_key(c, key);
  if ((s = hj_array(c, arr, min, max, n))) return s;
  char *buf = hearth_calloc_array(*n ? *n : 1, elem_size);
  if (!buf) return hj_fail(c, HEARTH_E_NOMEM, "cannot allocate %zu %s", *n, what);
  for (size_t i = 0; i < *n; i++) {
    size_t m2 = hj_push_index(c, i);
    if ((s = one(c, json_array_get(arr, i), buf + i * elem_size))) {
      free(buf);
      return s;
    }
    hj_pop(c, m2);
  }
  *items = buf;
  return HEARTH_OK;
}

/* a view's five file entries, in the order of docs/dataset.md */
static const char *const k_file_keys[5] = {"rgb", "cutout", "depth", "depth_intrinsics", "thermal"};

static hearth_status view_files_from_json(hj_ctx *c, const json_t *v, void *elem) {
  hearth_view_files *f = elem;
  if (!json_is_object(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(v));
  hearth_status s;
  if ((s = hr_get_checked(c, v, "view", f->view, sizeof f->view, hj_simple_name,
                          "a view name of letters, digits, '_' or '-'")))
    return s;
  if ((s = hj_get_int(c, v, "elevation_index", 0, HR_MAX_INDEX, &f->elevation_index))) return s;
  if ((s = hj_get_int(c, v, "azimuth_index", 0, HR_MAX_INDEX, &f->azimuth_index))) return s;
  char *dst[5] = {f->rgb, f->cutout, f->depth, f->depth_intrinsics, f->thermal};
  for (int k = 0; k < 5; k++)
    if ((s = hr_get_checked(c, v, k_file_keys[k], dst[k], sizeof f->rgb, hj_relative_path_ok,
                            "a relative path without '..' or empty components")))
      return s;
  f->has_time = 0;
  f->time_s = 0;
  if (json_object_get(v, "time_s")) {
    if ((s = hj_get_number(c, v, "time_s", &f->time_s))) return s;
    if (!(f->time_s >= 0 && f->time_s <= 1e6))
      return hj_fail(c, HEARTH_E_RANGE, "time_s: expected seconds in 0..1e6, found %g", f->time_s);
    f->has_time = 1;
  }
  f->has_turntable = 0;
  f->turntable_deg = 0;
  if (json_object_get(v, "turntable_deg")) {
    if ((s = hj_get_number(c, v, "turntable_deg", &f->turntable_deg))) return s;
    if (!(f->turntable_deg >= -3600 && f->turntable_deg <= 3600))
      return hj_fail(c, HEARTH_E_RANGE, "turntable_deg: expected degrees in -3600..3600, found %g",
                     f->turntable_deg);
    f->has_turntable = 1;
  }
  return HEARTH_OK;
}

/* the five file entries of every view, each with "." components dropped,
 * so that two spellings of one file compare equal */
typedef struct file_ref {
  char norm[128];
  size_t view;
  int key;
} file_ref;

static const char *view_file(const hearth_view_files *f, int key) {
  const char *v[5] = {f->rgb, f->cutout, f->depth, f->depth_intrinsics, f->thermal};
  return v[key];
}

static void normalise_path(const char *in, char *out, size_t cap) {
  size_t n = 0;
  for (const char *p = in; *p;) {
    const char *e = strchr(p, '/');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    if (!(len == 1 && p[0] == '.')) {
      if (n && n + 1 < cap) out[n++] = '/';
      for (size_t i = 0; i < len && n + 1 < cap; i++) out[n++] = p[i];
    }
    p += len + (e ? 1 : 0);
  }
  out[n] = 0;
}

static void key_file_ref(const void *ctx, size_t i, const char **a, const char **b) {
  const file_ref *r = ctx;
  *a = r[i].norm;
  *b = NULL;
}

/* Two views naming one file (the same thermal CSV, say) would give both the
 * same measurement: refused at the second reference, naming both views. */
static hearth_status check_file_refs(hj_ctx *c, const hearth_manifest *m) {
  size_t n = m->n_views * 5;
  file_ref *r = hearth_alloc_array(n ? n : 1, sizeof *r);
  if (!r) return hj_fail(c, HEARTH_E_NOMEM, "cannot allocate %zu file references", n);
  for (size_t v = 0; v < m->n_views; v++)
    for (int k = 0; k < 5; k++) {
      file_ref *q = &r[v * 5 + (size_t)k];
      normalise_path(view_file(&m->views[v], k), q->norm, sizeof q->norm);
      q->view = v;
      q->key = k;
    }
  size_t first, second;
  hearth_status s = HEARTH_OK;
  if (hr_find_duplicate(n, key_file_ref, r, &first, &second)) {
    const file_ref *a = &r[first], *b = &r[second];
    hj_push_index(c, b->view);
    hj_push_key(c, k_file_keys[b->key]);
    s = hj_fail(c, HEARTH_E_INCONSISTENT,
                "view \"%s\" names \"%s\", the file of view \"%s\" (views[%zu].%s): each "
                "view needs files of its own",
                m->views[b->view].view, view_file(&m->views[b->view], b->key),
                m->views[a->view].view, a->view, k_file_keys[a->key]);
  }
  free(r);
  return s;
}

static hearth_status manifest_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_manifest m;
  memset(&m, 0, sizeof m);
  hearth_status s;
  if ((s = hr_get_checked(c, root, "instance", m.instance, sizeof m.instance,
                          hearth_instance_id_valid,
                          "an instance id <category>_<NN> with one of the 18 categories")))
    return s;
  if ((s = hr_get_checked(c, root, "state", m.state, sizeof m.state, hearth_state_valid,
                          "neutral, hot, warm, iced or used")))
    return s;
  size_t mk, n;
  void *items = NULL;
  if ((s = records_from_json(c, root, "views", 1, HEARTH_MAX_VIEWS, sizeof *m.views, "views",
                             view_files_from_json, &items, &n, &mk)))
    return s;
  m.views = items;
  m.n_views = n;
  size_t first, second;
  if (hr_find_duplicate(n, key_manifest, &m, &first, &second)) {
    hj_push_index(c, second);
    hj_push_key(c, "view");
    s = hj_fail(c, HEARTH_E_INCONSISTENT, "duplicate view name \"%s\" (also views[%zu])",
                m.views[second].view, first);
    free(m.views);
    return s;
  }
  if ((s = check_file_refs(c, &m))) {
    free(m.views);
    return s;
  }
  hj_pop(c, mk);
  *(hearth_manifest *)out = m;
  return HEARTH_OK;
}

hearth_status hearth_manifest_parse(const char *text, size_t len, const char *name,
                                    hearth_manifest *m, hearth_err *err) {
  memset(m, 0, sizeof *m);
  return hr_parse_doc(text, len, name, manifest_from_json, m, err);
}

hearth_status hearth_manifest_read(const char *path, hearth_manifest *m, hearth_err *err) {
  memset(m, 0, sizeof *m);
  return hr_read_doc(path, manifest_from_json, m, err);
}

static hearth_status manifest_validate(const char *text, size_t len, const char *name,
                                       hearth_err *err) {
  hearth_manifest m;
  hearth_status s = hearth_manifest_parse(text, len, name, &m, err);
  hearth_manifest_free(&m);
  return s;
}

hearth_status hearth_manifest_write(const char *path, const hearth_manifest *m, hearth_err *err) {
  json_t *o = json_object();
  json_t *vv = json_array();
  int ok = o && vv;
  for (size_t i = 0; ok && i < m->n_views; i++) {
    const hearth_view_files *f = &m->views[i];
    json_t *v = json_object();
    ok = hj_set(v, "view", hj_str(f->view)) &&
         hj_set(v, "elevation_index", json_integer(f->elevation_index)) &&
         hj_set(v, "azimuth_index", json_integer(f->azimuth_index)) &&
         hj_set(v, "rgb", hj_str(f->rgb)) && hj_set(v, "cutout", hj_str(f->cutout)) &&
         hj_set(v, "depth", hj_str(f->depth)) &&
         hj_set(v, "depth_intrinsics", hj_str(f->depth_intrinsics)) &&
         hj_set(v, "thermal", hj_str(f->thermal)) &&
         (!f->has_time || hj_set(v, "time_s", hj_real(f->time_s))) &&
         (!f->has_turntable || hj_set(v, "turntable_deg", hj_real(f->turntable_deg)));
    if (!ok || json_array_append_new(vv, v) != 0) {
      if (ok) ok = 0;
      else json_decref(v);
    }
  }
  ok = ok && hj_set(o, "instance", hj_str(m->instance)) && hj_set(o, "state", hj_str(m->state)) &&
       hj_set(o, "views", json_incref(vv));
  json_decref(vv);
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, manifest_validate, err);
}

/* ---- poses_*.json ------------------------------------------------------------------------ */

void hearth_poses_free(hearth_poses *p) {
  if (!p) return;
  free(p->views);
  p->views = NULL;
  p->n = 0;
}

const hearth_view_pose *hearth_poses_find(const hearth_poses *p, const char *state,
                                          const char *view) {
  if (!p || !state || !view) return NULL;
  for (size_t i = 0; i < p->n; i++)
    if (!strcmp(p->views[i].state, state) && !strcmp(p->views[i].view, view)) return &p->views[i];
  return NULL;
}

static void key_poses(const void *ctx, size_t i, const char **a, const char **b) {
  const hearth_poses *p = ctx;
  *a = p->views[i].state;
  *b = p->views[i].view;
}

/* a fixed string value ("convention", "units") */
static hearth_status get_fixed(hj_ctx *c, const json_t *obj, const char *key, const char *want) {
  char buf[128];
  hearth_status s = hj_get_string(c, obj, key, buf, sizeof buf);
  if (s) return s;
  if (strcmp(buf, want) != 0) {
    size_t m = hj_push_key(c, key);
    s = hj_fail(c, HEARTH_E_UNSUPPORTED, "expected \"%s\", found \"%s\"", want, buf);
    hj_pop(c, m);
  }
  return s;
}

static hearth_status pose_from_json(hj_ctx *c, const json_t *v, void *elem) {
  hearth_view_pose *p = elem;
  if (!json_is_object(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(v));
  hearth_status s;
  if ((s = hr_get_checked(c, v, "state", p->state, sizeof p->state, hearth_state_valid,
                          "neutral, hot, warm, iced or used")))
    return s;
  if ((s = hr_get_checked(c, v, "view", p->view, sizeof p->view, hj_simple_name,
                          "a view name of letters, digits, '_' or '-'")))
    return s;
  json_t *tv;
  if ((s = hj_member(c, v, "T_world_from_cam", &tv))) return s;
  size_t m = hj_push_key(c, "T_world_from_cam");
  if ((s = hj_mat4_rigid(c, tv, &p->T_world_from_cam))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

static hearth_status poses_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_poses p = {0, NULL};
  hearth_status s;
  if ((s = get_fixed(c, root, "convention", HR_CONVENTION))) return s;
  if ((s = get_fixed(c, root, "units", HR_UNITS))) return s;
  size_t mk, n;
  void *items = NULL;
  if ((s = records_from_json(c, root, "views", 0, HR_MAX_POSES, sizeof *p.views, "poses",
                             pose_from_json, &items, &n, &mk)))
    return s;
  p.views = items;
  p.n = n;
  size_t first, second;
  if (hr_find_duplicate(n, key_poses, &p, &first, &second)) {
    hj_push_index(c, second);
    s = hj_fail(c, HEARTH_E_INCONSISTENT,
                "duplicate pose for state \"%s\", view \"%s\" "
                "(also views[%zu])",
                p.views[second].state, p.views[second].view, first);
    free(p.views);
    return s;
  }
  hj_pop(c, mk);
  *(hearth_poses *)out = p;
  return HEARTH_OK;
}

hearth_status hearth_poses_parse(const char *text, size_t len, const char *name, hearth_poses *p,
                                 hearth_err *err) {
  memset(p, 0, sizeof *p);
  return hr_parse_doc(text, len, name, poses_from_json, p, err);
}

hearth_status hearth_poses_read(const char *path, hearth_poses *p, hearth_err *err) {
  memset(p, 0, sizeof *p);
  return hr_read_doc(path, poses_from_json, p, err);
}

static hearth_status poses_validate(const char *text, size_t len, const char *name,
                                    hearth_err *err) {
  hearth_poses p;
  hearth_status s = hearth_poses_parse(text, len, name, &p, err);
  hearth_poses_free(&p);
  return s;
}

hearth_status hearth_poses_write(const char *path, const hearth_poses *p, hearth_err *err) {
  json_t *o = json_object();
  json_t *vv = json_array();
  int ok = o && vv;
  for (size_t i = 0; ok && i < p->n; i++) {
    const hearth_view_pose *q = &p->views[i];
    json_t *v = json_object();
    ok = hj_set(v, "state", hj_str(q->state)) && hj_set(v, "view", hj_str(q->view)) &&
         hj_set(v, "T_world_from_cam", hj_mat4_new(&q->T_world_from_cam));
    if (!ok || json_array_append_new(vv, v) != 0) {
      if (ok) ok = 0;
      else json_decref(v);
    }
  }
  ok = ok && hj_set(o, "convention", hj_str(HR_CONVENTION)) &&
       hj_set(o, "units", hj_str(HR_UNITS)) && hj_set(o, "views", json_incref(vv));
  json_decref(vv);
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, poses_validate, err);
}

/* ---- detections.json ------------------------------------------------------------------ */

void hearth_detections_free(hearth_detections *d) {
  if (!d) return;
  free(d->frames);
  d->frames = NULL;
  d->n = 0;
}

static void key_detections(const void *ctx, size_t i, const char **a, const char **b) {
  const hearth_detections *d = ctx;
  *a = d->frames[i].frame;
  *b = d->frames[i].camera;
}

static int camera_name_ok(const char *s) { return !strcmp(s, "thermal") || !strcmp(s, "rgb"); }

/* the pattern block: the paper's plate in its original form (rows,
 * cols_even, cols_odd, pitch_m, row_step_m; only that plate), or any target
 * as target.json describes it (a "lattice" key, then rows, cols, pitch_m,
 * hole_diameter_m) */
static hearth_status pattern_from_json(hj_ctx *c, const json_t *root, hearth_target *t) {
  json_t *pv;
  hearth_status s = hj_get_object(c, root, "pattern", &pv);
  if (s) return s;
  size_t m = hj_push_key(c, "pattern");
  if (json_object_get(pv, "lattice")) {
    char name[32];
    memset(t, 0, sizeof *t);
    if ((s = hj_get_string(c, pv, "lattice", name, sizeof name))) return s;
    if (!hearth_lattice_parse(name, &t->lattice)) {
      hj_push_key(c, "lattice");
      return hj_fail(c, HEARTH_E_UNSUPPORTED,
                     "expected \"hex-alternating\", \"hex\" or \"grid\", found \"%s\"", name);
    }
    if ((s = hj_get_int(c, pv, "rows", 3, 64, &t->rows)) ||
        (s = hj_get_int(c, pv, "cols", 3, 64, &t->cols)) ||
        (s = hj_get_number(c, pv, "pitch_m", &t->pitch_m)) ||
        (s = hj_get_number(c, pv, "hole_diameter_m", &t->hole_diameter_m)))
      return s;
    hearth_err e2;
    if (hearth_target_check(t, "target", &e2))
      return hj_fail(c, e2.status, "%s", e2.msg + strlen("target: "));
    hj_pop(c, m);
    return HEARTH_OK;
  }
  *t = hearth_target_default();
  static const struct {
    const char *key;
    int want;
  } ints[3] = {{"rows", HEARTH_PLATE_ROWS}, {"cols_even", 11}, {"cols_odd", 10}};
  for (int i = 0; i < 3; i++) {
    int x;
    if ((s = hj_get_int(c, pv, ints[i].key, 0, 1 << 20, &x))) return s;
    if (x != ints[i].want) {
      hj_push_key(c, ints[i].key);
      return hj_fail(c, HEARTH_E_UNSUPPORTED,
                     "expected %d (the plate of docs/dataset.md), "
                     "found %d",
                     ints[i].want, x);
    }
  }
  static const struct {
    const char *key;
    double want;
  } reals[2] = {{"pitch_m", HEARTH_PLATE_PITCH_M}, {"row_step_m", HEARTH_PLATE_ROW_STEP_M}};
  for (int i = 0; i < 2; i++) {
    double x;
    if ((s = hj_get_number(c, pv, reals[i].key, &x))) return s;
    if (!(fabs(x - reals[i].want) <= 1e-9)) {
      hj_push_key(c, reals[i].key);
      return hj_fail(c, HEARTH_E_UNSUPPORTED,
                     "expected %.9g (the plate of docs/dataset.md), "
                     "found %.17g",
                     reals[i].want, x);
    }
  }
  hj_pop(c, m);
  return HEARTH_OK;
}

/* one frame; a found frame has `holes` centres */
static hearth_status detection_from_json(hj_ctx *c, const json_t *v, size_t holes,
                                         hearth_detection *f) {
  if (!json_is_object(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(v));
  hearth_status s;
  if ((s = hr_get_checked(c, v, "frame", f->frame, sizeof f->frame, hj_simple_name,
                          "a frame name of letters, digits, '_' or '-'")))
    return s;
  if ((s = hr_get_checked(c, v, "camera", f->camera, sizeof f->camera, camera_name_ok,
                          "\"thermal\" or \"rgb\"")))
    return s;
  json_t *fv;
  if ((s = hj_member(c, v, "found", &fv))) return s;
  size_t m = hj_push_key(c, "found");
  if ((s = hj_bool(c, fv, &f->found))) return s;
  hj_pop(c, m);
  if (f->found) {
    json_t *cv;
    if ((s = hj_member(c, v, "centres", &cv))) return s;
    m = hj_push_key(c, "centres");
    if ((s = hj_mat(c, cv, holes, 2, &f->centres[0][0]))) return s;
    hj_pop(c, m);
  } else {
    /* a frame without a detection says why; partial centres are not read */
    if ((s = hr_get_nonempty(c, v, "reason", f->reason, sizeof f->reason))) return s;
  }
  return HEARTH_OK;
}

static hearth_status detections_from_json(hj_ctx *c, const json_t *root, void *out) {
  hearth_detections d;
  memset(&d, 0, sizeof d);
  hearth_status s;
  if ((s = pattern_from_json(c, root, &d.target))) return s;
  size_t holes = hearth_target_holes(&d.target), n;
  json_t *arr;
  if ((s = hj_member(c, root, "frames", &arr))) return s;
  size_t mk = hj_push_key(c, "frames");
  if ((s = hj_array(c, arr, 0, HR_MAX_FRAMES, &n))) return s;
  d.frames = hearth_calloc_array(n ? n : 1, sizeof *d.frames);
  if (!d.frames) return hj_fail(c, HEARTH_E_NOMEM, "cannot allocate %zu frames", n);
  d.n = n;
  for (size_t i = 0; i < n; i++) {
    size_t m2 = hj_push_index(c, i);
    if ((s = detection_from_json(c, json_array_get(arr, i), holes, &d.frames[i]))) {
      free(d.frames);
      return s;
    }
    hj_pop(c, m2);
  }
  size_t first, second;
  if (hr_find_duplicate(n, key_detections, &d, &first, &second)) {
    hj_push_index(c, second);
    s = hj_fail(c, HEARTH_E_INCONSISTENT,
                "duplicate frame \"%s\" of camera \"%s\" "
                "(also frames[%zu])",
                d.frames[second].frame, d.frames[second].camera, first);
    free(d.frames);
    return s;
  }
  hj_pop(c, mk);
  *(hearth_detections *)out = d;
  return HEARTH_OK;
}

hearth_status hearth_detections_parse(const char *text, size_t len, const char *name,
                                      hearth_detections *d, hearth_err *err) {
  memset(d, 0, sizeof *d);
  return hr_parse_doc(text, len, name, detections_from_json, d, err);
}

hearth_status hearth_detections_read(const char *path, hearth_detections *d, hearth_err *err) {
  memset(d, 0, sizeof *d);
  return hr_read_doc(path, detections_from_json, d, err);
}

static hearth_status detections_validate(const char *text, size_t len, const char *name,
                                         hearth_err *err) {
  hearth_detections d;
  hearth_status s = hearth_detections_parse(text, len, name, &d, err);
  hearth_detections_free(&d);
  return s;
}

hearth_status hearth_detections_write(const char *path, const hearth_detections *d,
                                      hearth_err *err) {
  json_t *o = json_object();
  json_t *pat = json_object();
  json_t *fv = json_array();
  int ok = o && pat && fv;
  hearth_target tdef;
  const hearth_target *t = hearth_target_or_default(&d->target, &tdef);
  size_t holes = hearth_target_holes(t);
  if (hearth_target_is_default(t))
    ok = ok && hj_set(pat, "rows", json_integer(HEARTH_PLATE_ROWS)) &&
         hj_set(pat, "cols_even", json_integer(11)) && hj_set(pat, "cols_odd", json_integer(10)) &&
         hj_set(pat, "pitch_m", json_real(HEARTH_PLATE_PITCH_M)) &&
         hj_set(pat, "row_step_m", json_real(HEARTH_PLATE_ROW_STEP_M));
  else
    ok = ok && hj_set(pat, "lattice", json_string(hearth_lattice_name(t->lattice))) &&
         hj_set(pat, "rows", json_integer(t->rows)) && hj_set(pat, "cols", json_integer(t->cols)) &&
         hj_set(pat, "pitch_m", hj_real(t->pitch_m)) &&
         hj_set(pat, "hole_diameter_m", hj_real(t->hole_diameter_m));
  for (size_t i = 0; ok && i < d->n; i++) {
    const hearth_detection *f = &d->frames[i];
    json_t *v = json_object();
    ok = hj_set(v, "frame", hj_str(f->frame)) && hj_set(v, "camera", hj_str(f->camera)) &&
         hj_set(v, "found", json_boolean(f->found));
    if (ok && f->found) ok = hj_set(v, "centres", hj_mat_new(&f->centres[0][0], holes, 2));
    else if (ok) ok = hj_set(v, "reason", hj_str(f->reason));
    if (!ok || json_array_append_new(fv, v) != 0) {
      if (ok) ok = 0;
      else json_decref(v);
    }
  }
  ok = ok && hj_set(o, "pattern", json_incref(pat)) && hj_set(o, "frames", json_incref(fv));
  json_decref(pat);
  json_decref(fv);
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, detections_validate, err);
}
