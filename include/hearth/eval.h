/* hearth/eval.h - area eval (src/eval/; built with HEARTH_SIM): scoring
 * policies on the sim tasks (H1-H3 by default; H4-H6) the way the paper does (10 episodes per
 * instruction, 20 per task, 60 per policy; success = target on the mat
 * within the time limit), for policies running anywhere:
 * the scripted expert (an upper bound), a replay of an HDF5 demonstration
 * (a determinism check) and an openpi policy server over WebSocket.
 *
 * Held-out layouts: evaluation episode e of a task uses layout
 * HEARTH_EVAL_LAYOUT_BASE + e of the seed stream, never reached by
 * collection (which uses layouts 0, 1, 2, ... up to at most 100000 + retries);
 * both instructions of an episode index share the layout, as in the paper.
 * The policy protocol and results.json: docs/simulation.md. */
#ifndef HEARTH_EVAL_H
#define HEARTH_EVAL_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"
#include "hearth/sim.h"
#include "hearth/ws.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_EVAL_LAYOUT_BASE ((uint64_t)1 << 32)
/* Time limits in control steps (policy steps; the 10 no-op steps of the
 * openpi client come on top, as in openpi's LIBERO example). LIBERO uses
 * 220 (spatial), 280 (object), 300 (goal) and 520 (long); our tasks are
 * single pick-and-place like LIBERO-Object, so 280 for each (the scripted
 * expert finishes well within it). */
int hearth_eval_time_limit(hearth_sim_task t);

/* ---- openpi observations ----------------------------------------------------
 * openpi's image_tools.resize_with_pad: scale to fit out_w x out_h keeping
 * the aspect ratio (bilinear), centre, pad with zeros. RGB U8, in[w*h*3]
 * into the caller's out[out_w*out_h*3]. */
void hearth_eval_resize_with_pad(const uint8_t *in, int w, int h, uint8_t *out, int out_w,
                                 int out_h);
/* Build the openpi LIBERO request (msgpack map): observation/image,
 * observation/wrist_image (and observation/thermal_image if thermal), each
 * rotated 180 degrees from OpenGL order and resized with padding to
 * size x size; observation/state (8 x <f8: ee pos, axis-angle, gripper);
 * prompt. Appended to w (initialised by the caller, who frees it). */
struct hearth_mp_writer;
hearth_status hearth_eval_encode_obs(const hearth_sim_obs *obs, const char *prompt, int thermal,
                                     int size, struct hearth_mp_writer *w, hearth_err *err);

/* ---- evaluation ------------------------------------------------------------ */
typedef struct hearth_eval_opts {
  unsigned tasks;       /* bit (1 << task): default H1, H2, H3 */
  const char *policy;   /* "oracle", "replay:FILE.hdf5[#K]", "ws://HOST:PORT" */
  int episodes;         /* per instruction; default 10 */
  int thermal;          /* send observation/thermal_image; default 1 */
  uint64_t seed;        /* layout stream; default 1 (collection's default) */
  uint64_t layout_base; /* episode k uses layout layout_base + k; default HEARTH_EVAL_LAYOUT_BASE */
  const char *release_root;
  int use_ground_truth;
  int render_size;       /* sim view side; default 256 (as collection stores) */
  int shadows;           /* as hearth_sim_opts.shadows; default 0 */
  const char *renderer;  /* as hearth_sim_opts.renderer: the same default as
                          * hearth_sim_collect, so evaluation sees the images
                          * training saw */
  const char *gl;        /* as hearth_sim_opts.gl */
  int thermal_mode;      /* as hearth_sim_opts.thermal (static by default) */
  int image_size;        /* policy image side; default 224 (openpi's model input) */
  int max_steps;         /* 0 = hearth_eval_time_limit(task) */
  int replan_steps;      /* default 5 */
  int wait_steps;        /* no-op steps before querying; default 10 */
  double timeout_s;      /* per server reply and connect; default 120 */
  const char *video_dir; /* animated PNG per episode if set */
  int video_every;       /* keep every k-th frame; default 2 */
  int quiet;
} hearth_eval_opts;
void hearth_eval_opts_default(hearth_eval_opts *o);

typedef struct hearth_eval_episode {
  hearth_sim_task task;
  int instruction, episode;
  uint64_t seed, layout;
  int success, steps;
  int error;            /* the policy failed (server gone, bad reply ...) */
  char reason[512];     /* why it failed ("time limit", the error) */
  double state_diff;    /* replay: max |state - stored state| over the replayed steps; else -1 */
  int expected_success; /* replay: 1 (the stored demo succeeded), else -1 */
} hearth_eval_episode;

typedef struct hearth_eval_results {
  hearth_eval_episode *eps;
  size_t n;
  char policy[256];
  int thermal;      /* server policies: 1 observation/thermal_image is sent, 0 not;
                            * -1 for the other policies */
  int thermal_used; /* server policies: 1 sent and the server's metadata declares it
                            * reads it; 0 not sent; -1 sent, the metadata says nothing */
  double seconds;
  char *metadata_json; /* the server's whole metadata map as JSON (malloc'd), NULL
                            * without a server */
  int render_size, image_size, replan_steps, wait_steps, shadows; /* the options run */
  char renderer[256]; /* hearth_sim_renderer of the evaluation's env */
  char warning[512];  /* "" or what the reader must know (thermal use unknown) */
} hearth_eval_results;

/* Run every episode; r is filled on success (the caller frees it with
 * hearth_eval_results_free, which accepts a zeroed struct). A policy's
 * failure fails its episode and the run goes on; a simulator failure stops
 * the run with an error. A server policy is connected before the first
 * episode: an unreachable server is an error, and so is the thermal
 * condition (o->thermal) with a server whose metadata declares that it
 * ignores the thermal view ("hearth_thermal": false, or "image_keys"
 * without "observation/thermal_image"); a server that declares nothing
 * gets a warning (r->warning, on stderr unless quiet) and thermal_used -1. */
hearth_status hearth_eval_run(const hearth_eval_opts *o, hearth_eval_results *r, hearth_err *err);
void hearth_eval_results_free(hearth_eval_results *r);
/* Episodes failed by the policy (server errors, bad replies), as opposed
 * to task failures. */
size_t hearth_eval_policy_errors(const hearth_eval_results *r);

/* Success rates: per (task, instruction) and task (NaN where no episode);
 * overall over every episode. Returns the overall fraction. */
double hearth_eval_rates(const hearth_eval_results *r, double per_instr[HEARTH_SIM_TASK_END][2],
                         double per_task[HEARTH_SIM_TASK_END]);
/* The paper's table (Task, Thermal, Instr. 1, Instr. 2, Average) as text
 * (the setup and server metadata first; ends with a line "overall <pct>
 * (k/n)"), Markdown and JSON (with the setup, the metadata and every
 * episode). Thermal reads "w/", "w/o", or "w/?" when the server did not
 * declare whether it reads the thermal view. malloc'd strings (the caller
 * frees them). */
char *hearth_eval_format_text(const hearth_eval_results *r);
char *hearth_eval_format_markdown(const hearth_eval_results *r);
char *hearth_eval_format_json(const hearth_eval_results *r);

#ifdef __cplusplus
}
#endif
#endif
