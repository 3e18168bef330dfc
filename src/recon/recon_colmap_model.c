/* A COLMAP sparse model in memory: reading a model folder (format chosen by
 * the files present), the per-file parse entry, sorting by id, lookups, and
 * the checks shared by the text and binary readers. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "recon/recon_internal.h"

void *rc_vec_push(rc_vec *v, size_t max) {
  if (v->n >= max) return NULL;
  if (v->n == v->cap) {
    size_t cap = v->cap ? v->cap * 2 : 16;
    if (cap > max) cap = max;
    size_t bytes;
    if (!hearth_mul_size(cap, v->size, &bytes)) return NULL;
    void *p = realloc(v->data, bytes);
    if (!p) return NULL;
    v->data = p;
    v->cap = cap;
  }
  char *slot = (char *)v->data + v->n * v->size;
  memset(slot, 0, v->size);
  v->n++;
  return slot;
}

typedef struct rc_key {
  uint64_t id;
  size_t i;
} rc_key;

static int rc_key_cmp(const void *pa, const void *pb) {
  const rc_key *x = pa, *y = pb;
  if (x->id != y->id) return x->id < y->id ? -1 : 1;
  return (x->i > y->i) - (x->i < y->i);
}

int rc_sort_by_id(void *records, size_t n, size_t size, const rc_where *w, uint64_t *dup_id,
                  size_t *a, size_t *b) {
  if (n < 2) return 1;
  rc_key *k = hearth_alloc_array(n, sizeof *k);
  char *tmp = hearth_alloc_array(n, size);
  if (!k || !tmp) {
    free(k);
    free(tmp);
    return -1;
  }
  for (size_t i = 0; i < n; i++) k[i] = (rc_key){w[i].id, i};
  qsort(k, n, sizeof *k, rc_key_cmp);
  for (size_t i = 1; i < n; i++)
    if (k[i].id == k[i - 1].id) {
      size_t p = w[k[i - 1].i].pos, q = w[k[i].i].pos;
      *dup_id = k[i].id;
      *a = p < q ? p : q;
      *b = p < q ? q : p;
      free(k);
      free(tmp);
      return 0;
    }
  for (size_t i = 0; i < n; i++) memcpy(tmp + i * size, (char *)records + k[i].i * size, size);
  memcpy(records, tmp, n * size);
  free(k);
  free(tmp);
  return 1;
}

int rc_image_pose(hearth_colmap_image *im, char *why, size_t whysz) {
  const double *q = im->q_cam_from_world, *t = im->t_cam_from_world;
  for (int i = 0; i < 4; i++)
    if (!isfinite(q[i])) {
      snprintf(why, whysz, "quaternion component %d is not finite", i + 1);
      return -1;
    }
  for (int i = 0; i < 3; i++)
    if (!isfinite(t[i])) {
      snprintf(why, whysz, "translation component %d is not finite", i + 1);
      return -1;
    }
  double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(fabs(norm - 1.0) <= 1e-3)) {
    snprintf(why, whysz, "quaternion (%.17g, %.17g, %.17g, %.17g) has norm %.9g, expected 1", q[0],
             q[1], q[2], q[3], norm);
    return -1;
  }
  double w = q[0] / norm, x = q[1] / norm, y = q[2] / norm, z = q[3] / norm;
  /* R_cam_from_world of the Hamilton quaternion (w, x, y, z) */
  hearth_rigid cw;
  cw.R[0] = 1 - 2 * (y * y + z * z);
  cw.R[1] = 2 * (x * y - w * z);
  cw.R[2] = 2 * (x * z + w * y);
  cw.R[3] = 2 * (x * y + w * z);
  cw.R[4] = 1 - 2 * (x * x + z * z);
  cw.R[5] = 2 * (y * z - w * x);
  cw.R[6] = 2 * (x * z - w * y);
  cw.R[7] = 2 * (y * z + w * x);
  cw.R[8] = 1 - 2 * (x * x + y * y);
  memcpy(cw.t, t, sizeof cw.t);
  hearth_rigid_inverse(&cw, &im->T_world_from_cam);
  return 0;
}

hearth_status rc_camera_finish(hearth_colmap_camera *cam, hearth_err *err) {
  return hearth_colmap_camera_convert(cam->model_id, cam->params, cam->n_params, cam->width,
                                      cam->height, &cam->camera, err);
}

static void rc_model_set(hearth_colmap_model *m, hearth_colmap_file which, rc_vec *v) {
  switch (which) {
    case HEARTH_COLMAP_CAMERAS:
      free(m->cameras);
      m->cameras = v->data;
      m->n_cameras = v->n;
      break;
    case HEARTH_COLMAP_IMAGES:
      free(m->images);
      m->images = v->data;
      m->n_images = v->n;
      break;
    case HEARTH_COLMAP_POINTS3D:
      free(m->points);
      m->points = v->data;
      m->n_points = v->n;
      break;
  }
  memset(v, 0, sizeof *v);
}

