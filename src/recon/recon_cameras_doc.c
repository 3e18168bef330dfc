/* The cameras document written beside a poses file by the COLMAP import
 * (schema in hearth/recon.h): a deterministic writer that checks its text
 * with the reader before writing, and a strict reader (jansson) whose
 * errors name the file and the JSON path. */
#include <jansson.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "recon/recon_internal.h"

#define RC_CONVENTION "hearth camera: OpenCV axes, pixel (0, 0) at the centre of the top-left pixel"
#define RC_MAX_DOC ((size_t)64 << 20)
#define RC_MAX_CAMERAS 65536
#define RC_MAX_VIEWS 8192

/* ---- writing ---------------------------------------------------------------------- */
void rc_json_real(hearth_strbuf *b, double x) {
  char buf[40] = "0.0";
  locale_t c = newlocale(LC_ALL_MASK, "C", (locale_t)0);
  locale_t old = c ? uselocale(c) : (locale_t)0;
  for (int p = 15; p <= 17; p++) {
    snprintf(buf, sizeof buf, "%.*g", p, x);
    if (strtod(buf, NULL) == x) break;
  }
  if (c) {
    uselocale(old);
    freelocale(c);
  }
  if (!strchr(buf, '.') && !strchr(buf, 'e') && !strchr(buf, 'n') && !strchr(buf, 'i'))
    strcat(buf, ".0");
  hearth_strbuf_printf(b, "%s", buf);
}

void rc_json_string(hearth_strbuf *b, const char *s) {
  hearth_strbuf_printf(b, "\"");
  for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
    if (*p == '"' || *p == '\\') hearth_strbuf_printf(b, "\\%c", *p);
    else if (*p < 0x20) hearth_strbuf_printf(b, "\\u%04x", *p);
    else hearth_strbuf_printf(b, "%c", *p);
  }
  hearth_strbuf_printf(b, "\"");
}

void rc_json_reals(hearth_strbuf *b, const double *x, size_t n) {
  hearth_strbuf_printf(b, "[");
  for (size_t i = 0; i < n; i++) {
    if (i) hearth_strbuf_printf(b, ", ");
    rc_json_real(b, x[i]);
  }
  hearth_strbuf_printf(b, "]");
}

static char *cameras_text(const hearth_recon_cameras *c) {
  hearth_strbuf b = {0};
  hearth_strbuf_printf(&b, "{\n  \"convention\": ");
  rc_json_string(&b, RC_CONVENTION);
  hearth_strbuf_printf(&b, ",\n  \"cameras\": [%s", c->n_cameras ? "\n" : "");
  for (size_t i = 0; i < c->n_cameras; i++) {
    const hearth_colmap_camera *k = &c->cameras[i];
    const hearth_camera *h = &k->camera;
    const char *model = hearth_colmap_model_name(k->model_id);
    hearth_strbuf_printf(&b, "    {\n      \"colmap_camera_id\": %u,\n      \"colmap_model\": ",
                         (unsigned)k->id);
    rc_json_string(&b, model ? model : "");
    hearth_strbuf_printf(&b, ",\n      \"colmap_params\": ");
    rc_json_reals(&b, k->params, k->n_params);
    hearth_strbuf_printf(&b, ",\n      \"width\": %d,\n      \"height\": %d,\n      \"K\": [\n",
                         h->width, h->height);
    double K[9];
    hearth_camera_K(h, K);
    for (int r = 0; r < 3; r++) {
      hearth_strbuf_printf(&b, "        ");
      rc_json_reals(&b, K + 3 * r, 3);
      hearth_strbuf_printf(&b, "%s\n", r < 2 ? "," : "");
    }
    hearth_strbuf_printf(&b, "      ],\n      \"dist\": ");
    rc_json_reals(&b, h->dist, 5);
    hearth_strbuf_printf(&b, "\n    }%s\n", i + 1 < c->n_cameras ? "," : "");
  }
  hearth_strbuf_printf(&b, "%s],\n  \"views\": [%s", c->n_cameras ? "  " : "",
                       c->n_views ? "\n" : "");
  for (size_t i = 0; i < c->n_views; i++) {
    const hearth_recon_view_camera *v = &c->views[i];
    hearth_strbuf_printf(&b, "    {\n      \"state\": ");
    rc_json_string(&b, v->state);
    hearth_strbuf_printf(&b, ",\n      \"view\": ");
    rc_json_string(&b, v->view);
    hearth_strbuf_printf(&b,
                         ",\n      \"colmap_camera_id\": %u,\n      \"colmap_image_id\": %u,\n"
                         "      \"colmap_image\": ",
                         (unsigned)v->camera_id, (unsigned)v->image_id);
    rc_json_string(&b, v->image);
    hearth_strbuf_printf(&b, "\n    }%s\n", i + 1 < c->n_views ? "," : "");
  }
  hearth_strbuf_printf(&b, "%s]\n}\n", c->n_views ? "  " : "");
  return hearth_strbuf_take(&b);
}

