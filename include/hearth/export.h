/* hearth/export.h - area export (src/export/; built with HEARTH_SIM, links
 * HDF5): demonstrations from hearth's LIBERO-layout HDF5 collections
 * (`hearth sim collect`, layout in docs/simulation.md) as a LeRobot
 * dataset, codebase version v2.1, in the files and fields LeRobot's own
 * writer produces (LeRobotDataset.create + add_frame + save_episode of
 * lerobot 0cf86487, the commit openpi pins), plus openpi's norm_stats.json.
 * Every field, and where hearth's output differs from LeRobot's bytes:
 * docs/lerobot.md.
 *
 * Features, in this order: image, wrist_image, thermal_image (dtype
 * "image": PNG bytes in a struct<bytes, path> Parquet column), state
 * (float32 (8,)), actions (float32 (7,)), thermal_state (float32 (R,),
 * only from dynamic-temperature collections: obs/thermal_state with its
 * region names), then LeRobot's timestamp,
 * frame_index, episode_index, index and task_index. Images are the HDF5's
 * rotated by 180 degrees (OpenGL rows -> openpi's LIBERO convention, what
 * `hearth sim eval` sends before resizing); the state is the grip site's
 * position, its orientation as a continuous axis-angle
 * (hearth_lerobot_axis_angle) and the two finger positions. */
#ifndef HEARTH_EXPORT_H
#define HEARTH_EXPORT_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_LEROBOT_VERSION "v2.1"
#define HEARTH_LEROBOT_CHUNK_SIZE 1000 /* episodes per data/chunk-NNN directory */
#define HEARTH_LEROBOT_ROWS_PER_GROUP \
  100 /* Parquet row group (datasets' size for image features) */
#define HEARTH_LEROBOT_MAX_INPUTS 256

/* ---- the per-frame conversions (also what a policy client should send) -----
 * Axis-angle of a rotation given as a rotation vector (angle in [0, pi], as
 * the HDF5's obs/ee_ori and hearth_sim_obs.ee_ori hold it), continuous over
 * the orientations the tasks reach: the rotation's unit quaternion (w x y z)
 * is taken in the hemisphere of HEARTH_LEROBOT_QUAT_REF (the hand pointing
 * straight down: half a turn about world x), then turned into axis * angle
 * the way openpi's LIBERO client does (robosuite's quat2axisangle: angle
 * 2 acos(w) in [0, 2 pi)). A plain rotation vector flips sign near half a
 * turn, where the hand works; this one does not. */
#define HEARTH_LEROBOT_QUAT_REF \
  { 0.0, 1.0, 0.0, 0.0 } /* = HEARTH_SIM_STATE_QUAT_REF of sim.h */
void hearth_lerobot_axis_angle(const double rotvec[3], double out[3]);
/* state[8] = ee_pos (3), hearth_lerobot_axis_angle(ee_ori) (3), gripper (2). */
void hearth_lerobot_state(const double ee_pos[3], const double ee_ori[3], const double gripper[2],
                          double state[8]);
/* An RGB U8 image of w x h pixels in OpenGL row order (bottom row first)
 * rotated by 180 degrees into out (w*h*3 bytes, not aliasing in): top row
 * first, columns mirrored, as openpi's LIBERO client (img[::-1, ::-1]). */
void hearth_lerobot_rotate180(const uint8_t *in, int w, int h, uint8_t *out);

/* ---- the export ------------------------------------------------------------- */
typedef struct hearth_lerobot_opts {
  const char *out_dir;       /* the dataset root; must not exist or be empty */
  const char *const *inputs; /* collection files, exported in this order */
  size_t n_inputs;           /* 1..HEARTH_LEROBOT_MAX_INPUTS */
  const char *robot_type;    /* default "panda" (openpi's LIBERO example) */
  int thermal;               /* include thermal_image and thermal_state; default 1 */
  int threads;               /* PNG encoding; 0 = hearth_default_threads() */
  int quiet;
} hearth_lerobot_opts;
void hearth_lerobot_opts_default(hearth_lerobot_opts *o);

typedef struct hearth_lerobot_stats {
  size_t episodes, frames, tasks;
  double seconds;
} hearth_lerobot_stats;

/* Write the dataset: meta/info.json, meta/tasks.jsonl, meta/episodes.jsonl,
 * meta/episodes_stats.jsonl, data/chunk-NNN/episode_NNNNNN.parquet (one per
 * demo, files in order, demos in index order) and norm_stats.json (openpi's
 * form, over every frame). Every input must have the same image size and
 * control rate (LeRobot's fps). The tree is built under a temporary name
 * beside out_dir and renamed into place: on failure nothing is left. st may
 * be NULL. */
hearth_status hearth_lerobot_export(const hearth_lerobot_opts *o, hearth_lerobot_stats *st,
                                    hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
