/* Reading hearth's LIBERO-layout collection files (docs/simulation.md):
 * data's attributes, then one demo at a time with every dataset's shape
 * checked against the demo's length and the file's image size. */
#include <hdf5.h>
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "export/export_internal.h"

static int str_attr(hid_t obj, const char *name, char *buf, size_t n) {
  if (H5Aexists(obj, name) <= 0) return 0;
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  hid_t t = H5Aget_type(a);
  int ok = 0;
  if (H5Tget_class(t) == H5T_STRING && !H5Tis_variable_str(t)) {
    size_t sz = H5Tget_size(t);
    char *tmp = calloc(1, sz + 1);
    if (tmp && H5Aread(a, t, tmp) >= 0) ok = snprintf(buf, n, "%s", tmp) < (int)n;
    free(tmp);
  } else if (H5Tget_class(t) == H5T_STRING) {
    /* a variable-length string (h5py writes str so), ASCII or UTF-8 */
    char *s = NULL;
    hid_t mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, H5T_VARIABLE);
    H5Tset_cset(mt, H5Tget_cset(t));
    if (H5Aread(a, mt, &s) >= 0 && s) ok = snprintf(buf, n, "%s", s) < (int)n;
    if (s) H5free_memory(s);
    H5Tclose(mt);
  }
  H5Tclose(t);
  H5Aclose(a);
  return ok;
}

static int int_attr(hid_t obj, const char *name, int64_t *v) {
  if (H5Aexists(obj, name) <= 0) return 0;
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  long long x = 0;
  int ok = H5Aread(a, H5T_NATIVE_LLONG, &x) >= 0;
  H5Aclose(a);
  *v = x;
  return ok;
}

/* obs/thermal_state of group obs: its column count (0 when absent, -1 when
 * it is not float (T, 1..EX_STATS_MAX_DIM) with region_names fitting names) */
static int thermal_state_shape(hid_t obs, hsize_t *rows, char *names, size_t n) {
  if (H5Lexists(obs, "thermal_state", H5P_DEFAULT) <= 0) return 0;
  hid_t d = H5Dopen2(obs, "thermal_state", H5P_DEFAULT);
  if (d < 0) return -1;
  hid_t sp = H5Dget_space(d), t = H5Dget_type(d);
  hsize_t dims[2] = {0, 0};
  int ok = H5Sget_simple_extent_ndims(sp) == 2 && H5Sget_simple_extent_dims(sp, dims, NULL) == 2 &&
           H5Tget_class(t) == H5T_FLOAT && dims[1] >= 1 && dims[1] <= EX_STATS_MAX_DIM &&
           str_attr(d, "region_names", names, n);
  H5Tclose(t), H5Sclose(sp), H5Dclose(d);
  if (rows) *rows = dims[0];
  return ok ? (int)dims[1] : -1;
}

static void copy_str(char *dst, size_t n, json_t *v) {
  const char *s = json_string_value(v);
  snprintf(dst, n, "%s", s ? s : "");
}

