/* hearth/calib.h - area calib (src/calib/): hole targets (hearth_target of
 * dataset.h: the paper's 84-hole plate or any hex / grid target of
 * calibration/target.json): hole-centre detection in colour and thermal images, thermal intrinsics (Zhang +
 * Levenberg-Marquardt) and the RGB-thermal stereo transform, plus the
 * release-level `detect` and `calibrate` stages.
 *
 * Detection never alters its input: thermal enhancement (percentile clip,
 * 8-bit, upsampling) works on a private copy and the final centres are
 * intensity-weighted centroids on the raw matrix, in native pixels.
 * Centres come out in target order (hearth_target_points), so index i is the
 * same hole in every frame and camera; a frame that cannot be ordered with
 * certainty is reported found = 0 with a reason, never guessed. Holes may be
 * brighter or darker than the plate in either camera: detection tries the
 * usual polarity first (thermal: warm holes; colour: dark holes), then the
 * other. */
#ifndef HEARTH_CALIB_H
#define HEARTH_CALIB_H

#include <stddef.h>
#include "hearth/core.h"
#include "hearth/camera.h"
#include "hearth/geom.h"
#include "hearth/image.h"
#include "hearth/dataset.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- detection ------------------------------------------------------------- */
typedef struct hearth_detect_opts {
  int upsample;       /* thermal upsampling before blob detection; default 4 */
  double clip_lo_pct; /* thermal percentile clip bounds; default 1 and 99.5 */
  double clip_hi_pct;
  double max_blur_frac; /* reject frames whose estimated blur sigma exceeds this
                           fraction of the hole radius; default 0.4 (the
                           estimate reads low: 2.5 px blur on 3 px holes gives 0.28,
                           the virtual rig 1.3 px blurred frames up to 0.28) */
  hearth_target target; /* the target to find; zeroed (the default): the paper's plate */
} hearth_detect_opts;
void hearth_detect_opts_default(hearth_detect_opts *o);

/* Thermal matrix (1-channel F32, degC), holes warmer or cooler than the plate. Fills
 * det->found, det->reason, det->centres (native pixels); det->frame and
 * det->camera are left to the caller. Errors only for invalid arguments.
 * o may be NULL (the defaults); temps is only read. */
hearth_status hearth_detect_plate_thermal(const hearth_image *temps, const hearth_detect_opts *o,
                                          hearth_detection *det, hearth_err *err);
/* Colour or gray U8 image (1, 3 or 4 channels; an 8-bit tone-mapped thermal
 * frame too), holes darker or brighter than the plate. */
hearth_status hearth_detect_plate_color(const hearth_image *img, const hearth_detect_opts *o,
                                        hearth_detection *det, hearth_err *err);

/* Order n candidate centres (pixels, any order, possibly with outliers) by
 * the target's lattice and row structure. Returns 1 and fills
 * centres[0..hearth_target_holes(t)) if exactly the target's holes were
 * identified in an unambiguous order, else 0 with a reason. t may be NULL
 * or zeroed (the paper's plate). */
int hearth_target_order(const hearth_target *t, const double (*pts)[2], size_t n,
                        double (*centres)[2], char *reason, size_t reason_size);
/* hearth_target_order for the paper's plate. */
int hearth_plate_order(const double (*pts)[2], size_t n, double centres[HEARTH_PLATE_HOLES][2],
                       char *reason, size_t reason_size);

/* ---- calibration ------------------------------------------------------------- */
typedef struct hearth_calib_opts {
  int max_iterations;    /* Levenberg-Marquardt; default 100 */
  double outlier_factor; /* stereo: reject pairs whose RMS > factor * median ... */
  double outlier_min_px; /* ... and above this floor; defaults 2.5 and 0.01 px */
  /* release stage only: correct the perspective bias of hole centroids (the
   * centroid of a tilted hole's image is not the image of its centre) from
   * the estimated poses, and re-solve; default 1 */
  int perspective_correction;
  /* with perspective_correction: a hole of a plate with a thickness
   * (target.json "thickness_m") shows only the overlap of its front and back
   * openings; correct that centroid to the front opening's projected centre
   * too; default 1 (0: the centroid taken as a thin hole's) */
  int wall_correction;
  double hole_radius_m; /* default 0.004; the release stage takes the target's */
  /* hearth_calib_intrinsics: the lens model solved for; default
   * HEARTH_LENS_BROWN5 (the rational model starts from the 5-parameter
   * solution) */
  hearth_lens_model lens_model;
  /* hearth_calib_stereo: camera a has a rolling shutter (reads its rows in
   * turn) and the plate may move during the readout: a velocity per pair
   * (first order in each point's row time) is solved with its pose and kept
   * when it explains more than noise would; default 1 */
  int rolling_shutter;
  /* hearth_calib_stereo_joint: camera b's intrinsics and distortion are
   * refined with the extrinsic, from the pairs (whose plate poses camera a
   * fixes) and camera b's own frames; default 1 (0: camera b's intrinsics
   * held fixed, the paper's stereo) */
  int stereo_intrinsics;
  /* with stereo_intrinsics: the target's holes are taken as drilled where
   * the data put them, each hole's in-plane offset from the nominal lattice
   * solved jointly with the rest (the offsets' similarity part held at
   * zero: the gauge), under a prior N(0, target_sigma_m^2) per axis, and
   * the calibration run again from the target as solved; default 0 */
  int target_points;
  double target_sigma_m; /* the holes' drilling tolerance, 1 sigma; default 4e-5 */
} hearth_calib_opts;
void hearth_calib_opts_default(hearth_calib_opts *o);

