/* hearth/geom.h - area core (src/core/core_geom.c): rigid transforms and
 * small 3-D helpers. Plain values, nothing allocated.
 *
 * A transform named T_a_from_b maps coordinates in frame b to frame a:
 *   x_a = R * x_b + t,  R row-major 3x3.
 * Camera poses are stored as T_world_from_cam. Units are metres.
 * See docs/conventions.md. */
#ifndef HEARTH_GEOM_H
#define HEARTH_GEOM_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct hearth_rigid {
  double R[9]; /* row-major rotation */
  double t[3]; /* translation, metres */
} hearth_rigid;

void hearth_rigid_identity(hearth_rigid *T);
/* out = a * b  (T_x_from_z = T_x_from_y * T_y_from_z); out may alias a or b. */
void hearth_rigid_compose(const hearth_rigid *a, const hearth_rigid *b, hearth_rigid *out);
/* out = inverse(T): rotation R^T, translation -R^T t; out may alias T. */
void hearth_rigid_inverse(const hearth_rigid *T, hearth_rigid *out);
/* y = R x + t (y may alias x). */
void hearth_rigid_apply(const hearth_rigid *T, const double x[3], double y[3]);
/* y = R x. */
void hearth_rigid_rotate(const hearth_rigid *T, const double x[3], double y[3]);
/* 4x4 row-major homogeneous matrix <-> rigid. from_mat4 checks that the top
 * left block is a rotation (orthonormal to tol, det +1) and the last row is
 * 0 0 0 1; returns 0 if not. */
void hearth_rigid_to_mat4(const hearth_rigid *T, double M[16]);
int hearth_rigid_from_mat4(const double M[16], double tol, hearth_rigid *T);
/* 1 if R is a rotation within tol (|R^T R - I|_max <= tol, det > 0). */
int hearth_is_rotation(const double R[9], double tol);

/* Rotation vector (axis * angle, radians) <-> matrix (Rodrigues). */
void hearth_rotvec_to_matrix(const double w[3], double R[9]);
void hearth_matrix_to_rotvec(const double R[9], double w[3]);
/* Derivative of the rotation matrix w.r.t. the rotation vector:
 * dR[k*9 + i] = d R[i] / d w[k]. */
void hearth_rotvec_to_matrix_jac(const double w[3], double R[9], double dR[27]);
/* Angle of the relative rotation between two matrices, radians (0..pi). */
double hearth_rotation_angle_between(const double Ra[9], const double Rb[9]);
/* Axis * angle of the rotation given as rotation vector w, continuous near
 * q_ref: the rotation's unit quaternion (w x y z) is taken in the
 * hemisphere of q_ref, then written as axis * 2 acos(qw) (angle in
 * [0, 2 pi); robosuite's quat2axisangle, which openpi's LIBERO client
 * sends). A plain rotation vector (angle <= pi) jumps by 2 pi where the
 * rotation passes half a turn; this one does not while the rotation stays
 * within a quarter turn of q_ref. */
void hearth_rotvec_to_axis_angle_near(const double w[3], const double q_ref[4], double out[3]);

/* Re-orthonormalise a nearly orthonormal matrix (SVD-free polar iteration). */
void hearth_orthonormalize(double R[9]);

/* Small vector helpers. */
double hearth_dot3(const double a[3], const double b[3]);
void hearth_cross3(const double a[3], const double b[3], double out[3]);
double hearth_norm3(const double a[3]);
void hearth_mat3_mul(const double A[9], const double B[9], double out[9]);
void hearth_mat3_transpose(const double A[9], double out[9]);

/* A similarity x' = s R x + t (used by the reconstruction stand-in). */
typedef struct hearth_similarity {
  double s;
  hearth_rigid T;
} hearth_similarity;

#ifdef __cplusplus
}
#endif
#endif
