/* private: the env struct shared by the sim sources, and the privileged
 * helpers of sim_env.c */
#ifndef HEARTH_SIM_ENV_H
#define HEARTH_SIM_ENV_H

#include "sim/sim_internal.h"
#include "sim/sim_tasks.h"

#define SIM_MAXNV 64

typedef struct sim_render sim_render;

/* one object's thermal model (sim_thermal.c): its network, the texture
 * regions it came from and what maps texels and contacts to regions */
typedef struct sim_thermal_obj {
  hearth_thermo_net net;
  double T0[HEARTH_THERMO_MAX_REGIONS]; /* region temperatures at reset */
  double heat_in;                       /* J from air, table, fingers since reset */
  double heat_link;                     /* J from the other objects since reset */
  size_t R;                             /* texture side */
  uint8_t *label;                       /* R*R network region per texel, 255: none */
  float *offset;                        /* R*R degC over the region's temperature */
  uint8_t *vregion;                     /* per mesh vertex: network region */
  int texid;                            /* the thermal texture in the model */
  int flip;                             /* model texture rows reversed from the map's */
} sim_thermal_obj;

/* H4's pot (sim_handles.c): collision boxes in its asset frame (handles
 * along x: handle 0 at -x, 1 at +x), the two temperature maps (map k:
 * handle k hot) and their Turbo textures, and the episode's hot handle */
typedef struct sim_handles {
  double rb;                          /* body radius, m */
  double body_c[3], body_half[3];     /* the body up to its shoulder */
  int has_lid;                        /* a lid's dome and knob rise above it */
  double lid_c[3], lid_half[3];       /* their box */
  double lug_c[2][3], lug_half[2][3]; /* each handle from the body out */
  double lug_reach[2];                /* |x| of each handle's far end */
  float *temp[2];                     /* R*R degC, rows as the asset's map */
  hearth_image turbo[2];              /* their thermal textures */
  int hot;                            /* the hot handle now */
  int texid, flip;                    /* the pot's thermal texture in the model */
  double finger_max_c;                /* hottest finger contact of the last step */
} sim_handles;

/* which renderer an env draws its views with */
enum { SIM_RENDER_SOFT = 0, SIM_RENDER_GL = 1, SIM_RENDER_NONE = 2 };

struct hearth_sim_env {
  hearth_sim_task task;
  int width, height, max_steps, render_wrist, shadows;
  char gl[16];
  int render_kind;     /* SIM_RENDER_* */
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
  int failed;         /* the episode can no longer succeed (hearth_sim_failure) */
  char fail_msg[160]; /* why */
  sim_render *rnd;
  /* H4 */
  sim_handles hd;
  int expert_lug; /* the handle the expert grasps: -1 the cool one (default) */
  /* dynamic temperatures */
  int thermal;
  double h_table, h_finger, h_object, thermal_speedup;
  int thermal_dirty; /* textures behind the networks' temperatures */
  int table_geom;
#define SIM_TH_LUT 2048
  uint8_t th_lut[SIM_TH_LUT][3]; /* Turbo over SIM_TLO..SIM_THI */
  sim_thermal_obj th[SIM_NOBJ];
  /* the last step's object-object links, at most one per pair of regions */
#define SIM_TH_MAX_LINKS \
  (SIM_NOBJ * (SIM_NOBJ - 1) / 2 * HEARTH_THERMO_MAX_REGIONS * HEARTH_THERMO_MAX_REGIONS)
  size_t n_th_links;
  hearth_thermo_link th_links[SIM_TH_MAX_LINKS];
};

/* visibility rule of a layout: both candidates at least this visible */
#define SIM_MIN_VISIBLE 0.7
#define SIM_MAX_ATTEMPTS 20
/* privileged helpers for tests and audits: object k's position (its
 * bottom centre) and teleporting it upright at rest to xyz */
void sim_object_pos(const hearth_sim_env *e, int k, double xyz[3]);
void sim_place_object(hearth_sim_env *e, int k, const double xyz[3]);
/* object k's mean temperature (heat-capacity weighted over its network's
 * regions) now or at reset, degC; NaN with static temperatures */
double sim_mean_temperature(const hearth_sim_env *e, int k, int at_reset);
/* fraction of object k's surface samples seen by the front camera */
double sim_visible_frac(const hearth_sim_env *e, int k);
/* sim_render.c: the GL context and scene of an env, and their release */
hearth_status sim_render_init(hearth_sim_env *e, hearth_err *err);
void sim_render_free(hearth_sim_env *e);
/* sim_render.c: the model's texture id was rewritten; update the renderer's copy */
void sim_render_texture_changed(hearth_sim_env *e, int texid);
/* sim_thermal.c: the objects' networks (after the model is loaded), their
 * reset, one control step's heat exchange, the textures from the current
 * temperatures, and their release */
hearth_status sim_thermal_init(hearth_sim_env *e, hearth_err *err);
void sim_thermal_reset(hearth_sim_env *e);
hearth_status sim_thermal_step(hearth_sim_env *e, double dt, hearth_err *err);
void sim_thermal_update_textures(hearth_sim_env *e);
void sim_thermal_free(hearth_sim_env *e);
/* sim_handles.c (tasks with td->handles): the handles' boxes and maps
 * from asset 0 (before the scene files are written: the asset's thermal
 * texture becomes map 1's), the model's texture found after loading, the
 * episode's map put into it at reset (handle 1 - swap hot), the pot's
 * collision boxes as MJCF, the temperature of the pot's surface nearest a
 * world point, the failure test over the finger pads' contacts, the grasp
 * point of a handle (world) and the handles' pixel boxes in the front view
 * (slot A handle 0, OpenGL rows) */
hearth_status sim_handles_init(hearth_sim_env *e, hearth_err *err);
hearth_status sim_handles_model(hearth_sim_env *e, hearth_err *err);
void sim_handles_free(sim_handles *hd);
void sim_handles_reset(hearth_sim_env *e);
void sim_handles_mjcf(const hearth_sim_env *e, double friction, hearth_strbuf *b);
double sim_handles_temp_at(const hearth_sim_env *e, const double p[3]);
void sim_handles_check(hearth_sim_env *e, double limit_c);
void sim_handles_grasp_point(const hearth_sim_env *e, int lug, double xyz[3]);
void sim_handles_boxes(const hearth_sim_env *e, int boxes[2][4]);

#endif
