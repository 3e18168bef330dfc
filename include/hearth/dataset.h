/* hearth/dataset.h - area dataset (src/dataset/): the JSON documents of a
 * release tree and the names used in it (categories, states, instances).
 *
 * The on-disk contract is docs/dataset.md. Readers are strict: a missing
 * key, a wrong type, a non-finite number, a non-rotation R or an array of
 * the wrong length is an error naming the file and the JSON path
 * (e.g. "views[3].T_world_from_cam[2][1]"). Writers are atomic and
 * deterministic, and refuse what their reader would refuse.
 *
 * Every document has _read (a file), _parse (text[0..len), not necessarily
 * NUL-terminated, `name` naming it in messages) and _write. Documents with
 * arrays (manifest, poses, detections, release) own them after a read and
 * are released with their _free (which accepts a zeroed struct); the others
 * hold no heap memory. Lengths in metres, angles in radians, pixel values
 * in pixels (docs/conventions.md). */
#ifndef HEARTH_DATASET_H
#define HEARTH_DATASET_H

#include <stddef.h>
#include "hearth/core.h"
#include "hearth/camera.h"
#include "hearth/geom.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_MAX_VIEWS 1024
#define HEARTH_NAME_MAX 64

/* ---- rig.json ------------------------------------------------------------ */
/* The calibrated rig: the three cameras, the thermal and depth cameras'
 * transforms from the colour camera, and the calibration's RMS errors
 * (pixels). A thermal-only rig (thermal_only = 1, from `hearth calibrate
 * --thermal-only`) has only the thermal camera (5- or 8-coefficient lens)
 * and thermal_rms_px; its other fields are zero. */
typedef struct hearth_rig {
  hearth_camera rgb, thermal, depth;
  hearth_rigid T_thermal_from_rgb;
  hearth_rigid T_depth_from_rgb;
  double thermal_rms_px, stereo_rms_px;
  int thermal_only;
} hearth_rig;
hearth_status hearth_rig_read(const char *path, hearth_rig *rig, hearth_err *err);
hearth_status hearth_rig_parse(const char *text, size_t len, const char *name, hearth_rig *rig,
                               hearth_err *err);
hearth_status hearth_rig_write(const char *path, const hearth_rig *rig, hearth_err *err);
/* HEARTH_OK for a rig with the stereo calibration; for a thermal-only rig
 * an error (HEARTH_E_UNSUPPORTED) naming path and saying that `stage`
 * needs T_thermal_from_rgb. */
hearth_status hearth_rig_require_stereo(const hearth_rig *rig, const char *path, const char *stage,
                                        hearth_err *err);

/* ---- depth/vNN.json: per-frame depth intrinsics ------------------------- */
typedef struct hearth_depth_intrinsics {
  hearth_camera depth;
  hearth_rigid T_depth_from_rgb;
} hearth_depth_intrinsics;
hearth_status hearth_depth_intrinsics_read(const char *path, hearth_depth_intrinsics *d,
                                           hearth_err *err);
hearth_status hearth_depth_intrinsics_write(const char *path, const hearth_depth_intrinsics *d,
                                            hearth_err *err);
hearth_status hearth_depth_intrinsics_parse(const char *text, size_t len, const char *name,
                                            hearth_depth_intrinsics *d, hearth_err *err);

/* ---- calibration/factory.json: factory colour + depth calibration -------- */
/* rig.json's schema without the thermal camera, T_thermal_from_rgb and the
 * rms fields (docs/dataset.md). */
typedef struct hearth_factory_calib {
  hearth_camera rgb, depth;
  hearth_rigid T_depth_from_rgb;
} hearth_factory_calib;
hearth_status hearth_factory_read(const char *path, hearth_factory_calib *f, hearth_err *err);
hearth_status hearth_factory_parse(const char *text, size_t len, const char *name,
                                   hearth_factory_calib *f, hearth_err *err);
hearth_status hearth_factory_write(const char *path, const hearth_factory_calib *f,
                                   hearth_err *err);

/* ---- manifest.json ------------------------------------------------------- */
/* One state's views and the files of each, relative to raw/<state>/. */
typedef struct hearth_view_files {
  char view[HEARTH_NAME_MAX]; /* "v00" */
  int elevation_index, azimuth_index;
  char rgb[128], cutout[128], depth[128], depth_intrinsics[128], thermal[128];
  int has_time;         /* the optional "time_s" is present */
  double time_s;        /* seconds from the preparation of the state (0..1e6) to this view */
  int has_turntable;    /* the optional "turntable_deg" is present */
  double turntable_deg; /* the turntable encoder's angle at this view, degrees (-3600..3600) */
} hearth_view_files;

