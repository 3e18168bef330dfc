/* private: the env struct shared by the sim sources, and the privileged
 * helpers of sim_env.c */
#ifndef HEARTH_SIM_ENV_H
#define HEARTH_SIM_ENV_H

#include "sim/sim_internal.h"
#include "sim/sim_tasks.h"

#define SIM_MAXNV 64

typedef struct sim_render sim_render;

/* which renderer an env draws its views with */
enum { SIM_RENDER_SOFT = 0, SIM_RENDER_GL = 1, SIM_RENDER_NONE = 2 };

struct hearth_sim_env {
  hearth_sim_task task;
  int width, height, max_steps, render_wrist, shadows;
  char gl[16];
  int render_kind;    /* SIM_RENDER_* */
  char render_name[8]; /* "soft", "gl", "none" */
  char work_dir[4096];
  int own_work_dir;
  sim_asset assets[SIM_NOBJ]; /* 0, 1: candidates (instruction i targets i); 2, 3: distractors */
  mjModel *m;
  mjData *d;
  int site_grip, cam_front, cam_wrist, mat_geom;
  int arm_qadr[7], arm_dadr[7], fing_qadr[2], pad_geom[2];
  int obj_body[SIM_NOBJ], obj_qadr[SIM_NOBJ], obj_dadr[SIM_NOBJ];
  int obj_geom_rgb[SIM_NOBJ], obj_geom_th[SIM_NOBJ];
  /* episode */
  int swap, instruction, target, steps;
  int layout_attempts; /* draws the visibility check needed (1 = first) */
  double goal_pos[3], goal_R[9], R0[9], grip_cmd;
  int phase, phase_steps;
  sim_render *rnd;
};

/* visibility rule of a layout: both candidates at least this visible */
#define SIM_MIN_VISIBLE 0.7
#define SIM_MAX_ATTEMPTS 20
/* privileged helpers for tests and audits: object k's position (its
 * bottom centre) and teleporting it upright at rest to xyz */
void sim_object_pos(const hearth_sim_env *e, int k, double xyz[3]);
void sim_place_object(hearth_sim_env *e, int k, const double xyz[3]);
/* fraction of object k's surface samples seen by the front camera */
double sim_visible_frac(const hearth_sim_env *e, int k);
/* sim_render.c: the GL context and scene of an env, and their release */
hearth_status sim_render_init(hearth_sim_env *e, hearth_err *err);
void sim_render_free(hearth_sim_env *e);

#endif
