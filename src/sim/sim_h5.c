/* The collection file's writer and reader: demos as LIBERO stores them,
 * string attributes as variable-length UTF-8 (h5py reads str), object
 * timestamps off, so the same demos written in the same order give the
 * same bytes. */
#include <libdeflate.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_h5.h"

/* the most region columns a file may hold (4 objects of at most 16 regions) */
#define SIM_NOBJ_MAX_REGIONS 64

const char *const sim_h5_key_names[SIM_H5_NKEYS] = {"env_name",          "problem_info",
                                                    "env_args",          "bddl_file_name",
                                                    "bddl_file_content", "macros_image_convention",
                                                    "instructions",      "image_row_order",
                                                    "thermal_colormap"};

int sim_demo_grow(sim_demo *b, size_t cap) {
  if (cap <= b->cap) return 1;
  double **dp[] = {&b->actions, &b->states, &b->joint, &b->grip, &b->ee, &b->robot};
  size_t dn[] = {7, b->nstate, 7, 2, 6, SIM_ROBOT_STATE_DIM};
  for (int i = 0; i < 6; i++) {
    void *q = hearth_alloc_array(cap * dn[i], sizeof(double));
    if (!q) return 0;
    if (*dp[i]) memcpy(q, *dp[i], b->T * dn[i] * sizeof(double));
    free(*dp[i]);
    *dp[i] = q;
  }
  if (b->nth) {
    float *q = hearth_alloc_array(cap * b->nth, sizeof(float));
    if (!q) return 0;
    if (b->th) memcpy(q, b->th, b->T * b->nth * sizeof(float));
    free(b->th);
    b->th = q;
  }
  uint8_t **ip[] = {&b->front, &b->thermal, &b->wrist};
  for (int i = 0; i < 3 && b->img; i++) {
    void *q = hearth_alloc_array(cap, b->img);
    if (!q) return 0;
    if (*ip[i]) memcpy(q, *ip[i], b->T * b->img);
    free(*ip[i]);
    *ip[i] = q;
  }
  b->cap = cap;
  return 1;
}

void sim_demo_free(sim_demo *b) {
  free(b->actions), free(b->states), free(b->joint), free(b->grip), free(b->ee), free(b->robot);
  free(b->front), free(b->thermal), free(b->wrist);
  free(b->th), free(b->th_names), free(b->th_C);
  memset(b, 0, sizeof *b);
}

void sim_h5_meta_free(sim_h5_meta *m) {
  for (int i = 0; i < SIM_H5_NKEYS; i++) free(m->str[i]);
  memset(m, 0, sizeof *m);
}

/* ---- attribute and dataset helpers -------------------------------------------- */
static hid_t vlen_utf8(void) {
  hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_UTF8);
  return t;
}

static int h5_str_attr(hid_t obj, const char *name, const char *val) {
  hid_t t = vlen_utf8();
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
  int ok = a >= 0 && H5Awrite(a, t, &val) >= 0;
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp), H5Tclose(t);
  return ok;
}

static int h5_int_attr(hid_t obj, const char *name, long long v) {
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(obj, name, H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
  int ok = a >= 0 && H5Awrite(a, H5T_NATIVE_LLONG, &v) >= 0;
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp);
  return ok;
}

