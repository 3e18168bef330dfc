/* Zhang's closed-form start: plane homographies by the normalised DLT, the
 * intrinsic matrix from the image of the absolute conic, poses from K^-1 H. */
#include <math.h>
#include <string.h>
#include <stdlib.h>
#include <lapacke.h>
#include "calib/calib_internal.h"

int calib_chol_solve(double *A, double *b, int n) {
  if (n <= 0 || n > CALIB_CHOL_MAX) return 0;
  /* in-place lower Cholesky factor */
  for (int j = 0; j < n; j++) {
    double d = A[j * n + j];
    for (int k = 0; k < j; k++) d -= A[j * n + k] * A[j * n + k];
    if (!(d > 0.0)) return 0;
    d = sqrt(d);
    A[j * n + j] = d;
    for (int i = j + 1; i < n; i++) {
      double s = A[i * n + j];
      for (int k = 0; k < j; k++) s -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = s / d;
    }
  }
  /* forward then back substitution */
  for (int i = 0; i < n; i++) {
    double s = b[i];
    for (int k = 0; k < i; k++) s -= A[i * n + k] * b[k];
    b[i] = s / A[i * n + i];
  }
  for (int i = n - 1; i >= 0; i--) {
    double s = b[i];
    for (int k = i + 1; k < n; k++) s -= A[k * n + i] * b[k];
    b[i] = s / A[i * n + i];
  }
  return 1;
}

int calib_chol_invert(double *A, int n) {
  double M[256], col[16], out[256];
  if (n <= 0 || n > 16) return 0;
  for (int j = 0; j < n; j++) {
    memcpy(M, A, sizeof(double) * (size_t)(n * n));
    for (int i = 0; i < n; i++) col[i] = i == j ? 1.0 : 0.0;
    if (!calib_chol_solve(M, col, n)) return 0;
    for (int i = 0; i < n; i++) out[i * n + j] = col[i];
  }
  memcpy(A, out, sizeof(double) * (size_t)(n * n));
  return 1;
}

/* similarity that moves points to zero mean and mean distance sqrt(2) */
static void normaliser(const double *p, size_t n, double T[9]) {
  double mx = 0, my = 0, d = 0;
  for (size_t i = 0; i < n; i++) {
    mx += p[2 * i];
    my += p[2 * i + 1];
  }
  mx /= (double)n;
  my /= (double)n;
  for (size_t i = 0; i < n; i++) d += hypot(p[2 * i] - mx, p[2 * i + 1] - my);
  d /= (double)n;
  double s = d > 0 ? sqrt(2.0) / d : 1.0;
  double M[9] = {s, 0, -s * mx, 0, s, -s * my, 0, 0, 1};
  memcpy(T, M, sizeof M);
}

/* smallest right singular vector of a rows x cols row-major matrix */
static int null_vector(double *A, int rows, int cols, double *v) {
  double s[16], vt[256], superb[16];
  if (rows < cols - 1 || cols > 16) return 0;
  int info =
      LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'N', 'A', rows, cols, A, cols, s, NULL, 1, vt, cols, superb);
  if (info != 0) return 0;
  for (int j = 0; j < cols; j++) v[j] = vt[(cols - 1) * cols + j];
  return 1;
}

