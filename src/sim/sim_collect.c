/* demonstration collection with the scripted expert, stored in LIBERO's
 * HDF5 layout (plus obs/agentview_thermal) by sim_h5.c; one process or one
 * shard of many */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_env.h"
#include "sim/sim_h5.h"
#include "sim/sim_mjcf.h"

void hearth_sim_collect_opts_default(hearth_sim_collect_opts *o) {
  memset(o, 0, sizeof *o);
  o->task = HEARTH_SIM_H1;
  o->use_ground_truth = 1;
  o->layouts = 200;
  o->seed = 1;
  o->image_size = 256;
  o->max_steps = 400;
}

void hearth_sim_split_path(const char *out_path, int ins, char *buf, size_t bufsz) {
  size_t n = strlen(out_path);
  if (n >= 5 && strcmp(out_path + n - 5, ".hdf5") == 0) n -= 5;
  snprintf(buf, bufsz, "%.*s_instr%d.hdf5", (int)n, out_path, ins + 1);
}

/* one rollout of the expert from (layout, instruction) into b */
static hearth_status rollout(hearth_sim_env *e, uint64_t seed, uint64_t layout, int ins,
                             sim_demo *b, int *success, hearth_err *err) {
  hearth_status st = hearth_sim_reset(e, seed, layout, ins, err);
  if (st) return st;
  b->T = 0;
  b->layout = layout;
  b->instruction = ins;
  *success = 0;
  size_t px = b->img;
  for (int t = 0; t < e->max_steps; t++) {
    hearth_sim_obs ob;
    if ((st = hearth_sim_observe(e, &ob, err))) return st;
    if (!sim_demo_grow(b, b->T + 1 > b->cap ? b->cap * 2 + 64 : b->cap))
      return hearth_err_set(err, HEARTH_E_NOMEM, "sim collect: out of memory");
    size_t i = b->T;
    if (px) {
      memcpy(b->front + i * px, ob.agentview_rgb, px);
      memcpy(b->thermal + i * px, ob.agentview_thermal, px);
      memcpy(b->wrist + i * px, ob.eye_in_hand_rgb, px);
    }
    memcpy(b->joint + 7 * i, ob.joint_states, sizeof ob.joint_states);
    memcpy(b->grip + 2 * i, ob.gripper_states, sizeof ob.gripper_states);
    memcpy(b->ee + 6 * i, ob.ee_pos, sizeof ob.ee_pos);
    memcpy(b->ee + 6 * i + 3, ob.ee_ori, sizeof ob.ee_ori);
    /* LIBERO's robot state: gripper qpos, ee pos, ee quat in robosuite's
     * x y z w order */
    double *r = b->robot + SIM_ROBOT_STATE_DIM * i;
    r[0] = ob.gripper_states[0], r[1] = ob.gripper_states[1];
    r[2] = ob.ee_pos[0], r[3] = ob.ee_pos[1], r[4] = ob.ee_pos[2];
    r[5] = ob.ee_quat[1], r[6] = ob.ee_quat[2], r[7] = ob.ee_quat[3], r[8] = ob.ee_quat[0];
    hearth_sim_state(e, b->states + b->nstate * i, b->nstate);
    if (b->nth) hearth_sim_thermal_state(e, b->th + b->nth * i, b->nth);
    double a[7];
    hearth_sim_expert_action(e, a);
    memcpy(b->actions + 7 * i, a, sizeof a);
    b->T++;
    if ((st = hearth_sim_step(e, a, err))) return st;
    if (hearth_sim_success(e)) {
      *success = 1;
      break;
    }
    if (hearth_sim_failure(e)) break;
  }
  return HEARTH_OK;
}

/* dynamic temperatures: the columns of obs/thermal_state (names and heat
 * capacities of every object's regions) */