/* Intrinsics and 5-parameter distortion from n_frames views of n_pts known
 * planar points (obj z = 0, metres). img holds n_frames * n_pts (u, v)
 * pairs in pixels, frame after frame. Zhang's closed form initialises, then
 * LM refines intrinsics, distortion and every pose. Outputs: cam
 * (width/height set from the arguments), rms_px = sqrt(mean squared point
 * error), optionally per-frame RMS (n_frames) and T_cam_from_plate
 * (n_frames), into the caller's arrays (NULL to skip). o may be NULL (the
 * defaults). */
hearth_status hearth_calib_intrinsics(const double (*obj)[3], size_t n_pts, const double *img,
                                      size_t n_frames, int width, int height,
                                      const hearth_calib_opts *o, hearth_camera *cam,
                                      double *rms_px, double *frame_rms,
                                      hearth_rigid *T_cam_from_plate, hearth_err *err);

/* Pose of a plate seen by a calibrated camera (homography start + LM). */
hearth_status hearth_calib_pose(const hearth_camera *cam, const double (*obj)[3], size_t n_pts,
                                const double *img, hearth_rigid *T_cam_from_plate, double *rms_px,
                                hearth_err *err);

/* Stereo with both intrinsics fixed: T_b_from_a from n_pairs views of the
 * plate (img_a, img_b laid out as in hearth_calib_intrinsics). Jointly
 * refines T_b_from_a and the per-pair plate poses in camera a. Pairs whose
 * RMS exceeds the outlier rule are dropped and the solve repeated.
 * rms_px = sqrt(mean squared point error over both cameras and the pairs
 * used). pair_rms (n_pairs) and pair_used (n_pairs) may be NULL. With
 * o->rolling_shutter, camera a's point at row v is taken as seen at time
 * (v + 0.5) / height - 0.5 of a frame from its middle row (camera b's at
 * that middle row), each pair's plate moving at a velocity solved with its
 * pose; the model is kept only when it explains more than noise, otherwise
 * the result is the rigid solve's. */
hearth_status hearth_calib_stereo(const hearth_camera *cam_a, const hearth_camera *cam_b,
                                  const double (*obj)[3], size_t n_pts, const double *img_a,
                                  const double *img_b, size_t n_pairs, const hearth_calib_opts *o,
                                  hearth_rigid *T_b_from_a, double *rms_px, double *pair_rms,
                                  int *pair_used, hearth_err *err);

/* hearth_calib_stereo, then (o->stereo_intrinsics) camera b's fx fy cx cy
 * and k1 k2 p1 p2 k3 refined jointly with T_b_from_a, every used pair's
 * plate pose (and velocity) and the pose of each of camera b's own frames
 * img_c (n_c frames of n_pts points, as img_b; the frames its intrinsics
 * were calibrated from, or none): cam_b is updated. own_rms_px (may be
 * NULL): the RMS over img_c at the end (NAN without the refinement). */
hearth_status hearth_calib_stereo_joint(const hearth_camera *cam_a, hearth_camera *cam_b,
                                        const double (*obj)[3], size_t n_pts, const double *img_a,
                                        const double *img_b, size_t n_pairs, const double *img_c,
                                        size_t n_c, const hearth_calib_opts *o,
                                        hearth_rigid *T_b_from_a, double *rms_px,
                                        double *own_rms_px, double *pair_rms, int *pair_used,
                                        hearth_err *err);

/* ---- release stages ----------------------------------------------------------- */
/* Detect the target of <root>/calibration/target.json (absent: the paper's
 * plate) in every capture under <root>/calibration/captures (thermal
 * captures of any one size) and
 * write <root>/calibration/detections.json and, if overlays, the
 * calibration/overlays/<frame>_<camera>.png images. Frames are listed
 * thermal fNNN first, then each stereo pair pNNN (rgb, thermal). out (may
 * be NULL) receives the detections (the caller frees them with
 * hearth_detections_free). */