hearth_status hearth_recon_cameras_write(const char *path, const hearth_recon_cameras *c,
                                         hearth_err *err) {
  char *text = cameras_text(c);
  if (!text) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  hearth_recon_cameras back;
  hearth_status s = hearth_recon_cameras_parse(text, strlen(text), path, &back, err);
  hearth_recon_cameras_free(&back);
  if (s) hearth_err_prefix(err, "refusing to write");
  else s = hearth_write_file_atomic(path, text, strlen(text), err);
  free(text);
  return s;
}

/* ---- reading ------------------------------------------------------------------------ */
typedef struct rd {
  const char *name;
  char path[128]; /* JSON path of the value being read */
  hearth_err *err;
} rd;

static hearth_status rd_fail(rd *r, hearth_status s, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static hearth_status rd_fail(rd *r, hearth_status s, const char *fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return hearth_err_set(r->err, s, "%s: %s: %s", r->name, r->path[0] ? r->path : "(top level)",
                        msg);
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

/* the member `key` of obj, with r->path set to prefix.key */
static hearth_status rd_member(rd *r, const json_t *obj, const char *prefix, const char *key,
                               json_t **out) {
  snprintf(r->path, sizeof r->path, "%s%s%s", prefix, *prefix ? "." : "", key);
  *out = json_object_get(obj, key);
  if (!*out) return rd_fail(r, HEARTH_E_NOT_FOUND, "missing");
  return HEARTH_OK;
}

static hearth_status rd_uint(rd *r, const json_t *v, json_int_t lo, json_int_t hi,
                             json_int_t *out) {
  if (!json_is_integer(v))
    return rd_fail(r, HEARTH_E_PARSE, "expected an integer, found %s", type_name(v));
  json_int_t x = json_integer_value(v);
  if (x < lo || x > hi)
    return rd_fail(r, HEARTH_E_RANGE, "expected an integer in %lld..%lld, found %lld",
                   (long long)lo, (long long)hi, (long long)x);
  *out = x;
  return HEARTH_OK;
}

static hearth_status rd_string(rd *r, const json_t *v, char *buf, size_t bufsz) {
  if (!json_is_string(v))
    return rd_fail(r, HEARTH_E_PARSE, "expected a string, found %s", type_name(v));
  size_t n = json_string_length(v);
  const char *s = json_string_value(v);
  if (n >= bufsz || memchr(s, 0, n))
    return rd_fail(r, HEARTH_E_LIMIT, "expected a string of at most %zu bytes without NUL",
                   bufsz - 1);
  memcpy(buf, s, n + 1);
  return HEARTH_OK;
}

/* an array of exactly n finite numbers (n_max: any count up to it, *got) */
static hearth_status rd_reals(rd *r, const json_t *v, size_t n, size_t n_max, double *out,
                              size_t *got) {
  if (!json_is_array(v))
    return rd_fail(r, HEARTH_E_PARSE, "expected an array, found %s", type_name(v));
  size_t m = json_array_size(v);
  if (n_max ? m > n_max : m != n) {
    if (n_max)
      return rd_fail(r, HEARTH_E_SIZE, "expected at most %zu numbers, found %zu", n_max, m);
    return rd_fail(r, HEARTH_E_SIZE, "expected %zu numbers, found %zu", n, m);
  }
  for (size_t i = 0; i < m; i++) {
    const json_t *e = json_array_get(v, i);
    if (!json_is_number(e)) {
      size_t L = strlen(r->path);
      snprintf(r->path + L, sizeof r->path - L, "[%zu]", i);
      return rd_fail(r, HEARTH_E_PARSE, "expected a number, found %s", type_name(e));
    }
    out[i] = json_number_value(e);
  }
  if (got) *got = m;
  return HEARTH_OK;
}

static hearth_status rd_camera(rd *r, const json_t *o, const char *at, hearth_colmap_camera *c) {
  json_t *v;
  json_int_t x;
  char model[40];
  hearth_status s;
  if (!json_is_object(o)) {
    snprintf(r->path, sizeof r->path, "%s", at);
    return rd_fail(r, HEARTH_E_PARSE, "expected an object, found %s", type_name(o));
  }
  if ((s = rd_member(r, o, at, "colmap_camera_id", &v)) || (s = rd_uint(r, v, 0, UINT32_MAX, &x)))
    return s;
  c->id = (uint32_t)x;
  if ((s = rd_member(r, o, at, "colmap_model", &v)) || (s = rd_string(r, v, model, sizeof model)))
    return s;
  c->model_id = hearth_colmap_model_id(model);
  if (c->model_id < 0) return rd_fail(r, HEARTH_E_RANGE, "unknown COLMAP model \"%s\"", model);
  if ((s = rd_member(r, o, at, "colmap_params", &v)) ||
      (s = rd_reals(r, v, (size_t)hearth_colmap_model_n_params(c->model_id), 0, c->params, NULL)))
    return s;
  c->n_params = (size_t)hearth_colmap_model_n_params(c->model_id);
  if ((s = rd_member(r, o, at, "width", &v)) || (s = rd_uint(r, v, 1, 65536, &x))) return s;
  c->width = (uint64_t)x;
  c->camera.width = (int)x;
  if ((s = rd_member(r, o, at, "height", &v)) || (s = rd_uint(r, v, 1, 65536, &x))) return s;
  c->height = (uint64_t)x;
  c->camera.height = (int)x;
  if ((s = rd_member(r, o, at, "K", &v))) return s;
  if (!json_is_array(v) || json_array_size(v) != 3)
    return rd_fail(r, HEARTH_E_SIZE, "expected a 3x3 array");
  double K[9];
  char kpath[128];
  snprintf(kpath, sizeof kpath, "%s", r->path);
  for (int i = 0; i < 3; i++) {
    snprintf(r->path, sizeof r->path, "%s[%d]", kpath, i);
    if ((s = rd_reals(r, json_array_get(v, (size_t)i), 3, 0, K + 3 * i, NULL))) return s;
  }
  snprintf(r->path, sizeof r->path, "%s", kpath);
  for (int i = 0; i < 9; i++)
    if (!isfinite(K[i])) return rd_fail(r, HEARTH_E_RANGE, "K holds a non-finite number");
  if (K[1] != 0 || K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
    return rd_fail(r, HEARTH_E_RANGE, "expected [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]");
  if (!(K[0] > 0) || !(K[4] > 0)) return rd_fail(r, HEARTH_E_RANGE, "expected fx, fy > 0");
  c->camera.fx = K[0];
  c->camera.cx = K[2];
  c->camera.fy = K[4];
  c->camera.cy = K[5];
  if ((s = rd_member(r, o, at, "dist", &v)) || (s = rd_reals(r, v, 5, 0, c->camera.dist, NULL)))
    return s;
  for (int i = 0; i < 5; i++)
    if (!isfinite(c->camera.dist[i])) return rd_fail(r, HEARTH_E_RANGE, "non-finite coefficient");
  return HEARTH_OK;
}

static int cam_id_cmp(const void *pa, const void *pb) {
  const hearth_colmap_camera *a = pa, *b = pb;
  return (a->id > b->id) - (a->id < b->id);
}

static hearth_status rd_view(rd *r, const json_t *o, const char *at, const hearth_recon_cameras *c,
                             hearth_recon_view_camera *v) {
  json_t *x;
  json_int_t n;
  hearth_status s;
  if (!json_is_object(o)) {
    snprintf(r->path, sizeof r->path, "%s", at);
    return rd_fail(r, HEARTH_E_PARSE, "expected an object, found %s", type_name(o));
  }
  if ((s = rd_member(r, o, at, "state", &x)) || (s = rd_string(r, x, v->state, sizeof v->state)))
    return s;
  if (!hearth_state_valid(v->state))
    return rd_fail(r, HEARTH_E_RANGE, "expected neutral, hot, warm, iced or used, found \"%s\"",
                   v->state);
  if ((s = rd_member(r, o, at, "view", &x)) || (s = rd_string(r, x, v->view, sizeof v->view)))
    return s;
  char st[HEARTH_NAME_MAX], vw[HEARTH_NAME_MAX];
  if (hearth_colmap_view_of(v->view, v->state, st, vw, NULL) || strcmp(vw, v->view))
    return rd_fail(r, HEARTH_E_RANGE,
                   "expected a view name of letters, digits, '_' or '-', found \"%s\"", v->view);
  if ((s = rd_member(r, o, at, "colmap_camera_id", &x)) || (s = rd_uint(r, x, 0, UINT32_MAX, &n)))
    return s;
  v->camera_id = (uint32_t)n;
  hearth_colmap_camera key = {.id = v->camera_id};
  if (!bsearch(&key, c->cameras, c->n_cameras, sizeof key, cam_id_cmp))
    return rd_fail(r, HEARTH_E_INCONSISTENT, "camera %u is not in cameras", (unsigned)v->camera_id);
  if ((s = rd_member(r, o, at, "colmap_image_id", &x)) || (s = rd_uint(r, x, 0, UINT32_MAX, &n)))
    return s;
  v->image_id = (uint32_t)n;
  if ((s = rd_member(r, o, at, "colmap_image", &x)) ||
      (s = rd_string(r, x, v->image, sizeof v->image)))
    return s;
  return HEARTH_OK;
}

static hearth_status rd_doc(rd *r, const json_t *root, hearth_recon_cameras *c) {
  json_t *v;
  char conv[128];
  hearth_status s;
  if (!json_is_object(root))
    return rd_fail(r, HEARTH_E_PARSE, "expected an object, found %s", type_name(root));
  if ((s = rd_member(r, root, "", "convention", &v)) || (s = rd_string(r, v, conv, sizeof conv)))
    return s;
  if (strcmp(conv, RC_CONVENTION))
    return rd_fail(r, HEARTH_E_RANGE, "expected \"%s\", found \"%s\"", RC_CONVENTION, conv);
  json_t *cams, *views;
  if ((s = rd_member(r, root, "", "cameras", &cams))) return s;
  if (!json_is_array(cams))
    return rd_fail(r, HEARTH_E_PARSE, "expected an array, found %s", type_name(cams));
  if ((s = rd_member(r, root, "", "views", &views))) return s;
  if (!json_is_array(views))
    return rd_fail(r, HEARTH_E_PARSE, "expected an array, found %s", type_name(views));
  size_t nc = json_array_size(cams), nv = json_array_size(views);
  if (nc > RC_MAX_CAMERAS)
    return rd_fail(r, HEARTH_E_LIMIT, "more than %d cameras", RC_MAX_CAMERAS);
  if (nv > RC_MAX_VIEWS) return rd_fail(r, HEARTH_E_LIMIT, "more than %d views", RC_MAX_VIEWS);
  c->cameras = hearth_calloc_array(nc ? nc : 1, sizeof *c->cameras);
  c->views = hearth_calloc_array(nv ? nv : 1, sizeof *c->views);
  if (!c->cameras || !c->views)
    return hearth_err_set(r->err, HEARTH_E_NOMEM, "%s: out of memory", r->name);
  char at[48];
  for (size_t i = 0; i < nc; i++) {
    snprintf(at, sizeof at, "cameras[%zu]", i);
    if ((s = rd_camera(r, json_array_get(cams, i), at, &c->cameras[i]))) return s;
    for (size_t j = 0; j < i; j++)
      if (c->cameras[j].id == c->cameras[i].id) {
        snprintf(r->path, sizeof r->path, "%s.colmap_camera_id", at);
        return rd_fail(r, HEARTH_E_INCONSISTENT, "duplicate of cameras[%zu]", j);
      }
    c->n_cameras = i + 1;
  }
  qsort(c->cameras, nc, sizeof *c->cameras, cam_id_cmp);
  for (size_t i = 0; i < nv; i++) {
    snprintf(at, sizeof at, "views[%zu]", i);
    if ((s = rd_view(r, json_array_get(views, i), at, c, &c->views[i]))) return s;
    for (size_t j = 0; j < i; j++)
      if (!strcmp(c->views[j].state, c->views[i].state) &&
          !strcmp(c->views[j].view, c->views[i].view)) {
        snprintf(r->path, sizeof r->path, "%s", at);
        return rd_fail(r, HEARTH_E_INCONSISTENT, "duplicate of views[%zu] (state %s, view %s)", j,
                       c->views[i].state, c->views[i].view);
      }
    c->n_views = i + 1;
  }
  return HEARTH_OK;
}

hearth_status hearth_recon_cameras_parse(const char *text, size_t len, const char *name,
                                         hearth_recon_cameras *c, hearth_err *err) {
  memset(c, 0, sizeof *c);
  if (!name) name = "cameras document";
  if (len > RC_MAX_DOC) return hearth_err_set(err, HEARTH_E_LIMIT, "%s: larger than 64 MiB", name);
  json_error_t je;
  json_t *root = json_loadb(text, len, JSON_REJECT_DUPLICATES, &je);
  if (!root)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: line %d, column %d: %s", name, je.line,
                          je.column, je.text);
  rd r = {.name = name, .err = err};
  hearth_status s = rd_doc(&r, root, c);
  json_decref(root);
  if (s) hearth_recon_cameras_free(c);
  return s;
}

hearth_status hearth_recon_cameras_read(const char *path, hearth_recon_cameras *c,
                                        hearth_err *err) {
  memset(c, 0, sizeof *c);
  uint8_t *data;
  size_t size;
  hearth_status s = hearth_read_file(path, RC_MAX_DOC, &data, &size, err);
  if (s) return s;
  s = hearth_recon_cameras_parse((const char *)data, size, path, c, err);
  free(data);
  return s;
}
