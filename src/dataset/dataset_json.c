/* Strict JSON reading with JSON paths in every message, and a deterministic
 * pretty printer, shared by the documents of a release (io_release.c). */
#include "dataset/dataset_json.h"

#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/dataset.h"

/* ---- context and paths ---------------------------------------------------- */

void hj_init(hj_ctx *c, const char *file, hearth_err *err) {
  c->file = file ? file : "(json)";
  c->err = err;
  c->len = 0;
  c->path[0] = 0;
}

/* append text to the path; a path too long for the buffer ends in "..." */
static void hj_append(hj_ctx *c, const char *s) {
  size_t cap = sizeof c->path;
  size_t n = strlen(s);
  if (c->len + n + 4 >= cap) {
    if (c->len + 4 < cap) {
      memcpy(c->path + c->len, "...", 4);
      c->len += 3;
    }
    return;
  }
  memcpy(c->path + c->len, s, n + 1);
  c->len += n;
}

size_t hj_push_key(hj_ctx *c, const char *key) {
  size_t mark = c->len;
  if (c->len) hj_append(c, ".");
  hj_append(c, key);
  return mark;
}

size_t hj_push_index(hj_ctx *c, size_t i) {
  size_t mark = c->len;
  char buf[32];
  snprintf(buf, sizeof buf, "[%zu]", i);
  hj_append(c, buf);
  return mark;
}

void hj_pop(hj_ctx *c, size_t mark) {
  if (mark <= c->len) {
    c->len = mark;
    c->path[mark] = 0;
  }
}

hearth_status hj_fail(hj_ctx *c, hearth_status s, const char *fmt, ...) {
  char what[768];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  return hearth_err_set(c->err, s, "%s: %s: %s", c->file, c->len ? c->path : "(top level)", what);
}

/* ---- loading ------------------------------------------------------------- */

hearth_status hj_read_text(const char *path, char **text, size_t *len, hearth_err *err) {
  uint8_t *data = NULL;
  hearth_status s = hearth_read_file(path, HJ_MAX_FILE_BYTES, &data, len, err);
  *text = (char *)data;
  return s;
}

hearth_status hj_load(hj_ctx *c, const char *text, size_t len, json_t **root) {
  *root = NULL;
  if (!text && len) return hearth_err_set(c->err, HEARTH_E_ARG, "%s: no text", c->file);
  if (len > HJ_MAX_FILE_BYTES)
    return hearth_err_set(c->err, HEARTH_E_LIMIT, "%s: %zu bytes exceeds the limit of %zu bytes",
                          c->file, len, HJ_MAX_FILE_BYTES);
  json_error_t je;
  json_t *v = json_loadb(text ? text : "", len, JSON_REJECT_DUPLICATES, &je);
  if (!v)
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: line %d, column %d: %s", c->file, je.line,
                          je.column, je.text);
  if (!json_is_object(v)) {
    hearth_status s =
        hj_fail(c, HEARTH_E_PARSE, "expected a JSON object, found %s", hj_type_name(v));
    json_decref(v);
    return s;
  }
  *root = v;
  return HEARTH_OK;
}

/* ---- value-level checks ------------------------------------------------------ */

const char *hj_type_name(const json_t *v) {
  if (!v) return "nothing";
  switch (json_typeof(v)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER: return "an integer";
    case JSON_REAL: return "a number";
    case JSON_TRUE: return "true";
    case JSON_FALSE: return "false";
    case JSON_NULL: return "null";
  }
  return "an unknown value";
}