static hearth_status thermal_columns(const hearth_sim_env *e, sim_demo *b, hearth_err *err) {
  b->nth = hearth_sim_thermal_state(e, NULL, 0);
  if (!b->nth) return HEARTH_OK;
  hearth_strbuf names = {0};
  b->th_C = hearth_alloc_array(b->nth, sizeof(double));
  size_t j = 0;
  for (int k = 0; k < SIM_NOBJ; k++) {
    const hearth_thermo_net *n = hearth_sim_thermal_net(e, k);
    for (size_t r = 0; r < n->n; r++, j++) {
      hearth_strbuf_printf(&names, "%sobj%d/%s/%s/%s", j ? ";" : "", k, e->assets[k].category,
                           e->assets[k].state, n->region[r].name);
      if (b->th_C) b->th_C[j] = n->region[r].C;
    }
  }
  b->th_names = hearth_strbuf_take(&names);
  if (!b->th_C || !b->th_names)
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim collect: out of memory");
  return HEARTH_OK;
}

/* the state of one collection: its env, the files it writes and the two
 * rollouts of the slot at hand */
typedef struct collect_run {
  const hearth_sim_collect_opts *o;
  hearth_sim_env *env;
  int nfile; /* 1, or 2 with split_instructions */
  char path[2][4200];
  sim_h5_out out[2];
  sim_h5_meta meta[2];
  char *model_file; /* the scene's MJCF, stored with every demo */
  sim_demo demo[2]; /* instruction 0, 1 */
} collect_run;

static void run_free(collect_run *c) {
  for (int i = 0; i < 2; i++) {
    sim_h5_abort(&c->out[i]);
    sim_h5_meta_free(&c->meta[i]);
    sim_demo_free(&c->demo[i]);
  }
  free(c->model_file);
  hearth_sim_env_free(c->env);
}

/* the env, the description of each file and the files themselves */
static hearth_status run_open(collect_run *c, hearth_err *err) {
  const hearth_sim_collect_opts *o = c->o;
  for (int i = 0; i < 2; i++) c->out[i].f = c->out[i].data = -1;
  hearth_sim_opts so;
  hearth_sim_opts_default(&so);
  so.task = o->task;
  so.release_root = o->release_root;
  so.use_ground_truth = o->use_ground_truth;
  so.width = so.height = o->image_size;
  so.max_steps = o->max_steps;
  so.shadows = o->shadows;
  so.renderer = o->renderer;
  so.gl = o->gl;
  so.thermal = o->thermal;
  if (o->thermal_speedup > 0) so.thermal_speedup = o->thermal_speedup;
  hearth_status st = hearth_sim_env_new(&so, &c->env, err);
  if (st) return st;
  if (!o->quiet) fprintf(stderr, "renderer: %s\n", hearth_sim_renderer(c->env));
  hearth_strbuf mj = {0};
  sim_mjcf_scene_text(c->env, ".", &mj);
  if (!(c->model_file = hearth_strbuf_take(&mj)))
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim collect: out of memory");
  c->nfile = o->split_instructions ? 2 : 1;
  for (int i = 0; i < 2; i++) {
    c->demo[i].nstate = hearth_sim_state(c->env, NULL, 0);
    /* renderer none: no images to keep */
    c->demo[i].img = c->env->render_kind == SIM_RENDER_NONE
                         ? 0
                         : (size_t)o->image_size * (size_t)o->image_size * 3;
    if ((st = thermal_columns(c->env, &c->demo[i], err))) return st;
  }
  for (int i = 0; i < c->nfile && !st; i++) {
    if (c->nfile == 2) hearth_sim_split_path(o->out_path, i, c->path[i], sizeof c->path[i]);
    else snprintf(c->path[i], sizeof c->path[i], "%s", o->out_path);
    st = sim_h5_describe(o, c->nfile == 2 ? i : 0, c->nfile == 2 ? 1 : 2,
                         c->env->render_kind == SIM_RENDER_GL ? c->env->gl : c->env->render_name,
                         &c->meta[i], err);
    if (!st) st = sim_h5_create(&c->out[i], c->path[i], err);
  }
  return st;
}

