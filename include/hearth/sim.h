/* hearth/sim.h - area sim (src/sim/; built with HEARTH_SIM, links MuJoCo,
 * OSMesa and HDF5): the paper's three temperature-aware pick-and-place tasks
 * (H1 study table: hot/normal cup; H2 kitchen: iced/normal can; H3 kitchen:
 * hot phone/hot sponge), one that needs where an object is hot (H4: a pot
 * grasped by its cool handle) and two whose temperatures change (H5: the
 * cup still warm; H6: the iced can before it warms up) on MuJoCo, with hearth
 * assets, a Panda arm under an operational-space pose controller, three
 * rendered views (front RGB, front thermal, wrist RGB), a scripted expert
 * and a LIBERO-layout HDF5 writer.
 * Scenes, robot, controller, file layout and image conventions:
 * docs/simulation.md.
 *
 * Frames: world z up, table top centre at (0, 0, HEARTH_SIM_TABLE_Z), the
 * robot base behind the table at x = -0.66 facing +x. Images are RGB U8 in
 * OpenGL row order (bottom row first), as LIBERO stores them. */
#ifndef HEARTH_SIM_H
#define HEARTH_SIM_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"
#include "hearth/thermo.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The orientation the policy state's axis-angle is continuous around (w x y
 * z): the hand pointing straight down, half a turn about world x. The
 * LeRobot export (export.h) and the evaluation's observation both write
 * hearth_rotvec_to_axis_angle_near(ee_ori, this), so a policy sees in
 * evaluation the state it was trained on. */
#define HEARTH_SIM_STATE_QUAT_REF \
  { 0.0, 1.0, 0.0, 0.0 }

#define HEARTH_SIM_TABLE_Z 0.90
#define HEARTH_SIM_CONTROL_HZ 20
#define HEARTH_SIM_TIMESTEP 0.002

/* H1-H3: the paper's tasks (static temperatures by default). H4: a hot pot
 * with two handles alike in colour, one of them hot (which one changes
 * with the layout): grasp it by the cool one and place it on the mat (the
 * trivet); a finger touching the pot above 45 degC fails the episode
 * (always static temperatures). H5, H6 need temperatures that change and
 * always run with dynamic ones: H5 two identical hot cups, one filled half
 * an hour before the other; H6 an iced can that must be on the mat before
 * it warms past a limit. docs/simulation.md, "Tasks". */
typedef enum hearth_sim_task {
  HEARTH_SIM_H1 = 1,
  HEARTH_SIM_H2 = 2,
  HEARTH_SIM_H3 = 3,
  HEARTH_SIM_H4 = 4,
  HEARTH_SIM_H5 = 5,
  HEARTH_SIM_H6 = 6
} hearth_sim_task;
/* task numbers are below this */
#define HEARTH_SIM_TASK_END 7

/* Parse "H1".."H6" (case-insensitive); 0 if unknown or not built. */
hearth_sim_task hearth_sim_task_parse(const char *s);
/* 1 when t is a task of the table */
int hearth_sim_task_valid(hearth_sim_task t);
/* "H1".."H6" ("?" for an invalid task); a static string. */
const char *hearth_sim_task_name(hearth_sim_task t);
/* The instruction (0 or 1) of a task: "pick up the hot cup and place it on
 * the mat", ...; a static string, "" for invalid arguments. */
const char *hearth_sim_instruction_text(hearth_sim_task t, int instruction);

/* Where the assets come from. A release root holds the instances of the
 * categories a task needs (cup, canned_drink, electric_kettle, eraser,
 * orange, pot, smartphone, sponge) in the states it needs (neutral, hot, iced).
 * With use_ground_truth (virtual-rig releases) the metric mesh is
 * ground_truth/instances/<id>/mesh.glb and temperatures come from
 * <state>/temperature_true.npy; otherwise derived/mesh.glb and
 * derived/<state>/thermal_turbo.png. Strings are borrowed for the call that
 * takes the options. */
/* temperature textures: fixed (the paper) or from a lumped thermal model
 * per object (docs/simulation.md, "Dynamic temperatures") */
