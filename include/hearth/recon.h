/* hearth/recon.h - area recon (src/recon/): camera poses from an outside
 * structure-from-motion tool. Reads COLMAP sparse models (text and binary),
 * maps their cameras onto hearth's camera, turns their poses into hearth's
 * poses document, runs Debian's `colmap` program over an instance's colour
 * views, and aligns a pose set to a reference by a similarity (for checks
 * against ground truth).
 *
 * COLMAP's conventions, as its source states them (src/colmap/sensor/models.h,
 * src/colmap/scene/reconstruction_io_{text,binary}.cc):
 * - An image's pose is cam_from_world: x_cam = R(q) x_world + t, with the
 *   unit quaternion q = (qw, qx, qy, qz) (Hamilton, w first). Camera axes
 *   are OpenCV's (+x right, +y down, +z forward). hearth stores
 *   T_world_from_cam = (R^T, -R^T t) (docs/conventions.md).
 * - Pixel coordinates: the top-left corner of the image is (0, 0), so the
 *   centre of the top-left pixel is (0.5, 0.5). In hearth that centre is
 *   (0, 0): a COLMAP principal point (cx, cy) is hearth's (cx - 0.5, cy - 0.5).
 *   Focal lengths and distortion coefficients carry over unchanged.
 * - Camera models (id, name, parameters in order):
 *     0 SIMPLE_PINHOLE  f, cx, cy                       -> fx = fy = f
 *     1 PINHOLE         fx, fy, cx, cy
 *     2 SIMPLE_RADIAL   f, cx, cy, k                    -> k1 = k
 *     3 RADIAL          f, cx, cy, k1, k2
 *     4 OPENCV          fx, fy, cx, cy, k1, k2, p1, p2
 *     6 FULL_OPENCV     fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6
 *                       (only with k4 = k5 = k6 = 0: the rational model's
 *                       denominator is not in hearth's camera)
 *   are read; 5 OPENCV_FISHEYE, 7 FOV, 8 SIMPLE_RADIAL_FISHEYE,
 *   9 RADIAL_FISHEYE, 10 THIN_PRISM_FISHEYE, 11 RAD_TAN_THIN_PRISM_FISHEYE,
 *   12 SIMPLE_DIVISION, 13 DIVISION, 14 SIMPLE_FISHEYE, 15 FISHEYE, 16 EUCM
 *   and 17 EQUIRECTANGULAR are not pinhole + Brown-Conrady and are refused
 *   with an error naming the camera id and the model.
 *
 * Binary files are little-endian: cameras.bin is a uint64 count, then per
 * camera uint32 id, int32 model id, uint64 width, uint64 height and the
 * model's parameters as doubles; images.bin a uint64 count, then per image
 * uint32 id, 7 doubles (qw qx qy qz tx ty tz), uint32 camera id, the name
 * NUL-terminated, a uint64 count of 2-D points and per point x, y (doubles)
 * and an int64 3-D point id (-1: none); points3D.bin a uint64 count, then per
 * point uint64 id, 3 doubles xyz, 3 bytes rgb, double error, uint64 track
 * length and per element uint32 image id, uint32 2-D point index.
 *
 * Readers are strict and bounded: a count is checked against the bytes left
 * before anything is allocated, every error names the file and its line
 * (text) or byte offset (binary) and says what was expected. Ids need not be
 * contiguous. Images of the database that the mapper did not register are
 * simply not in the model. */
#ifndef HEARTH_RECON_H
#define HEARTH_RECON_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/dataset.h"
#include "hearth/geom.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- COLMAP camera models ------------------------------------------------ */
#define HEARTH_COLMAP_MAX_PARAMS 16
/* The model's name ("OPENCV"), or NULL for an id COLMAP does not define. */
const char *hearth_colmap_model_name(int model_id);
/* The model's parameter count, or -1 for an unknown id. */
int hearth_colmap_model_n_params(int model_id);
/* The id of a model name (exact, upper case), or -1. */
int hearth_colmap_model_id(const char *name);
/* hearth's camera for COLMAP camera (model_id, params[0..n_params), width,
 * height), principal point shifted by -0.5 px (see above). An unsupported
 * model, a wrong parameter count, a size outside 1..65536, a non-finite
 * parameter or a focal length <= 0 is an error whose message says which
 * (the caller adds file, line and camera id). */
