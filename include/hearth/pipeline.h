/* hearth/pipeline.h - pipeline stages that read and write a release tree
 * (layout: docs/dataset.md). Each stage writes its outputs atomically: a
 * stage that fails leaves the previous outputs (or none) in place. */
#ifndef HEARTH_PIPELINE_H
#define HEARTH_PIPELINE_H

#include "hearth/core.h"
#include "hearth/map.h"

#ifdef __cplusplus
extern "C" {
#endif

/* hearth transfer: T_world_from_th = T_world_from_rgb * inverse(T_th_from_rgb)
 * for every view of every state. Reads derived/poses_rgb.json and
 * calibration/rig.json (rig_path overrides); writes
 * derived/poses_thermal_transferred.json and, unless a refined
 * derived/poses_thermal.json newer than it exists or keep_refined is 0,
 * derived/poses_thermal.json. */
typedef struct hearth_transfer_job {
  const char *root;
  const char *instance;    /* required */
  const char *rig_path;    /* NULL: <root>/calibration/rig.json */
  const char *poses_path;  /* NULL: <root>/instances/<id>/derived/poses_rgb.json */
  int keep_refined;        /* 1: do not overwrite a refined poses_thermal.json */
} hearth_transfer_job;
hearth_status hearth_transfer_run(const hearth_transfer_job *job, hearth_err *err);

/* hearth map: one state of one instance. */
typedef struct hearth_map_job {
  const char *root;
  const char *instance;
  const char *state;
  hearth_map_opts map;
  const char *mesh_path;   /* NULL: derived/mesh.glb */
  const char *poses_path;  /* NULL: derived/poses_thermal.json */
  const char *rig_path;    /* NULL: calibration/rig.json */
  const char *views;       /* NULL: all; else comma-separated view names */
  const char *out_dir;     /* NULL: derived/<state> */
  double turbo_lo, turbo_hi; /* 10, 60 */
  hearth_map_timing *timing; /* optional: phase times of the run */
} hearth_map_job;
void hearth_map_job_default(hearth_map_job *job);
/* stats (optional) receives the result's counters (arrays not kept). */
hearth_status hearth_map_run(const hearth_map_job *job, hearth_map_result *stats,
                             hearth_err *err);

/* hearth map --rgb: bake the colour texture from the colour views into
 * derived/rgb_texture.png and embed it in derived/mesh.glb. */
typedef struct hearth_bake_job {
  const char *root;
  const char *instance;
  const char *state;       /* which state's colour views (NULL: the first state) */
  size_t resolution;       /* default 1024 */
  int pixel_stride;        /* default 2 */
  const char *mesh_path, *poses_path, *rig_path;
  int threads;
} hearth_bake_job;
hearth_status hearth_bake_rgb_run(const hearth_bake_job *job, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