typedef struct hearth_manifest {
  char instance[HEARTH_NAME_MAX];
  char state[HEARTH_NAME_MAX];
  size_t n_views;
  hearth_view_files *views; /* owned */
} hearth_manifest;
void hearth_manifest_free(hearth_manifest *m);
hearth_status hearth_manifest_read(const char *path, hearth_manifest *m, hearth_err *err);
hearth_status hearth_manifest_parse(const char *text, size_t len, const char *name,
                                    hearth_manifest *m, hearth_err *err);
hearth_status hearth_manifest_write(const char *path, const hearth_manifest *m, hearth_err *err);

/* ---- poses_*.json ---------------------------------------------------------- */
/* Camera poses T_world_from_cam of the views of one or more states. */
typedef struct hearth_view_pose {
  char state[HEARTH_NAME_MAX];
  char view[HEARTH_NAME_MAX];
  hearth_rigid T_world_from_cam;
} hearth_view_pose;

typedef struct hearth_poses {
  size_t n;
  hearth_view_pose *views; /* owned */
} hearth_poses;
void hearth_poses_free(hearth_poses *p);
hearth_status hearth_poses_read(const char *path, hearth_poses *p, hearth_err *err);
hearth_status hearth_poses_parse(const char *text, size_t len, const char *name, hearth_poses *p,
                                 hearth_err *err);
hearth_status hearth_poses_write(const char *path, const hearth_poses *p, hearth_err *err);
/* The pose of (state, view), or NULL; points into p. */
const hearth_view_pose *hearth_poses_find(const hearth_poses *p, const char *state,
                                          const char *view);

/* ---- calibration/target.json: the hole target ------------------------------- */
#define HEARTH_PLATE_ROWS 8
#define HEARTH_PLATE_HOLES 84
#define HEARTH_PLATE_PITCH_M 0.012
#define HEARTH_PLATE_ROW_STEP_M 0.0103923
/* The paper's calibration plate: 84 holes in 8 rows of alternately 11 and
 * 10, HEARTH_PLATE_PITCH_M apart in a row, rows HEARTH_PLATE_ROW_STEP_M
 * apart, odd rows shifted by half a pitch. Plate coordinates (metres, z = 0)
 * of hole i in row-by-row order. */
void hearth_plate_hole(int i, double xyz[3]);

/* A target of holes on a plane. Lattices:
 *   hex-alternating  rows of C and C-1 holes (even rows C), odd rows shifted
 *                    by P/2: the paper's plate (8 x 11, P = 12 mm, 8 mm holes)
 *   hex              C holes in every row, odd rows shifted by P/2 (OpenCV's
 *                    asymmetric circle grid)
 *   grid             R x C holes, P apart both ways
 * Hex rows are P*sqrt(3)/2 apart, rounded to 0.1 um (the paper plate's
 * 10.3923 mm). Holes are numbered row by row from row 0, each row by
 * increasing x; plate x along a row, y across rows, z = 0 on the plate.
 * A zeroed hearth_target (rows == 0) stands for the paper's plate wherever a
 * target is taken. How the order is fixed in an image (symmetric targets
 * included): docs/dataset.md. */
typedef enum hearth_lattice {
  HEARTH_LATTICE_HEX_ALTERNATING = 0,
  HEARTH_LATTICE_HEX,
  HEARTH_LATTICE_GRID
} hearth_lattice;

typedef struct hearth_target {
  hearth_lattice lattice;
  int rows, cols;
  double pitch_m, hole_diameter_m;
  /* the plate's thickness (target.json "thickness_m", optional); 0: unknown
   * or thin, hole centres are then taken as if the plate had no depth */
  double thickness_m;
} hearth_target;

#define HEARTH_TARGET_MAX_HOLES 512

/* The paper's plate: hex-alternating, 8 x 11, 12 mm pitch, 8 mm holes. */
hearth_target hearth_target_default(void);
/* t itself, or the default for a zeroed target (rows == 0); never NULL. */
const hearth_target *hearth_target_or_default(const hearth_target *t, hearth_target *scratch);
/* "hex-alternating", "hex", "grid"; "?" for another value. */
const char *hearth_lattice_name(hearth_lattice l);
/* Parse a lattice name; returns 0 if unknown. */
int hearth_lattice_parse(const char *name, hearth_lattice *out);
/* Holes of the target (0 if it is not valid). */
size_t hearth_target_holes(const hearth_target *t);
/* Rows between hex rows / grid rows (metres). */
double hearth_target_row_step(const hearth_target *t);
/* Number of holes in row r. */
int hearth_target_row_holes(const hearth_target *t, int r);
/* Plate coordinates of the holes in order into xyz[0..holes) (z = 0). */
void hearth_target_points(const hearth_target *t, double (*xyz)[3]);
/* 1 if t is the paper's plate (same lattice, rows, cols, pitch, hole). */
int hearth_target_is_default(const hearth_target *t);
/* Checks: rows and cols 3..64 (hex-alternating cols 4..64: every target
 * then has a hole with all its lattice neighbours), at most HEARTH_TARGET_MAX_HOLES holes, pitch
 * 1 mm..1 m, 0 < hole diameter <= 0.8 pitch. name names the source. */
