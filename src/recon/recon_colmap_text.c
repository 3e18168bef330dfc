/* COLMAP's text model files (cameras.txt, images.txt, points3D.txt): lines
 * of whitespace-separated fields; '#' lines and blank lines are skipped
 * between records. An image is two lines: the header, then always its 2-D
 * points (possibly an empty line). Numbers are read in the C locale and
 * correctly rounded, so a text model reads to the same doubles as the
 * binary one it was written from (COLMAP writes 17 significant digits). */
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "recon/recon_internal.h"

#define TX_MAX_RECORDS ((size_t)1 << 28)

typedef struct tx {
  const char *p, *end; /* unread bytes */
  const char *name;
  size_t line;          /* number of the current line (1-based) */
  const char *cur, *le; /* the current line's unread part, its end (trimmed) */
  locale_t c_locale;
  hearth_err *err;
} tx;

static int tx_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/* next line (trimmed) into cur..le; 0 at the end of the data */
static int tx_next_line(tx *t) {
  if (t->p >= t->end) return 0;
  const char *s = t->p, *nl = memchr(s, '\n', (size_t)(t->end - s));
  const char *e = nl ? nl : t->end;
  t->p = nl ? nl + 1 : t->end;
  t->line++;
  while (s < e && tx_space(*s)) s++;
  while (e > s && tx_space(e[-1])) e--;
  t->cur = s;
  t->le = e;
  return 1;
}

/* next line that is neither blank nor a comment */
static int tx_next_record(tx *t) {
  while (tx_next_line(t))
    if (t->cur < t->le && t->cur[0] != '#') return 1;
  return 0;
}