/* fill slot k: its first candidate layout where the expert succeeds on
 * both instructions (any with keep_failures), stored in every file */
static hearth_status fill_slot(collect_run *c, int k, hearth_sim_collect_stats *stats,
                               hearth_err *err) {
  const hearth_sim_collect_opts *o = c->o;
  for (int j = 0; j < HEARTH_SIM_SLOT_TRIES; j++) {
    uint64_t l = (uint64_t)k + (uint64_t)j * 2u * HEARTH_SIM_MAX_LAYOUTS;
    int ok[2] = {0, 0};
    for (int ins = 0; ins < 2; ins++) {
      hearth_status st = rollout(c->env, o->seed, l, ins, &c->demo[ins], &ok[ins], err);
      if (st) return st;
      stats->attempts[ins]++;
      stats->successes[ins] += ok[ins];
      stats->steps += (long)c->demo[ins].T;
    }
    if (!(ok[0] && ok[1]) && !o->keep_failures) {
      stats->rejected_layouts++;
      continue;
    }
    for (int ins = 0; ins < 2; ins++) {
      sim_h5_out *out = &c->out[c->nfile == 2 ? ins : 0];
      hearth_status st =
          sim_h5_add_demo(out, &c->demo[ins], o->image_size,
                          hearth_sim_instruction_text(o->task, ins), c->model_file, err);
      if (st) return st;
    }
    return HEARTH_OK;
  }
  return hearth_err_set(
      err, HEARTH_E_NUMERIC,
      "sim collect %s: the expert failed on all %d candidate layouts of slot %d (layouts %d, "
      "%d + 200000 j ...); check the assets or pass --keep-failures",
      hearth_sim_task_name(o->task), HEARTH_SIM_SLOT_TRIES, k, k, k);
}

hearth_status hearth_sim_collect(const hearth_sim_collect_opts *o, hearth_sim_collect_stats *stats,
                                 hearth_err *err) {
  hearth_sim_collect_stats dummy;
  if (!stats) stats = &dummy;
  memset(stats, 0, sizeof *stats);
  if (!o->out_path) return hearth_err_set(err, HEARTH_E_ARG, "sim collect: no output path");
  if (o->layouts < 1 || o->layouts > HEARTH_SIM_MAX_LAYOUTS)
    return hearth_err_set(err, HEARTH_E_RANGE, "sim collect: layouts must be 1..%d, got %d",
                          HEARTH_SIM_MAX_LAYOUTS, o->layouts);
  int count = o->shard_count > 1 ? o->shard_count : 1,
      index = o->shard_count > 1 ? o->shard_index : 0;
  if (index < 0 || index >= count)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "sim collect: shard %d/%d: expected 0 <= index < count", o->shard_index,
                          o->shard_count);
  if (index >= o->layouts)
    return hearth_err_set(
        err, HEARTH_E_ARG,
        "sim collect: shard %d/%d has no slot of %d layout(s): use at most %d shards", index, count,
        o->layouts, o->layouts);
  double t0 = hearth_now();
  collect_run c = {.o = o};
  hearth_status st = run_open(&c, err);
  int slots = (o->layouts - index + count - 1) / count;
  hearth_progress pr;
  hearth_progress_begin(&pr, "collect", (size_t)slots * 2, o->quiet || st);
  for (int k = index; k < o->layouts && !st; k += count) {
    st = fill_slot(&c, k, stats, err);
    if (!st) stats->slots++;
    hearth_progress_step(&pr, 2);
  }
  hearth_progress_end(&pr);
  sim_h5_shard shard = {index, count, o->layouts};
  for (int i = 0; i < c.nfile && !st; i++) {
    stats->demos = c.out[i].ndemo;
    st = sim_h5_finish(&c.out[i], &c.meta[i], count > 1 ? &shard : NULL, err);
  }
  run_free(&c);
  stats->seconds = hearth_now() - t0;
  return st;
}
