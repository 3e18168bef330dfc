/* demonstration collection with the scripted expert, stored in LIBERO's
 * HDF5 layout (plus obs/agentview_thermal) */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sim/sim_env.h"

void hearth_sim_collect_opts_default(hearth_sim_collect_opts *o) {
  memset(o, 0, sizeof *o);
  o->task = HEARTH_SIM_H1;
  o->use_ground_truth = 1;
  o->layouts = 200;
  o->seed = 1;
  o->image_size = 128;
  o->max_steps = 400;
}

typedef struct demo_buf {
  size_t T, cap, nstate, img;
  double *actions, *states, *joint, *grip, *ee;
  uint8_t *front, *thermal, *wrist;
} demo_buf;

static void demo_free(demo_buf *b) {
  free(b->actions), free(b->states), free(b->joint), free(b->grip), free(b->ee);
  free(b->front), free(b->thermal), free(b->wrist);
  memset(b, 0, sizeof *b);
}

static int demo_grow(demo_buf *b, size_t cap) {
  if (cap <= b->cap) return 1;
  double **dp[] = {&b->actions, &b->states, &b->joint, &b->grip, &b->ee};
  size_t dn[] = {7, b->nstate, 7, 2, 6};
  for (int i = 0; i < 5; i++) {
    void *q = realloc(*dp[i], cap * dn[i] * sizeof(double));
    if (!q) return 0;
    *dp[i] = q;
  }
  uint8_t **ip[] = {&b->front, &b->thermal, &b->wrist};
  for (int i = 0; i < 3; i++) {
    void *q = realloc(*ip[i], cap * b->img);
    if (!q) return 0;
    *ip[i] = q;
  }
  b->cap = cap;
  return 1;
}

