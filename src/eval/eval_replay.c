/* Replay policy: the actions (and states, for the determinism check) of
 * LIBERO-layout HDF5 demos, read with the HDF5 C library. */
#include <hdf5.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eval/eval_replay.h"

void eval_replay_free(eval_replay_file *r) {
  for (int i = 0; i < r->n; i++) free(r->demos[i].actions), free(r->demos[i].states);
  free(r->demos);
  memset(r, 0, sizeof *r);
}

static int h5_read_str_attr(hid_t obj, const char *name, char *buf, size_t n) {
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  hid_t t = H5Aget_type(a);
  int ok = 0;
  if (H5Tget_class(t) == H5T_STRING && !H5Tis_variable_str(t)) {
    size_t sz = H5Tget_size(t);
    char *tmp = calloc(1, sz + 1);
    if (tmp && H5Aread(a, t, tmp) >= 0) snprintf(buf, n, "%s", tmp), ok = 1;
    free(tmp);
  } else if (H5Tget_class(t) == H5T_STRING) {
    /* variable length: read with the attribute's own type (HDF5 converts
     * no string between ASCII and UTF-8) */
    char *s = NULL;
    if (H5Aread(a, t, &s) >= 0 && s) snprintf(buf, n, "%s", s), ok = 1;
    if (s) H5free_memory(s);
  }
  H5Tclose(t);
  H5Aclose(a);
  return ok;
}

static int h5_read_int_attr(hid_t obj, const char *name, long long *v) {
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  int ok = H5Aread(a, H5T_NATIVE_LLONG, v) >= 0;
  H5Aclose(a);
  return ok;
}

static double *h5_read_2d(hid_t g, const char *name, size_t *rows, size_t *cols) {
  hid_t d = H5Dopen2(g, name, H5P_DEFAULT);
  if (d < 0) return NULL;
  hid_t sp = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  double *buf = NULL;
  if (H5Sget_simple_extent_ndims(sp) == 2) {
    H5Sget_simple_extent_dims(sp, dims, NULL);
    if (dims[0] < 100000 && dims[1] < 100000) {
      buf = hearth_alloc_array(dims[0] * dims[1] > 0 ? (size_t)(dims[0] * dims[1]) : 1,
                               sizeof(double));
      if (buf && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
        free(buf), buf = NULL;
    }
  }
  H5Sclose(sp);
  H5Dclose(d);
  *rows = (size_t)dims[0], *cols = (size_t)dims[1];
  return buf;
}

hearth_status eval_replay_load(const char *spec, eval_replay_file *r, hearth_err *err) {
  memset(r, 0, sizeof *r);
  char path[4096];
  snprintf(path, sizeof path, "%s", spec);
  int only = -1;
  char *hash = strrchr(path, '#');
  if (hash) {
    long k;
    char *end;
    k = strtol(hash + 1, &end, 10);
    if (*end || k < 0 || k > 1000000)
      return hearth_err_set(err, HEARTH_E_ARG,
                            "replay: \"%s\": expected FILE.hdf5#K with K a demo index", spec);
    only = (int)k;
    *hash = 0;
  }
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  /* a FIFO or a directory would block or confuse HDF5: regular files only */
  hearth_status rs = hearth_check_regular(path, err);
  if (rs) return rs;
  hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open as HDF5", path);
  hearth_status st = HEARTH_OK;
  hid_t data = H5Gopen2(f, "data", H5P_DEFAULT);
  char ea[16384];
  long long ndemo = 0;
  if (data < 0 || !h5_read_str_attr(data, "env_args", ea, sizeof ea) ||
      !h5_read_int_attr(data, "num_demos", &ndemo)) {
    st = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                        "%s: expected group data with attributes env_args and num_demos", path);
    goto done;
  }
  json_error_t je;
  json_t *j = json_loads(ea, 0, &je);
  const char *env = j ? json_string_value(json_object_get(j, "env_name")) : NULL;
  json_t *seed = j ? json_object_get(json_object_get(j, "env_kwargs"), "seed") : NULL;
  if (env && strncmp(env, "hearth_", 7) == 0) r->task = hearth_sim_task_parse(env + 7);
  if (seed && json_is_integer(seed)) r->seed = (uint64_t)json_integer_value(seed);
  json_decref(j);
  if (!r->task || !seed) {
    st = hearth_err_set(err, HEARTH_E_PARSE,
                        "%s: data.env_args: expected env_name \"hearth_H1..3\" and env_kwargs.seed",
                        path);
    goto done;
  }
  if (ndemo < 0 || ndemo > 100000 || (only >= 0 && only >= ndemo)) {
    st = hearth_err_set(err, HEARTH_E_RANGE, "%s: demo %d requested, file has %lld", path, only,
                        ndemo);
    goto done;
  }
  int first = only >= 0 ? only : 0, count = only >= 0 ? 1 : (int)ndemo;
  r->demos = calloc((size_t)(count ? count : 1), sizeof *r->demos);
  if (!r->demos) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "replay: demos");
    goto done;
  }
  for (int i = 0; i < count && !st; i++) {
    char name[64];
    snprintf(name, sizeof name, "demo_%d", first + i);
    hid_t g = H5Gopen2(data, name, H5P_DEFAULT);
    eval_replay_demo *d = &r->demos[i];
    long long lay = 0, ins = 0;
    size_t ar = 0, ac = 0, sr = 0, sc = 0;
    if (g >= 0) {
      d->actions = h5_read_2d(g, "actions", &ar, &ac);
      d->states = h5_read_2d(g, "states", &sr, &sc);
    }
    if (g < 0 || !h5_read_int_attr(g, "layout", &lay) ||
        !h5_read_int_attr(g, "instruction_index", &ins) || !d->actions || ac != 7 ||
        (d->states && sr != ar) || ins < 0 || ins > 1 || lay < 0)
      st = hearth_err_set(
          err, HEARTH_E_PARSE,
          "%s: data/%s: expected attributes layout, instruction_index and datasets actions (T,7), states (T,S)",
          path, name);
    if (g >= 0) H5Gclose(g);
    d->index = first + i, d->instruction = (int)ins, d->layout = (uint64_t)lay, d->T = ar,
    d->S = d->states ? sc : 0;
    r->n = i + 1;
  }
done:
  if (data >= 0) H5Gclose(data);
  H5Fclose(f);
  if (st) eval_replay_free(r);
  return st;
}