hearth_status hearth_colmap_camera_convert(int model_id, const double *params, size_t n_params,
                                           uint64_t width, uint64_t height, hearth_camera *cam,
                                           hearth_err *err);

/* ---- COLMAP sparse models -------------------------------------------------- */
#define HEARTH_COLMAP_NAME_MAX 512 /* bytes of an image name, NUL included */

typedef struct hearth_colmap_camera {
  uint32_t id;
  int model_id;
  size_t n_params;
  double params[HEARTH_COLMAP_MAX_PARAMS]; /* as stored, COLMAP's pixel convention */
  uint64_t width, height;
  hearth_camera camera; /* the same camera in hearth's conventions */
} hearth_colmap_camera;

typedef struct hearth_colmap_image {
  uint32_t id, camera_id;
  double q_cam_from_world[4]; /* qw qx qy qz as stored */
  double t_cam_from_world[3];
  hearth_rigid T_world_from_cam;     /* the inverse, from the normalised quaternion */
  char name[HEARTH_COLMAP_NAME_MAX]; /* relative to COLMAP's image folder, '/' separated */
  size_t n_points2d;                 /* 2-D points (features) of the image */
  size_t n_observations;             /* those with a 3-D point */
} hearth_colmap_image;

typedef struct hearth_colmap_point {
  uint64_t id;
  double xyz[3];
  uint8_t rgb[3];
  double error;        /* mean reprojection error, pixels */
  size_t track_length; /* images observing the point */
} hearth_colmap_point;

typedef enum hearth_colmap_format {
  HEARTH_COLMAP_TEXT = 0,  /* cameras.txt, images.txt, points3D.txt */
  HEARTH_COLMAP_BINARY = 1 /* cameras.bin, images.bin, points3D.bin */
} hearth_colmap_format;

typedef enum hearth_colmap_file {
  HEARTH_COLMAP_CAMERAS = 0,
  HEARTH_COLMAP_IMAGES = 1,
  HEARTH_COLMAP_POINTS3D = 2
} hearth_colmap_file;

/* A model: cameras, images and points each sorted by id (ids unique). The
 * arrays are owned; release with hearth_colmap_model_free (which accepts a
 * zeroed model). */
typedef struct hearth_colmap_model {
  hearth_colmap_format format;
  size_t n_cameras, n_images, n_points;
  hearth_colmap_camera *cameras;
  hearth_colmap_image *images;
  hearth_colmap_point *points;
} hearth_colmap_model;
void hearth_colmap_model_free(hearth_colmap_model *m);

/* Read the model in dir: binary when cameras.bin, images.bin and points3D.bin
 * are all there (as COLMAP itself prefers), else text when the three .txt
 * files are, else HEARTH_E_NOT_FOUND naming what is missing. Files are read
 * cameras, images, points3D; images must name cameras of the model, and
 * point tracks registered images and their 2-D points. Each file may be at
 * most 1 GiB. On failure *m is zeroed. */
hearth_status hearth_colmap_read(const char *dir, hearth_colmap_model *m, hearth_err *err);

/* Parse one file's bytes data[0..len) (`name` names it in messages) into m,
 * replacing that file's array and setting m->format. Images must name
 * cameras already in m and point tracks images already in m, so parse in
 * the order cameras, images, points3D (as hearth_colmap_read does). On
 * failure that array of m is left empty and the others untouched. */
hearth_status hearth_colmap_parse(hearth_colmap_file which, hearth_colmap_format format,
                                  const uint8_t *data, size_t len, const char *name,
                                  hearth_colmap_model *m, hearth_err *err);

/* The camera / image with that id, or NULL (binary search; points into m). */
const hearth_colmap_camera *hearth_colmap_find_camera(const hearth_colmap_model *m, uint32_t id);
const hearth_colmap_image *hearth_colmap_find_image(const hearth_colmap_model *m, uint32_t id);

