/* COLMAP's camera models as a table (id, name, parameter count, how the
 * parameters map onto hearth's camera) and the conversion of one camera. */
#include <math.h>
#include <string.h>

#include "hearth/recon.h"

/* where hearth's fx, fy, cx, cy, k1, k2, p1, p2, k3 sit in the model's
 * parameters (-1: zero; fy = -1 means fy = fx); the parameters from
 * `must_be_zero` on must all be 0 */
typedef struct colmap_model_row {
  const char *name;
  int n_params;
  int supported;
  int fx, fy, cx, cy, dist[5];
  int must_be_zero;
  const char *why; /* unsupported: what the model is */
} colmap_model_row;

static const colmap_model_row k_models[] = {
    /* 0 */ {"SIMPLE_PINHOLE", 3, 1, 0, -1, 1, 2, {-1, -1, -1, -1, -1}, 3, NULL},
    /* 1 */ {"PINHOLE", 4, 1, 0, 1, 2, 3, {-1, -1, -1, -1, -1}, 4, NULL},
    /* 2 */ {"SIMPLE_RADIAL", 4, 1, 0, -1, 1, 2, {3, -1, -1, -1, -1}, 4, NULL},
    /* 3 */ {"RADIAL", 5, 1, 0, -1, 1, 2, {3, 4, -1, -1, -1}, 5, NULL},
    /* 4 */ {"OPENCV", 8, 1, 0, 1, 2, 3, {4, 5, 6, 7, -1}, 8, NULL},
    /* 5 */ {"OPENCV_FISHEYE", 8, 0, 0, 0, 0, 0, {0}, 0, "an equidistant fisheye model"},
    /* 6 */ {"FULL_OPENCV", 12, 1, 0, 1, 2, 3, {4, 5, 6, 7, 8}, 9, NULL},
    /* 7 */ {"FOV", 5, 0, 0, 0, 0, 0, {0}, 0, "the field-of-view distortion model"},
    /* 8 */ {"SIMPLE_RADIAL_FISHEYE", 4, 0, 0, 0, 0, 0, {0}, 0, "a fisheye model"},
    /* 9 */ {"RADIAL_FISHEYE", 5, 0, 0, 0, 0, 0, {0}, 0, "a fisheye model"},
    /* 10 */ {"THIN_PRISM_FISHEYE", 12, 0, 0, 0, 0, 0, {0}, 0, "a fisheye model with thin-prism terms"},
    /* 11 */
    {"RAD_TAN_THIN_PRISM_FISHEYE",
     16,
     0,
     0,
     0,
     0,
     0,
     {0},
     0,
     "a fisheye model with thin-prism terms"},
    /* 12 */ {"SIMPLE_DIVISION", 4, 0, 0, 0, 0, 0, {0}, 0, "the division distortion model"},
    /* 13 */ {"DIVISION", 5, 0, 0, 0, 0, 0, {0}, 0, "the division distortion model"},
    /* 14 */ {"SIMPLE_FISHEYE", 3, 0, 0, 0, 0, 0, {0}, 0, "a fisheye model"},
    /* 15 */ {"FISHEYE", 4, 0, 0, 0, 0, 0, {0}, 0, "a fisheye model"},
    /* 16 */ {"EUCM", 6, 0, 0, 0, 0, 0, {0}, 0, "the unified camera model"},
    /* 17 */ {"EQUIRECTANGULAR", 2, 0, 0, 0, 0, 0, {0}, 0, "a spherical projection"},
};
#define N_MODELS ((int)(sizeof k_models / sizeof k_models[0]))

static const colmap_model_row *row_of(int id) {
  return id >= 0 && id < N_MODELS ? &k_models[id] : NULL;
}

const char *hearth_colmap_model_name(int model_id) {
  const colmap_model_row *r = row_of(model_id);
  return r ? r->name : NULL;
}

int hearth_colmap_model_n_params(int model_id) {
  const colmap_model_row *r = row_of(model_id);
  return r ? r->n_params : -1;
}

int hearth_colmap_model_id(const char *name) {
  if (!name) return -1;
  for (int i = 0; i < N_MODELS; i++)
    if (!strcmp(name, k_models[i].name)) return i;
  return -1;
}

hearth_status hearth_colmap_camera_convert(int model_id, const double *params, size_t n_params,
                                           uint64_t width, uint64_t height, hearth_camera *cam,
                                           hearth_err *err) {
  const colmap_model_row *r = row_of(model_id);
  if (!r)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "unknown COLMAP camera model id %d", model_id);
  if (!r->supported)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "model %s (id %d) is %s; hearth's camera is a pinhole with "
                          "Brown-Conrady distortion (k1 k2 p1 p2 k3) and cannot represent it",
                          r->name, model_id, r->why);
  if (n_params != (size_t)r->n_params)
    return hearth_err_set(err, HEARTH_E_SIZE, "model %s takes %d parameters, found %zu", r->name,
                          r->n_params, n_params);
  for (size_t i = 0; i < n_params; i++)
    if (!isfinite(params[i]))
      return hearth_err_set(err, HEARTH_E_RANGE, "model %s: parameter %zu is not finite", r->name,
                            i + 1);
  if (width < 1 || width > 65536 || height < 1 || height > 65536)
    return hearth_err_set(err, HEARTH_E_RANGE, "size %llux%llu outside 1..65536 pixels per side",
                          (unsigned long long)width, (unsigned long long)height);
  for (int i = r->must_be_zero; i < r->n_params; i++)
    if (params[i] != 0.0)
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                            "model %s with k4 k5 k6 = (%.17g, %.17g, %.17g) is the rational "
                            "model, not representable by hearth's 5-parameter Brown-Conrady camera "
                            "(only k4 = k5 = k6 = 0 is)",
                            r->name, params[9], params[10], params[11]);
  hearth_camera c;
  memset(&c, 0, sizeof c);
  c.width = (int)width;
  c.height = (int)height;
  c.fx = params[r->fx];
  c.fy = r->fy < 0 ? params[r->fx] : params[r->fy];
  /* COLMAP: top-left pixel centre at (0.5, 0.5); hearth: at (0, 0) */
  c.cx = params[r->cx] - 0.5;
  c.cy = params[r->cy] - 0.5;
  for (int k = 0; k < 5; k++) c.dist[k] = r->dist[k] < 0 ? 0.0 : params[r->dist[k]];
  if (!(c.fx > 0) || !(c.fy > 0))
    return hearth_err_set(err, HEARTH_E_RANGE, "model %s: focal length must be > 0, found %.17g",
                          r->name, c.fx > 0 ? c.fy : c.fx);
  *cam = c;
  return HEARTH_OK;
}