static int h5_f64_array_attr(hid_t obj, const char *name, const double *v, size_t n) {
  hsize_t d = n;
  hid_t sp = H5Screate_simple(1, &d, NULL);
  hid_t a = H5Acreate2(obj, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
  int ok = a >= 0 && H5Awrite(a, H5T_NATIVE_DOUBLE, v) >= 0;
  if (a >= 0) H5Aclose(a);
  H5Sclose(sp);
  return ok;
}

static int h5_write(hid_t g, const char *name, hid_t ftype, hid_t mtype, int rank,
                    const hsize_t *dims, const void *data) {
  hid_t sp = H5Screate_simple(rank, dims, NULL);
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  H5Pset_obj_track_times(dcpl, 0); /* same inputs, same bytes */
  hid_t ds = H5Dcreate2(g, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  int ok = ds >= 0 && H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0;
  if (ds >= 0) H5Dclose(ds);
  H5Pclose(dcpl), H5Sclose(sp);
  return ok;
}

/* An image dataset (T, S, S, 3) of U8, one frame per chunk with HDF5's
 * deflate filter (level SIM_H5_DEFLATE_LEVEL in its filter message): each
 * frame is compressed here with libdeflate into a zlib stream, the format
 * that filter stores, and written as the chunk itself, so that HDF5 runs
 * no compressor of its own. The chunks are a function of the pixels alone
 * and any reader with the deflate filter (h5py included) decodes them. */
static int h5_write_images(sim_h5_out *o, hid_t g, const char *name, const hsize_t dims[4],
                           const uint8_t *data) {
  size_t frame = (size_t)(dims[1] * dims[2] * dims[3]);
  if (dims[0] == 0) return h5_write(g, name, H5T_STD_U8LE, H5T_NATIVE_UINT8, 4, dims, data);
  if (!o->zc) o->zc = libdeflate_alloc_compressor(SIM_H5_DEFLATE_LEVEL);
  size_t bound = o->zc ? libdeflate_zlib_compress_bound(o->zc, frame) : 0;
  if (bound > o->zcap) {
    free(o->zbuf);
    o->zbuf = malloc(bound);
    o->zcap = o->zbuf ? bound : 0;
  }
  if (!o->zc || !o->zbuf) return 0;
  hid_t sp = H5Screate_simple(4, dims, NULL);
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  H5Pset_obj_track_times(dcpl, 0); /* same inputs, same bytes */
  hsize_t ch[4] = {1, dims[1], dims[2], dims[3]};
  H5Pset_chunk(dcpl, 4, ch);
  H5Pset_deflate(dcpl, SIM_H5_DEFLATE_LEVEL);
  hid_t ds = H5Dcreate2(g, name, H5T_STD_U8LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  int ok = ds >= 0;
  for (hsize_t t = 0; t < dims[0] && ok; t++) {
    const uint8_t *src = data + (size_t)t * frame;
    size_t n = libdeflate_zlib_compress(o->zc, src, frame, o->zbuf, o->zcap);
    hsize_t at[4] = {t, 0, 0, 0};
    /* filter mask 0: the chunk went through the deflate filter */
    ok = n > 0 && H5Dwrite_chunk(ds, H5P_DEFAULT, 0, at, n, o->zbuf) >= 0;
  }
  if (ds >= 0) H5Dclose(ds);
  H5Pclose(dcpl), H5Sclose(sp);
  return ok;
}

static hid_t h5_group(hid_t parent, const char *name) {
  hid_t gcpl = H5Pcreate(H5P_GROUP_CREATE);
  H5Pset_obj_track_times(gcpl, 0);
  hid_t g = H5Gcreate2(parent, name, H5P_DEFAULT, gcpl, H5P_DEFAULT);
  H5Pclose(gcpl);
  return g;
}

/* ---- writing ------------------------------------------------------------------- */
hearth_status sim_h5_create(sim_h5_out *o, const char *path, hearth_err *err) {
  memset(o, 0, sizeof *o);
  o->f = o->data = -1;
  /* temporaries of this file left by a killed collection go first */
  hearth_status st = hearth_sweep_temps_of(path, NULL, err);
  if (!st) st = hearth_atomic_open(&o->af, path, err);
  if (st) return st;
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  o->f = H5Fcreate(o->af.tmp_path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (o->f >= 0) o->data = h5_group(o->f, "data");
  if (o->data < 0) {
    st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot create the HDF5 file", o->af.tmp_path);
    sim_h5_abort(o);
  }
  return st;
}

hearth_status sim_h5_add_demo(sim_h5_out *o, const sim_demo *b, int S, const char *instruction,
                              const char *model_file, hearth_err *err) {
  char name[32];
  snprintf(name, sizeof name, "demo_%d", o->ndemo);
  hid_t g = h5_group(o->data, name);
  if (g < 0) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create data/%s", o->af.path, name);
  hsize_t T = b->T;
  int ok = h5_int_attr(g, "num_samples", (long long)T) &&
           h5_int_attr(g, "layout", (long long)b->layout) &&
           h5_int_attr(g, "instruction_index", b->instruction) &&
           h5_str_attr(g, "language_instruction", instruction) &&
           h5_str_attr(g, "model_file", model_file);
  size_t n = T ? (size_t)T : 1;
  uint8_t *rew = calloc(n, 1), *don = calloc(n, 1);
  double *pos = hearth_alloc_array(n * 3, sizeof(double)),
         *ori = hearth_alloc_array(n * 3, sizeof(double));
  if (!rew || !don || !pos || !ori) ok = 0;
  if (ok && T) {
    ok = h5_f64_array_attr(g, "init_state", b->states, b->nstate);
    rew[T - 1] = don[T - 1] = 1;
    for (size_t t = 0; t < T; t++)
      for (int i = 0; i < 3; i++)
        pos[3 * t + i] = b->ee[6 * t + i], ori[3 * t + i] = b->ee[6 * t + 3 + i];
    hsize_t d7[2] = {T, 7}, dS[2] = {T, b->nstate}, dR[2] = {T, SIM_ROBOT_STATE_DIM}, d1[1] = {T},
            d2[2] = {T, 2}, d6[2] = {T, 6}, d3[2] = {T, 3}, dI[4] = {T, (hsize_t)S, (hsize_t)S, 3};
    hid_t f64 = H5T_IEEE_F64LE, nd = H5T_NATIVE_DOUBLE, u8 = H5T_STD_U8LE, nu8 = H5T_NATIVE_UINT8;
    ok = ok && h5_write(g, "actions", f64, nd, 2, d7, b->actions) &&
         h5_write(g, "states", f64, nd, 2, dS, b->states) &&
         h5_write(g, "robot_states", f64, nd, 2, dR, b->robot) &&
         h5_write(g, "rewards", u8, nu8, 1, d1, rew) && h5_write(g, "dones", u8, nu8, 1, d1, don);
    hid_t ob = ok ? h5_group(g, "obs") : -1;
    if (ob < 0) ok = 0;
    if (ok)
      ok = (b->img == 0 || (h5_write_images(o, ob, "agentview_rgb", dI, b->front) &&
                            h5_write_images(o, ob, "agentview_thermal", dI, b->thermal) &&
                            h5_write_images(o, ob, "eye_in_hand_rgb", dI, b->wrist))) &&
           h5_write(ob, "joint_states", f64, nd, 2, d7, b->joint) &&
           h5_write(ob, "gripper_states", f64, nd, 2, d2, b->grip) &&
           h5_write(ob, "ee_states", f64, nd, 2, d6, b->ee) &&
           h5_write(ob, "ee_pos", f64, nd, 2, d3, pos) &&
           h5_write(ob, "ee_ori", f64, nd, 2, d3, ori);
    if (ok && b->nth) {
      /* dynamic temperatures: the region temperatures and their columns */
      hsize_t dT[2] = {T, b->nth};
      ok = h5_write(ob, "thermal_state", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, 2, dT, b->th);
      hid_t ds = ok ? H5Dopen2(ob, "thermal_state", H5P_DEFAULT) : -1;
      ok = ds >= 0 && h5_str_attr(ds, "region_names", b->th_names ? b->th_names : "") &&
           h5_f64_array_attr(ds, "heat_capacity", b->th_C, b->nth) &&
           h5_str_attr(ds, "units", "degC");
      if (ds >= 0) H5Dclose(ds);
    }
    if (ob >= 0) H5Gclose(ob);
  }
  free(rew), free(don), free(pos), free(ori);
  H5Gclose(g);
  if (!ok) return hearth_err_set(err, HEARTH_E_IO, "%s: writing data/%s failed", o->af.path, name);
  o->ndemo++;
  o->total += (long long)T;
  return HEARTH_OK;
}

/* the image compressor and its buffer */
static void h5_out_free_z(sim_h5_out *o) {
  libdeflate_free_compressor(o->zc);
  free(o->zbuf);
  o->zc = NULL, o->zbuf = NULL, o->zcap = 0;
}

void sim_h5_abort(sim_h5_out *o) {
  h5_out_free_z(o);
  if (o->data >= 0) H5Gclose(o->data);
  if (o->f >= 0) H5Fclose(o->f);
  o->data = o->f = -1;
  hearth_atomic_abort(&o->af);
}

hearth_status sim_h5_finish(sim_h5_out *o, const sim_h5_meta *m, const sim_h5_shard *shard,
                            hearth_err *err) {
  h5_out_free_z(o);
  int ok = 1;
  for (int k = 0; k < SIM_H5_NKEYS && ok; k++)
    ok = h5_str_attr(o->data, sim_h5_key_names[k], m->str[k] ? m->str[k] : "");
  ok = ok && h5_int_attr(o->data, "num_demos", o->ndemo) && h5_int_attr(o->data, "total", o->total);
  if (ok && shard) {
    char s[64];
    snprintf(s, sizeof s, "%d/%d", shard->index, shard->count);
    ok = h5_str_attr(o->data, "hearth_shard", s) &&
         h5_int_attr(o->data, "hearth_layouts", shard->layouts);
  }
  H5Gclose(o->data);
  o->data = -1;
  if (H5Fclose(o->f) < 0) ok = 0;
  o->f = -1;
  if (!ok) {
    hearth_atomic_abort(&o->af);
    return hearth_err_set(err, HEARTH_E_IO, "%s: writing the attributes of data failed",
                          o->af.path);
  }
  /* HDF5 wrote through its own descriptor; the atomic file's stream holds
   * nothing, and commit renames the temporary over the path */
  hearth_status st = hearth_atomic_commit(&o->af, err);
  o->af.tmp_path[0] = 0; /* renamed or removed: nothing left to abort */
  return st;
}

/* ---- reading --------------------------------------------------------------------- */
/* a string attribute (variable or fixed length) as a malloc'd string; NULL
 * if missing or not a string */
static char *h5_read_str(hid_t obj, const char *name) {
  if (H5Aexists(obj, name) <= 0) return NULL;
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return NULL;
  hid_t t = H5Aget_type(a);
  char *out = NULL;
  if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t)) {
    /* the attribute's own type: HDF5 converts no string between ASCII and UTF-8 */
    char *s = NULL;
    if (H5Aread(a, t, &s) >= 0 && s) out = strdup(s);
    if (s) H5free_memory(s);
  } else if (H5Tget_class(t) == H5T_STRING) {
    size_t n = H5Tget_size(t);
    out = calloc(1, n + 1);
    if (out && H5Aread(a, t, out) < 0) free(out), out = NULL;
  }
  H5Tclose(t), H5Aclose(a);
  return out;
}

static int h5_read_int(hid_t obj, const char *name, long long *v) {
  if (H5Aexists(obj, name) <= 0) return 0;
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  int ok = H5Aread(a, H5T_NATIVE_LLONG, v) >= 0;
  H5Aclose(a);
  return ok;
}

/* dims of dataset g/name (rank r) into d; 0 if missing or of another rank */
static int h5_dims(hid_t g, const char *name, int r, hsize_t *d) {
  if (H5Lexists(g, name, H5P_DEFAULT) <= 0) return 0;
  hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
  if (ds < 0) return 0;
  hid_t sp = H5Dget_space(ds);
  int ok = H5Sget_simple_extent_ndims(sp) == r && H5Sget_simple_extent_dims(sp, d, NULL) == r;
  H5Sclose(sp), H5Dclose(ds);
  return ok;
}

static int h5_read(hid_t g, const char *name, hid_t mtype, void *buf) {
  hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
  if (ds < 0) return 0;
  int ok = H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0;
  H5Dclose(ds);
  return ok;
}

void sim_h5_close(sim_h5_in *in) {
  if (in->data >= 0) H5Gclose(in->data);
  if (in->f >= 0) H5Fclose(in->f);
  in->data = in->f = -1;
  sim_h5_meta_free(&in->meta);
}

hearth_status sim_h5_open(sim_h5_in *in, const char *path, hearth_err *err) {
  memset(in, 0, sizeof *in);
  in->f = in->data = -1;
  snprintf(in->path, sizeof in->path, "%s", path);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  /* a FIFO or a directory would block or confuse HDF5: regular files only */
  hearth_status rs = hearth_check_regular(path, err);
  if (rs) return rs;
  in->f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (in->f < 0) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open as HDF5", path);
  in->data = H5Gopen2(in->f, "data", H5P_DEFAULT);
  long long nd = -1;
  if (in->data < 0 || !h5_read_int(in->data, "num_demos", &nd) || nd < 0 || nd > 1000000) {
    sim_h5_close(in);
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: expected group data with attribute num_demos",
                          path);
  }
  in->ndemo = (int)nd;
  for (int k = 0; k < SIM_H5_NKEYS; k++) {
    in->meta.str[k] = h5_read_str(in->data, sim_h5_key_names[k]);
    if (!in->meta.str[k]) {
      sim_h5_close(in);
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: data has no string attribute %s (not a hearth sim collect file?)",
                            path, sim_h5_key_names[k]);
    }
  }
  char *sh = h5_read_str(in->data, "hearth_shard");
  if (sh) {
    int i = -1, n = 0, used = 0;
    if (sscanf(sh, "%d/%d%n", &i, &n, &used) != 2 || sh[used] || n < 1 || i < 0 || i >= n ||
        !h5_read_int(in->data, "hearth_layouts", &in->shard.layouts) || in->shard.layouts < 1) {
      hearth_status st = hearth_err_set(
          err, HEARTH_E_PARSE,
          "%s: data@hearth_shard \"%s\": expected I/N with 0 <= I < N and data@hearth_layouts",
          path, sh);
      free(sh);
      sim_h5_close(in);
      return st;
    }
    in->shard.index = i, in->shard.count = n;
    free(sh);
  }
  return HEARTH_OK;
}