hearth_status hj_number(hj_ctx *c, const json_t *v, double *out) {
  if (!json_is_number(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected a number, found %s", hj_type_name(v));
  double x = json_number_value(v);
  if (!isfinite(x)) return hj_fail(c, HEARTH_E_RANGE, "expected a finite number");
  *out = x;
  return HEARTH_OK;
}

hearth_status hj_integer(hj_ctx *c, const json_t *v, long long lo, long long hi, long long *out) {
  if (!json_is_integer(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected an integer, found %s", hj_type_name(v));
  long long x = (long long)json_integer_value(v);
  if (x < lo || x > hi)
    return hj_fail(c, HEARTH_E_RANGE, "expected an integer in [%lld, %lld], found %lld", lo, hi, x);
  *out = x;
  return HEARTH_OK;
}

hearth_status hj_string(hj_ctx *c, const json_t *v, char *buf, size_t bufsz) {
  if (!json_is_string(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected a string, found %s", hj_type_name(v));
  size_t n = json_string_length(v);
  if (n >= bufsz)
    return hj_fail(c, HEARTH_E_LIMIT, "string of %zu bytes is longer than the limit of %zu", n,
                   bufsz - 1);
  memcpy(buf, json_string_value(v), n);
  buf[n] = 0;
  return HEARTH_OK;
}

hearth_status hj_bool(hj_ctx *c, const json_t *v, int *out) {
  if (!json_is_boolean(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected true or false, found %s", hj_type_name(v));
  *out = json_is_true(v);
  return HEARTH_OK;
}

hearth_status hj_array(hj_ctx *c, const json_t *v, size_t min, size_t max, size_t *n) {
  if (!json_is_array(v))
    return hj_fail(c, HEARTH_E_PARSE, "expected an array, found %s", hj_type_name(v));
  size_t k = json_array_size(v);
  if (min == max && k != min)
    return hj_fail(c, HEARTH_E_SIZE, "expected an array of %zu elements, found %zu", min, k);
  if (k < min)
    return hj_fail(c, HEARTH_E_SIZE, "expected at least %zu element%s, found %zu", min,
                   min == 1 ? "" : "s", k);
  if (k > max) return hj_fail(c, HEARTH_E_LIMIT, "%zu elements exceeds the limit of %zu", k, max);
  *n = k;
  return HEARTH_OK;
}

hearth_status hj_vec(hj_ctx *c, const json_t *v, size_t n, double *out) {
  size_t k;
  hearth_status s = hj_array(c, v, n, n, &k);
  if (s) return s;
  for (size_t i = 0; i < n; i++) {
    size_t m = hj_push_index(c, i);
    s = hj_number(c, json_array_get(v, i), &out[i]);
    if (s) return s;
    hj_pop(c, m);
  }
  return HEARTH_OK;
}

hearth_status hj_mat(hj_ctx *c, const json_t *v, size_t rows, size_t cols, double *out) {
  size_t k;
  hearth_status s = hj_array(c, v, rows, rows, &k);
  if (s) return s;
  for (size_t r = 0; r < rows; r++) {
    size_t m = hj_push_index(c, r);
    s = hj_vec(c, json_array_get(v, r), cols, out + r * cols);
    if (s) return s;
    hj_pop(c, m);
  }
  return HEARTH_OK;
}

/* an element of a matrix that must hold a fixed value */
static hearth_status hj_expect_entry(hj_ctx *c, const double *M, size_t cols, size_t r, size_t k,
                                     double want, double tol, const char *why) {
  double x = M[r * cols + k];
  if (fabs(x - want) <= tol) return HEARTH_OK;
  size_t m1 = hj_push_index(c, r);
  hj_push_index(c, k);
  hearth_status s = hj_fail(c, HEARTH_E_RANGE, "expected %g (%s), found %.17g", want, why, x);
  hj_pop(c, m1);
  return s;
}

hearth_status hj_camera(hj_ctx *c, const json_t *obj, hearth_camera *cam) {
  if (!json_is_object(obj))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(obj));
  hearth_status s;
  if ((s = hj_get_int(c, obj, "width", 1, HJ_MAX_IMAGE_SIDE, &cam->width))) return s;
  if ((s = hj_get_int(c, obj, "height", 1, HJ_MAX_IMAGE_SIDE, &cam->height))) return s;
  json_t *kv;
  if ((s = hj_member(c, obj, "K", &kv))) return s;
  size_t m = hj_push_key(c, "K");
  double K[9];
  if ((s = hj_mat(c, kv, 3, 3, K))) return s;
  /* the pinhole form [[fx,0,cx],[0,fy,cy],[0,0,1]], no skew */
  static const int zero_at[4][2] = {{0, 1}, {1, 0}, {2, 0}, {2, 1}};
  for (int i = 0; i < 4; i++)
    if ((s = hj_expect_entry(c, K, 3, (size_t)zero_at[i][0], (size_t)zero_at[i][1], 0.0, 0.0,
                             "K is [[fx,0,cx],[0,fy,cy],[0,0,1]]")))
      return s;
  if ((s = hj_expect_entry(c, K, 3, 2, 2, 1.0, 0.0, "K is [[fx,0,cx],[0,fy,cy],[0,0,1]]")))
    return s;
  for (int i = 0; i < 2; i++) {
    double f = K[i * 4];
    if (!(f > 0)) {
      size_t m1 = hj_push_index(c, (size_t)i);
      hj_push_index(c, (size_t)i);
      s = hj_fail(c, HEARTH_E_RANGE, "expected %s > 0, found %.17g", i ? "fy" : "fx", f);
      hj_pop(c, m1);
      return s;
    }
  }
  hj_pop(c, m);
  cam->fx = K[0];
  cam->fy = K[4];
  cam->cx = K[2];
  cam->cy = K[5];
  json_t *dv;
  if ((s = hj_member(c, obj, "dist", &dv))) return s;
  m = hj_push_key(c, "dist");
  /* 5 coefficients: Brown-Conrady; 8: OpenCV's rational model */
  size_t nd;
  if ((s = hj_array(c, dv, 5, 8, &nd))) return s;
  if (nd != 5 && nd != 8)
    return hj_fail(c, HEARTH_E_SIZE,
                   "expected 5 coefficients (k1 k2 p1 p2 k3) or 8 (k1 k2 p1 p2 k3 k4 k5 k6, the "
                   "rational model), found %zu",
                   nd);
  memset(cam->dist, 0, sizeof cam->dist);
  if ((s = hj_vec(c, dv, nd, cam->dist))) return s;
  cam->model = nd == 8 ? HEARTH_LENS_RATIONAL8 : HEARTH_LENS_BROWN5;
  hj_pop(c, m);
  return HEARTH_OK;
}

/* det and max |R^T R - I| of a 3x3, for messages about non-rotations */
static void hj_rotation_defect(const double R[9], double *det, double *dev) {
  *det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
         R[2] * (R[3] * R[7] - R[4] * R[6]);
  double worst = 0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double d = 0;
      for (int k = 0; k < 3; k++) d += R[k * 3 + i] * R[k * 3 + j];
      d -= (i == j) ? 1.0 : 0.0;
      if (fabs(d) > worst || d != d) worst = fabs(d);
    }
  *dev = worst;
}

static hearth_status hj_check_rotation(hj_ctx *c, const double R[9]) {
  if (hearth_is_rotation(R, HJ_ROT_TOL)) return HEARTH_OK;
  double det, dev;
  hj_rotation_defect(R, &det, &dev);
  return hj_fail(c, HEARTH_E_RANGE, "not a rotation (det=%.9g, max |R^T R - I| = %.3g, tol %g)",
                 det, dev, HJ_ROT_TOL);
}

hearth_status hj_rigid(hj_ctx *c, const json_t *obj, hearth_rigid *T) {
  if (!json_is_object(obj))
    return hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(obj));
  hearth_status s;
  json_t *rv, *tv;
  if ((s = hj_member(c, obj, "R", &rv))) return s;
  size_t m = hj_push_key(c, "R");
  if ((s = hj_mat(c, rv, 3, 3, T->R))) return s;
  if ((s = hj_check_rotation(c, T->R))) return s;
  hj_pop(c, m);
  if ((s = hj_member(c, obj, "t", &tv))) return s;
  m = hj_push_key(c, "t");
  if ((s = hj_vec(c, tv, 3, T->t))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

hearth_status hj_mat4_rigid(hj_ctx *c, const json_t *v, hearth_rigid *T) {
  double M[16];
  hearth_status s = hj_mat(c, v, 4, 4, M);
  if (s) return s;
  /* last row 0 0 0 1 (tiny slack for tools that compute it) */
  for (size_t k = 0; k < 4; k++)
    if ((s = hj_expect_entry(c, M, 4, 3, k, k == 3 ? 1.0 : 0.0, 1e-12, "last row is 0 0 0 1")))
      return s;
  double R[9] = {M[0], M[1], M[2], M[4], M[5], M[6], M[8], M[9], M[10]};
  if (!hearth_is_rotation(R, HJ_ROT_TOL)) {
    double det, dev;
    hj_rotation_defect(R, &det, &dev);
    return hj_fail(c, HEARTH_E_RANGE,
                   "top-left 3x3 block is not a rotation (det=%.9g, max |R^T R - I| = %.3g, "
                   "tol %g)",
                   det, dev, HJ_ROT_TOL);
  }
  if (!hearth_rigid_from_mat4(M, HJ_ROT_TOL, T))
    return hj_fail(c, HEARTH_E_RANGE, "not a rigid transform");
  return HEARTH_OK;
}

/* ---- key-level getters ----------------------------------------------------- */

hearth_status hj_member(hj_ctx *c, const json_t *obj, const char *key, json_t **out) {
  json_t *v = json_object_get(obj, key);
  if (!v) {
    size_t m = hj_push_key(c, key);
    hearth_status s = hj_fail(c, HEARTH_E_NOT_FOUND, "missing key");
    hj_pop(c, m);
    return s;
  }
  *out = v;
  return HEARTH_OK;
}

hearth_status hj_get_number(hj_ctx *c, const json_t *obj, const char *key, double *out) {
  json_t *v;
  hearth_status s = hj_member(c, obj, key, &v);
  if (s) return s;
  size_t m = hj_push_key(c, key);
  if ((s = hj_number(c, v, out))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

hearth_status hj_get_integer(hj_ctx *c, const json_t *obj, const char *key, long long lo,
                             long long hi, long long *out) {
  json_t *v;
  hearth_status s = hj_member(c, obj, key, &v);
  if (s) return s;
  size_t m = hj_push_key(c, key);
  if ((s = hj_integer(c, v, lo, hi, out))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

hearth_status hj_get_int(hj_ctx *c, const json_t *obj, const char *key, int lo, int hi, int *out) {
  long long x;
  hearth_status s = hj_get_integer(c, obj, key, lo, hi, &x);
  if (s) return s;
  *out = (int)x;
  return HEARTH_OK;
}

hearth_status hj_get_string(hj_ctx *c, const json_t *obj, const char *key, char *buf,
                            size_t bufsz) {
  json_t *v;
  hearth_status s = hj_member(c, obj, key, &v);
  if (s) return s;
  size_t m = hj_push_key(c, key);
  if ((s = hj_string(c, v, buf, bufsz))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

hearth_status hj_get_object(hj_ctx *c, const json_t *obj, const char *key, json_t **out) {
  json_t *v;
  hearth_status s = hj_member(c, obj, key, &v);
  if (s) return s;
  if (!json_is_object(v)) {
    size_t m = hj_push_key(c, key);
    s = hj_fail(c, HEARTH_E_PARSE, "expected an object, found %s", hj_type_name(v));
    hj_pop(c, m);
    return s;
  }
  *out = v;
  return HEARTH_OK;
}

hearth_status hj_get_camera(hj_ctx *c, const json_t *obj, const char *key, hearth_camera *cam) {
  json_t *v;
  hearth_status s = hj_member(c, obj, key, &v);
  if (s) return s;
  size_t m = hj_push_key(c, key);
  if ((s = hj_camera(c, v, cam))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

hearth_status hj_get_rigid(hj_ctx *c, const json_t *obj, const char *key, hearth_rigid *T) {
  json_t *v;
  hearth_status s = hj_member(c, obj, key, &v);
  if (s) return s;
  size_t m = hj_push_key(c, key);
  if ((s = hj_rigid(c, v, T))) return s;
  hj_pop(c, m);
  return HEARTH_OK;
}

/* ---- building ----------------------------------------------------------------- */

json_t *hj_real(double x) { return isfinite(x) ? json_real(x) : json_null(); }

json_t *hj_str(const char *s) {
  json_t *v = s ? json_string(s) : NULL;
  return v ? v : json_null();
}

json_t *hj_vec_new(const double *x, size_t n) {
  json_t *a = json_array();
  if (!a) return NULL;
  for (size_t i = 0; i < n; i++)
    if (json_array_append_new(a, hj_real(x[i])) != 0) {
      json_decref(a);
      return NULL;
    }
  return a;
}

json_t *hj_mat_new(const double *x, size_t rows, size_t cols) {
  json_t *a = json_array();
  if (!a) return NULL;
  for (size_t r = 0; r < rows; r++)
    if (json_array_append_new(a, hj_vec_new(x + r * cols, cols)) != 0) {
      json_decref(a);
      return NULL;
    }
  return a;
}

int hj_set(json_t *obj, const char *key, json_t *v) {
  if (!obj || !v) {
    json_decref(v);
    return 0;
  }
  return json_object_set_new(obj, key, v) == 0;
}

json_t *hj_camera_new(const hearth_camera *cam) {
  json_t *o = json_object();
  double K[9] = {cam->fx, 0, cam->cx, 0, cam->fy, cam->cy, 0, 0, 1};
  int ok = hj_set(o, "width", json_integer(cam->width)) &&
           hj_set(o, "height", json_integer(cam->height)) && hj_set(o, "K", hj_mat_new(K, 3, 3)) &&
           hj_set(o, "dist", hj_vec_new(cam->dist, (size_t)hearth_lens_n_coeffs(cam->model)));
  if (!ok) {
    json_decref(o);
    return NULL;
  }
  return o;
}

json_t *hj_rigid_new(const hearth_rigid *T) {
  json_t *o = json_object();
  int ok = hj_set(o, "R", hj_mat_new(T->R, 3, 3)) && hj_set(o, "t", hj_vec_new(T->t, 3));
  if (!ok) {
    json_decref(o);
    return NULL;
  }
  return o;
}

json_t *hj_mat4_new(const hearth_rigid *T) {
  double M[16];
  hearth_rigid_to_mat4(T, M);
  return hj_mat_new(M, 4, 4);
}

/* ---- pretty printer ----------------------------------------------------------- */

typedef struct hj_buf {
  char *p;
  size_t len, cap;
  int oom;
} hj_buf;

static void hb_put(hj_buf *b, const char *s, size_t n) {
  if (b->oom) return;
  if (b->len + n + 1 > b->cap) {
    size_t cap = b->cap ? b->cap : 256;
    while (cap < b->len + n + 1) {
      if (cap > ((size_t)-1) / 2) {
        b->oom = 1;
        return;
      }
      cap *= 2;
    }
    char *q = realloc(b->p, cap);
    if (!q) {
      b->oom = 1;
      return;
    }
    b->p = q;
    b->cap = cap;
  }
  memcpy(b->p + b->len, s, n);
  b->len += n;
  b->p[b->len] = 0;
}

static void hb_str(hj_buf *b, const char *s) { hb_put(b, s, strlen(s)); }

static void hb_indent(hj_buf *b, int n) {
  for (int i = 0; i < n; i++) hb_put(b, " ", 1);
}

/* a JSON string literal; UTF-8 passes through (jansson validated it) */
static void hb_quoted(hj_buf *b, const char *s, size_t n) {
  hb_put(b, "\"", 1);
  for (size_t i = 0; i < n; i++) {
    unsigned char ch = (unsigned char)s[i];
    char esc[8];
    switch (ch) {
      case '"': hb_str(b, "\\\""); break;
      case '\\': hb_str(b, "\\\\"); break;
      case '\n': hb_str(b, "\\n"); break;
      case '\r': hb_str(b, "\\r"); break;
      case '\t': hb_str(b, "\\t"); break;
      case '\b': hb_str(b, "\\b"); break;
      case '\f': hb_str(b, "\\f"); break;
      default:
        if (ch < 0x20) {
          snprintf(esc, sizeof esc, "\\u%04x", ch);
          hb_str(b, esc);
        } else {
          hb_put(b, (const char *)&ch, 1);
        }
    }
  }
  hb_put(b, "\"", 1);
}

/* x as "%.*g" with jansson's clean-up (".0" appended when the text would
 * read as an integer; no '+' or leading zeros in the exponent); 0 when the
 * locale's decimal point is not '.' or the text does not fit */
static int real_text(char *buf, size_t size, double x, int prec) {
  const char *point = localeconv()->decimal_point;
  if (!point || point[0] != '.' || point[1]) return 0;
  int n = snprintf(buf, size, "%.*g", prec, x);
  if (n < 0 || (size_t)n + 3 > size) return 0;
  if (!strchr(buf, '.') && !strchr(buf, 'e')) {
    memcpy(buf + n, ".0", 3);
    n += 2;
  }
  char *e = strchr(buf, 'e');
  if (e) {
    char *d = e + 1, *src = e + 1;
    if (*src == '-') d++, src++;
    else if (*src == '+') src++;
    while (*src == '0' && src[1]) src++;
    if (src != d) memmove(d, src, strlen(src) + 1);
  }
  return 1;
}

/* the shortest of %.15g/%.16g/%.17g (jansson's locale-independent
 * formatting) that parses back to exactly x */
static void hb_real(hj_buf *b, double x) {
  char fast[40];
  for (int p = 15; p <= 17 && isfinite(x); p++) {
    if (!real_text(fast, sizeof fast, x, p)) break;
    double y = strtod(fast, NULL);
    if (p == 17 || memcmp(&x, &y, sizeof x) == 0) {
      hb_str(b, fast);
      return;
    }
  }
  for (int p = 15; p <= 17; p++) {
    json_t *r = json_real(x);
    char *s = r ? json_dumps(r, JSON_ENCODE_ANY | JSON_REAL_PRECISION(p)) : NULL;
    json_decref(r);
    if (!s) {
      b->oom = 1;
      return;
    }
    int same = 0;
    if (p == 17) {
      same = 1;
    } else {
      json_t *back = json_loads(s, JSON_DECODE_ANY, NULL);
      if (back && json_is_number(back)) {
        double y = json_number_value(back);
        same = memcmp(&x, &y, sizeof x) == 0;
      }
      json_decref(back);
    }
    if (same) {
      hb_str(b, s);
      free(s);
      return;
    }
    free(s);
  }
}

static int hj_has_object(const json_t *v) {
  if (json_is_object(v)) return 1;
  if (json_is_array(v)) {
    size_t i;
    json_t *e;
    json_array_foreach(v, i, e) if (hj_has_object(e)) return 1;
  }
  return 0;
}

static void hj_emit(hj_buf *b, const json_t *v, int indent, size_t col);

/* arrays without objects on one line: "[a, b, [c, d]]" */
static void hj_emit_inline(hj_buf *b, const json_t *v) {
  if (json_is_array(v)) {
    hb_put(b, "[", 1);
    size_t i;
    json_t *e;
    json_array_foreach(v, i, e) {
      if (i) hb_put(b, ", ", 2);
      hj_emit_inline(b, e);
    }
    hb_put(b, "]", 1);
    return;
  }
  hj_emit(b, v, 0, 0);
}

#define HJ_LINE_WIDTH 100

static void hj_emit(hj_buf *b, const json_t *v, int indent, size_t col) {
  switch (json_typeof(v)) {
    case JSON_OBJECT: {
      if (json_object_size(v) == 0) {
        hb_str(b, "{}");
        return;
      }
      hb_str(b, "{\n");
      const char *key;
      json_t *e;
      size_t k = 0, n = json_object_size(v);
      json_object_foreach((json_t *)v, key, e) {
        hb_indent(b, indent + 2);
        hb_quoted(b, key, strlen(key));
        hb_str(b, ": ");
        hj_emit(b, e, indent + 2, (size_t)indent + 2 + strlen(key) + 4);
        hb_str(b, ++k < n ? ",\n" : "\n");
      }
      hb_indent(b, indent);
      hb_str(b, "}");
      return;
    }
    case JSON_ARRAY: {
      size_t n = json_array_size(v);
      if (n == 0) {
        hb_str(b, "[]");
        return;
      }
      if (!hj_has_object(v)) {
        hj_buf t = {0};
        hj_emit_inline(&t, v);
        int fits = !t.oom && col + t.len <= HJ_LINE_WIDTH;
        if (fits) hb_put(b, t.p, t.len);
        if (t.oom) b->oom = 1;
        free(t.p);
        if (fits || b->oom) return;
      }
      hb_str(b, "[\n");
      size_t i;
      json_t *e;
      json_array_foreach(v, i, e) {
        hb_indent(b, indent + 2);
        hj_emit(b, e, indent + 2, (size_t)indent + 2);
        hb_str(b, i + 1 < n ? ",\n" : "\n");
      }
      hb_indent(b, indent);
      hb_str(b, "]");
      return;
    }
    case JSON_STRING: hb_quoted(b, json_string_value(v), json_string_length(v)); return;
    case JSON_INTEGER: {
      char s[32];
      snprintf(s, sizeof s, "%" JSON_INTEGER_FORMAT, json_integer_value(v));
      hb_str(b, s);
      return;
    }
    case JSON_REAL: hb_real(b, json_real_value(v)); return;
    case JSON_TRUE: hb_str(b, "true"); return;
    case JSON_FALSE: hb_str(b, "false"); return;
    case JSON_NULL: hb_str(b, "null"); return;
  }
}

hearth_status hj_dump(const json_t *root, char **text, size_t *len, hearth_err *err) {
  *text = NULL;
  *len = 0;
  if (!root) return hearth_err_set(err, HEARTH_E_NOMEM, "cannot build the JSON document");
  hj_buf b = {0};
  hj_emit(&b, root, 0, 0);
  hb_str(&b, "\n");
  if (b.oom) {
    free(b.p);
    return hearth_err_set(err, HEARTH_E_NOMEM, "out of memory formatting a JSON document");
  }
  *text = b.p;
  *len = b.len;
  return HEARTH_OK;
}

hearth_status hj_write_doc(const char *path, json_t *root, hj_validate_fn validate,
                           hearth_err *err) {
  char *text;
  size_t len;
  hearth_status s = hj_dump(root, &text, &len, err);
  json_decref(root);
  if (s) return hearth_err_prefix(err, "%s", path);
  /* never write what our own reader would refuse */
  if (validate && (s = validate(text, len, path, err)) != HEARTH_OK) {
    free(text);
    return hearth_err_prefix(err, "not written");
  }
  s = hearth_write_file_atomic(path, text, len, err);
  free(text);
  return s;
}

/* ---- names ----------------------------------------------------------------------- */

int hj_simple_name(const char *s) {
  size_t n = strlen(s);
  if (n == 0 || n >= HEARTH_NAME_MAX) return 0;
  for (size_t i = 0; i < n; i++) {
    char ch = s[i];
    int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
             ch == '_' || ch == '-';
    if (!ok) return 0;
  }
  return 1;
}

int hj_relative_path_ok(const char *s) {
  if (!*s || *s == '/') return 0;
  const char *comp = s;
  for (const char *p = s;; p++) {
    if (*p == '/' || *p == 0) {
      size_t n = (size_t)(p - comp);
      if (n == 0) return 0;
      if (n == 2 && comp[0] == '.' && comp[1] == '.') return 0;
      if (*p == 0) break;
      comp = p + 1;
    } else if (*p == '\\' || (unsigned char)*p < 0x20 || *p == 0x7f) {
      return 0;
    }
  }
  return 1;
}
