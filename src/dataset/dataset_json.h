/* dataset_json.h - private helpers shared by the JSON documents of a release:
 * strict typed getters that track the JSON path of the value being read,
 * and a deterministic pretty printer with shortest round-trip numbers.
 *
 * Error messages read "<file>: <json path>: <what was expected>", e.g.
 * "poses.json: views[3].T_world_from_cam[2][1]: expected a number, found a string". */
#ifndef HEARTH_DATASET_JSON_H
#define HEARTH_DATASET_JSON_H

#include <jansson.h>
#include <stddef.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/geom.h"

/* documents are small; anything larger than this is refused unread */
#define HJ_MAX_FILE_BYTES ((size_t)64 << 20)
/* tolerance for rotation blocks (orthonormality and det) */
#define HJ_ROT_TOL 1e-6
/* sane image sizes */
#define HJ_MAX_IMAGE_SIDE 65536

/* a reading context: the file name for messages, the error and the current
 * JSON path ("" at the top level) */
typedef struct hj_ctx {
  const char *file;
  hearth_err *err;
  size_t len;
  char path[512];
} hj_ctx;

void hj_init(hj_ctx *c, const char *file, hearth_err *err);
/* push ".key" / "[i]" onto the path; return a mark for hj_pop */
size_t hj_push_key(hj_ctx *c, const char *key);
size_t hj_push_index(hj_ctx *c, size_t i);
void hj_pop(hj_ctx *c, size_t mark);
/* record "<file>: <path>: <message>" and return s */
hearth_status hj_fail(hj_ctx *c, hearth_status s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* parse text into a JSON object (duplicates rejected; syntax errors carry
 * jansson's line and column). *root is owned by the caller (json_decref). */
hearth_status hj_load(hj_ctx *c, const char *text, size_t len, json_t **root);
/* read a file (size-limited) into a NUL-terminated buffer */
hearth_status hj_read_text(const char *path, char **text, size_t *len, hearth_err *err);

/* ---- value-level checks: the value's path is the current path ---------- */
const char *hj_type_name(const json_t *v);
hearth_status hj_number(hj_ctx *c, const json_t *v, double *out);
hearth_status hj_integer(hj_ctx *c, const json_t *v, long long lo, long long hi, long long *out);
hearth_status hj_string(hj_ctx *c, const json_t *v, char *buf, size_t bufsz);
hearth_status hj_bool(hj_ctx *c, const json_t *v, int *out);
hearth_status hj_array(hj_ctx *c, const json_t *v, size_t min, size_t max, size_t *n);
/* exactly n numbers */
hearth_status hj_vec(hj_ctx *c, const json_t *v, size_t n, double *out);
/* rows x cols nested numbers, row-major */
hearth_status hj_mat(hj_ctx *c, const json_t *v, size_t rows, size_t cols, double *out);
/* {"width","height","K","dist"} with the checks of docs/dataset.md */
hearth_status hj_camera(hj_ctx *c, const json_t *obj, hearth_camera *cam);
/* {"R","t"}; R must be a rotation */
hearth_status hj_rigid(hj_ctx *c, const json_t *obj, hearth_rigid *T);
/* a 4x4 homogeneous rigid transform */
hearth_status hj_mat4_rigid(hj_ctx *c, const json_t *v, hearth_rigid *T);

/* ---- key-level getters: push the key, check, pop ----------------------- */
/* the member or a NOT_FOUND error ("missing key") */
hearth_status hj_member(hj_ctx *c, const json_t *obj, const char *key, json_t **out);
hearth_status hj_get_number(hj_ctx *c, const json_t *obj, const char *key, double *out);
hearth_status hj_get_integer(hj_ctx *c, const json_t *obj, const char *key, long long lo,
                             long long hi, long long *out);
hearth_status hj_get_int(hj_ctx *c, const json_t *obj, const char *key, int lo, int hi, int *out);
hearth_status hj_get_string(hj_ctx *c, const json_t *obj, const char *key, char *buf, size_t bufsz);
hearth_status hj_get_object(hj_ctx *c, const json_t *obj, const char *key, json_t **out);
hearth_status hj_get_camera(hj_ctx *c, const json_t *obj, const char *key, hearth_camera *cam);
hearth_status hj_get_rigid(hj_ctx *c, const json_t *obj, const char *key, hearth_rigid *T);

/* ---- building and writing ----------------------------------------------- */
/* a real, or null for a non-finite value (so that validation of the written
 * text names the place) */
json_t *hj_real(double x);
/* a string, or null for text that is not UTF-8 (validation names the place) */
json_t *hj_str(const char *s);
json_t *hj_vec_new(const double *x, size_t n);
json_t *hj_mat_new(const double *x, size_t rows, size_t cols);
json_t *hj_camera_new(const hearth_camera *cam);
json_t *hj_rigid_new(const hearth_rigid *T);
json_t *hj_mat4_new(const hearth_rigid *T);
/* set a member, taking ownership of v; returns 0 on failure (v released) */
int hj_set(json_t *obj, const char *key, json_t *v);

/* pretty-print: 2-space indent, keys in insertion order, arrays without
 * objects inline when they fit ~100 columns, numbers in the shortest form
 * that parses back to the same double. *text is malloc'ed, NUL-terminated. */
hearth_status hj_dump(const json_t *root, char **text, size_t *len, hearth_err *err);

/* the check a writer runs on its own output before writing it */
typedef hearth_status (*hj_validate_fn)(const char *text, size_t len, const char *name,
                                        hearth_err *err);
/* dump root (consumed: decref'ed here, may be NULL after an allocation
 * failure), validate the text with the document's own parser, write it
 * atomically */
hearth_status hj_write_doc(const char *path, json_t *root, hj_validate_fn validate,
                           hearth_err *err);

/* ---- names ----------------------------------------------------------------- */
/* a view / frame name: 1..63 characters of [A-Za-z0-9_-] */
int hj_simple_name(const char *s);
/* a relative path without '..' components, empty components or backslashes */
int hj_relative_path_ok(const char *s);

#endif