hearth_status hearth_target_check(const hearth_target *t, const char *name, hearth_err *err);
/* Strict reader of calibration/target.json: exactly the keys lattice, rows,
 * cols, pitch_m, hole_diameter_m; errors name the file and the key. A path
 * that does not exist gives the default target (HEARTH_OK). */
hearth_status hearth_target_read(const char *path, hearth_target *t, hearth_err *err);
hearth_status hearth_target_parse(const char *text, size_t len, const char *name, hearth_target *t,
                                  hearth_err *err);
hearth_status hearth_target_write(const char *path, const hearth_target *t, hearth_err *err);

/* ---- detections.json -------------------------------------------------------- */
typedef struct hearth_detection {
  char frame[HEARTH_NAME_MAX]; /* "f000", "p003" */
  char camera[16];             /* "thermal" | "rgb" */
  int found;
  char reason[256]; /* when !found */
  /* (u, v) pixels in target order, when found: the first
     hearth_target_holes(target) entries */
  double centres[HEARTH_TARGET_MAX_HOLES][2];
} hearth_detection;

typedef struct hearth_detections {
  size_t n;
  hearth_detection *frames; /* owned */
  hearth_target target;     /* the target detected; zeroed: the paper's plate */
} hearth_detections;
void hearth_detections_free(hearth_detections *d);
hearth_status hearth_detections_read(const char *path, hearth_detections *d, hearth_err *err);
hearth_status hearth_detections_parse(const char *text, size_t len, const char *name,
                                      hearth_detections *d, hearth_err *err);
hearth_status hearth_detections_write(const char *path, const hearth_detections *d,
                                      hearth_err *err);

/* ---- scale.json --------------------------------------------------------------- */
/* views_used and residual_median_mm are optional in the file (0 when absent). */
typedef struct hearth_scale_doc {
  double scale; /* metres per reconstruction unit */
  int views_used;
  double residual_median_mm;
} hearth_scale_doc;
hearth_status hearth_scale_doc_read(const char *path, hearth_scale_doc *s, hearth_err *err);
hearth_status hearth_scale_doc_write(const char *path, const hearth_scale_doc *s, hearth_err *err);
hearth_status hearth_scale_doc_parse(const char *text, size_t len, const char *name,
                                     hearth_scale_doc *s, hearth_err *err);

/* ---- release.json / instance.json ---------------------------------------- */
#define HEARTH_MAX_STATES 8
typedef struct hearth_instance_doc {
  char id[HEARTH_NAME_MAX];       /* "cup_03" */
  char category[HEARTH_NAME_MAX]; /* "cup" */
  size_t n_states;
  char states[HEARTH_MAX_STATES][HEARTH_NAME_MAX];
  char notes[512];
} hearth_instance_doc;
hearth_status hearth_instance_read(const char *path, hearth_instance_doc *d, hearth_err *err);
hearth_status hearth_instance_write(const char *path, const hearth_instance_doc *d,
                                    hearth_err *err);
hearth_status hearth_instance_parse(const char *text, size_t len, const char *name,
                                    hearth_instance_doc *d, hearth_err *err);
/* <root>/instances/<id>/instance.json, read and checked to describe the
 * instance of its directory (its id equal to `id`). */
hearth_status hearth_instance_load(const char *root, const char *id, hearth_instance_doc *d,
                                   hearth_err *err);

typedef struct hearth_release_doc {
  char name[128];
  char version[32];
  char software_version[32];
  size_t n_instances;
  char (*instances)[HEARTH_NAME_MAX]; /* owned */
} hearth_release_doc;
void hearth_release_free(hearth_release_doc *d);
hearth_status hearth_release_read(const char *path, hearth_release_doc *d, hearth_err *err);
hearth_status hearth_release_write(const char *path, const hearth_release_doc *d, hearth_err *err);
hearth_status hearth_release_parse(const char *text, size_t len, const char *name,
                                   hearth_release_doc *d, hearth_err *err);

/* ---- names ----------------------------------------------------------------- */
/* The 18 categories of the paper, lower case with underscores
 * ("bottled_drink", "electric_kettle", ...); a constant table. */
extern const char *const hearth_categories[18];
/* 1 if name is one of them. */
int hearth_category_valid(const char *name);
/* 1 if name is a state: neutral | hot | warm | iced | used */
int hearth_state_valid(const char *name);
/* "<category>_<NN>": a valid category, '_', two to four decimal digits. */
int hearth_instance_id_valid(const char *id);

#ifdef __cplusplus
}
#endif
#endif