/* ---- from a model to hearth's documents ------------------------------------ */
/* The (state, view) of an image name: view = the file name's stem
 * ("neutral/v07.jpg" -> "v07"), state = the first folder of the name when it
 * is a valid state (hearth_state_valid), else default_state. Fails
 * (HEARTH_E_RANGE, message says why) when the view is not a valid view name
 * (1..63 of [A-Za-z0-9_-]) or default_state is needed and not a state. */
hearth_status hearth_colmap_view_of(const char *image_name, const char *default_state,
                                    char state[HEARTH_NAME_MAX], char view[HEARTH_NAME_MAX],
                                    hearth_err *err);

/* Which COLMAP camera and image each view came from. */
typedef struct hearth_recon_view_camera {
  char state[HEARTH_NAME_MAX], view[HEARTH_NAME_MAX];
  uint32_t camera_id, image_id;
  char image[HEARTH_COLMAP_NAME_MAX];
} hearth_recon_view_camera;

/* The intrinsics beside a poses document: one hearth camera per COLMAP
 * camera (with COLMAP's model and parameters for reference) and the camera
 * of each view, in the poses' order. Owned arrays; free with
 * hearth_recon_cameras_free (accepts a zeroed struct). */
typedef struct hearth_recon_cameras {
  size_t n_cameras;
  hearth_colmap_camera *cameras;
  size_t n_views;
  hearth_recon_view_camera *views;
} hearth_recon_cameras;
void hearth_recon_cameras_free(hearth_recon_cameras *c);

/* Every registered image of m as a view pose (see hearth_colmap_view_of),
 * sorted by state (neutral, hot, warm, iced, used) and then view name, and,
 * when cams is not NULL, the cameras they use. Two images with the same
 * (state, view) are an error naming both. On failure the outputs are zeroed. */
hearth_status hearth_colmap_to_poses(const hearth_colmap_model *m, const char *default_state,
                                     hearth_poses *poses, hearth_recon_cameras *cams,
                                     hearth_err *err);

/* The intrinsics file written beside poses file P: P without its ".json"
 * ending, then "_cameras.json" ("recon/poses_rgb.json" ->
 * "recon/poses_rgb_cameras.json"). HEARTH_E_LIMIT if it does not fit. */
hearth_status hearth_recon_cameras_path(const char *poses_path, char *buf, size_t bufsz);

/* The cameras document:
 *   {"convention": "hearth camera: OpenCV axes, pixel (0, 0) at the centre of the top-left pixel",
 *    "cameras": [{"colmap_camera_id": 1, "colmap_model": "PINHOLE", "colmap_params": [...],
 *                 "width": 1920, "height": 1080, "K": [[fx,0,cx],[0,fy,cy],[0,0,1]],
 *                 "dist": [k1,k2,p1,p2,k3]}],
 *    "views": [{"state": "neutral", "view": "v00", "colmap_camera_id": 1,
 *               "colmap_image_id": 3, "colmap_image": "neutral/v00.jpg"}]}
 * written atomically and deterministically in the style of the dataset
 * documents (docs/dataset.md); the reader is strict in the same way (camera
 * ids unique, every view's camera listed, K and dist as in rig.json). */
hearth_status hearth_recon_cameras_write(const char *path, const hearth_recon_cameras *c,
                                         hearth_err *err);
hearth_status hearth_recon_cameras_parse(const char *text, size_t len, const char *name,
                                         hearth_recon_cameras *c, hearth_err *err);
hearth_status hearth_recon_cameras_read(const char *path, hearth_recon_cameras *c, hearth_err *err);

/* Poses against instance `instance` of the release at root: every pose must
 * be a colour view (raw/<state>/manifest.json) of a state of instance.json
 * (HEARTH_E_INCONSISTENT naming the first that is not); the instance's views
 * without a pose are counted and the first HEARTH_RECON_MISSING_LISTED of
 * them listed as "state/view". */
#define HEARTH_RECON_MISSING_LISTED 16
typedef struct hearth_recon_coverage {
  size_t n_views;   /* colour views of the instance */
  size_t n_missing; /* of those, without a pose */
  char missing[HEARTH_RECON_MISSING_LISTED][2 * HEARTH_NAME_MAX];
} hearth_recon_coverage;
hearth_status hearth_recon_match_instance(const char *root, const char *instance,
                                          const hearth_poses *p, hearth_recon_coverage *cov,
                                          hearth_err *err);

