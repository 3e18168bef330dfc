/* Private to the calibration area: small dense linear algebra, the plane
 * homography and Zhang's closed form, shared by the solvers and tests. */
#ifndef HEARTH_CALIB_INTERNAL_H
#define HEARTH_CALIB_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "hearth/calib.h"

/* Solve A x = b for a symmetric positive definite n x n A (row-major, n <=
 * CALIB_CHOL_MAX) by Cholesky; A and b are overwritten (b becomes x).
 * Returns 0 if A is not positive definite. */
#define CALIB_CHOL_MAX (16 + 2 * HEARTH_TARGET_MAX_HOLES)
int calib_chol_solve(double *A, double *b, int n);
/* Invert a symmetric positive definite n x n matrix in place (n <= 16). */
int calib_chol_invert(double *A, int n);

/* Homography H (row-major 3x3, H[8] = 1 scale not imposed) mapping plane
 * points (X, Y) to image points (u, v), by the normalised DLT. pts are
 * interleaved pairs. Returns 0 if degenerate. */
int calib_homography(const double *plane_xy, const double *img_uv, size_t n, double H[9]);

/* Zhang's closed-form intrinsics from n >= 3 homographies (skew solved then
 * dropped). Returns 0 if the system is degenerate or not positive. */
int calib_zhang_intrinsics(const double *H, size_t n, double *fx, double *fy, double *cx,
                           double *cy);

/* Plate pose from a homography of plane -> normalised image coordinates
 * (i.e. K^-1 H). Returns 0 if degenerate. */
int calib_pose_from_homography(const double Hn[9], hearth_rigid *T);

/* Plate (x, y, z) and pixel pairs -> interleaved helpers. */
void calib_plate_points(double obj[HEARTH_PLATE_HOLES][3]);

/* Rotation vector + translation <-> rigid. */
void calib_rigid_from_params(const double p[6], hearth_rigid *T);
void calib_params_from_rigid(const hearth_rigid *T, double p[6]);

/* Residual and Jacobian of one projected point with respect to a pose
 * (rotvec w, translation t): Xc = R(w) X + t. Returns 0 if behind camera.
 * d_pose: 2 x 6 row-major (dw then dt); jac from hearth_camera_project.
 * Xc_out may be NULL. */
int calib_project_pose(const hearth_camera *cam, const double R[9], const double dR[27],
                       const double t[3], const double X[3], double uv[2], hearth_project_jac *jac,
                       double d_pose[12], double Xc_out[3]);

/* Per-point bias (n x 2) of a circle's image centroid over the projected
 * centre, for circles of `radius` (metres) around obj on the plate plane.
 * thickness > 0: the holes go through a plate that deep (its back face at
 * plate z = +thickness, away from the camera), so what shows through is the
 * overlap of the projected front and back openings; the bias is that
 * overlap's centroid over the projected front centre. */
void calib_circle_bias(const hearth_camera *cam, const hearth_rigid *T, const double (*obj)[3],
                       size_t n, double radius, double thickness, double *bias);

/* hearth_calib_stereo_joint, and each pair's trigger time into pair_time
 * (n_pairs; may be NULL): when camera b saw the plate, in frames of camera
 * a's readout from camera a's middle row (positive: after it), as the
 * rolling-shutter model solved it; NAN for a pair not used or where the
 * model was not kept (o->rolling_shutter off, or a still plate).
 * rms_nominal_px (may be NULL): the stereo RMS solved against the nominal
 * target obj (with o->target_points, before the holes' offsets are solved;
 * otherwise *rms_px). pts_out (n_pts, may be NULL): the target's points
 * as solved (obj itself without o->target_points). */
hearth_status calib_stereo_joint_times(const hearth_camera *cam_a, hearth_camera *cam_b,
                                       const double (*obj)[3], size_t n_pts, const double *img_a,
                                       const double *img_b, size_t n_pairs, const double *img_c,
                                       size_t n_c, const hearth_calib_opts *o,
                                       hearth_rigid *T_b_from_a, double *rms_px, double *own_rms_px,
                                       double *pair_rms, int *pair_used, double *pair_time,
                                       double *rms_nominal_px, double (*pts_out)[3],
                                       hearth_err *err);

/* ---- shared by the release stages (calib_release.c) and the thermal-only
 * calibration (calib_thermal_only.c) ---- */
/* The overlay of a detection of target (as `detect` draws it), PNG-encoded
 * into *png (malloc'ed, the caller frees). */
hearth_status calib_overlay_encode(const hearth_image *img, int thermal,
                                   const hearth_target *target, const hearth_detection *det,
                                   uint8_t **png, size_t *size, hearth_err *err);
/* OpenCV FileStorage YAML pieces: a number (locale-free, 16 digits) and a
 * !!opencv-matrix of doubles. */
void calib_yaml_num(FILE *fp, double x);
void calib_yaml_mat(FILE *fp, const char *name, int rows, int cols, const double *v);
/* `detect` on a root without calibration/captures/stereo. */
hearth_status calib_detect_thermal_only(const char *root, const hearth_detect_job *run,
                                        hearth_detections *out, hearth_err *err);

#endif
