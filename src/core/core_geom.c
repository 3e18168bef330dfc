/* Rigid transforms, rotation vectors and small 3-D helpers (see geom.h). */
#include <math.h>
#include <string.h>
#include "hearth/geom.h"

/* ---- vectors and 3x3 matrices -------------------------------------------- */

double hearth_dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void hearth_cross3(const double a[3], const double b[3], double out[3]) {
  double c0 = a[1] * b[2] - a[2] * b[1];
  double c1 = a[2] * b[0] - a[0] * b[2];
  double c2 = a[0] * b[1] - a[1] * b[0];
  out[0] = c0;
  out[1] = c1;
  out[2] = c2;
}

double hearth_norm3(const double a[3]) { return sqrt(hearth_dot3(a, a)); }

void hearth_mat3_mul(const double A[9], const double B[9], double out[9]) {
  double C[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[i * 3 + j] = A[i * 3] * B[j] + A[i * 3 + 1] * B[3 + j] + A[i * 3 + 2] * B[6 + j];
  memcpy(out, C, sizeof C);
}

void hearth_mat3_transpose(const double A[9], double out[9]) {
  double C[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) C[i * 3 + j] = A[j * 3 + i];
  memcpy(out, C, sizeof C);
}

static double det3(const double A[9]) {
  return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
         A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* ---- rigid transforms ------------------------------------------------------ */

void hearth_rigid_identity(hearth_rigid *T) {
  memset(T, 0, sizeof *T);
  T->R[0] = T->R[4] = T->R[8] = 1.0;
}

void hearth_rigid_rotate(const hearth_rigid *T, const double x[3], double y[3]) {
  double r0 = T->R[0] * x[0] + T->R[1] * x[1] + T->R[2] * x[2];
  double r1 = T->R[3] * x[0] + T->R[4] * x[1] + T->R[5] * x[2];
  double r2 = T->R[6] * x[0] + T->R[7] * x[1] + T->R[8] * x[2];
  y[0] = r0;
  y[1] = r1;
  y[2] = r2;
}

void hearth_rigid_apply(const hearth_rigid *T, const double x[3], double y[3]) {
  double r[3];
  hearth_rigid_rotate(T, x, r);
  y[0] = r[0] + T->t[0];
  y[1] = r[1] + T->t[1];
  y[2] = r[2] + T->t[2];
}

void hearth_rigid_compose(const hearth_rigid *a, const hearth_rigid *b, hearth_rigid *out) {
  /* work on copies so out may alias a or b */
  hearth_rigid r;
  hearth_mat3_mul(a->R, b->R, r.R);
  hearth_rigid_apply(a, b->t, r.t);
  *out = r;
}

void hearth_rigid_inverse(const hearth_rigid *T, hearth_rigid *out) {
  hearth_rigid r;
  hearth_mat3_transpose(T->R, r.R);
  double t[3];
  for (int i = 0; i < 3; i++)
    t[i] = -(r.R[i * 3] * T->t[0] + r.R[i * 3 + 1] * T->t[1] + r.R[i * 3 + 2] * T->t[2]);
  memcpy(r.t, t, sizeof t);
  *out = r;
}

void hearth_rigid_to_mat4(const hearth_rigid *T, double M[16]) {
  for (int i = 0; i < 3; i++) {
    M[i * 4 + 0] = T->R[i * 3 + 0];
    M[i * 4 + 1] = T->R[i * 3 + 1];
    M[i * 4 + 2] = T->R[i * 3 + 2];
    M[i * 4 + 3] = T->t[i];
  }
  M[12] = M[13] = M[14] = 0.0;
  M[15] = 1.0;
}

int hearth_is_rotation(const double R[9], double tol) {
  for (int i = 0; i < 9; i++)
    if (!isfinite(R[i])) return 0;
  /* R^T R - I, entry by entry */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j];
      if (fabs(s - (i == j ? 1.0 : 0.0)) > tol) return 0;
    }
  return det3(R) > 0.0;
}

int hearth_rigid_from_mat4(const double M[16], double tol, hearth_rigid *T) {
  for (int i = 0; i < 16; i++)
    if (!isfinite(M[i])) return 0;
  if (fabs(M[12]) > tol || fabs(M[13]) > tol || fabs(M[14]) > tol || fabs(M[15] - 1.0) > tol)
    return 0;
  hearth_rigid r;
  for (int i = 0; i < 3; i++) {
    r.R[i * 3 + 0] = M[i * 4 + 0];
    r.R[i * 3 + 1] = M[i * 4 + 1];
    r.R[i * 3 + 2] = M[i * 4 + 2];
    r.t[i] = M[i * 4 + 3];
  }
  if (!hearth_is_rotation(r.R, tol)) return 0;
  *T = r;
  return 1;
}