static hearth_status tx_fail(tx *t, hearth_status s, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static hearth_status tx_fail(tx *t, hearth_status s, const char *fmt, ...) {
  char msg[768];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return hearth_err_set(t->err, s, "%s:%zu: %s", t->name, t->line, msg);
}

static int tx_token(tx *t, const char **s, size_t *n) {
  while (t->cur < t->le && tx_space(*t->cur)) t->cur++;
  if (t->cur >= t->le) return 0;
  const char *b = t->cur;
  while (t->cur < t->le && !tx_space(*t->cur)) t->cur++;
  *s = b;
  *n = (size_t)(t->cur - b);
  return 1;
}

static int tx_more(tx *t) {
  while (t->cur < t->le && tx_space(*t->cur)) t->cur++;
  return t->cur < t->le;
}

/* a shown copy of a token for messages */
static const char *tx_show(const char *s, size_t n, char *buf, size_t bufsz) {
  size_t k = 0;
  for (size_t i = 0; i < n && k + 4 < bufsz; i++)
    buf[k++] = (s[i] >= 0x20 && s[i] < 0x7f) ? s[i] : '?';
  if (k + 4 >= bufsz && n > k) memcpy(buf + k, "...", 3), k += 3;
  buf[k] = 0;
  return buf;
}

static hearth_status tx_u64(tx *t, const char *what, uint64_t max, uint64_t *out) {
  const char *s;
  size_t n;
  if (!tx_token(t, &s, &n))
    return tx_fail(t, HEARTH_E_PARSE, "expected %s, found the end of the line", what);
  uint64_t v = 0;
  int ok = n > 0 && n <= 20;
  for (size_t i = 0; ok && i < n; i++) {
    if (s[i] < '0' || s[i] > '9') ok = 0;
    else if (v > (UINT64_MAX - (uint64_t)(s[i] - '0')) / 10) ok = 0;
    else v = v * 10 + (uint64_t)(s[i] - '0');
  }
  char show[48];
  if (!ok || v > max)
    return tx_fail(t, HEARTH_E_PARSE, "expected %s (an integer in 0..%llu), found '%s'", what,
                   (unsigned long long)max, tx_show(s, n, show, sizeof show));
  *out = v;
  return HEARTH_OK;
}

static hearth_status tx_u32(tx *t, const char *what, uint32_t *out) {
  uint64_t v;
  hearth_status s = tx_u64(t, what, UINT32_MAX, &v);
  if (!s) *out = (uint32_t)v;
  return s;
}

static hearth_status tx_real(tx *t, const char *what, double *out) {
  const char *s;
  size_t n;
  if (!tx_token(t, &s, &n))
    return tx_fail(t, HEARTH_E_PARSE, "expected %s, found the end of the line", what);
  char show[48], buf[80];
  double check;
  /* hearth_parse_double decides the syntax (no NaN, Inf or hex); strtod in
   * the C locale gives the correctly rounded value */
  if (n >= sizeof buf || hearth_parse_double(s, n, 0, &check) != 0)
    return tx_fail(t, HEARTH_E_PARSE, "expected %s (a finite decimal number), found '%s'", what,
                   tx_show(s, n, show, sizeof show));
  memcpy(buf, s, n);
  buf[n] = 0;
  locale_t old = uselocale(t->c_locale);
  double v = strtod(buf, NULL);
  uselocale(old);
  if (!isfinite(v)) return tx_fail(t, HEARTH_E_RANGE, "%s '%s' is out of range", what, buf);
  *out = v;
  return HEARTH_OK;
}

static hearth_status tx_end_of_line(tx *t, const char *after) {
  if (!tx_more(t)) return HEARTH_OK;
  const char *s = t->cur;
  size_t n = 0;
  tx_token(t, &s, &n);
  char show[48];
  return tx_fail(t, HEARTH_E_PARSE, "unexpected '%s' after %s", tx_show(s, n, show, sizeof show),
                 after);
}

/* ---- cameras.txt: CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] ------------------- */
static hearth_status tx_cameras(tx *t, rc_vec *v, rc_vec *w) {
  hearth_status s;
  while (tx_next_record(t)) {
    hearth_colmap_camera *c = rc_vec_push(v, TX_MAX_RECORDS);
    rc_where *wh = rc_vec_push(w, TX_MAX_RECORDS);
    if (!c || !wh) return tx_fail(t, HEARTH_E_NOMEM, "out of memory for cameras");
    if ((s = tx_u32(t, "a camera id", &c->id))) return s;
    const char *nm;
    size_t nn;
    if (!tx_token(t, &nm, &nn))
      return tx_fail(t, HEARTH_E_PARSE,
                     "camera %u: expected a model name, found the end of the line",
                     (unsigned)c->id);
    char model[40], show[48];
    c->model_id = -1;
    if (nn < sizeof model) {
      memcpy(model, nm, nn);
      model[nn] = 0;
      c->model_id = hearth_colmap_model_id(model);
    }
    if (c->model_id < 0)
      return tx_fail(t, HEARTH_E_UNSUPPORTED, "camera %u: unknown camera model '%s'",
                     (unsigned)c->id, tx_show(nm, nn, show, sizeof show));
    if ((s = tx_u64(t, "the width", UINT64_MAX, &c->width)) ||
        (s = tx_u64(t, "the height", UINT64_MAX, &c->height)))
      return s;
    int np = hearth_colmap_model_n_params(c->model_id);
    while (tx_more(t)) {
      if (c->n_params >= (size_t)np)
        return tx_fail(t, HEARTH_E_SIZE, "camera %u: model %s takes %d parameters, found more",
                       (unsigned)c->id, model, np);
      char what[64];
      snprintf(what, sizeof what, "parameter %zu of camera %u", c->n_params + 1, (unsigned)c->id);
      if ((s = tx_real(t, what, &c->params[c->n_params]))) return s;
      c->n_params++;
    }
    if (c->n_params != (size_t)np)
      return tx_fail(t, HEARTH_E_SIZE, "camera %u: model %s takes %d parameters, found %zu",
                     (unsigned)c->id, model, np, c->n_params);
    if ((s = rc_camera_finish(c, t->err)))
      return hearth_err_prefix(t->err, "%s:%zu: camera %u", t->name, t->line, (unsigned)c->id);
    *wh = (rc_where){c->id, t->line};
  }
  return HEARTH_OK;
}

/* ---- images.txt: IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then
 * POINTS2D[] as (X, Y, POINT3D_ID) ------------------------------------------- */
static hearth_status tx_images(tx *t, const hearth_colmap_model *m, rc_vec *v, rc_vec *w) {
  static const char *const k_pose[7] = {"QW", "QX", "QY", "QZ", "TX", "TY", "TZ"};
  hearth_status s;
  char what[64], why[256];
  while (tx_next_record(t)) {
    hearth_colmap_image *im = rc_vec_push(v, TX_MAX_RECORDS);
    rc_where *wh = rc_vec_push(w, TX_MAX_RECORDS);
    if (!im || !wh) return tx_fail(t, HEARTH_E_NOMEM, "out of memory for images");
    if ((s = tx_u32(t, "an image id", &im->id))) return s;
    for (int k = 0; k < 7; k++) {
      snprintf(what, sizeof what, "%s of image %u", k_pose[k], (unsigned)im->id);
      double *dst = k < 4 ? &im->q_cam_from_world[k] : &im->t_cam_from_world[k - 4];
      if ((s = tx_real(t, what, dst))) return s;
    }
    snprintf(what, sizeof what, "the camera id of image %u", (unsigned)im->id);
    if ((s = tx_u32(t, what, &im->camera_id))) return s;
    const char *nm;
    size_t nn;
    if (!tx_token(t, &nm, &nn))
      return tx_fail(t, HEARTH_E_PARSE,
                     "image %u: expected the image name, found the end of the line",
                     (unsigned)im->id);
    if (nn >= sizeof im->name)
      return tx_fail(t, HEARTH_E_LIMIT, "image %u: name longer than %zu bytes", (unsigned)im->id,
                     sizeof im->name - 1);
    for (size_t i = 0; i < nn; i++)
      if ((unsigned char)nm[i] < 0x20 || nm[i] == 0x7f)
        return tx_fail(t, HEARTH_E_PARSE, "image %u: control character in the image name",
                       (unsigned)im->id);
    memcpy(im->name, nm, nn);
    im->name[nn] = 0;
    if ((s = tx_end_of_line(t, "the image name"))) return s;
    if (!hearth_colmap_find_camera(m, im->camera_id))
      return tx_fail(t, HEARTH_E_INCONSISTENT,
                     "image %u (%s): camera %u is not in the model's cameras", (unsigned)im->id,
                     im->name, (unsigned)im->camera_id);
    if (rc_image_pose(im, why, sizeof why))
      return tx_fail(t, HEARTH_E_RANGE, "image %u: %s", (unsigned)im->id, why);
    *wh = (rc_where){im->id, t->line};
    /* the next line holds the 2-D points, whatever it looks like; a file may
     * end right after its last header */
    if (!tx_next_line(t)) break;
    if (t->cur < t->le && t->cur[0] == '#')
      return tx_fail(t, HEARTH_E_PARSE,
                     "expected the 2-D points of image %u (X Y POINT3D_ID ...), found a comment",
                     (unsigned)im->id);
    while (tx_more(t)) {
      double x, y;
      snprintf(what, sizeof what, "X of 2-D point %zu of image %u", im->n_points2d,
               (unsigned)im->id);
      if ((s = tx_real(t, what, &x))) return s;
      snprintf(what, sizeof what, "Y of 2-D point %zu of image %u", im->n_points2d,
               (unsigned)im->id);
      if ((s = tx_real(t, what, &y))) return s;
      const char *id;
      size_t idn;
      if (!tx_token(t, &id, &idn))
        return tx_fail(t, HEARTH_E_PARSE,
                       "image %u: 2-D point %zu: expected its POINT3D_ID, found the end of the line",
                       (unsigned)im->id, im->n_points2d);
      if (!(idn == 2 && id[0] == '-' && id[1] == '1')) {
        t->cur = id; /* re-read it as an id */
        uint64_t pid;
        snprintf(what, sizeof what, "POINT3D_ID of 2-D point %zu of image %u (or -1)",
                 im->n_points2d, (unsigned)im->id);
        if ((s = tx_u64(t, what, UINT64_MAX - 1, &pid))) return s;
        im->n_observations++;
      }
      im->n_points2d++;
    }
  }
  return HEARTH_OK;
}

/* ---- points3D.txt: POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID,
 * POINT2D_IDX) ------------------------------------------------------------------ */
static hearth_status tx_points(tx *t, const hearth_colmap_model *m, rc_vec *v, rc_vec *w) {
  static const char *const k_xyz[3] = {"X", "Y", "Z"}, *const k_rgb[3] = {"R", "G", "B"};
  hearth_status s;
  char what[64], why[256];
  while (tx_next_record(t)) {
    hearth_colmap_point *p = rc_vec_push(v, TX_MAX_RECORDS);
    rc_where *wh = rc_vec_push(w, TX_MAX_RECORDS);
    if (!p || !wh) return tx_fail(t, HEARTH_E_NOMEM, "out of memory for 3-D points");
    if ((s = tx_u64(t, "a 3-D point id", UINT64_MAX - 1, &p->id))) return s;
    for (int k = 0; k < 3; k++) {
      snprintf(what, sizeof what, "%s of point %llu", k_xyz[k], (unsigned long long)p->id);
      if ((s = tx_real(t, what, &p->xyz[k]))) return s;
    }
    for (int k = 0; k < 3; k++) {
      uint64_t c;
      snprintf(what, sizeof what, "%s of point %llu", k_rgb[k], (unsigned long long)p->id);
      if ((s = tx_u64(t, what, 255, &c))) return s;
      p->rgb[k] = (uint8_t)c;
    }
    snprintf(what, sizeof what, "ERROR of point %llu", (unsigned long long)p->id);
    if ((s = tx_real(t, what, &p->error))) return s;
    while (tx_more(t)) {
      uint32_t im, idx;
      snprintf(what, sizeof what, "IMAGE_ID of track element %zu of point %llu", p->track_length,
               (unsigned long long)p->id);
      if ((s = tx_u32(t, what, &im))) return s;
      snprintf(what, sizeof what, "POINT2D_IDX of track element %zu of point %llu", p->track_length,
               (unsigned long long)p->id);
      if ((s = tx_u32(t, what, &idx))) return s;
      if (rc_track_check(m, im, idx, why, sizeof why))
        return tx_fail(t, HEARTH_E_INCONSISTENT, "point %llu: %s", (unsigned long long)p->id, why);
      p->track_length++;
    }
    *wh = (rc_where){p->id, t->line};
  }
  return HEARTH_OK;
}

hearth_status rc_parse_text(hearth_colmap_file which, const uint8_t *data, size_t len,
                            const char *name, hearth_colmap_model *m, hearth_err *err) {
  static const size_t k_size[3] = {sizeof(hearth_colmap_camera), sizeof(hearth_colmap_image),
                                   sizeof(hearth_colmap_point)};
  tx t = {.p = (const char *)data, .end = (const char *)data + len, .name = name, .err = err};
  t.c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
  if (t.c_locale == (locale_t)0)
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot create the C locale", name);
  rc_vec v = {.size = k_size[which]}, w = {.size = sizeof(rc_where)};
  hearth_status s;
  if (which == HEARTH_COLMAP_CAMERAS) s = tx_cameras(&t, &v, &w);
  else if (which == HEARTH_COLMAP_IMAGES) s = tx_images(&t, m, &v, &w);
  else s = tx_points(&t, m, &v, &w);
  freelocale(t.c_locale);
  return rc_finish(m, which, &v, &w, s, name, 0, err);
}
