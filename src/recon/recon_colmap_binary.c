/* COLMAP's binary model files (cameras.bin, images.bin, points3D.bin):
 * little-endian fixed-size fields (layout in hearth/recon.h). Every count is
 * checked against the bytes left before anything is allocated; errors give
 * the byte offset where the offending field starts. */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "recon/recon_internal.h"

typedef struct bn {
  const uint8_t *data;
  size_t len, off;
  const char *name;
  hearth_err *err;
} bn;

static hearth_status bn_fail(bn *b, size_t at, hearth_status s, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static hearth_status bn_fail(bn *b, size_t at, hearth_status s, const char *fmt, ...) {
  char msg[768];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return hearth_err_set(b->err, s, "%s: byte offset %zu: %s", b->name, at, msg);
}

/* n bytes at the cursor, or a "truncated" error naming what was expected */
static hearth_status bn_take(bn *b, size_t n, const char *what, const uint8_t **p) {
  if (b->len - b->off < n)
    return bn_fail(b, b->off, HEARTH_E_PARSE, "truncated: expected %s (%zu bytes), %zu left", what,
                   n, b->len - b->off);
  *p = b->data + b->off;
  b->off += n;
  return HEARTH_OK;
}

static uint64_t le64(const uint8_t *p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; i--) v = (v << 8) | p[i];
  return v;
}
static uint32_t le32(const uint8_t *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static double led(const uint8_t *p) {
  uint64_t u = le64(p);
  double d;
  memcpy(&d, &u, sizeof d);
  return d;
}

static hearth_status bn_u64(bn *b, const char *what, uint64_t *out) {
  const uint8_t *p = NULL;
  hearth_status s = bn_take(b, 8, what, &p);
  if (!s) *out = le64(p);
  return s;
}
static hearth_status bn_u32(bn *b, const char *what, uint32_t *out) {
  const uint8_t *p = NULL;
  hearth_status s = bn_take(b, 4, what, &p);
  if (!s) *out = le32(p);
  return s;
}
static hearth_status bn_doubles(bn *b, size_t n, const char *what, double *out) {
  const uint8_t *p = NULL;
  hearth_status s = bn_take(b, 8 * n, what, &p);
  for (size_t i = 0; !s && i < n; i++) out[i] = led(p + 8 * i);
  return s;
}

/* the record count at the start of a file: at most (bytes left) / (the
 * smallest record) */
static hearth_status bn_count(bn *b, const char *kind, size_t min_record, size_t *n) {
  uint64_t c;
  hearth_status s = bn_u64(b, "the record count", &c);
  if (s) return s;
  uint64_t most = (uint64_t)((b->len - b->off) / min_record);
  if (c > most)
    return bn_fail(b, 0, HEARTH_E_PARSE,
                   "%llu %s announced, but the %zu bytes left hold at most %llu",
                   (unsigned long long)c, kind, b->len - b->off, (unsigned long long)most);
  *n = (size_t)c;
  return HEARTH_OK;
}

/* ---- cameras.bin ---------------------------------------------------------------- */
static hearth_status bn_cameras(bn *b, rc_vec *v, rc_vec *w) {
  size_t n;
  hearth_status s = bn_count(b, "cameras", 24, &n);
  if (s) return s;
  char what[80];
  for (size_t i = 0; i < n; i++) {
    size_t at = b->off;
    hearth_colmap_camera *c = rc_vec_push(v, n);
    rc_where *wh = rc_vec_push(w, n);
    if (!c || !wh) return bn_fail(b, at, HEARTH_E_NOMEM, "out of memory for cameras");
    uint32_t model;
    snprintf(what, sizeof what, "the id of camera record %zu", i);
    if ((s = bn_u32(b, what, &c->id))) return s;
    snprintf(what, sizeof what, "the model id of camera %u", (unsigned)c->id);
    size_t at_model = b->off;
    if ((s = bn_u32(b, what, &model))) return s;
    c->model_id = (int32_t)model;
    snprintf(what, sizeof what, "the width of camera %u", (unsigned)c->id);
    if ((s = bn_u64(b, what, &c->width))) return s;
    snprintf(what, sizeof what, "the height of camera %u", (unsigned)c->id);
    if ((s = bn_u64(b, what, &c->height))) return s;
    int np = hearth_colmap_model_n_params(c->model_id);
    if (np < 0)
      return bn_fail(b, at_model, HEARTH_E_UNSUPPORTED, "camera %u: unknown camera model id %d",
                     (unsigned)c->id, c->model_id);
    c->n_params = (size_t)np;
    snprintf(what, sizeof what, "the %d parameters of camera %u (%s)", np, (unsigned)c->id,
             hearth_colmap_model_name(c->model_id));
    if ((s = bn_doubles(b, c->n_params, what, c->params))) return s;
    if ((s = rc_camera_finish(c, b->err)))
      return hearth_err_prefix(b->err, "%s: byte offset %zu: camera %u", b->name, at,
                               (unsigned)c->id);
    *wh = (rc_where){c->id, at};
  }
  return HEARTH_OK;
}

/* ---- images.bin ------------------------------------------------------------------ */
static hearth_status bn_images(bn *b, const hearth_colmap_model *m, rc_vec *v, rc_vec *w) {
  size_t n;
  hearth_status s = bn_count(b, "images", 4 + 56 + 4 + 1 + 8, &n);
  if (s) return s;
  char what[96], why[256];
  for (size_t i = 0; i < n; i++) {
    size_t at = b->off;
    hearth_colmap_image *im = rc_vec_push(v, n);
    rc_where *wh = rc_vec_push(w, n);
    if (!im || !wh) return bn_fail(b, at, HEARTH_E_NOMEM, "out of memory for images");
    snprintf(what, sizeof what, "the id of image record %zu", i);
    if ((s = bn_u32(b, what, &im->id))) return s;
    double pose[7];
    snprintf(what, sizeof what, "the pose of image %u (7 doubles)", (unsigned)im->id);
    if ((s = bn_doubles(b, 7, what, pose))) return s;
    memcpy(im->q_cam_from_world, pose, sizeof im->q_cam_from_world);
    memcpy(im->t_cam_from_world, pose + 4, sizeof im->t_cam_from_world);
    size_t at_cam = b->off;
    snprintf(what, sizeof what, "the camera id of image %u", (unsigned)im->id);
    if ((s = bn_u32(b, what, &im->camera_id))) return s;
    /* the name, NUL-terminated */
    size_t at_name = b->off, k = 0;
    for (;;) {
      if (b->off >= b->len)
        return bn_fail(b, at_name, HEARTH_E_PARSE, "truncated: the name of image %u has no NUL end",
                       (unsigned)im->id);
      uint8_t ch = b->data[b->off++];
      if (!ch) break;
      if (k + 1 >= sizeof im->name)
        return bn_fail(b, at_name, HEARTH_E_LIMIT, "image %u: name longer than %zu bytes",
                       (unsigned)im->id, sizeof im->name - 1);
      if (ch < 0x20 || ch == 0x7f)
        return bn_fail(b, b->off - 1, HEARTH_E_PARSE,
                       "image %u: control character in the image name", (unsigned)im->id);
      im->name[k++] = (char)ch;
    }
    im->name[k] = 0;
    if (!k) return bn_fail(b, at_name, HEARTH_E_PARSE, "image %u: empty name", (unsigned)im->id);
    if (!hearth_colmap_find_camera(m, im->camera_id))
      return bn_fail(b, at_cam, HEARTH_E_INCONSISTENT,
                     "image %u (%s): camera %u is not in the model's cameras", (unsigned)im->id,
                     im->name, (unsigned)im->camera_id);
    if (rc_image_pose(im, why, sizeof why))
      return bn_fail(b, at + 4, HEARTH_E_RANGE, "image %u: %s", (unsigned)im->id, why);
    uint64_t np;
    size_t at_np = b->off;
    snprintf(what, sizeof what, "the 2-D point count of image %u", (unsigned)im->id);
    if ((s = bn_u64(b, what, &np))) return s;
    if (np > (b->len - b->off) / 24)
      return bn_fail(b, at_np, HEARTH_E_PARSE,
                     "image %u: %llu 2-D points announced, but the %zu bytes left hold at most %zu",
                     (unsigned)im->id, (unsigned long long)np, b->len - b->off,
                     (b->len - b->off) / 24);
    im->n_points2d = (size_t)np;
    const uint8_t *p = b->data + b->off;
    b->off += 24 * im->n_points2d;
    for (size_t j = 0; j < im->n_points2d; j++) {
      double x = led(p + 24 * j), y = led(p + 24 * j + 8);
      if (!isfinite(x) || !isfinite(y))
        return bn_fail(b, (size_t)(p - b->data) + 24 * j, HEARTH_E_RANGE,
                       "image %u: 2-D point %zu is not finite", (unsigned)im->id, j);
      if (le64(p + 24 * j + 16) != UINT64_MAX) im->n_observations++;
    }
    *wh = (rc_where){im->id, at};
  }
  return HEARTH_OK;
}

/* ---- points3D.bin ------------------------------------------------------------------ */
static hearth_status bn_points(bn *b, const hearth_colmap_model *m, rc_vec *v, rc_vec *w) {
  size_t n;
  hearth_status s = bn_count(b, "3-D points", 51, &n);
  if (s) return s;
  char what[96], why[256];
  for (size_t i = 0; i < n; i++) {
    size_t at = b->off;
    hearth_colmap_point *pt = rc_vec_push(v, n);
    rc_where *wh = rc_vec_push(w, n);
    if (!pt || !wh) return bn_fail(b, at, HEARTH_E_NOMEM, "out of memory for 3-D points");
    const uint8_t *p = NULL;
    snprintf(what, sizeof what, "3-D point record %zu (43 bytes)", i);
    if ((s = bn_take(b, 43, what, &p))) return s;
    pt->id = le64(p);
    for (int k = 0; k < 3; k++) pt->xyz[k] = led(p + 8 + 8 * k);
    memcpy(pt->rgb, p + 32, 3);
    pt->error = led(p + 35);
    if (pt->id == UINT64_MAX)
      return bn_fail(b, at, HEARTH_E_RANGE, "3-D point id 2^64-1 is COLMAP's 'no point'");
    for (int k = 0; k < 3; k++)
      if (!isfinite(pt->xyz[k]))
        return bn_fail(b, at + 8, HEARTH_E_RANGE, "point %llu: coordinates not finite",
                       (unsigned long long)pt->id);
    if (!isfinite(pt->error))
      return bn_fail(b, at + 35, HEARTH_E_RANGE, "point %llu: error not finite",
                     (unsigned long long)pt->id);
    uint64_t tl;
    size_t at_tl = b->off;
    snprintf(what, sizeof what, "the track length of point %llu", (unsigned long long)pt->id);
    if ((s = bn_u64(b, what, &tl))) return s;
    if (tl > (b->len - b->off) / 8)
      return bn_fail(
          b, at_tl, HEARTH_E_PARSE,
          "point %llu: track of %llu elements announced, but the %zu bytes left hold at most %zu",
          (unsigned long long)pt->id, (unsigned long long)tl, b->len - b->off,
          (b->len - b->off) / 8);
    pt->track_length = (size_t)tl;
    const uint8_t *t = b->data + b->off;
    for (size_t j = 0; j < pt->track_length; j++)
      if (rc_track_check(m, le32(t + 8 * j), le32(t + 8 * j + 4), why, sizeof why))
        return bn_fail(b, b->off + 8 * j, HEARTH_E_INCONSISTENT, "point %llu: %s",
                       (unsigned long long)pt->id, why);
    b->off += 8 * pt->track_length;
    *wh = (rc_where){pt->id, at};
  }
  return HEARTH_OK;
}

hearth_status rc_parse_binary(hearth_colmap_file which, const uint8_t *data, size_t len,
                              const char *name, hearth_colmap_model *m, hearth_err *err) {
  static const size_t k_size[3] = {sizeof(hearth_colmap_camera), sizeof(hearth_colmap_image),
                                   sizeof(hearth_colmap_point)};
  bn b = {.data = data, .len = len, .name = name, .err = err};
  rc_vec v = {.size = k_size[which]}, w = {.size = sizeof(rc_where)};
  hearth_status s;
  if (which == HEARTH_COLMAP_CAMERAS) s = bn_cameras(&b, &v, &w);
  else if (which == HEARTH_COLMAP_IMAGES) s = bn_images(&b, m, &v, &w);
  else s = bn_points(&b, m, &v, &w);
  if (!s && b.off != b.len)
    s = bn_fail(&b, b.off, HEARTH_E_PARSE, "%zu bytes after the last record", b.len - b.off);
  return rc_finish(m, which, &v, &w, s, name, 1, err);
}
