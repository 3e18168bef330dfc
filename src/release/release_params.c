/* build.json: the parameters a build ran with (docs/dataset.md), read and
 * written by the rules of every release document: strict reader (unknown
 * keys ignored, duplicates refused), atomic deterministic writer that
 * checks its text with the reader first. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "release/release_internal.h"

#define PARAMS_MAX_BYTES (64u << 20)

static const char *const k_fusion_names[] = {"max", "robust", "mean", "corrected"};

void hb_params_default(hb_params *p) {
  p->resolution = 1024;
  p->fusion = HEARTH_FUSE_MAX;
  p->min_cos = 0.0;
  p->rgb_resolution = 1024;
  p->bake_rgb = 1;
  p->calibrate = 1;
  p->calib_overlays = 1;
}

int hb_params_same(const hb_params *a, const hb_params *b) {
  return a->resolution == b->resolution && a->fusion == b->fusion &&
         !memcmp(&a->min_cos, &b->min_cos, sizeof a->min_cos) &&
         a->rgb_resolution == b->rgb_resolution && a->bake_rgb == b->bake_rgb &&
         a->calibrate == b->calibrate && a->calib_overlays == b->calib_overlays;
}

static const char *type_name(const json_t *v) {
  switch (json_typeof(v)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER: return "an integer";
    case JSON_REAL: return "a real number";
    case JSON_TRUE:
    case JSON_FALSE: return "a boolean";
    default: return "null";
  }
}

/* the member key of o, or an error naming it */
static hearth_status member(const char *name, const json_t *o, const char *key, json_t **v,
                            hearth_err *err) {
  *v = json_object_get(o, key);
  if (!*v) return hearth_err_set(err, HEARTH_E_PARSE, "%s: %s: missing", name, key);
  return HEARTH_OK;
}

static hearth_status get_size(const char *name, const json_t *o, const char *key, long long lo,
                              long long hi, size_t *out, hearth_err *err) {
  json_t *v;
  hearth_status s = member(name, o, key, &v, err);
  if (s) return s;
  if (!json_is_integer(v))
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: %s: expected an integer, found %s", name, key,
                          type_name(v));
  long long x = json_integer_value(v);
  if (x < lo || x > hi)
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: %s: %lld outside %lld..%lld", name, key, x, lo,
                          hi);
  *out = (size_t)x;
  return HEARTH_OK;
}

static hearth_status get_bool(const char *name, const json_t *o, const char *key, int *out,
                              hearth_err *err) {
  json_t *v;
  hearth_status s = member(name, o, key, &v, err);
  if (s) return s;
  if (!json_is_boolean(v))
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: %s: expected true or false, found %s", name,
                          key, type_name(v));
  *out = json_is_true(v);
  return HEARTH_OK;
}

hearth_status hb_params_parse(const char *text, size_t len, const char *name, hb_params *p,
                              hearth_err *err) {
  json_error_t je;
  json_t *o = json_loadb(text, len, JSON_REJECT_DUPLICATES, &je);
  if (!o)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: line %d, column %d: %s", name, je.line,
                          je.column, je.text);
  hearth_status s = HEARTH_OK;
  json_t *v;
  if (!json_is_object(o)) {
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: expected an object at the top level, found %s",
                       name, type_name(o));
    goto done;
  }
  if ((s = get_size(name, o, "resolution", 2, 16384, &p->resolution, err))) goto done;
  if ((s = member(name, o, "fusion", &v, err))) goto done;
  const char *f = json_string_value(v);
  int fi = -1;
  for (int i = 0; f && i < 4; i++)
    if (!strcmp(f, k_fusion_names[i])) fi = i;
  if (fi < 0) {
    s = hearth_err_set(
        err, HEARTH_E_PARSE,
        "%s: fusion: expected \"max\", \"robust\", \"mean\" or \"corrected\", found %s%s%s", name,
        f ? "\"" : type_name(v), f ? f : "", f ? "\"" : "");
    goto done;
  }
  p->fusion = (hearth_fusion)fi;
  if ((s = member(name, o, "min_cos", &v, err))) goto done;
  if (!json_is_number(v)) {
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: min_cos: expected a number, found %s", name,
                       type_name(v));
    goto done;
  }
  p->min_cos = json_number_value(v);
  if (!(p->min_cos >= 0.0 && p->min_cos < 1.0)) {
    s = hearth_err_set(err, HEARTH_E_RANGE, "%s: min_cos: %g outside [0, 1)", name, p->min_cos);
    goto done;
  }
  if ((s = get_size(name, o, "rgb_resolution", 16, 16384, &p->rgb_resolution, err))) goto done;
  if ((s = get_bool(name, o, "bake_rgb", &p->bake_rgb, err))) goto done;
  if ((s = get_bool(name, o, "calibrate", &p->calibrate, err))) goto done;
  s = get_bool(name, o, "calib_overlays", &p->calib_overlays, err);
done:
  json_decref(o);
  return s;
}

hearth_status hb_params_read(const char *path, hb_params *p, hearth_err *err) {
  uint8_t *text = NULL;
  size_t len = 0;
  hearth_status s = hearth_read_file(path, PARAMS_MAX_BYTES, &text, &len, err);
  if (!s) s = hb_params_parse((const char *)text, len, path, p, err);
  free(text);
  return s;
}

/* the document with min_cos at `prec` significant digits (malloc'ed) */
static char *params_text(const hb_params *p, int prec) {
  json_t *o = json_object();
  json_object_set_new(o, "resolution", json_integer((json_int_t)p->resolution));
  json_object_set_new(o, "fusion", json_string(k_fusion_names[p->fusion]));
  json_object_set_new(o, "min_cos", json_real(p->min_cos));
  json_object_set_new(o, "rgb_resolution", json_integer((json_int_t)p->rgb_resolution));
  json_object_set_new(o, "bake_rgb", json_boolean(p->bake_rgb));
  json_object_set_new(o, "calibrate", json_boolean(p->calibrate));
  json_object_set_new(o, "calib_overlays", json_boolean(p->calib_overlays));
  char *text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(prec));
  json_decref(o);
  return text;
}

hearth_status hb_params_write(const char *path, const hb_params *p, hearth_err *err) {
  if ((unsigned)p->fusion > 3)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "%s: fusion %d: expected max, robust, mean or corrected", path,
                          (int)p->fusion);
  /* min_cos in the shortest of 15, 16 or 17 digits that reads back exactly */
  char *text = NULL;
  hb_params back;
  hearth_status s = HEARTH_OK;
  for (int prec = 15; prec <= 17; prec++) {
    free(text);
    if (!(text = params_text(p, prec)))
      return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot encode", path);
    if ((s = hb_params_parse(text, strlen(text), path, &back, err))) break;
    if (!memcmp(&back.min_cos, &p->min_cos, sizeof back.min_cos)) break;
  }
  if (!s) {
    size_t len = strlen(text);
    text[len] = '\n';
    s = hearth_write_file_atomic(path, text, len + 1, err);
  }
  free(text);
  return s;
}