typedef enum hearth_sim_thermal {
  HEARTH_SIM_THERMAL_STATIC = 0,
  HEARTH_SIM_THERMAL_DYNAMIC = 1
} hearth_sim_thermal;
/* "static" / "dynamic" -> the mode, -1 if neither */
int hearth_sim_thermal_parse(const char *s);
/* air, table and fingers, degC */
#define HEARTH_SIM_THERMAL_ROOM 22.0
/* default contact conductance per unit area, W/(m^2 K): a light dry
 * press of non-metal surfaces (docs/simulation.md has the reasoning) */
#define HEARTH_SIM_H_CONTACT 1000.0

typedef struct hearth_sim_opts {
  hearth_sim_task task;
  const char *release_root;
  int use_ground_truth;
  int width, height;    /* rendered size of every view; default 256 */
  int max_steps;        /* time limit in control steps; default 400 */
  int render_wrist;     /* default 1 */
  int shadows;          /* shadow-mapped light in the RGB views; default 0
                          * (a shadow-map pass per lit view, costly on the
                          * CPU; the thermal view is unlit either way) */
  const char *renderer; /* "soft": hearth's software rasteriser (the
                          * default: the same bytes on every machine, no
                          * shadows); "gl": MuJoCo's OpenGL renderer
                          * through the back end `gl` (shadows, large
                          * images); "none": no images (observe leaves
                          * the image pointers NULL; physics and control
                          * alone). NULL: $HEARTH_RENDERER, else "gl" with
                          * shadows and "soft" without */
  const char *gl;       /* GL back end of renderer "gl": "osmesa" (CPU,
                          * default) or "egl" (GPU through EGL's device
                          * platform, else Mesa's surfaceless platform);
                          * NULL: $HEARTH_GL, else "osmesa" */
  const char *work_dir; /* scratch for the MJCF/mesh files; NULL = a fresh dir under
                          * $TMPDIR (else /tmp), removed with the env */
  int thermal;          /* HEARTH_SIM_THERMAL_STATIC (default: the paper's fixed
                          * temperature textures) or _DYNAMIC (a lumped thermal
                          * network per object, integrated with the physics);
                          * H4 is always static, H5 and H6 always dynamic */
  /* dynamic: contact conductances per unit area, W/(m^2 K), of the table
   * (and mat) and of the finger pads, both held at HEARTH_SIM_THERMAL_ROOM;
   * defaults HEARTH_SIM_H_CONTACT; 0 removes that kind of link */
  double h_contact_table, h_contact_finger;
  /* dynamic: contact conductance per unit area, W/(m^2 K), of two objects
   * touching (a link between their networks); default HEARTH_SIM_H_CONTACT,
   * 0 removes the links */
  double h_contact_object;
  /* dynamic: thermal seconds per simulated second (default 1; e.g. 60
   * makes a 20 s episode show 20 minutes of cooling), > 0; H5 and H6 use
   * their own (30 and 80) */
  double thermal_speedup;
} hearth_sim_opts;
void hearth_sim_opts_default(hearth_sim_opts *o);

typedef struct hearth_sim_env hearth_sim_env;

/* Build the scene (assets, model, renderer) for a task, with the GL back end
 * of o->gl. The env owns everything it made; hearth_sim_env_free releases it
 * (NULL is fine). Use an env from one thread at a time. */
hearth_status hearth_sim_env_new(const hearth_sim_opts *o, hearth_sim_env **out, hearth_err *err);
void hearth_sim_env_free(hearth_sim_env *env);
/* The renderer in use, e.g. "soft: hearth rasteriser 1", "osmesa:
 * llvmpipe (...)", "egl device: NVIDIA H100 ..." or "none"; owned by the
 * env. */
const char *hearth_sim_renderer(const hearth_sim_env *env);

/* Start an episode: layout `layout` of the stream `seed` (object positions
 * and the candidate-to-slot assignment, identical for both instructions),
 * asking for `instruction` (0 or 1). Positions are redrawn from the
 * layout's own stream until both candidates are at least 70% visible from
 * the front camera (ray casts: independent of the image size). */
hearth_status hearth_sim_reset(hearth_sim_env *env, uint64_t seed, uint64_t layout, int instruction,
                               hearth_err *err);

/* One control step (25 physics steps): action [dx dy dz dax day daz grip] in
 * [-1, 1] (clipped; non-finite is HEARTH_E_RANGE), 1.0 = 0.05 m / 0.5 rad
 * (world frame, at the grip site); grip -1 open, +1 closed. */