/* ---- comparing pose sets ----------------------------------------------------- */
/* The similarity x_ref = s R x_est + t that best maps the camera centres of
 * est onto those of ref (least squares over the views both have, in closed
 * form: Horn's quaternion solution, the same optimum as Umeyama's SVD one),
 * and the errors left after it: per common view the angle
 * between R R_est and R_ref and the distance between the mapped and the
 * reference centre (reference units). At least 3 common views whose centres
 * are not all on one line are needed (HEARTH_E_NUMERIC otherwise). */
typedef struct hearth_pose_alignment {
  hearth_similarity ref_from_est;
  size_t n_common; /* views in both sets */
  double rot_median_deg, rot_max_deg;
  double pos_median, pos_rms, pos_max; /* reference units */
} hearth_pose_alignment;
hearth_status hearth_poses_align(const hearth_poses *est, const hearth_poses *ref,
                                 hearth_pose_alignment *out, hearth_err *err);

/* ---- running an outside program ---------------------------------------------- */
/* Runs argv[0] (searched on PATH) with argv, stdin from /dev/null, its
 * stdout and stderr together appended to log_path (when not NULL) and
 * handed line by line to on_line (when not NULL; lines without their
 * newline, cut at 4095 bytes). Fails with HEARTH_E_NOT_FOUND when the
 * program cannot be started, and with HEARTH_E_IO when it exits non-zero or
 * dies; the message then gives the exit status and the last lines of its
 * output. `what` names the step in messages ("colmap mapper"). */
typedef void (*hearth_exec_line_fn)(void *ctx, const char *line);
hearth_status hearth_exec(const char *what, const char *const *argv, const char *log_path,
                          hearth_exec_line_fn on_line, void *ctx, hearth_err *err);
/* 1 if `program` is a path to an executable file, or is found as one on PATH. */
int hearth_program_found(const char *program);

/* ---- hearth recon --poses colmap ------------------------------------------------ */
typedef enum hearth_colmap_intrinsics {
  /* the colour camera of calibration/rig.json (else calibration/factory.json)
   * given to COLMAP as FULL_OPENCV and held fixed in bundle adjustment */
  HEARTH_COLMAP_INTR_CALIBRATION = 0,
  /* COLMAP's own self-calibration (SIMPLE_RADIAL from the image size) */
  HEARTH_COLMAP_INTR_ESTIMATE = 1
} hearth_colmap_intrinsics;

typedef struct hearth_colmap_job {
  const char *root;     /* release root */
  const char *instance; /* instance id */
  const char *out;      /* poses file; NULL: <instance>/recon/poses_rgb.json */
  const char *work;     /* workspace kept there; NULL: a temporary one, removed on success */
  const char *colmap;   /* the program; NULL: "colmap" on PATH */
  hearth_colmap_intrinsics intrinsics;
  int no_masks; /* 1: features everywhere, not only inside the cut-outs */
  int threads;  /* 0: hearth_default_threads() */
  int force;    /* 1: replace an existing out file */
  int quiet;    /* 1: no progress on stderr */
} hearth_colmap_job;

typedef struct hearth_colmap_result {
  size_t n_views;      /* colour views of all states given to COLMAP */
  size_t n_registered; /* views with a pose in the chosen model */
  size_t n_models;     /* models the mapper made */
  size_t n_points;     /* 3-D points of the chosen model */
  double seconds[3];   /* feature_extractor, exhaustive_matcher, mapper */
  char out[4096];      /* the poses file written */
  char work[4096];     /* the workspace (removed unless job.work or a failure) */
} hearth_colmap_result;

/* Run feature_extractor (cut-outs as masks, one shared camera, CPU SIFT),
 * exhaustive_matcher and mapper over every colour view of every state of
 * the instance (instance.json, raw/<state>/manifest.json), import the model
 * with the most registered images and write its poses and cameras
 * (hearth_recon_cameras_path) to job->out. A missing program or a failed
 * step is an error naming the step, its exit status and the tail of its
 * log (kept in the workspace). The mapper registering no image at all is
 * HEARTH_E_NUMERIC. */
hearth_status hearth_colmap_run(const hearth_colmap_job *job, hearth_colmap_result *res,
                                hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
