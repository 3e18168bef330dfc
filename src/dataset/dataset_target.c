/* calibration/target.json: the hole target as data (lattice, rows, cols,
 * pitch, hole diameter), its hole numbering and plate coordinates. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "dataset/dataset_internal.h"

static const char *const LATTICE_NAMES[3] = {"hex-alternating", "hex", "grid"};

hearth_target hearth_target_default(void) {
  hearth_target t = {HEARTH_LATTICE_HEX_ALTERNATING, HEARTH_PLATE_ROWS, 11, HEARTH_PLATE_PITCH_M,
                     0.008};
  return t;
}

const hearth_target *hearth_target_or_default(const hearth_target *t, hearth_target *scratch) {
  if (t && t->rows) return t;
  *scratch = hearth_target_default();
  return scratch;
}

const char *hearth_lattice_name(hearth_lattice l) {
  return (unsigned)l < 3 ? LATTICE_NAMES[l] : "?";
}

int hearth_lattice_parse(const char *name, hearth_lattice *out) {
  for (int i = 0; i < 3; i++)
    if (name && !strcmp(name, LATTICE_NAMES[i])) {
      *out = (hearth_lattice)i;
      return 1;
    }
  return 0;
}

int hearth_target_row_holes(const hearth_target *t, int r) {
  if (t->lattice == HEARTH_LATTICE_HEX_ALTERNATING && (r & 1)) return t->cols - 1;
  return t->cols;
}

size_t hearth_target_holes(const hearth_target *t) {
  if (!t || (unsigned)t->lattice > 2 || t->rows < 1 || t->cols < 2 || t->rows > 64 || t->cols > 64)
    return 0;
  size_t n = 0;
  for (int r = 0; r < t->rows; r++) n += (size_t)hearth_target_row_holes(t, r);
  return n;
}

double hearth_target_row_step(const hearth_target *t) {
  if (t->lattice == HEARTH_LATTICE_GRID) return t->pitch_m;
  /* P sqrt(3) / 2 to 0.1 um: the integer count over 1e7 is the double
   * nearest that decimal, so the paper plate gets exactly 0.0103923 */
  return (double)llround(t->pitch_m * sqrt(3.0) / 2.0 * 1e7) / 1e7;
}

void hearth_target_points(const hearth_target *t, double (*xyz)[3]) {
  double step = hearth_target_row_step(t);
  size_t i = 0;
  for (int r = 0; r < t->rows; r++) {
    double off = (t->lattice != HEARTH_LATTICE_GRID && (r & 1)) ? 0.5 * t->pitch_m : 0.0;
    for (int c = 0; c < hearth_target_row_holes(t, r); c++, i++) {
      /* the same operations as hearth_plate_hole for the paper plate */
      xyz[i][0] = t->pitch_m * c + off;
      xyz[i][1] = step * r;
      xyz[i][2] = 0.0;
    }
  }
}

int hearth_target_is_default(const hearth_target *t) {
  hearth_target d = hearth_target_default();
  return t && t->lattice == d.lattice && t->rows == d.rows && t->cols == d.cols &&
         t->pitch_m == d.pitch_m && t->hole_diameter_m == d.hole_diameter_m;
}

hearth_status hearth_target_check(const hearth_target *t, const char *name, hearth_err *err) {
  if (!name) name = "target";
  if ((unsigned)t->lattice > 2)
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: lattice: unknown lattice %d", name,
                          (int)t->lattice);
  if (t->rows < 3 || t->rows > 64)
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: rows: expected 3..64, found %d", name, t->rows);
  if (t->cols < 3 || t->cols > 64)
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: cols: expected 3..64, found %d", name, t->cols);
  if (t->lattice == HEARTH_LATTICE_HEX_ALTERNATING && t->cols < 4)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "%s: cols: expected 4..64 for hex-alternating (rows of C and C-1), "
                          "found %d",
                          name, t->cols);
  size_t n = hearth_target_holes(t);
  if (n > HEARTH_TARGET_MAX_HOLES)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %d x %d: %zu holes, at most %d handled", name,
                          t->rows, t->cols, n, HEARTH_TARGET_MAX_HOLES);
  if (!(t->pitch_m >= 1e-3 && t->pitch_m <= 1.0))
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: pitch_m: expected 0.001..1, found %.17g", name,
                          t->pitch_m);
  if (!(t->hole_diameter_m > 0 && t->hole_diameter_m <= 0.8 * t->pitch_m))
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "%s: hole_diameter_m: expected > 0 and at most 0.8 pitch_m (%.6g), "
                          "found %.17g",
                          name, 0.8 * t->pitch_m, t->hole_diameter_m);
  if (!(t->thickness_m >= 0 && t->thickness_m <= 0.05))
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: thickness_m: expected 0..0.05, found %.17g",
                          name, t->thickness_m);
  return HEARTH_OK;
}

