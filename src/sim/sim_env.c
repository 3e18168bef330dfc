/* The task environment: building it (assets, scene files, MuJoCo model,
 * renderer), episodes (reset with the visibility-checked layout, control
 * steps through the pose controller), its state and the success test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hearth/geom.h"
#include "sim/sim_control.h"
#include "sim/sim_env.h"
#include "sim/sim_mjcf.h"
#include "sim/sim_robot.h"

void hearth_sim_opts_default(hearth_sim_opts *o) {
  memset(o, 0, sizeof *o);
  o->task = HEARTH_SIM_H1;
  o->use_ground_truth = 1;
  o->width = o->height = 256;
  o->max_steps = 400;
  o->render_wrist = 1;
  o->thermal = HEARTH_SIM_THERMAL_STATIC;
  o->h_contact_table = o->h_contact_finger = o->h_contact_object = HEARTH_SIM_H_CONTACT;
  o->thermal_speedup = 1.0;
}

/* ---- env construction ---------------------------------------------------- */
void hearth_sim_env_free(hearth_sim_env *e) {
  if (!e) return;
  sim_render_free(e);
  sim_thermal_free(e);
  sim_handles_free(&e->hd);
  if (e->d) mj_deleteData(e->d);
  if (e->m) mj_deleteModel(e->m);
  for (int k = 0; k < SIM_NOBJ; k++) sim_asset_free(&e->assets[k]);
  if (e->own_work_dir && e->work_dir[0]) hearth_remove_tree(e->work_dir, NULL);
  free(e);
}

/* a task's candidates that stood in the room before the episode (H5's cup
 * filled earlier): their networks' reset temperatures carried forward by
 * age_s of still-air exchange, in 10 s steps */