/* obs/thermal_state of a dynamic collection into b (nth 0 when absent) */
static hearth_status read_thermal_state(sim_h5_in *in, hid_t ob, const char *name, size_t T,
                                        sim_demo *b, hearth_err *err) {
  free(b->th), free(b->th_names), free(b->th_C);
  b->th = NULL, b->th_names = NULL, b->th_C = NULL, b->nth = 0;
  if (H5Lexists(ob, "thermal_state", H5P_DEFAULT) <= 0) return HEARTH_OK;
  hsize_t d[2] = {0};
  hid_t ds = -1;
  int ok = h5_dims(ob, "thermal_state", 2, d) && d[0] == T && d[1] >= 1 &&
           d[1] <= SIM_NOBJ_MAX_REGIONS && (ds = H5Dopen2(ob, "thermal_state", H5P_DEFAULT)) >= 0;
  if (ok) {
    b->nth = (size_t)d[1];
    b->th = hearth_alloc_array(T * b->nth, sizeof(float));
    b->th_C = hearth_alloc_array(b->nth, sizeof(double));
    b->th_names = h5_read_str(ds, "region_names");
    hid_t a = b->th_C && H5Aexists(ds, "heat_capacity") > 0
                  ? H5Aopen(ds, "heat_capacity", H5P_DEFAULT)
                  : -1;
    hid_t sp = a >= 0 ? H5Aget_space(a) : -1;
    ok = b->th && b->th_names && a >= 0 && sp >= 0 &&
         H5Sget_simple_extent_npoints(sp) == (hssize_t)b->nth &&
         H5Aread(a, H5T_NATIVE_DOUBLE, b->th_C) >= 0 &&
         H5Dread(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, b->th) >= 0;
    if (sp >= 0) H5Sclose(sp);
    if (a >= 0) H5Aclose(a);
  }
  if (ds >= 0) H5Dclose(ds);
  if (!ok)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: data/%s/obs/thermal_state: expected float32 (T, R) with attributes "
                          "region_names and heat_capacity (R)",
                          in->path, name);
  return HEARTH_OK;
}