hearth_status hearth_sim_step(hearth_sim_env *env, const double action[7], hearth_err *err);

typedef struct hearth_sim_obs {
  int width, height;
  uint8_t *agentview_rgb; /* width*height*3, owned by the env, valid until next observe */
  uint8_t *agentview_thermal;
  uint8_t *eye_in_hand_rgb; /* NULL if the wrist view is off */
  double joint_states[7];
  double gripper_states[2]; /* left finger, minus right finger position (m) */
  double ee_pos[3];         /* grip site, world, m */
  double ee_ori[3];         /* axis-angle of the end-effector rotation */
  double ee_quat[4];        /* w x y z */
} hearth_sim_obs;

/* Render the views and read the robot state into obs (its image buffers
 * belong to the env). */
hearth_status hearth_sim_observe(hearth_sim_env *env, hearth_sim_obs *obs, hearth_err *err);

/* 1 when the target rests on the mat, released by the gripper, and the
 * episode has not failed. */
int hearth_sim_success(const hearth_sim_env *env);
/* Why the episode can no longer succeed (H4: "a finger touched the pot at
 * 58.1 degC, above 45 degC"; H6: "the iced can warmed past 10.5 degC
 * before it was placed"), NULL while it can; owned by the env,
 * valid until the next reset. Failure is checked after every step. */
const char *hearth_sim_failure(const hearth_sim_env *env);
/* Control steps since reset; the time limit. */
int hearth_sim_steps(const hearth_sim_env *env);
int hearth_sim_max_steps(const hearth_sim_env *env);
const char *hearth_sim_instruction(const hearth_sim_env *env);
/* Full simulator state [time, qpos, qvel]; returns its length and writes it
 * into state only when max is at least that (state may be NULL). */
size_t hearth_sim_state(const hearth_sim_env *env, double *state, size_t max);
/* Fraction of the target candidate's and the other candidate's pixels
 * visible in the front view at the current state, from segmentation
 * renders (privileged; tests and audits). */
hearth_status hearth_sim_visibility(hearth_sim_env *env, double *target_frac, double *other_frac,
                                    hearth_err *err);
/* Pixel boxes [x0 y0 x1 y1] (OpenGL rows) of the two candidates in the
 * front view, slot A then slot B (privileged; tests and audits). H4: the
 * pot's two handles, slot A the one at the image's left (world -y), from
 * the projection of their outer halves (the part clear of the body). */
hearth_status hearth_sim_candidate_boxes(hearth_sim_env *env, int boxes[2][4], hearth_err *err);

/* ---- dynamic temperatures (opts.thermal = HEARTH_SIM_THERMAL_DYNAMIC) ---- */
/* Object k's (0..3) thermal network now, contact links of the last step
 * included; NULL with static temperatures or k out of range. */
const hearth_thermo_net *hearth_sim_thermal_net(const hearth_sim_env *env, int k);
/* Set region `region` of object k's network to T degC now (an experiment's
 * start state, e.g. a cup just filled; the next reset restores the map's
 * temperatures); the heat bookkeeping starts again from this state.
 * HEARTH_E_ARG with static temperatures or indices out of range,
 * HEARTH_E_RANGE for T not above -273.15. */
hearth_status hearth_sim_thermal_set(hearth_sim_env *env, int k, size_t region, double T,
                                     hearth_err *err);
/* Heat object k took in from outside (air, table, fingers) since reset
 * (or the last hearth_sim_thermal_set), J, as the thermo library books it.
 * Its network's energy now minus then is this plus
 * hearth_sim_thermal_heat_exchanged, to rounding. */
double hearth_sim_thermal_heat_in(const hearth_sim_env *env, int k);
/* Heat object k got from the other objects through contact links since
 * reset (or the last hearth_sim_thermal_set), J (over the four objects
 * these sum to zero, to rounding). */
double hearth_sim_thermal_heat_exchanged(const hearth_sim_env *env, int k);
/* The object-object links of the last step (net indices a, b are object
 * numbers 0..3, ra, rb their regions); returns their count and writes up
 * to max of them (links may be NULL). */
size_t hearth_sim_thermal_links(const hearth_sim_env *env, hearth_thermo_link *links, size_t max);
/* The region temperatures of objects 0..3 one after another (the columns
 * of obs/thermal_state); returns their count and writes them when max is
 * at least that (T may be NULL). 0 with static temperatures. */