static hearth_status target_from_json(hj_ctx *c, const json_t *root, void *out) {
  static const char *const keys[6] = {"lattice",         "rows",       "cols", "pitch_m",
                                      "hole_diameter_m", "thickness_m"};
  const char *key;
  json_t *v;
  json_object_foreach((json_t *)root, key, v) {
    int known = 0;
    for (int i = 0; i < 6; i++) known |= !strcmp(key, keys[i]);
    if (!known) {
      hj_push_key(c, key);
      return hj_fail(c, HEARTH_E_PARSE,
                     "unknown key (expected lattice, rows, cols, pitch_m, hole_diameter_m, "
                     "thickness_m)");
    }
  }
  hearth_target t;
  memset(&t, 0, sizeof t);
  char name[32];
  hearth_status s;
  if ((s = hj_get_string(c, root, "lattice", name, sizeof name))) return s;
  if (!hearth_lattice_parse(name, &t.lattice)) {
    hj_push_key(c, "lattice");
    return hj_fail(c, HEARTH_E_UNSUPPORTED,
                   "expected \"hex-alternating\", \"hex\" or \"grid\", found \"%s\"", name);
  }
  if ((s = hj_get_int(c, root, "rows", 3, 64, &t.rows)) ||
      (s = hj_get_int(c, root, "cols", 3, 64, &t.cols)) ||
      (s = hj_get_number(c, root, "pitch_m", &t.pitch_m)) ||
      (s = hj_get_number(c, root, "hole_diameter_m", &t.hole_diameter_m)))
    return s;
  if (t.lattice == HEARTH_LATTICE_HEX_ALTERNATING && t.cols < 4) {
    hj_push_key(c, "cols");
    return hj_fail(c, HEARTH_E_RANGE,
                   "expected 4..64 for hex-alternating (rows of C and C-1), found %d", t.cols);
  }
  if (hearth_target_holes(&t) > HEARTH_TARGET_MAX_HOLES) {
    hj_push_key(c, "rows");
    return hj_fail(c, HEARTH_E_LIMIT, "%d x %d: %zu holes, at most %d handled", t.rows, t.cols,
                   hearth_target_holes(&t), HEARTH_TARGET_MAX_HOLES);
  }
  if (!(t.pitch_m >= 1e-3 && t.pitch_m <= 1.0)) {
    hj_push_key(c, "pitch_m");
    return hj_fail(c, HEARTH_E_RANGE, "expected 0.001..1 (metres), found %.17g", t.pitch_m);
  }
  if (!(t.hole_diameter_m > 0 && t.hole_diameter_m <= 0.8 * t.pitch_m)) {
    hj_push_key(c, "hole_diameter_m");
    return hj_fail(c, HEARTH_E_RANGE, "expected > 0 and at most 0.8 pitch_m (%.6g), found %.17g",
                   0.8 * t.pitch_m, t.hole_diameter_m);
  }
  if (json_object_get(root, "thickness_m")) {
    if ((s = hj_get_number(c, root, "thickness_m", &t.thickness_m))) return s;
    if (!(t.thickness_m >= 0 && t.thickness_m <= 0.05)) {
      hj_push_key(c, "thickness_m");
      return hj_fail(c, HEARTH_E_RANGE, "expected 0..0.05 (metres), found %.17g", t.thickness_m);
    }
  }
  *(hearth_target *)out = t;
  return HEARTH_OK;
}

hearth_status hearth_target_parse(const char *text, size_t len, const char *name, hearth_target *t,
                                  hearth_err *err) {
  return hr_parse_doc(text, len, name, target_from_json, t, err);
}

hearth_status hearth_target_read(const char *path, hearth_target *t, hearth_err *err) {
  if (!hearth_path_exists(path)) {
    *t = hearth_target_default();
    return HEARTH_OK;
  }
  return hr_read_doc(path, target_from_json, t, err);
}

static hearth_status target_validate(const char *text, size_t len, const char *name,
                                     hearth_err *err) {
  hearth_target t;
  return hearth_target_parse(text, len, name, &t, err);
}

hearth_status hearth_target_write(const char *path, const hearth_target *t, hearth_err *err) {
  hearth_status s = hearth_target_check(t, path, err);
  if (s) return s;
  json_t *o = json_object();
  int ok = o && hj_set(o, "lattice", json_string(hearth_lattice_name(t->lattice))) &&
           hj_set(o, "rows", json_integer(t->rows)) && hj_set(o, "cols", json_integer(t->cols)) &&
           hj_set(o, "pitch_m", hj_real(t->pitch_m)) &&
           hj_set(o, "hole_diameter_m", hj_real(t->hole_diameter_m)) &&
           (!(t->thickness_m > 0) || hj_set(o, "thickness_m", hj_real(t->thickness_m)));
  if (!ok) {
    json_decref(o);
    o = NULL;
  }
  return hj_write_doc(path, o, target_validate, err);
}