hearth_status sim_h5_read_demo(sim_h5_in *in, int idx, sim_demo *b, int *S, char **instruction,
                               char **model_file, hearth_err *err) {
  *instruction = *model_file = NULL;
  char name[32];
  snprintf(name, sizeof name, "demo_%d", idx);
  hid_t g = H5Gopen2(in->data, name, H5P_DEFAULT);
  if (g < 0) return hearth_err_set(err, HEARTH_E_PARSE, "%s: no data/%s", in->path, name);
  hearth_status st = HEARTH_OK;
  long long T = -1, lay = -1, ins = -1;
  hsize_t da[2] = {0}, ds[2] = {0}, di[4] = {0};
  if (!h5_read_int(g, "num_samples", &T) || !h5_read_int(g, "layout", &lay) ||
      !h5_read_int(g, "instruction_index", &ins) || T < 0 || T > 10000000 || lay < 0 || ins < 0 ||
      ins > 1 || !(*instruction = h5_read_str(g, "language_instruction")) ||
      !(*model_file = h5_read_str(g, "model_file")))
    st = hearth_err_set(err, HEARTH_E_PARSE,
                        "%s: data/%s: expected attributes num_samples, layout, instruction_index, "
                        "language_instruction and model_file",
                        in->path, name);
  hid_t ob = -1;
  if (!st && T > 0) {
    ob = H5Gopen2(g, "obs", H5P_DEFAULT);
    if (ob < 0 || !h5_dims(g, "actions", 2, da) || da[0] != (hsize_t)T || da[1] != 7 ||
        !h5_dims(g, "states", 2, ds) || ds[0] != (hsize_t)T || ds[1] < 1 || ds[1] > 100000 ||
        !h5_dims(ob, "agentview_rgb", 4, di) || di[0] != (hsize_t)T || di[1] != di[2] ||
        di[3] != 3 || di[1] < 1 || di[1] > 8192)
      st = hearth_err_set(
          err, HEARTH_E_PARSE,
          "%s: data/%s: expected actions (T, 7), states (T, S) and obs/agentview_rgb (T, S, S, 3) "
          "with T = num_samples %lld",
          in->path, name, T);
  }
  if (!st) {
    if (T > 0 && (b->nstate != (size_t)ds[1] || b->img != (size_t)di[1] * di[1] * 3)) {
      sim_demo_free(b);
      b->nstate = (size_t)ds[1], b->img = (size_t)di[1] * di[1] * 3;
    }
    b->T = 0;
    if (!sim_demo_grow(b, T > 0 ? (size_t)T : 1))
      st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: data/%s: out of memory", in->path, name);
  }
  if (!st && T > 0) {
    /* every dataset the demo is made of, with the shape it must have */
    const struct {
      hid_t grp;
      const char *name;
      size_t width; /* 2-D: columns; 0: an image (T, S, S, 3) */
      void *dst;
    } k_read[] = {
        {g, "actions", 7, b->actions},
        {g, "states", b->nstate, b->states},
        {g, "robot_states", SIM_ROBOT_STATE_DIM, b->robot},
        {ob, "joint_states", 7, b->joint},
        {ob, "gripper_states", 2, b->grip},
        {ob, "ee_states", 6, b->ee},
        {ob, "agentview_rgb", 0, b->front},
        {ob, "agentview_thermal", 0, b->thermal},
        {ob, "eye_in_hand_rgb", 0, b->wrist},
    };
    for (size_t k = 0; k < sizeof k_read / sizeof k_read[0] && !st; k++) {
      hsize_t d[4] = {0};
      int img = k_read[k].width == 0;
      int shape_ok = img ? h5_dims(k_read[k].grp, k_read[k].name, 4, d) && d[0] == (hsize_t)T &&
                               d[1] == di[1] && d[2] == di[1] && d[3] == 3
                         : h5_dims(k_read[k].grp, k_read[k].name, 2, d) && d[0] == (hsize_t)T &&
                               d[1] == k_read[k].width;
      if (!shape_ok || !h5_read(k_read[k].grp, k_read[k].name,
                                img ? H5T_NATIVE_UINT8 : H5T_NATIVE_DOUBLE, k_read[k].dst)) {
        char want[64];
        if (img)
          snprintf(want, sizeof want, "%lld, %llu, %llu, 3", T, (unsigned long long)di[1],
                   (unsigned long long)di[1]);
        else snprintf(want, sizeof want, "%lld, %zu", T, k_read[k].width);
        st = hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: data/%s/%s%s: missing, unreadable or not of shape (%s)", in->path,
                            name, k_read[k].grp == ob ? "obs/" : "", k_read[k].name, want);
      }
    }
  }
  if (!st && T > 0) st = read_thermal_state(in, ob, name, (size_t)T, b, err);
  if (ob >= 0) H5Gclose(ob);
  H5Gclose(g);
  if (st) {
    free(*instruction), free(*model_file);
    *instruction = *model_file = NULL;
    return st;
  }
  b->T = (size_t)T;
  b->layout = (uint64_t)lay;
  b->instruction = (int)ins;
  *S = T > 0 ? (int)di[1] : 0;
  return HEARTH_OK;
}