/* ---- rotation vectors ----------------------------------------------------- */

/* Coefficients of R = I + a W + b W^2 (W = [w]x) and of their derivatives
 * divided by theta: c = a'(t)/t, d = b'(t)/t. Series below 1e-2 rad where
 * the closed forms lose digits to cancellation. */
static void rodrigues_coeffs(double th, double *a, double *b, double *c, double *d) {
  double t2 = th * th;
  if (th < 1e-2) {
    *a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
    *b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    *c = -1.0 / 3.0 + t2 / 30.0 - t2 * t2 / 840.0;
    *d = -1.0 / 12.0 + t2 / 180.0 - t2 * t2 / 6720.0;
  } else {
    double s = sin(th), co = cos(th);
    *a = s / th;
    *b = (1.0 - co) / t2;
    *c = (th * co - s) / (t2 * th);
    *d = (th * s - 2.0 * (1.0 - co)) / (t2 * t2);
  }
}

static void skew(const double w[3], double W[9]) {
  W[0] = 0.0;
  W[1] = -w[2];
  W[2] = w[1];
  W[3] = w[2];
  W[4] = 0.0;
  W[5] = -w[0];
  W[6] = -w[1];
  W[7] = w[0];
  W[8] = 0.0;
}

void hearth_rotvec_to_matrix(const double w[3], double R[9]) {
  double th = hearth_norm3(w), a, b, c, d, W[9], W2[9];
  rodrigues_coeffs(th, &a, &b, &c, &d);
  skew(w, W);
  hearth_mat3_mul(W, W, W2);
  for (int i = 0; i < 9; i++) R[i] = a * W[i] + b * W2[i];
  R[0] += 1.0;
  R[4] += 1.0;
  R[8] += 1.0;
}

void hearth_rotvec_to_matrix_jac(const double w[3], double R[9], double dR[27]) {
  double th = hearth_norm3(w), a, b, c, d, W[9], W2[9];
  rodrigues_coeffs(th, &a, &b, &c, &d);
  skew(w, W);
  hearth_mat3_mul(W, W, W2);
  if (R) {
    for (int i = 0; i < 9; i++) R[i] = a * W[i] + b * W2[i];
    R[0] += 1.0;
    R[4] += 1.0;
    R[8] += 1.0;
  }
  /* dR/dw_k = c w_k W + a E_k + d w_k W^2 + b (E_k W + W E_k), E_k = [e_k]x */
  for (int k = 0; k < 3; k++) {
    double e[3] = {0, 0, 0}, E[9], EW[9], WE[9];
    e[k] = 1.0;
    skew(e, E);
    hearth_mat3_mul(E, W, EW);
    hearth_mat3_mul(W, E, WE);
    for (int i = 0; i < 9; i++)
      dR[k * 9 + i] = c * w[k] * W[i] + a * E[i] + d * w[k] * W2[i] + b * (EW[i] + WE[i]);
  }
}

void hearth_matrix_to_rotvec(const double R[9], double w[3]) {
  /* s = sin(theta) * axis from the antisymmetric part; cos from the trace */
  double s[3] = {0.5 * (R[7] - R[5]), 0.5 * (R[2] - R[6]), 0.5 * (R[3] - R[1])};
  double co = 0.5 * (R[0] + R[4] + R[8] - 1.0);
  if (co > 1.0) co = 1.0;
  if (co < -1.0) co = -1.0;
  double sn = hearth_norm3(s);
  double th = atan2(sn, co);
  if (co > 0.0) {
    /* away from pi: axis from the antisymmetric part is well conditioned */
    double f;
    if (sn < 1e-7) f = 1.0 + sn * sn / 6.0; /* theta / sin(theta) */
    else f = th / sn;
    w[0] = s[0] * f;
    w[1] = s[1] * f;
    w[2] = s[2] * f;
    return;
  }
  /* near pi: (R + R^T)/2 - cos I = (1 - cos) n n^T; take the largest column */
  double B[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) B[i * 3 + j] = 0.5 * (R[i * 3 + j] + R[j * 3 + i]);
  B[0] -= co;
  B[4] -= co;
  B[8] -= co;
  int k = 0;
  if (B[4] > B[k * 4]) k = 1;
  if (B[8] > B[k * 4]) k = 2;
  double n[3] = {B[k], B[3 + k], B[6 + k]};
  double nn = hearth_norm3(n);
  if (!(nn > 0.0)) {
    w[0] = w[1] = w[2] = 0.0;
    return;
  }
  n[0] /= nn;
  n[1] /= nn;
  n[2] /= nn;
  /* the sign of the axis follows sin(theta) * axis (undetermined at exactly pi) */
  if (hearth_dot3(n, s) < 0.0) {
    n[0] = -n[0];
    n[1] = -n[1];
    n[2] = -n[2];
  }
  w[0] = n[0] * th;
  w[1] = n[1] * th;
  w[2] = n[2] * th;
}