static hearth_status age_candidates(hearth_sim_env *e, hearth_err *err) {
  const sim_task_def *td = sim_task_get(e->task);
  if (e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return HEARTH_OK;
  for (int k = 0; k < 2; k++) {
    if (!(td->age_s[k] > 0)) continue;
    sim_thermal_obj *o = &e->th[k];
    hearth_thermo_net net = o->net;
    hearth_thermo_clear_contacts(&net);
    for (size_t i = 0; i < net.n; i++) net.region[i].T = o->T0[i];
    int n = (int)ceil(td->age_s[k] / 10.0);
    for (int s = 0; s < n; s++) {
      double q = 0;
      hearth_status st = hearth_thermo_step(&net, td->age_s[k] / n, &q, err);
      if (st) return hearth_err_prefix(err, "sim %s candidate %d: ", td->name, k);
    }
    for (size_t i = 0; i < net.n; i++) o->T0[i] = net.region[i].T;
  }
  sim_thermal_reset(e);
  return HEARTH_OK;
}

hearth_status hearth_sim_env_new(const hearth_sim_opts *o, hearth_sim_env **out, hearth_err *err) {
  *out = NULL;
  if (!o || !hearth_sim_task_valid(o->task))
    return hearth_err_set(err, HEARTH_E_ARG, "sim: task must be H1, H2, H3, H4, H5 or H6");
  if (!o->release_root) return hearth_err_set(err, HEARTH_E_ARG, "sim: no asset release root");
  if (o->width < 16 || o->height < 16 || o->width > 4096 || o->height > 4096)
    return hearth_err_set(err, HEARTH_E_RANGE, "sim: image size %dx%d outside 16..4096", o->width,
                          o->height);
  hearth_sim_env *e = calloc(1, sizeof *e);
  if (!e) return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory");
  e->task = o->task;
  e->width = o->width, e->height = o->height;
  e->max_steps = o->max_steps > 0 ? o->max_steps : 400;
  e->render_wrist = o->render_wrist;
  e->shadows = o->shadows;
  if (o->thermal != HEARTH_SIM_THERMAL_STATIC && o->thermal != HEARTH_SIM_THERMAL_DYNAMIC) {
    free(e);
    return hearth_err_set(err, HEARTH_E_ARG, "sim: thermal mode %d is not static or dynamic",
                          o->thermal);
  }
  if (!(o->h_contact_table >= 0 && o->h_contact_finger >= 0 && o->h_contact_object >= 0 &&
        isfinite(o->h_contact_table) && isfinite(o->h_contact_finger) &&
        isfinite(o->h_contact_object))) {
    free(e);
    return hearth_err_set(err, HEARTH_E_RANGE, "sim: contact conductances must be finite, >= 0");
  }
  e->thermal = o->thermal;
  e->h_table = o->h_contact_table, e->h_finger = o->h_contact_finger;
  e->h_object = o->h_contact_object;
  e->thermal_speedup = o->thermal_speedup > 0 ? o->thermal_speedup : 1.0;
  /* tasks of changing temperatures run dynamic at their own pace */
  const sim_task_def *tdef = sim_task_get(e->task);
  if (tdef->dynamic) e->thermal = HEARTH_SIM_THERMAL_DYNAMIC, e->thermal_speedup = tdef->speedup;
  /* H4's per-layout map is of the asset's fixed temperatures */
  if (tdef->handles) e->thermal = HEARTH_SIM_THERMAL_STATIC;
  e->expert_lug = -1;
  if (!isfinite(e->thermal_speedup) || e->thermal_speedup > 1e6) {
    free(e);
    return hearth_err_set(err, HEARTH_E_RANGE, "sim: thermal speed-up must be in (0, 1e6]");
  }
  const char *gl = o->gl && *o->gl ? o->gl : getenv("HEARTH_GL");
  if (!gl || !*gl) gl = "osmesa";
  if (strcmp(gl, "osmesa") != 0 && strcmp(gl, "egl") != 0) {
    free(e);
    return hearth_err_set(err, HEARTH_E_ARG,
                          "sim: renderer '%s' is not osmesa or egl (option gl / HEARTH_GL)", gl);
  }
  snprintf(e->gl, sizeof e->gl, "%s", gl);
  /* the renderer: soft unless shadows are asked for without naming one */
  const char *rn = o->renderer && *o->renderer ? o->renderer : getenv("HEARTH_RENDERER");
  if (!rn || !*rn) rn = o->shadows ? "gl" : "soft";
  if (strcmp(rn, "soft") == 0) e->render_kind = SIM_RENDER_SOFT;
  else if (strcmp(rn, "gl") == 0) e->render_kind = SIM_RENDER_GL;
  else if (strcmp(rn, "none") == 0) e->render_kind = SIM_RENDER_NONE;
  else {
    free(e);
    return hearth_err_set(err, HEARTH_E_ARG,
                          "sim: renderer '%s' is not soft, gl or none (option renderer / "
                          "HEARTH_RENDERER)",
                          rn);
  }
  if (e->render_kind == SIM_RENDER_SOFT && o->shadows) {
    free(e);
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "sim: the soft renderer draws no shadows: use renderer gl with shadows");
  }
  snprintf(e->render_name, sizeof e->render_name, "%s", rn);
  hearth_status st = HEARTH_OK;
  if (o->work_dir) {
    snprintf(e->work_dir, sizeof e->work_dir, "%s", o->work_dir);
    st = hearth_mkdirs(e->work_dir, err);
  } else {
    const char *tmp = getenv("TMPDIR");
    snprintf(e->work_dir, sizeof e->work_dir, "%s/hearth_sim_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(e->work_dir)) {
      st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot create a scratch directory", e->work_dir);
      e->work_dir[0] = 0;
    } else {
      e->own_work_dir = 1;
    }
  }
  /* assets: two candidates, two distractors */
  const sim_task_def *td = sim_task_get(e->task);
  for (int k = 0; k < SIM_NOBJ && !st; k++) {
    const sim_task_obj *to = k < 2 ? &td->cand[k] : &td->dist[k - 2];
    st = sim_asset_load(o->release_root, o->use_ground_truth, to->category, to->state,
                        &e->assets[k], err);
    if (!st && k == 0 && td->handles) st = sim_handles_init(e, err);
    char p[4200];
    if (!st) {
      snprintf(p, sizeof p, "%s/obj%d.obj", e->work_dir, k);
      st = sim_obj_write(p, &e->assets[k].mesh, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/rgb%d.png", e->work_dir, k);
      st = hearth_png_write(p, &e->assets[k].rgb, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/th%d.png", e->work_dir, k);
      st = hearth_png_write(p, &e->assets[k].thermal, err);
    }
  }
  char xml[4200];
  snprintf(xml, sizeof xml, "%s/scene.xml", e->work_dir);
  if (!st) st = sim_mjcf_write_scene(e, xml, err);
  if (!st) {
    char msg[1000] = "";
    e->m = mj_loadXML(xml, NULL, msg, sizeof msg);
    if (!e->m) st = hearth_err_set(err, HEARTH_E_PARSE, "%s: MuJoCo: %s", xml, msg);
  }
  if (!st) {
    e->d = mj_makeData(e->m);
    if (!e->d) st = hearth_err_set(err, HEARTH_E_NOMEM, "sim: mj_makeData failed");
  }
  if (!st) {
    mjModel *m = e->m;
    e->site_grip = mj_name2id(m, mjOBJ_SITE, "grip");
    e->cam_front = mj_name2id(m, mjOBJ_CAMERA, "agentview");
    e->cam_wrist = mj_name2id(m, mjOBJ_CAMERA, "eye_in_hand");
    for (int i = 0; i < 7; i++) {
      char nm[16];
      snprintf(nm, sizeof nm, "j%d", i + 1);
      int j = mj_name2id(m, mjOBJ_JOINT, nm);
      e->arm_qadr[i] = m->jnt_qposadr[j], e->arm_dadr[i] = m->jnt_dofadr[j];
    }
    for (int s = 0; s < 2; s++) {
      char nm[16];
      snprintf(nm, sizeof nm, "finger_%d", s + 1);
      int j = mj_name2id(m, mjOBJ_JOINT, nm);
      e->fing_qadr[s] = m->jnt_qposadr[j];
      snprintf(nm, sizeof nm, "pad_%d", s + 1);
      e->pad_geom[s] = mj_name2id(m, mjOBJ_GEOM, nm);
    }
    for (int k = 0; k < SIM_NOBJ; k++) {
      char nm[32];
      snprintf(nm, sizeof nm, "obj%d", k);
      e->obj_body[k] = mj_name2id(m, mjOBJ_BODY, nm);
      snprintf(nm, sizeof nm, "obj%d_free", k);
      int j = mj_name2id(m, mjOBJ_JOINT, nm);
      e->obj_qadr[k] = m->jnt_qposadr[j], e->obj_dadr[k] = m->jnt_dofadr[j];
      snprintf(nm, sizeof nm, "obj%d_rgb", k);
      e->obj_geom_rgb[k] = mj_name2id(m, mjOBJ_GEOM, nm);
      snprintf(nm, sizeof nm, "obj%d_th", k);
      e->obj_geom_th[k] = mj_name2id(m, mjOBJ_GEOM, nm);
    }
    e->mat_geom = mj_name2id(m, mjOBJ_GEOM, "mat");
    e->table_geom = mj_name2id(m, mjOBJ_GEOM, "table");
    st = sim_render_init(e, err);
    if (!st && td->handles) st = sim_handles_model(e, err);
    if (!st) st = sim_thermal_init(e, err);
    if (!st) st = age_candidates(e, err);
  }
  if (st) {
    hearth_sim_env_free(e);
    return st;
  }
  *out = e;
  return HEARTH_OK;
}

/* ---- episodes -------------------------------------------------------------- */
void sim_object_pos(const hearth_sim_env *e, int k, double xyz[3]) {
  for (int i = 0; i < 3; i++) xyz[i] = e->d->qpos[e->obj_qadr[k] + i];
}

void sim_place_object(hearth_sim_env *e, int k, const double xyz[3]) {
  double *q = e->d->qpos + e->obj_qadr[k], *v = e->d->qvel + e->obj_dadr[k];
  for (int i = 0; i < 3; i++) q[i] = xyz[i];
  q[3] = 1, q[4] = q[5] = q[6] = 0;
  for (int i = 0; i < 6; i++) v[i] = 0;
  mj_forward(e->m, e->d);
}

/* fraction of object k's surface samples (up to 96 mesh vertices) that the
 * front camera sees: inside its field of view and not hidden by another
 * geom. Ray casts, so it does not depend on the rendered image size */
double sim_visible_frac(const hearth_sim_env *e, int k) {
  const mjModel *m = e->m;
  const mjData *d = e->d;
  const hearth_mesh *me = &e->assets[k].mesh;
  const double *bp = d->xpos + 3 * e->obj_body[k], *bR = d->xmat + 9 * e->obj_body[k];
  const double *cp = d->cam_xpos + 3 * e->cam_front, *cR = d->cam_xmat + 9 * e->cam_front;
  double th = tan(0.5 * m->cam_fovy[e->cam_front] * M_PI / 180.0);
  double aspect = (double)e->width / (double)e->height;
  /* robot, scene and colour meshes; not the thermal copies or the boxes */
  mjtByte groups[mjNGROUP] = {1, 1, 1, 0, 0, 0};
  size_t n = me->n_vertices, stride = n > 96 ? n / 96 : 1;
  int total = 0, seen = 0;
  for (size_t i = 0; i < n && total < 96; i += stride) {
    const float *v = me->positions + 3 * i;
    double p[3], dir[3], c[3];
    for (int r = 0; r < 3; r++)
      p[r] = bp[r] + bR[3 * r] * v[0] + bR[3 * r + 1] * v[1] + bR[3 * r + 2] * v[2];
    for (int r = 0; r < 3; r++) dir[r] = p[r] - cp[r];
    /* camera frame: columns of cam_xmat are its x, y, z axes; it looks along -z */
    for (int r = 0; r < 3; r++) c[r] = cR[r] * dir[0] + cR[3 + r] * dir[1] + cR[6 + r] * dir[2];
    total++;
    if (c[2] > -1e-6 || fabs(c[0] / -c[2]) > th * aspect || fabs(c[1] / -c[2]) > th) continue;
    int gid = -1;
    mjtNum x = mj_ray(m, d, cp, dir, groups, 1, -1, &gid);
    if (gid < 0 || x > 1.0 - 0.01 / hearth_norm3(dir) || m->geom_bodyid[gid] == e->obj_body[k])
      seen++;
  }
  return total ? (double)seen / total : 0.0;
}

hearth_status hearth_sim_reset(hearth_sim_env *e, uint64_t seed, uint64_t layout, int instruction,
                               hearth_err *err) {
  if (instruction < 0 || instruction > 1)
    return hearth_err_set(err, HEARTH_E_ARG, "sim reset: instruction must be 0 or 1, got %d",
                          instruction);
  mjModel *m = e->m;
  mjData *d = e->d;
  const sim_task_def *td = sim_task_get(e->task);
  mj_resetData(m, d);
  e->instruction = instruction;
  e->target = sim_task_target(td, instruction); /* object index of the target */
  for (int i = 0; i < 7; i++) d->qpos[e->arm_qadr[i]] = sim_robot_q_start[i];
  for (int s = 0; s < 2; s++) d->qpos[e->fing_qadr[s]] = 0.04;
  /* visibility check: redraw the layout until both candidates are at
   * least SIM_MIN_VISIBLE visible in the front view (else keep the best
   * draw); the draw depends on (seed, layout) only, never on the
   * instruction, so both instructions start from the same state */
  int best = 0;
  double best_vis = -1;
  for (int attempt = 0; attempt < SIM_MAX_ATTEMPTS; attempt++) {
    double pos[SIM_NOBJ][2];
    int swap;
    sim_layout(seed, layout, attempt, sim_task_spots(td), pos, &swap);
    e->swap = swap;
    for (int k = 0; k < SIM_NOBJ; k++) {
      int slot = k < 2 && !td->handles ? (k ^ swap) : k;
      double *q = d->qpos + e->obj_qadr[k];
      q[0] = pos[slot][0], q[1] = pos[slot][1], q[2] = HEARTH_SIM_TABLE_Z + 0.0005;
      q[3] = 1, q[4] = q[5] = q[6] = 0;
      /* the pot a quarter turn about z: its handles along world y */
      if (k == 0 && td->handles) q[3] = q[6] = sqrt(0.5);
    }
    mj_forward(m, d);
    double vis = fmin(sim_visible_frac(e, 0), sim_visible_frac(e, 1));
    if (vis > best_vis) best_vis = vis, best = attempt;
    if (vis >= SIM_MIN_VISIBLE) break;
    if (attempt == SIM_MAX_ATTEMPTS - 1 && best != attempt) {
      /* none passed: go back to the best draw */
      sim_layout(seed, layout, best, sim_task_spots(td), pos, &swap);
      for (int k = 0; k < SIM_NOBJ; k++) {
        int slot = k < 2 && !td->handles ? (k ^ swap) : k;
        d->qpos[e->obj_qadr[k]] = pos[slot][0], d->qpos[e->obj_qadr[k] + 1] = pos[slot][1];
      }
      mj_forward(m, d);
    }
  }
  e->layout_attempts = best + 1;
  for (int i = 0; i < 3; i++) e->goal_pos[i] = d->site_xpos[3 * e->site_grip + i];
  memcpy(e->goal_R, d->site_xmat + 9 * e->site_grip, sizeof e->goal_R);
  memcpy(e->R0, e->goal_R, sizeof e->R0);
  if (td->handles) {
    /* the expert's hand a quarter turn about z: the fingers close along
     * world x, across the handle */
    const double Rz[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
    hearth_mat3_mul(Rz, e->goal_R, e->R0);
    sim_handles_reset(e);
  }
  e->grip_cmd = -1;
  /* let the objects settle with the arm held */
  for (int i = 0; i < 50; i++) {
    mj_step1(m, d);
    sim_osc(e);
    mj_step2(m, d);
  }
  mj_forward(m, d);
  e->steps = 0;
  e->phase = 0;
  e->phase_steps = 0;
  e->failed = 0;
  e->fail_msg[0] = 0;
  sim_thermal_reset(e);
  return HEARTH_OK;
}

double sim_mean_temperature(const hearth_sim_env *e, int k, int at_reset) {
  if (e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return NAN;
  const sim_thermal_obj *o = &e->th[k];
  if (!at_reset) return hearth_thermo_mean_temperature(&o->net);
  double cT = 0, c = 0;
  for (size_t i = 0; i < o->net.n; i++)
    cT += o->net.region[i].C * o->T0[i], c += o->net.region[i].C;
  return c > 0 ? cT / c : NAN;
}

/* the task's failure rules after a step: H4's finger on the pot above the
 * limit, H6's target warming past its limit before it is placed */
static void check_failure(hearth_sim_env *e) {
  const sim_task_def *td = sim_task_get(e->task);
  if (!e->failed && td->handles) sim_handles_check(e, td->handle_limit_c);
  if (e->failed || !(td->warm_limit_c > 0)) return;
  if (!(sim_mean_temperature(e, e->target, 1) < td->warm_limit_c)) return;
  double T = sim_mean_temperature(e, e->target, 0);
  if (T > td->warm_limit_c && !hearth_sim_success(e)) {
    e->failed = 1;
    snprintf(e->fail_msg, sizeof e->fail_msg,
             "the %s warmed past %.1f degC before it was placed (step %d)",
             td->cand[e->target].noun, td->warm_limit_c, e->steps);
  }
}

const char *hearth_sim_failure(const hearth_sim_env *e) { return e->failed ? e->fail_msg : NULL; }

hearth_status hearth_sim_step(hearth_sim_env *e, const double action[7], hearth_err *err) {
  double a[7];
  for (int i = 0; i < 7; i++) {
    if (!isfinite(action[i]))
      return hearth_err_set(err, HEARTH_E_RANGE, "sim step: action[%d] is not finite", i);
    a[i] = action[i] < -1 ? -1 : action[i] > 1 ? 1 : action[i];
  }
  mjModel *m = e->m;
  mjData *d = e->d;
  mj_forward(m, d);
  /* goal = current + scaled delta, held for the 25 physics steps */
  const double *x = d->site_xpos + 3 * e->site_grip, *R = d->site_xmat + 9 * e->site_grip;
  for (int i = 0; i < 3; i++) e->goal_pos[i] = x[i] + 0.05 * a[i];
  double w[3] = {0.5 * a[3], 0.5 * a[4], 0.5 * a[5]}, dR[9];
  hearth_rotvec_to_matrix(w, dR);
  hearth_mat3_mul(dR, R, e->goal_R);
  e->grip_cmd = a[6];
  int sub = (int)lround(1.0 / (HEARTH_SIM_CONTROL_HZ * HEARTH_SIM_TIMESTEP));
  for (int s = 0; s < sub; s++) {
    mj_step1(m, d);
    sim_osc(e);
    mj_step2(m, d);
  }
  mj_forward(m, d);
  for (int i = 0; i < m->nq; i++)
    if (!isfinite(d->qpos[i]))
      return hearth_err_set(err, HEARTH_E_NUMERIC, "sim step %d: the simulation diverged",
                            e->steps);
  /* the heat exchanged over the control step, with the contacts at its end */
  hearth_status st = sim_thermal_step(e, e->thermal_speedup / HEARTH_SIM_CONTROL_HZ, err);
  if (st) return st;
  e->steps++;
  check_failure(e);
  return HEARTH_OK;
}

/* ---- state, success ---------------------------------------------------------- */
int hearth_sim_steps(const hearth_sim_env *e) { return e->steps; }
int hearth_sim_max_steps(const hearth_sim_env *e) { return e->max_steps; }
const char *hearth_sim_instruction(const hearth_sim_env *e) {
  return hearth_sim_instruction_text(e->task, e->instruction);
}
size_t hearth_sim_state(const hearth_sim_env *e, double *s, size_t max) {
  size_t n = 1 + (size_t)e->m->nq + (size_t)e->m->nv;
  if (s && max >= n) {
    s[0] = e->d->time;
    memcpy(s + 1, e->d->qpos, sizeof(double) * (size_t)e->m->nq);
    memcpy(s + 1 + e->m->nq, e->d->qvel, sizeof(double) * (size_t)e->m->nv);
  }
  return n;
}

static int touching(const hearth_sim_env *e, int geom_a, int body_b) {
  const mjData *d = e->d;
  for (int i = 0; i < d->ncon; i++) {
    int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2;
    if ((g1 == geom_a && e->m->geom_bodyid[g2] == body_b) ||
        (g2 == geom_a && e->m->geom_bodyid[g1] == body_b))
      return 1;
  }
  return 0;
}

int hearth_sim_success(const hearth_sim_env *e) {
  if (e->failed) return 0;
  const mjData *d = e->d;
  int k = e->target;
  const double *q = d->qpos + e->obj_qadr[k], *v = d->qvel + e->obj_dadr[k];
  double top = HEARTH_SIM_TABLE_Z + 0.002;
  if (fabs(q[0] - sim_mat_centre[0]) > SIM_MAT_HALF ||
      fabs(q[1] - sim_mat_centre[1]) > SIM_MAT_HALF)
    return 0;
  /* resting on the mat: its frame origin (bottom centre) at the mat top,
   * upright enough, slow */
  if (q[2] < top - 0.02 || q[2] > top + 0.02) return 0;
  if (sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) > 0.05) return 0;
  for (int s = 0; s < 2; s++)
    if (touching(e, e->pad_geom[s], e->obj_body[k])) return 0;
  return 1;
}