typedef struct hearth_detect_job {
  hearth_detect_opts detect;
  int overlays; /* default 1 */
  int threads;  /* 0 = hearth_default_threads() */
  int quiet;
} hearth_detect_job;
void hearth_detect_job_default(hearth_detect_job *r);
hearth_status hearth_calib_detect_release(const char *root, const hearth_detect_job *r,
                                          hearth_detections *out, hearth_err *err);

/* What `calibrate` did, frame by frame. */
typedef struct hearth_calib_frame_report {
  char frame[HEARTH_NAME_MAX];
  int used;      /* 0: not found in detection, or rejected as an outlier */
  double rms_px; /* per-frame RMS (stereo: both cameras), NAN if unused */
  char note[96];
} hearth_calib_frame_report;

/* The thermal-only calibration's lens models, compared on held-out frames:
 * frames are dealt round-robin into `folds` folds; each fold's frames are
 * predicted (pose fitted, intrinsics and distortion fixed) by a calibration
 * on the other folds. The rational model is chosen only when its held-out
 * RMS is at least HEARTH_LENS_MARGIN_REL below the 5-parameter model's and
 * lower by HEARTH_LENS_MARGIN_PX or more. */
#define HEARTH_LENS_MARGIN_REL 0.10
#define HEARTH_LENS_MARGIN_PX 0.005
#define HEARTH_LENS_MIN_FRAMES 6 /* fewer used frames: no comparison, 5-parameter */
typedef struct hearth_lens_fit {
  hearth_camera cam;     /* the fit on every used frame */
  double train_rms_px;   /* its RMS over those frames */
  double heldout_rms_px; /* RMS of the held-out predictions; NAN if not compared */
} hearth_lens_fit;
typedef struct hearth_lens_choice {
  hearth_lens_fit fit[2];   /* indexed by hearth_lens_model */
  hearth_lens_model chosen; /* the model written to rig.json */
  int folds;                /* 0: not compared */
  int forced;               /* chosen by the caller, not by the rule */
  char reason[200];
} hearth_lens_choice;

typedef struct hearth_calib_report {
  size_t n_thermal, n_pairs;
  hearth_calib_frame_report *thermal; /* owned */
  hearth_calib_frame_report *pairs;   /* owned */
  hearth_rig rig;
  /* the stereo RMS against the nominal target (rig.stereo_rms_px is after
   * the target model, with opts.target_points; the same without it); NAN
   * for a thermal-only calibration */
  double stereo_rms_nominal_px;
  double t_calib_s;        /* seconds spent reading, solving (not writing) */
  hearth_lens_choice lens; /* thermal-only calibration only */
} hearth_calib_report;
/* Frees the frame lists and zeroes r; accepts a zeroed report. */
void hearth_calib_report_free(hearth_calib_report *r);

/* Read calibration/detections.json, calibration/factory.json and
 * calibration/target.json (absent: the paper's plate; it must be the target
 * the detections were made for), take the thermal camera's size from its
 * first thermal capture present, calibrate,
 * write calibration/rig.json, calibration/rig_opencv.yaml and
 * calibration/calibration_report.json (all atomically, all or nothing).
 * rep (required) is filled; the caller frees it with
 * hearth_calib_report_free. */
hearth_status hearth_calib_calibrate_release(const char *root, const hearth_calib_opts *o,
                                             hearth_calib_report *rep, hearth_err *err);

/* Thermal-only calibration of a root holding calibration/captures/thermal
 * (frames of any name: CSV, PNG or TIFF, see hearth_frame_read) and
 * calibration/detections.json from `detect` (which finds such a root by
 * the absence of captures/stereo). Every found frame is re-read for its
 * size (all must agree). Fits both lens models with outlier rejection and
 * perspective correction, compares them on held-out frames
 * (hearth_lens_choice), and writes a thermal-only calibration/rig.json,
 * calibration/rig_opencv.yaml (OpenCV's camera_matrix and
 * distortion_coefficients, 1x5 or 1x8) and calibration_report.json; no
 * output is written unless all inputs are good. force_model: -1 = choose
 * by the rule, else that hearth_lens_model. */
hearth_status hearth_calib_thermal_only_release(const char *root, const hearth_calib_opts *o,
                                                int force_model, hearth_calib_report *rep,
                                                hearth_err *err);

/* An OpenCV FileStorage YAML of the rig (cv2.FileStorage reads it). */
hearth_status hearth_calib_write_opencv_yaml(const char *path, const hearth_rig *rig,
                                             hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