double hearth_rotation_angle_between(const double Ra[9], const double Rb[9]) {
  double At[9], D[9];
  hearth_mat3_transpose(Ra, At);
  hearth_mat3_mul(At, Rb, D);
  double s[3] = {0.5 * (D[7] - D[5]), 0.5 * (D[2] - D[6]), 0.5 * (D[3] - D[1])};
  double co = 0.5 * (D[0] + D[4] + D[8] - 1.0);
  if (co > 1.0) co = 1.0;
  if (co < -1.0) co = -1.0;
  return atan2(hearth_norm3(s), co);
}

/* Gram-Schmidt fallback for matrices too far from orthonormal to invert. */
static void gram_schmidt(double R[9]) {
  double r0[3] = {R[0], R[1], R[2]}, r1[3] = {R[3], R[4], R[5]}, r2[3];
  double n = hearth_norm3(r0);
  if (!(n > 0.0)) {
    r0[0] = 1.0;
    r0[1] = r0[2] = 0.0;
    n = 1.0;
  }
  for (int i = 0; i < 3; i++) r0[i] /= n;
  double p = hearth_dot3(r0, r1);
  for (int i = 0; i < 3; i++) r1[i] -= p * r0[i];
  n = hearth_norm3(r1);
  if (!(n > 1e-300)) {
    /* any vector orthogonal to r0 */
    double e[3] = {fabs(r0[0]) < 0.9 ? 1.0 : 0.0, fabs(r0[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    hearth_cross3(r0, e, r1);
    n = hearth_norm3(r1);
  }
  for (int i = 0; i < 3; i++) r1[i] /= n;
  hearth_cross3(r0, r1, r2);
  memcpy(R, r0, sizeof r0);
  memcpy(R + 3, r1, sizeof r1);
  memcpy(R + 6, r2, sizeof r2);
}

void hearth_orthonormalize(double R[9]) {
  /* polar iteration X <- (X + X^-T) / 2 converges quadratically to the
   * nearest rotation when det > 0 */
  double X[9];
  memcpy(X, R, sizeof X);
  for (int it = 0; it < 50; it++) {
    double det = det3(X);
    if (!(det > 1e-12) || !isfinite(det)) {
      gram_schmidt(R);
      return;
    }
    /* inverse transpose = cofactor matrix / det */
    double C[9] = {X[4] * X[8] - X[5] * X[7], X[5] * X[6] - X[3] * X[8], X[3] * X[7] - X[4] * X[6],
                   X[2] * X[7] - X[1] * X[8], X[0] * X[8] - X[2] * X[6], X[1] * X[6] - X[0] * X[7],
                   X[1] * X[5] - X[2] * X[4], X[2] * X[3] - X[0] * X[5], X[0] * X[4] - X[1] * X[3]};
    double change = 0.0;
    for (int i = 0; i < 9; i++) {
      double nx = 0.5 * (X[i] + C[i] / det);
      double dv = fabs(nx - X[i]);
      if (dv > change) change = dv;
      X[i] = nx;
    }
    if (change < 1e-15) break;
  }
  memcpy(R, X, sizeof X);
}

void hearth_rotvec_to_axis_angle_near(const double w[3], const double q_ref[4], double out[3]) {
  double th = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  double q[4] = {1, 0, 0, 0};
  if (th > 0) {
    double s = sin(0.5 * th) / th;
    q[0] = cos(0.5 * th), q[1] = w[0] * s, q[2] = w[1] * s, q[3] = w[2] * s;
  }
  if (q[0] * q_ref[0] + q[1] * q_ref[1] + q[2] * q_ref[2] + q[3] * q_ref[3] < 0)
    for (int k = 0; k < 4; k++) q[k] = -q[k];
  double qw = q[0] > 1 ? 1 : q[0] < -1 ? -1 : q[0];
  double den = sqrt(1.0 - qw * qw);
  if (den == 0) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  double a = acos(qw);
  for (int k = 0; k < 3; k++) out[k] = q[k + 1] * 2.0 * a / den;
}