int calib_homography(const double *plane_xy, const double *img_uv, size_t n, double H[9]) {
  if (n < 4 || n > 100000) return 0;
  double Ta[9], Tb[9];
  normaliser(plane_xy, n, Ta);
  normaliser(img_uv, n, Tb);
  double *A = hearth_alloc_array(2 * n * 9, sizeof(double));
  if (!A) return 0;
  for (size_t i = 0; i < n; i++) {
    double x = Ta[0] * plane_xy[2 * i] + Ta[2], y = Ta[4] * plane_xy[2 * i + 1] + Ta[5];
    double u = Tb[0] * img_uv[2 * i] + Tb[2], v = Tb[4] * img_uv[2 * i + 1] + Tb[5];
    double *r0 = A + 18 * i, *r1 = r0 + 9;
    double a0[9] = {x, y, 1, 0, 0, 0, -u * x, -u * y, -u};
    double a1[9] = {0, 0, 0, x, y, 1, -v * x, -v * y, -v};
    memcpy(r0, a0, sizeof a0);
    memcpy(r1, a1, sizeof a1);
  }
  double h[9];
  int ok = null_vector(A, (int)(2 * n), 9, h);
  free(A);
  if (!ok) return 0;
  /* H = Tb^-1 Hn Ta */
  double Tbi[9] = {1 / Tb[0], 0, -Tb[2] / Tb[0], 0, 1 / Tb[4], -Tb[5] / Tb[4], 0, 0, 1};
  double tmp[9], out[9];
  hearth_mat3_mul(h, Ta, tmp);
  hearth_mat3_mul(Tbi, tmp, out);
  if (fabs(out[8]) < 1e-300) return 0;
  for (int i = 0; i < 9; i++) H[i] = out[i] / out[8];
  return 1;
}

/* Zhang's v_ij row from columns i, j of H */
static void zhang_v(const double H[9], int i, int j, double v[6]) {
  double hi[3] = {H[i], H[3 + i], H[6 + i]}, hj[3] = {H[j], H[3 + j], H[6 + j]};
  v[0] = hi[0] * hj[0];
  v[1] = hi[0] * hj[1] + hi[1] * hj[0];
  v[2] = hi[1] * hj[1];
  v[3] = hi[2] * hj[0] + hi[0] * hj[2];
  v[4] = hi[2] * hj[1] + hi[1] * hj[2];
  v[5] = hi[2] * hj[2];
}

int calib_zhang_intrinsics(const double *H, size_t n, double *fx, double *fy, double *cx,
                           double *cy) {
  if (n < 3 || n > 100000) return 0;
  /* condition the homographies: scale pixels so the numbers are O(1) */
  double s = 0;
  for (size_t k = 0; k < n; k++) s += fabs(H[9 * k + 2]) + fabs(H[9 * k + 5]);
  s = s > 0 ? (double)(2 * n) / s : 1.0;
  double *V = hearth_alloc_array(2 * n * 6, sizeof(double));
  if (!V) return 0;
  for (size_t k = 0; k < n; k++) {
    double Hs[9];
    memcpy(Hs, H + 9 * k, sizeof Hs);
    for (int j = 0; j < 6; j++) Hs[j] *= s;
    double v12[6], v11[6], v22[6];
    zhang_v(Hs, 0, 1, v12);
    zhang_v(Hs, 0, 0, v11);
    zhang_v(Hs, 1, 1, v22);
    for (int j = 0; j < 6; j++) {
      V[12 * k + j] = v12[j];
      V[12 * k + 6 + j] = v11[j] - v22[j];
    }
  }
  double b[6];
  int ok = null_vector(V, (int)(2 * n), 6, b);
  free(V);
  if (!ok) return 0;
  /* B = [b0 b1 b3; b1 b2 b4; b3 b4 b5] ~ K^-T K^-1 (Zhang 1999, appendix B) */
  double B11 = b[0], B12 = b[1], B22 = b[2], B13 = b[3], B23 = b[4], B33 = b[5];
  double den = B11 * B22 - B12 * B12;
  if (fabs(den) < 1e-300 || fabs(B11) < 1e-300) return 0;
  double v0 = (B12 * B13 - B11 * B23) / den;
  double lam = B33 - (B13 * B13 + v0 * (B12 * B13 - B11 * B23)) / B11;
  double a2 = lam / B11, b2 = lam * B11 / den;
  if (!(a2 > 0) || !(b2 > 0)) return 0;
  double alpha = sqrt(a2), beta = sqrt(b2);
  double gamma = -B12 * alpha * alpha * beta / lam;
  double u0 = gamma * v0 / beta - B13 * alpha * alpha / lam;
  *fx = alpha / s;
  *fy = beta / s;
  *cx = u0 / s;
  *cy = v0 / s;
  return isfinite(*fx) && isfinite(*fy) && isfinite(*cx) && isfinite(*cy);
}

