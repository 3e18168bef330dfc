/* Private to area recon: what the COLMAP readers (text, binary) share with
 * the model code, and the JSON writing helpers of the cameras document. */
#ifndef HEARTH_RECON_INTERNAL_H
#define HEARTH_RECON_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"
#include "hearth/image.h"
#include "hearth/recon.h"

/* A growing array of records of `size` bytes; zeroed to start. */
typedef struct rc_vec {
  void *data;
  size_t n, cap, size;
} rc_vec;
/* A zeroed slot at the end, or NULL when out of memory or past `max` records. */
void *rc_vec_push(rc_vec *v, size_t max);

/* Parsed records with where each came from (line or byte offset), before
 * they are sorted by id. */
typedef struct rc_where {
  uint64_t id;
  size_t pos;
} rc_where;

/* Sort records[0..n) (each `size` bytes; w[i] the id and position of
 * record i) by id. On a duplicate id returns 0 with the id and its two
 * positions in *a < *b and leaves the records unsorted; 1 otherwise; -1
 * without memory. */
int rc_sort_by_id(void *records, size_t n, size_t size, const rc_where *w, uint64_t *dup_id,
                  size_t *a, size_t *b);

/* Normalise the image's quaternion (refused when its norm is not finite or
 * differs from 1 by more than 1e-3) and fill T_world_from_cam. 0 on
 * success, else -1 with the reason in why. */
int rc_image_pose(hearth_colmap_image *im, char *why, size_t whysz);

/* Check a camera against m and convert it: message prefix is the caller's. */
hearth_status rc_camera_finish(hearth_colmap_camera *cam, hearth_err *err);

/* The end of a file's parse with status s: on success the records of v are
 * sorted by id (w: ids and positions, lines or byte offsets as `binary`
 * says) and a duplicate id is an error; then m's array for `which` is
 * replaced by them, or emptied on failure. v and w are released. */
hearth_status rc_finish(hearth_colmap_model *m, hearth_colmap_file which, rc_vec *v, rc_vec *w,
                        hearth_status s, const char *name, int binary, hearth_err *err);

hearth_status rc_parse_text(hearth_colmap_file which, const uint8_t *data, size_t len,
                            const char *name, hearth_colmap_model *m, hearth_err *err);
hearth_status rc_parse_binary(hearth_colmap_file which, const uint8_t *data, size_t len,
                              const char *name, hearth_colmap_model *m, hearth_err *err);

/* The check a point's track element gets against the model's images: 0 if
 * image `image_id` is in m and has a 2-D point `point2d`, else -1 with why. */
int rc_track_check(const hearth_colmap_model *m, uint32_t image_id, uint32_t point2d, char *why,
                   size_t whysz);

/* ---- cut-outs ------------------------------------------------------------- */
/* 1 if pixel p (index into width * height) of cut-out image c is the
 * object: the alpha channel when there is one, any non-zero channel else. */
int rc_cutout_at(const hearth_image *c, size_t p);

/* ---- a colour view for the photometric term (recon_photo.c) --------------- */
/* The grey level of a colour view at half resolution, band-passed inside
 * its cut-out (NaN off the object). */
typedef struct rc_photo {
  int w, h;
  float *img; /* w * h, owned */
} rc_photo;
/* Reads rgb_path (JPEG) and its cut-out cut_path, both of the colour
 * camera's size. */
hearth_status rc_photo_load(const char *rgb_path, const char *cut_path, const hearth_camera *rgb,
                            rc_photo *ph, hearth_err *err);
void rc_photo_free(rc_photo *ph); /* accepts a zeroed one */
/* The value at full-resolution pixel uv and, when grad is non-NULL, its
 * gradient per full-resolution pixel; 0 when that is off the object. */
int rc_photo_sample(const rc_photo *ph, const double uv[2], double *val, double grad[2]);

/* ---- JSON text (cameras document) ----------------------------------------- */
/* x in the shortest of %.15g/%.16g/%.17g that reads back to the same
 * double, with '.' whatever the locale and ".0" where it would read as an
 * integer; appended to b. */
void rc_json_real(hearth_strbuf *b, double x);
/* s as a JSON string literal. */
void rc_json_string(hearth_strbuf *b, const char *s);
/* x[0..n) as a JSON array "[a, b, ...]" of rc_json_real numbers */
void rc_json_reals(hearth_strbuf *b, const double *x, size_t n);

/* The inputs every depth-based reconstruction of an instance starts from
 * (recon_instance.c): its instance.json into *inst; with states NULL or
 * n_states 0, *states and *n_states become all the instance's states (their
 * names in own[HEARTH_MAX_STATES], which the caller keeps alive); and
 * calibration/factory.json into *fac. */
hearth_status recon_instance_inputs(const char *root, const char *instance,
                                    hearth_instance_doc *inst, const char **own,
                                    const char *const **states, size_t *n_states,
                                    hearth_factory_calib *fac, hearth_err *err);

#endif