hearth_status rc_finish(hearth_colmap_model *m, hearth_colmap_file which, rc_vec *v, rc_vec *w,
                        hearth_status s, const char *name, int binary, hearth_err *err) {
  static const char *const k_kind[3] = {"camera", "image", "3-D point"};
  if (!s) {
    size_t a, b;
    uint64_t id;
    int r = rc_sort_by_id(v->data, v->n, v->size, w->data, &id, &a, &b);
    if (r < 0) s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory sorting", name);
    else if (r == 0 && binary)
      s = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                         "%s: byte offset %zu: duplicate %s id %llu (also at byte offset %zu)",
                         name, b, k_kind[which], (unsigned long long)id, a);
    else if (r == 0)
      s = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                         "%s:%zu: duplicate %s id %llu (also on line %zu)", name, b, k_kind[which],
                         (unsigned long long)id, a);
  }
  free(w->data);
  memset(w, 0, sizeof *w);
  if (s) {
    free(v->data);
    memset(v, 0, sizeof *v);
  }
  rc_model_set(m, which, v);
  return s;
}

void hearth_colmap_model_free(hearth_colmap_model *m) {
  if (!m) return;
  free(m->cameras);
  free(m->images);
  free(m->points);
  memset(m, 0, sizeof *m);
}

const hearth_colmap_camera *hearth_colmap_find_camera(const hearth_colmap_model *m, uint32_t id) {
  size_t lo = 0, hi = m->n_cameras;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (m->cameras[mid].id == id) return &m->cameras[mid];
    if (m->cameras[mid].id < id) lo = mid + 1;
    else hi = mid;
  }
  return NULL;
}

const hearth_colmap_image *hearth_colmap_find_image(const hearth_colmap_model *m, uint32_t id) {
  size_t lo = 0, hi = m->n_images;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (m->images[mid].id == id) return &m->images[mid];
    if (m->images[mid].id < id) lo = mid + 1;
    else hi = mid;
  }
  return NULL;
}

int rc_track_check(const hearth_colmap_model *m, uint32_t image_id, uint32_t point2d, char *why,
                   size_t whysz) {
  const hearth_colmap_image *im = hearth_colmap_find_image(m, image_id);
  if (!im) {
    snprintf(why, whysz, "track names image %u, which is not in the model", (unsigned)image_id);
    return -1;
  }
  if (point2d >= im->n_points2d) {
    snprintf(why, whysz, "track names 2-D point %u of image %u, which has %zu", (unsigned)point2d,
             (unsigned)image_id, im->n_points2d);
    return -1;
  }
  return 0;
}

hearth_status hearth_colmap_parse(hearth_colmap_file which, hearth_colmap_format format,
                                  const uint8_t *data, size_t len, const char *name,
                                  hearth_colmap_model *m, hearth_err *err) {
  if (!m || (!data && len) || which < HEARTH_COLMAP_CAMERAS || which > HEARTH_COLMAP_POINTS3D)
    return hearth_err_set(err, HEARTH_E_ARG, "hearth_colmap_parse: invalid arguments");
  if (!name) name = "COLMAP model";
  m->format = format;
  if (format == HEARTH_COLMAP_BINARY) return rc_parse_binary(which, data, len, name, m, err);
  if (format == HEARTH_COLMAP_TEXT) return rc_parse_text(which, data, len, name, m, err);
  return hearth_err_set(err, HEARTH_E_ARG, "%s: unknown COLMAP format %d", name, (int)format);
}

#define RC_MAX_FILE ((size_t)1 << 30)

static const char *const k_files[3] = {"cameras", "images", "points3D"};

hearth_status hearth_colmap_read(const char *dir, hearth_colmap_model *m, hearth_err *err) {
  if (!dir || !m) return hearth_err_set(err, HEARTH_E_ARG, "hearth_colmap_read: NULL argument");
  memset(m, 0, sizeof *m);
  char path[3][2][4096];
  int have[3][2];
  for (int f = 0; f < 3; f++)
    for (int b = 0; b < 2; b++) {
      char file[32];
      snprintf(file, sizeof file, "%s.%s", k_files[f], b ? "bin" : "txt");
      if (hearth_path_join(path[f][b], sizeof path[f][b], dir, file))
        return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", dir);
      have[f][b] = hearth_path_exists(path[f][b]);
    }
  int binary;
  if (have[0][1] && have[1][1] && have[2][1]) {
    binary = 1;
  } else if (have[0][0] && have[1][0] && have[2][0]) {
    binary = 0;
  } else {
    if (!hearth_path_exists(dir))
      return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no such folder", dir);
    char missing[256] = "";
    int b = have[0][1] || have[1][1] || have[2][1];
    for (int f = 0; f < 3; f++)
      if (!have[f][b]) {
        size_t n = strlen(missing);
        snprintf(missing + n, sizeof missing - n, "%s%s.%s", n ? ", " : "", k_files[f],
                 b ? "bin" : "txt");
      }
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "%s: not a COLMAP sparse model: %s missing (a model is cameras, images "
                          "and points3D, all .txt or all .bin)",
                          dir, missing);
  }
  for (int f = 0; f < 3; f++) {
    uint8_t *data = NULL;
    size_t size = 0;
    hearth_status s = hearth_read_file(path[f][binary], RC_MAX_FILE, &data, &size, err);
    if (!s)
      s = hearth_colmap_parse((hearth_colmap_file)f,
                              binary ? HEARTH_COLMAP_BINARY : HEARTH_COLMAP_TEXT, data, size,
                              path[f][binary], m, err);
    free(data);
    if (s) {
      hearth_colmap_model_free(m);
      return s;
    }
  }
  return HEARTH_OK;
}