/* nearest rotation to M (row-major) by SVD */
static int nearest_rotation(const double M[9], double R[9]) {
  double A[9], s[3], u[9], vt[9], superb[3];
  memcpy(A, M, sizeof A);
  if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', 3, 3, A, 3, s, u, 3, vt, 3, superb) != 0) return 0;
  hearth_mat3_mul(u, vt, R);
  double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
               R[2] * (R[3] * R[7] - R[4] * R[6]);
  if (det < 0) {
    for (int i = 0; i < 3; i++) u[i * 3 + 2] = -u[i * 3 + 2];
    hearth_mat3_mul(u, vt, R);
  }
  return 1;
}

int calib_pose_from_homography(const double Hn[9], hearth_rigid *T) {
  double h1[3] = {Hn[0], Hn[3], Hn[6]}, h2[3] = {Hn[1], Hn[4], Hn[7]},
         h3[3] = {Hn[2], Hn[5], Hn[8]};
  double n1 = hearth_norm3(h1), n2 = hearth_norm3(h2);
  if (!(n1 > 0) || !(n2 > 0)) return 0;
  double lam = 2.0 / (n1 + n2);
  /* the plate lies in front of the camera: t_z > 0 */
  if (h3[2] < 0) lam = -lam;
  double r1[3], r2[3], r3[3], M[9];
  for (int i = 0; i < 3; i++) {
    r1[i] = lam * h1[i];
    r2[i] = lam * h2[i];
    T->t[i] = lam * h3[i];
  }
  hearth_cross3(r1, r2, r3);
  for (int i = 0; i < 3; i++) {
    M[i * 3 + 0] = r1[i];
    M[i * 3 + 1] = r2[i];
    M[i * 3 + 2] = r3[i];
  }
  return nearest_rotation(M, T->R);
}

void calib_plate_points(double obj[HEARTH_PLATE_HOLES][3]) {
  for (int i = 0; i < HEARTH_PLATE_HOLES; i++) hearth_plate_hole(i, obj[i]);
}

void calib_rigid_from_params(const double p[6], hearth_rigid *T) {
  hearth_rotvec_to_matrix(p, T->R);
  memcpy(T->t, p + 3, sizeof(double) * 3);
}

void calib_params_from_rigid(const hearth_rigid *T, double p[6]) {
  hearth_matrix_to_rotvec(T->R, p);
  memcpy(p + 3, T->t, sizeof(double) * 3);
}

int calib_project_pose(const hearth_camera *cam, const double R[9], const double dR[27],
                       const double t[3], const double X[3], double uv[2], hearth_project_jac *jac,
                       double d_pose[12], double Xc_out[3]) {
  double Xc[3];
  for (int i = 0; i < 3; i++)
    Xc[i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + t[i];
  if (Xc_out) memcpy(Xc_out, Xc, sizeof Xc);
  if (!hearth_camera_project(cam, Xc, uv, jac)) return 0;
  if (d_pose && jac) {
    /* dXc/dw_k = dR/dw_k X; dXc/dt = I */
    for (int k = 0; k < 3; k++) {
      const double *D = dR + 9 * k;
      double g[3];
      for (int i = 0; i < 3; i++)
        g[i] = D[3 * i] * X[0] + D[3 * i + 1] * X[1] + D[3 * i + 2] * X[2];
      for (int r = 0; r < 2; r++)
        d_pose[6 * r + k] = jac->d_point[3 * r] * g[0] + jac->d_point[3 * r + 1] * g[1] +
                            jac->d_point[3 * r + 2] * g[2];
    }
    for (int r = 0; r < 2; r++)
      for (int k = 0; k < 3; k++) d_pose[6 * r + 3 + k] = jac->d_point[3 * r + k];
  }
  return 1;
}