hearth_status ex_source_open(const char *path, ex_source *s, hearth_err *err) {
  memset(s, 0, sizeof *s);
  s->file_id = -1;
  snprintf(s->path, sizeof s->path, "%s", path);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  /* a FIFO or a directory would block or confuse HDF5: regular files only */
  hearth_status rs = hearth_check_regular(path, err);
  if (rs) return rs;
  hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open as HDF5", path);
  s->file_id = f;
  hid_t data = H5Lexists(f, "data", H5P_DEFAULT) > 0 ? H5Gopen2(f, "data", H5P_DEFAULT) : -1;
  char ea[4096], order[64];
  int ok = data >= 0 && str_attr(data, "env_args", ea, sizeof ea) &&
           int_attr(data, "num_demos", &s->num_demos);
  int order_ok = ok && str_attr(data, "image_row_order", order, sizeof order);
  if (data >= 0) H5Gclose(data);
  if (!ok) {
    ex_source_close(s);
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "%s: expected group data with attributes env_args and num_demos", path);
  }
  if (!order_ok || strcmp(order, "opengl_bottom_row_first") != 0) {
    ex_source_close(s);
    return hearth_err_set(
        err, HEARTH_E_UNSUPPORTED,
        "%s: data@image_row_order: expected \"opengl_bottom_row_first\", found \"%s\"", path,
        order_ok ? order : "(none)");
  }
  json_error_t je;
  json_t *j = json_loads(ea, 0, &je);
  json_t *kw = j ? json_object_get(j, "env_kwargs") : NULL;
  const char *env = j ? json_string_value(json_object_get(j, "env_name")) : NULL;
  json_t *seed = json_object_get(kw, "seed"), *freq = json_object_get(kw, "control_freq");
  json_t *hh = json_object_get(kw, "camera_heights"), *ww = json_object_get(kw, "camera_widths");
  int good = env && strncmp(env, "hearth_", 7) == 0 && strlen(env + 7) < sizeof s->task &&
             json_is_integer(seed) && json_is_integer(freq) && json_is_integer(hh) &&
             json_is_integer(ww) && json_integer_value(hh) == json_integer_value(ww) &&
             json_integer_value(hh) >= 1 && json_integer_value(hh) <= 4096 &&
             json_integer_value(freq) >= 1 && json_integer_value(freq) <= 10000;
  if (good) {
    snprintf(s->task, sizeof s->task, "%s", env + 7);
    s->seed = json_integer_value(seed);
    s->fps = (int)json_integer_value(freq);
    s->size = (int)json_integer_value(hh);
    copy_str(s->asset_source, sizeof s->asset_source, json_object_get(kw, "asset_source"));
    copy_str(s->renderer, sizeof s->renderer, json_object_get(kw, "renderer"));
  }
  json_decref(j);
  if (!good) {
    ex_source_close(s);
    return hearth_err_set(
        err, HEARTH_E_PARSE,
        "%s: data@env_args: expected JSON with env_name \"hearth_<task>\" and env_kwargs "
        "seed, control_freq, camera_heights = camera_widths (integers)",
        path);
  }
  if (s->num_demos < 0 || s->num_demos > 10000000) {
    ex_source_close(s);
    return hearth_err_set(err, HEARTH_E_RANGE, "%s: data@num_demos = %lld", path,
                          (long long)s->num_demos);
  }
  /* the thermal state's columns, from the first demo */
  if (s->num_demos > 0 && H5Lexists(f, "data/demo_0", H5P_DEFAULT) > 0 &&
      H5Lexists(f, "data/demo_0/obs", H5P_DEFAULT) > 0) {
    hid_t ob = H5Gopen2(f, "data/demo_0/obs", H5P_DEFAULT);
    s->th_dim = ob >= 0 ? thermal_state_shape(ob, NULL, s->th_names, sizeof s->th_names) : 0;
    if (ob >= 0) H5Gclose(ob);
    if (s->th_dim < 0) {
      ex_source_close(s);
      return hearth_err_set(err, HEARTH_E_SIZE,
                            "%s: data/demo_0/obs/thermal_state: expected float (T, 1..%d) with "
                            "attribute region_names",
                            path, EX_STATS_MAX_DIM);
    }
  }
  return HEARTH_OK;
}

void ex_source_close(ex_source *s) {
  if (s->file_id >= 0) H5Fclose((hid_t)s->file_id);
  s->file_id = -1;
}

/* dataset `name` of group g with exactly the dims `want` (rank n); read as
 * `mem` into a new buffer of `elem` bytes per value */
static hearth_status read_array(const ex_source *s, hid_t g, const char *demo, const char *name,
                                int n, const hsize_t *want, hid_t mem, size_t elem, void **out,
                                hearth_err *err) {
  *out = NULL;
  if (H5Lexists(g, name, H5P_DEFAULT) <= 0)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: data/%s/%s is missing", s->path, demo,
                          name);
  hid_t d = H5Dopen2(g, name, H5P_DEFAULT);
  if (d < 0)
    return hearth_err_set(err, HEARTH_E_IO, "%s: data/%s/%s: cannot open", s->path, demo, name);
  hid_t sp = H5Dget_space(d);
  hsize_t dims[4] = {0, 0, 0, 0};
  int rank = H5Sget_simple_extent_ndims(sp);
  int same = rank == n && H5Sget_simple_extent_dims(sp, dims, NULL) == n;
  size_t count = 1;
  for (int k = 0; k < n && same; k++) {
    same = dims[k] == want[k];
    if (same && !hearth_mul_size(count, (size_t)dims[k], &count)) same = 0;
  }
  H5Sclose(sp);
  hearth_status st = HEARTH_OK;
  if (!same) {
    char shape[96];
    int m = snprintf(shape, sizeof shape, "(");
    for (int k = 0; k < n && m < 80; k++)
      m += snprintf(shape + m, sizeof shape - (size_t)m, k ? ", %llu" : "%llu",
                    (unsigned long long)want[k]);
    snprintf(shape + m, sizeof shape - (size_t)m, ")");
    st = hearth_err_set(err, HEARTH_E_SIZE, "%s: data/%s/%s: expected shape %s", s->path, demo,
                        name, shape);
  } else {
    *out = hearth_alloc_array(count ? count : 1, elem);
    if (!*out) st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: data/%s/%s", s->path, demo, name);
    else if (H5Dread(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, *out) < 0)
      st = hearth_err_set(err, HEARTH_E_IO, "%s: data/%s/%s: read failed", s->path, demo, name);
    if (st) free(*out), *out = NULL;
  }
  H5Dclose(d);
  return st;
}