size_t hearth_sim_thermal_state(const hearth_sim_env *env, float *T, size_t max);

/* The scripted expert (privileged state): approach, grasp, lift, transport,
 * release. Call once per step after reset. */
void hearth_sim_expert_action(hearth_sim_env *env, double action[7]);

/* ---- demonstration collection (LIBERO HDF5) ------------------------------- */
typedef struct hearth_sim_collect_opts {
  hearth_sim_task task;
  const char *release_root;
  int use_ground_truth;
  int layouts;                  /* slots of the whole collection, 1..HEARTH_SIM_MAX_LAYOUTS; default
                         * 200: 2 instructions each */
  uint64_t seed;                /* default 1 */
  int image_size;               /* rendered and stored image side; default 256 (openpi's LIBERO
                         * data; what hearth_eval_opts.render_size renders by default) */
  int max_steps;                /* default 400 */
  int keep_failures;            /* store failed demos too (default 0: retry the slot with its next
                         * candidate layout) */
  int shadows;                  /* as hearth_sim_opts.shadows; default 0 */
  const char *renderer;         /* as hearth_sim_opts.renderer; "none" stores no
                         * image datasets (a physics-and-control timing run) */
  const char *gl;               /* as hearth_sim_opts.gl */
  int shard_index, shard_count; /* this process fills the slots k with k % count == index;
                         * count 0 or 1: all of them. The files of a shard are merged
                         * with hearth_sim_merge */
  int split_instructions;       /* one file per instruction: out_path without ".hdf5", plus
                         * "_instr1.hdf5" and "_instr2.hdf5" (hearth_sim_split_path) */
  int quiet;
  int thermal;            /* as hearth_sim_opts.thermal; dynamic adds obs/thermal_state */
  double thermal_speedup; /* as hearth_sim_opts.thermal_speedup; 0 = 1 */
  const char *out_path;   /* .hdf5, written atomically (layout: docs/simulation.md) */
} hearth_sim_collect_opts;
void hearth_sim_collect_opts_default(hearth_sim_collect_opts *o);

/* Slot k of a collection tries layout k, then, while the expert fails on
 * one of the two instructions, layouts k + j * 2 * HEARTH_SIM_MAX_LAYOUTS
 * for j = 1 .. HEARTH_SIM_SLOT_TRIES - 1 (the same parity as k, never
 * another slot's): which layout fills a slot depends on the slot alone,
 * so shards together store what one run stores. */
#define HEARTH_SIM_MAX_LAYOUTS 100000
#define HEARTH_SIM_SLOT_TRIES 20

typedef struct hearth_sim_collect_stats {
  int attempts[2], successes[2]; /* per instruction */
  int demos;                     /* per file */
  long steps;
  double seconds;
  int rejected_layouts; /* layouts skipped because the expert failed */
  int slots;            /* slots this process filled */
} hearth_sim_collect_stats;
/* Collect the slots of this shard x 2 demonstrations with the scripted
 * expert into out_path (or its two split files); stats may be NULL. */
hearth_status hearth_sim_collect(const hearth_sim_collect_opts *o, hearth_sim_collect_stats *stats,
                                 hearth_err *err);
/* The file of instruction ins (0 or 1) of a split collection written to
 * out_path: "<out_path without .hdf5>_instr<ins + 1>.hdf5", into buf. */
void hearth_sim_split_path(const char *out_path, int ins, char *buf, size_t bufsz);

/* Merge the files of the shards 0..N-1 of one collection (any order, each
 * once; for a split collection, the files of one instruction) into
 * out_path, written atomically: the same bytes as one unsharded run.
 * *n_demos (may be NULL) receives the demos written. */
hearth_status hearth_sim_merge(const char *out_path, const char *const *parts, int n_parts,
                               int *n_demos, hearth_err *err);

/* Render the task's scene (layout 0 of seed, instruction 0) to
 * <out_prefix>_rgb.png, <out_prefix>_thermal.png and (with the wrist view)
 * <out_prefix>_wrist.png, top row first. */
hearth_status hearth_sim_render_scene(const hearth_sim_opts *o, uint64_t seed,
                                      const char *out_prefix, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
