/* hearth/release.h - area release (src/release/): whole-release tools:
 * check a release against the layout contract (docs/dataset.md), summarise
 * it as the paper's dataset overview, build it incrementally (every stage,
 * every instance) and write the static HTML report.
 *
 * validate and stats only read; build writes through the stages' own atomic
 * writers and records a small stamp per finished stage so that a second run
 * does no work and an interrupted run resumes where it stopped. Structs
 * with "owned" arrays are released with their _free function, which
 * accepts a zeroed struct. */
#ifndef HEARTH_RELEASE_H
#define HEARTH_RELEASE_H

#include <stddef.h>
#include <stdio.h>
#include "hearth/core.h"
#include "hearth/map.h"
#include "hearth/recon.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- problems -------------------------------------------------------------- */
/* One finding of validate: the file (or directory) and what is wrong. */
typedef struct hearth_problem {
  char path[512];
  char what[1024];
} hearth_problem;

typedef struct hearth_problems {
  size_t n, cap;
  hearth_problem *items; /* owned */
} hearth_problems;
void hearth_problems_free(hearth_problems *p);
/* Append a problem (printf-style message). Returns HEARTH_E_NOMEM on failure. */
hearth_status hearth_problems_add(hearth_problems *p, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---- validate ---------------------------------------------------------------- */
typedef struct hearth_validate_opts {
  int threads;       /* 0 = hearth_default_threads() */
  int raw_only;      /* 1: a capture not yet built: skip derived/ */
  int decode_images; /* 1: decode every JPEG/PNG fully (default 0: headers + trailer) */
} hearth_validate_opts;
void hearth_validate_opts_default(hearth_validate_opts *o);

/* Check the release at root against docs/dataset.md: release.json and its
 * instances, instance.json, every manifest and the files it lists (sizes and
 * types of images, thermal CSVs of the thermal camera's size (rig.json; without it,
 * the first thermal capture's) within -50..650 degC, depth
 * intrinsics), calibration documents, and (unless raw_only) derived/: scale,
 * mesh, pose files (rotations, names of existing views, a pose per view),
 * per-state maps (R x R shapes and dtypes, mask values 0..3, observed finite
 * where mask == 1, filled finite where mask in {1, 2}), the Turbo texture and
 * provenance (instance, state, views of that state, resolution). Every
 * problem found is appended to *out (in a deterministic order); the return
 * status is not OK only when the check itself could not run (bad argument,
 * out of memory). files_checked (may be NULL) receives the count of files
 * examined. */
hearth_status hearth_validate_release(const char *root, const hearth_validate_opts *o,
                                      hearth_problems *out, size_t *files_checked, hearth_err *err);

/* ---- stats ------------------------------------------------------------------- */
#define HEARTH_N_STATE_KINDS 5 /* neutral hot warm iced used */
typedef struct hearth_release_stats {
  size_t n_categories;
  size_t instances_per_category[18]; /* indexed like hearth_categories */
  size_t n_instances;
  size_t n_states; /* object states (instance x state) */
  size_t states_by_kind[HEARTH_N_STATE_KINDS];
  size_t n_instances_nonneutral; /* instances with a state other than neutral */
  size_t n_categories_nonneutral;
  size_t views_min, views_max;     /* views per object state */
  size_t n_elevations, n_azimuths; /* distinct indices (0 if mixed per state) */
  size_t n_pairs;                  /* views with both an RGB image and a thermal matrix */
  size_t n_depth;                  /* views with a depth map */
  size_t rgb_w, rgb_h, thermal_w, thermal_h, depth_w, depth_h; /* of the first view (0 unknown) */
  /* derived assets present */
  size_t n_meshes, n_rgb_textures, n_scales, n_poses_rgb, n_poses_thermal;
  size_t n_maps;  /* states with temperature_filled.npy + mask.npy */
  size_t n_turbo; /* states with thermal_turbo.png */
  size_t n_provenance;
  size_t map_resolution; /* R of the first map (0 none) */
  int has_calibration;   /* calibration/rig.json present */
  int has_ground_truth;
  uint64_t raw_bytes, derived_bytes; /* file sizes under raw/ and derived/ */
} hearth_release_stats;

hearth_status hearth_release_stats_compute(const char *root, hearth_release_stats *st,
                                           hearth_err *err);
/* The dataset-overview table as text (two columns, like the paper's table). */
void hearth_release_stats_print(const hearth_release_stats *st, FILE *out);
/* The same as a JSON document (malloc'ed, NUL-terminated, the caller frees
 * it with free(); NULL if out of memory). */
char *hearth_release_stats_json(const hearth_release_stats *st);

/* ---- build ------------------------------------------------------------------- */
/* A list of file paths, relative to the release root. */
typedef struct hearth_build_files {
  size_t n, cap;
  char **paths; /* owned */
} hearth_build_files;
void hearth_build_files_free(hearth_build_files *f);
hearth_status hearth_build_files_add(hearth_build_files *f, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* A release-level stage run once per release before the instances. Detection
 * and calibration are built in (hearth_build_opts.calibrate); a caller may
 * add stages of its own, run after them. */
#define HEARTH_BUILD_MAX_STAGES 8
typedef struct hearth_build_stage {
  const char *name;   /* "detect" */
  const char *params; /* its parameters as text: a change forces a re-run */
  /* fill the stage's inputs and outputs (relative to root) */
  hearth_status (*files)(void *ctx, const char *root, hearth_build_files *in,
                         hearth_build_files *out, hearth_err *err);
  hearth_status (*run)(void *ctx, const char *root, int threads, hearth_err *err);
  void *ctx;
} hearth_build_stage;

/* The parameters that shape the outputs (resolution, fusion, min_cos,
 * rgb_resolution, bake_rgb, calibrate, calib_overlays) start "unset" in
 * hearth_build_opts_default: an unset parameter takes the value the
 * release's build.json recorded (the last build's), else its default. The
 * build records the parameters it runs with in build.json (docs/dataset.md),
 * so a later build without options changes nothing. */
#define HEARTH_BUILD_FUSION_UNSET ((hearth_fusion)-1)
typedef struct hearth_build_opts {
  int jobs;                     /* stages in parallel (of different instances, or states);
                                   0 = min(cores, instances) */
  int threads;                  /* total worker threads; 0 = hearth_default_threads() */
  int shard_index, shard_count; /* this machine does instances with index % count == index */
  const char *only_instance;    /* NULL: all of release.json */
  size_t resolution;            /* temperature-map R; 0 unset (default 1024) */
  hearth_fusion fusion;         /* HEARTH_BUILD_FUSION_UNSET (default HEARTH_FUSE_MAX) */
  double min_cos;               /* negative: unset (default 0) */
  size_t rgb_resolution;        /* baked colour texture side; 0 unset (default 1024) */
  int bake_rgb;                 /* 1 bake, 0 keep the recon's texture; -1 unset (default 1) */
  int force;                    /* re-run every stage */
  int quiet;                    /* no progress output */
  int dry_run;                  /* list what would run, run nothing (build.json untouched) */
  int calibrate;                /* 1: detect + calibrate when calibration/captures/ exists;
                                 -1 unset (default 1) */
  int calib_overlays;           /* 1: detection draws its overlay pictures; -1 unset (default 1) */
  int ignore_recorded;          /* 1: unset parameters take their defaults, not build.json's */
  size_t n_release_stages;      /* extra release-level stages (at most HEARTH_BUILD_MAX_STAGES) */
  const hearth_build_stage *release_stages;
  FILE *log; /* plain lines / summary; default stdout */
} hearth_build_opts;
void hearth_build_opts_default(hearth_build_opts *o);

/* What happened to one instance. */
typedef struct hearth_build_instance {
  char id[64];
  int failed; /* 1: a stage failed (later stages skipped) */
  char failed_stage[32];
  char reason[1024];
  size_t n_states, states_mapped;
  size_t stages_run, stages_skipped;
} hearth_build_instance;

typedef struct hearth_build_report {
  size_t n_instances;               /* of this shard */
  hearth_build_instance *instances; /* owned */
  size_t stages_run, stages_up_to_date;
  size_t temps_removed; /* temporaries of killed runs removed before re-running stages */
  int release_failed;   /* a release-level stage failed (no instance report; only the stages
                           that do not read the calibration, scale, may have run) */
  char release_reason[1024];
  double seconds;
} hearth_build_report;
void hearth_build_report_free(hearth_build_report *r);

/* The per-instance stages, in order, and whether each is part of this build
 * (recon, scale, bake, transfer, refine, map, overlay; recon runs only for
 * instances without a recon/ of another tool). */
size_t hearth_build_instance_stages(const char **names, int *available, size_t max);

/* Run every stale stage: release-level stages once, then for each instance
 * of this shard (in parallel) hearth's own reconstruction (when recon/ is
 * missing, or was made by an earlier build: its stamp), scale, transfer,
 * refine, colour baking and every state's map. Returns HEARTH_OK when the build could run (even with
 * failed instances, which are listed in rep); an error when release.json
 * cannot be read or a release-level stage fails. rep is filled either way
 * (the caller frees it with hearth_build_report_free). */
hearth_status hearth_build_release(const char *root, const hearth_build_opts *o,
                                   hearth_build_report *rep, hearth_err *err);
/* Print the end-of-build summary. */
void hearth_build_report_print(const hearth_build_report *r, FILE *out);

/* ---- ground truth through surface correspondence ------------------------------- */
/* The virtual rig's truth of one state resampled onto the UV layout of the
 * built derived/mesh.glb at R x R: each texel's surface point (the texel
 * centre on its UV triangle) is taken into the truth's frame by ref_from_est
 * (NULL: the similarity that best maps derived/poses_rgb.json onto
 * ground_truth/.../poses_rgb.json) and matched to the nearest point of
 * ground_truth/.../mesh.glb, whose UV picks the true texel (nearest) of
 * temperature_true.npy, and of temperature_apparent.npy and conditions.npy
 * where the truth has them. away[q] is 1 when some thermal view of the state
 * (derived/poses_thermal.json, the thermal camera of calibration/rig.json)
 * sees the texel's point inside its frame, unoccluded by the built mesh,
 * within 60 degrees of the triangle's normal. Arrays are owned (free with
 * hearth_truth_match_free, which accepts a zeroed struct); texels off the
 * surface hold NaN and away 0. */
typedef struct hearth_truth_match {
  size_t R;
  float *t_true;                   /* R*R degC */
  float *t_apparent;               /* R*R degC, or NULL: the truth has no apparent map */
  float *conditions;               /* R*R*3 (best cosine, mirror share, drift), or NULL */
  float *dist_m;                   /* R*R: distance to the matched true point, metres */
  uint8_t *away;                   /* R*R */
  int same_uvs;                    /* the built mesh has the truth's UVs (the stand-in) */
  hearth_pose_alignment alignment; /* derived/poses_rgb.json onto the true poses */
} hearth_truth_match;
void hearth_truth_match_free(hearth_truth_match *m);
hearth_status hearth_truth_match_state(const char *root, const char *instance, const char *state,
                                       size_t R, const hearth_similarity *ref_from_est,
                                       hearth_truth_match *out, hearth_err *err);

/* ---- report ------------------------------------------------------------------ */
/* One state of the report: coverage and, with ground truth (virtual rig), the
 * error of the observed texels against ground_truth/.../temperature_true.npy. */
typedef struct hearth_report_entry {
  char instance[64], state[64];
  int has_truth;
  size_t R, n_surface, n_observed, n_compared;
  double coverage;                /* observed / surface texels */
  double median_abs_c, p95_abs_c; /* |observed - true| over observed texels; NaN without truth */
  double mean_signed_c;           /* mean (observed - true) */
  /* with the virtual rig's object effects (ground_truth's temperature_apparent.npy and
     conditions.npy): on observed texels seen within 60 degrees of the normal (n_away),
     |observed - apparent| (the normal-incidence reading at the scan's start) and
     |observed - true|; and among the worst 5 % of all observed texels against the
     apparent truth, the shares seen only obliquely (best cosine < 0.5), mirroring the
     warm source in some view, drifting by more than 1 degC from cooling, within
     2 texels of a surface texel whose apparent truth differs by at least the
     worst 5 %'s threshold (registration), and in none of these */
  int has_apparent;
  size_t n_away;
  double app_median_abs_c, app_p95_abs_c, away_true_median_abs_c, away_true_p95_abs_c;
  double worst_grazing, worst_mirror, worst_cooling, worst_registration, worst_none;
  /* through surface correspondence (hearth_truth_match_state): on observed
     texels seen by some thermal view within 60 degrees of the normal (n_corr,
     corr_share of the observed ones), |observed - true| at the nearest true
     surface point, |observed - apparent| there (NaN without the rig's object
     effects), and the distances to those points */
  int has_corr, same_uvs;
  size_t n_corr;
  double corr_share, corr_median_abs_c, corr_p95_abs_c;
  double corr_app_median_abs_c, corr_app_p95_abs_c;
  double corr_dist_median_mm, corr_dist_p95_mm;
} hearth_report_entry;

typedef struct hearth_report {
  size_t n;
  hearth_report_entry *entries; /* owned */
} hearth_report;
void hearth_report_free(hearth_report *r);

/* A static HTML report (out_dir/index.html, no server needed) with relative
 * links to PNGs copied or drawn into out_dir: per state the Turbo thermal
 * texture beside the colour texture, the ground-truth texture and an error
 * map (when ground truth exists), and the before/after overlay contact sheet
 * (when derived/overlay/<state>/ exists); plus the numbers, which are also
 * returned in rep (the caller frees it with hearth_report_free).
 * validate_text (may be NULL) is shown as the validation result. */
hearth_status hearth_report_write(const char *root, const char *out_dir, const char *title,
                                  const char *validate_text, hearth_report *rep, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