hearth_status ex_demo_read(const ex_source *s, int64_t k, int want_thermal, ex_demo *d,
                           hearth_err *err) {
  memset(d, 0, sizeof *d);
  char demo[64];
  snprintf(demo, sizeof demo, "demo_%lld", (long long)k);
  hid_t f = (hid_t)s->file_id;
  char path[96];
  snprintf(path, sizeof path, "data/%s", demo);
  hid_t g = H5Lexists(f, "data", H5P_DEFAULT) > 0 && H5Lexists(f, path, H5P_DEFAULT) > 0
                ? H5Gopen2(f, path, H5P_DEFAULT)
                : -1;
  if (g < 0)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: data/%s is missing", s->path, demo);
  int64_t T = 0;
  hearth_status st = HEARTH_OK;
  if (!int_attr(g, "num_samples", &T) || !int_attr(g, "layout", &d->layout) ||
      !int_attr(g, "instruction_index", &d->instruction_index) ||
      !str_attr(g, "language_instruction", d->instruction, sizeof d->instruction))
    st =
        hearth_err_set(err, HEARTH_E_NOT_FOUND,
                       "%s: data/%s: expected attributes num_samples, layout, instruction_index and "
                       "language_instruction (a string under 1024 bytes)",
                       s->path, demo);
  else if (T < 1 || T > 10000000)
    st = hearth_err_set(err, HEARTH_E_RANGE, "%s: data/%s@num_samples = %lld", s->path, demo,
                        (long long)T);
  d->T = (size_t)T;
  hid_t obs = -1;
  if (!st) {
    obs = H5Lexists(g, "obs", H5P_DEFAULT) > 0 ? H5Gopen2(g, "obs", H5P_DEFAULT) : -1;
    if (obs < 0)
      st = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: data/%s/obs is missing", s->path, demo);
  }
  char od[96];
  snprintf(od, sizeof od, "%s/obs", demo);
  hsize_t S = (hsize_t)s->size;
  const hsize_t a7[2] = {(hsize_t)T, 7}, a3[2] = {(hsize_t)T, 3}, a2[2] = {(hsize_t)T, 2};
  const hsize_t im[4] = {(hsize_t)T, S, S, 3};
  /* the datasets read, in this order (the last only with want_thermal) */
  const struct {
    int in_obs, u8, rank;
    const char *name;
    const hsize_t *dims;
  } arrays[7] = {
      {0, 0, 2, "actions", a7},
      {1, 0, 2, "ee_pos", a3},
      {1, 0, 2, "ee_ori", a3},
      {1, 0, 2, "gripper_states", a2},
      {1, 1, 4, "agentview_rgb", im},
      {1, 1, 4, "eye_in_hand_rgb", im},
      {1, 1, 4, "agentview_thermal", im},
  };
  void *buf[7] = {NULL};
  for (int a = 0; a < (want_thermal ? 7 : 6) && !st; a++)
    st = read_array(s, arrays[a].in_obs ? obs : g, arrays[a].in_obs ? od : demo, arrays[a].name,
                    arrays[a].rank, arrays[a].dims,
                    arrays[a].u8 ? H5T_NATIVE_UINT8 : H5T_NATIVE_DOUBLE,
                    arrays[a].u8 ? 1 : sizeof(double), &buf[a], err);
  d->actions = buf[0], d->ee_pos = buf[1], d->ee_ori = buf[2], d->gripper = buf[3];
  d->rgb = buf[4], d->wrist = buf[5], d->thermal = buf[6];
  /* the thermal state: the columns and names of demo_0 in every demo */
  if (!st) {
    char names[sizeof s->th_names];
    hsize_t rows = 0;
    int dim = thermal_state_shape(obs, &rows, names, sizeof names);
    if (dim != s->th_dim || (dim > 0 && (rows != (hsize_t)T || strcmp(names, s->th_names) != 0)))
      st = hearth_err_set(err, HEARTH_E_INCONSISTENT, "%s: data/%s/obs/thermal_state: expected %s",
                          s->path, demo,
                          s->th_dim ? "the (T, R) shape and region_names of demo_0"
                                    : "none (demo_0 has none)");
    else if (dim > 0 && want_thermal) {
      const hsize_t ts[2] = {(hsize_t)T, (hsize_t)dim};
      void *b = NULL;
      st = read_array(s, obs, od, "thermal_state", 2, ts, H5T_NATIVE_FLOAT, sizeof(float), &b, err);
      d->thermal_state = b;
    }
  }
  if (obs >= 0) H5Gclose(obs);
  H5Gclose(g);
  return st;
}

void ex_demo_free(ex_demo *d) {
  free(d->actions), free(d->ee_pos), free(d->ee_ori), free(d->gripper);
  free(d->rgb), free(d->wrist), free(d->thermal), free(d->thermal_state);
  memset(d, 0, sizeof *d);
}