/* ---- HDF5 helpers ---------------------------------------------------------- */
static int h5_str_attr(hid_t obj, const char *name, const char *val) {
  hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, strlen(val) + 1);
  hid_t sp = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
  int ok = a >= 0 && H5Awrite(a, t, val) >= 0;
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
static int h5_write(hid_t g, const char *name, hid_t ftype, hid_t mtype, int rank,
                    const hsize_t *dims, const void *data) {
  hid_t sp = H5Screate_simple(rank, dims, NULL);
  hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  H5Pset_obj_track_times(dcpl, 0); /* same inputs, same bytes */
  if (rank == 4 && dims[0] > 0) {
    hsize_t ch[4] = {1, dims[1], dims[2], dims[3]};
    H5Pset_chunk(dcpl, 4, ch);
    H5Pset_deflate(dcpl, 1);
  }
  hid_t ds = H5Dcreate2(g, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  int ok = ds >= 0 && H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0;
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

static int write_demo(hid_t data, int idx, const demo_buf *b, int instruction, const char *instr,
                      uint64_t layout, int S) {
  char name[32];
  snprintf(name, sizeof name, "demo_%d", idx);
  hid_t g = h5_group(data, name);
  if (g < 0) return 0;
  hsize_t T = b->T;
  int ok = h5_int_attr(g, "num_samples", (long long)T) && h5_int_attr(g, "layout", (long long)layout) &&
           h5_int_attr(g, "instruction_index", instruction) && h5_str_attr(g, "language_instruction", instr);
  uint8_t *rew = calloc(T ? T : 1, 1), *don = calloc(T ? T : 1, 1);
  double *pos = malloc((T ? T : 1) * 3 * sizeof(double)), *ori = malloc((T ? T : 1) * 3 * sizeof(double));
  if (!rew || !don || !pos || !ori) ok = 0;
  if (ok && T) {
    rew[T - 1] = don[T - 1] = 1;
    for (size_t t = 0; t < T; t++)
      for (int i = 0; i < 3; i++) pos[3 * t + i] = b->ee[6 * t + i], ori[3 * t + i] = b->ee[6 * t + 3 + i];
    hsize_t d7[2] = {T, 7}, dS[2] = {T, b->nstate}, d1[1] = {T}, d2[2] = {T, 2}, d6[2] = {T, 6},
            d3[2] = {T, 3}, dI[4] = {T, (hsize_t)S, (hsize_t)S, 3};
    ok = h5_write(g, "actions", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d7, b->actions) &&
         h5_write(g, "states", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, dS, b->states) &&
         h5_write(g, "rewards", H5T_STD_U8LE, H5T_NATIVE_UINT8, 1, d1, rew) &&
         h5_write(g, "dones", H5T_STD_U8LE, H5T_NATIVE_UINT8, 1, d1, don);
    hid_t o = ok ? h5_group(g, "obs") : -1;
    if (o < 0) ok = 0;
    if (ok)
      ok = h5_write(o, "agentview_rgb", H5T_STD_U8LE, H5T_NATIVE_UINT8, 4, dI, b->front) &&
           h5_write(o, "agentview_thermal", H5T_STD_U8LE, H5T_NATIVE_UINT8, 4, dI, b->thermal) &&
           h5_write(o, "eye_in_hand_rgb", H5T_STD_U8LE, H5T_NATIVE_UINT8, 4, dI, b->wrist) &&
           h5_write(o, "joint_states", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d7, b->joint) &&
           h5_write(o, "gripper_states", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d2, b->grip) &&
           h5_write(o, "ee_states", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d6, b->ee) &&
           h5_write(o, "ee_pos", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d3, pos) &&
           h5_write(o, "ee_ori", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d3, ori);
    if (o >= 0) H5Gclose(o);
  }
  free(rew), free(don), free(pos), free(ori);
  H5Gclose(g);
  return ok;
}

/* one rollout of the expert from (layout, instruction) into b */
static hearth_status rollout(hearth_sim_env *e, uint64_t seed, uint64_t layout, int ins, demo_buf *b,
                             int *success, hearth_err *err) {
  hearth_status st = hearth_sim_reset(e, seed, layout, ins, err);
  if (st) return st;
  b->T = 0;
  *success = 0;
  size_t px = b->img;
  for (int t = 0; t < e->max_steps; t++) {
    hearth_sim_obs ob;
    if ((st = hearth_sim_observe(e, &ob, err))) return st;
    if (!demo_grow(b, b->T + 1 > b->cap ? b->cap * 2 + 64 : b->cap))
      return hearth_err_set(err, HEARTH_E_NOMEM, "sim collect: out of memory");
    size_t i = b->T;
    memcpy(b->front + i * px, ob.agentview_rgb, px);
    memcpy(b->thermal + i * px, ob.agentview_thermal, px);
    memcpy(b->wrist + i * px, ob.eye_in_hand_rgb, px);
    memcpy(b->joint + 7 * i, ob.joint_states, sizeof ob.joint_states);
    memcpy(b->grip + 2 * i, ob.gripper_states, sizeof ob.gripper_states);
    memcpy(b->ee + 6 * i, ob.ee_pos, sizeof ob.ee_pos);
    memcpy(b->ee + 6 * i + 3, ob.ee_ori, sizeof ob.ee_ori);
    hearth_sim_state(e, b->states + b->nstate * i, b->nstate);
    double a[7];
    hearth_sim_expert_action(e, a);
    memcpy(b->actions + 7 * i, a, sizeof a);
    b->T++;
    if ((st = hearth_sim_step(e, a, err))) return st;
    if (hearth_sim_success(e)) {
      *success = 1;
      break;
    }
  }
  return HEARTH_OK;
}

hearth_status hearth_sim_collect(const hearth_sim_collect_opts *o, hearth_sim_collect_stats *stats,
                                 hearth_err *err) {
  hearth_sim_collect_stats dummy;
  if (!stats) stats = &dummy;
  memset(stats, 0, sizeof *stats);
  if (!o->out_path) return hearth_err_set(err, HEARTH_E_ARG, "sim collect: no output path");
  if (o->layouts < 1 || o->layouts > 100000)
    return hearth_err_set(err, HEARTH_E_RANGE, "sim collect: layouts must be 1..100000, got %d", o->layouts);
  hearth_sim_opts so;
  hearth_sim_opts_default(&so);
  so.task = o->task;
  so.release_root = o->release_root;
  so.use_ground_truth = o->use_ground_truth;
  so.width = so.height = o->image_size;
  so.max_steps = o->max_steps;
  so.shadows = o->shadows;
  so.gl = o->gl;
  hearth_sim_env *e = NULL;
  hearth_status st = hearth_sim_env_new(&so, &e, err);
  if (st) return st;
  if (!o->quiet) fprintf(stderr, "renderer: %s\n", hearth_sim_renderer(e));
  double t0 = hearth_now();
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s.tmp%ld", o->out_path, (long)getpid());
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
  hid_t f = H5Fcreate(tmp, H5F_ACC_TRUNC, fcpl, H5P_DEFAULT);
  H5Pclose(fcpl);
  if (f < 0) {
    hearth_sim_env_free(e);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create the HDF5 file", tmp);
  }
  hid_t data = h5_group(f, "data");
  demo_buf b = {0};
  b.nstate = hearth_sim_state(e, NULL, 0);
  b.img = (size_t)o->image_size * (size_t)o->image_size * 3;
  demo_buf b2 = {0};
  b2.nstate = b.nstate, b2.img = b.img;
  hearth_progress pr;
  hearth_progress_begin(&pr, "collect", (size_t)o->layouts * 2, o->quiet);
  int ndemo = 0;
  long stored = 0;
  /* a layout is kept when the expert succeeds on both instructions (or
   * with keep_failures); a rejected layout is replaced by the next unused
   * one of the same parity, so the candidate-to-slot assignment (layout
   * parity) stays balanced: layout k of the file has parity k & 1 */
  uint64_t next[2] = {0, 1};
  long max_tries = 20L * o->layouts + 100;
  for (int k = 0; k < o->layouts && !st; k++) {
    int par = k & 1, kept = 0;
    while (!kept && !st) {
      if (stats->rejected_layouts >= max_tries) {
        st = hearth_err_set(err, HEARTH_E_NUMERIC,
                            "sim collect %s: the expert failed on %d layouts (stored %d of %d); "
                            "check the assets or pass --keep-failures",
                            hearth_sim_task_name(o->task), stats->rejected_layouts, k, o->layouts);
        break;
      }
      uint64_t l = next[par];
      next[par] += 2;
      int ok[2] = {0, 0};
      demo_buf *bb[2] = {&b, &b2};
      for (int ins = 0; ins < 2 && !st; ins++) {
        st = rollout(e, o->seed, l, ins, bb[ins], &ok[ins], err);
        if (st) break;
        stats->attempts[ins]++;
        stats->successes[ins] += ok[ins];
        stats->steps += (long)bb[ins]->T;
      }
      if (st) break;
      if (!(ok[0] && ok[1]) && !o->keep_failures) {
        stats->rejected_layouts++;
        continue;
      }
      kept = 1;
      for (int ins = 0; ins < 2 && !st; ins++) {
        if (!write_demo(data, ndemo, bb[ins], ins, hearth_sim_instruction_text(o->task, ins), l,
                        o->image_size))
          st = hearth_err_set(err, HEARTH_E_IO, "%s: writing demo_%d failed", tmp, ndemo);
        ndemo++;
        stored += (long)bb[ins]->T;
      }
      hearth_progress_step(&pr, 2);
    }
  }
  hearth_progress_end(&pr);
  demo_free(&b2);
  if (!st) {
    /* one file holds both instructions of a task. LIBERO's loaders read
     * problem_info["language_instruction"] as one string: it names the
     * first instruction; each demo carries its own language_instruction
     * attribute and data/instructions lists both (JSON) */
    char pi[1024], ea[1024], il[512];
    snprintf(pi, sizeof pi,
             "{\"problem_name\": \"hearth_%s\", \"domain_name\": \"hearth\", "
             "\"language_instruction\": \"%s\"}",
             hearth_sim_task_name(o->task), hearth_sim_instruction_text(o->task, 0));
    snprintf(il, sizeof il, "[\"%s\", \"%s\"]", hearth_sim_instruction_text(o->task, 0),
             hearth_sim_instruction_text(o->task, 1));
    snprintf(ea, sizeof ea,
             "{\"env_name\": \"hearth_%s\", \"type\": 1, \"env_kwargs\": {\"control_freq\": 20, "
             "\"camera_heights\": %d, \"camera_widths\": %d, \"controller\": \"OSC_POSE\", "
             "\"seed\": %llu, \"asset_source\": \"%s\", \"shadows\": %s, \"renderer\": \"%s\"}}",
             hearth_sim_task_name(o->task), o->image_size, o->image_size, (unsigned long long)o->seed,
             o->use_ground_truth ? "virtual_rig_ground_truth" : "release_derived",
             o->shadows ? "true" : "false", e->gl);
    if (!h5_str_attr(data, "problem_info", pi) || !h5_str_attr(data, "env_args", ea) ||
        !h5_int_attr(data, "num_demos", ndemo) || !h5_int_attr(data, "total", stored) ||
        !h5_str_attr(data, "instructions", il) ||
        !h5_str_attr(data, "image_row_order", "opengl_bottom_row_first") ||
        !h5_str_attr(data, "thermal_colormap", "turbo 10..60 degC"))
      st = hearth_err_set(err, HEARTH_E_IO, "%s: writing attributes failed", tmp);
  }
  H5Gclose(data);
  if (H5Fclose(f) < 0 && !st) st = hearth_err_set(err, HEARTH_E_IO, "%s: closing failed", tmp);
  if (!st && rename(tmp, o->out_path) != 0)
    st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename into place", o->out_path);
  if (st) unlink(tmp);
  demo_free(&b);
  hearth_sim_env_free(e);
  stats->demos = ndemo;
  stats->seconds = hearth_now() - t0;
  return st;
}
