/* Rigid transforms and rotation vectors against closed forms. */
#include <math.h>
#include "hearth/core.h"
#include "hearth/geom.h"
#include "test_util.h"

static double max_abs_diff(const double *a, const double *b, int n) {
  double m = 0.0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* closed-form rotations about the coordinate axes */
static void axis_rotation(int axis, double a, double R[9]) {
  double c = cos(a), s = sin(a);
  for (int i = 0; i < 9; i++) R[i] = 0.0;
  if (axis == 0) {
    R[0] = 1;
    R[4] = c;
    R[5] = -s;
    R[7] = s;
    R[8] = c;
  } else if (axis == 1) {
    R[4] = 1;
    R[0] = c;
    R[2] = s;
    R[6] = -s;
    R[8] = c;
  } else {
    R[8] = 1;
    R[0] = c;
    R[1] = -s;
    R[3] = s;
    R[4] = c;
  }
}

static void random_rotvec(hearth_rng *rng, double max_angle, double w[3]) {
  double a[3] = {hearth_rng_normal(rng), hearth_rng_normal(rng), hearth_rng_normal(rng)};
  double n = hearth_norm3(a), th = hearth_rng_range(rng, 0.0, max_angle);
  for (int i = 0; i < 3; i++) w[i] = a[i] / n * th;
}

int main(void) {
  const double pi = 3.14159265358979323846;
  /* vector helpers */
  double a[3] = {1, 2, 3}, b[3] = {-4, 5, 0.5}, c[3];
  CHECK_NEAR(hearth_dot3(a, b), -4 + 10 + 1.5, 1e-15);
  hearth_cross3(a, b, c);
  CHECK_NEAR(c[0], 2 * 0.5 - 3 * 5, 1e-15);
  CHECK_NEAR(c[1], 3 * -4 - 1 * 0.5, 1e-15);
  CHECK_NEAR(c[2], 1 * 5 - 2 * -4, 1e-15);
  CHECK_NEAR(hearth_norm3(a), sqrt(14.0), 1e-15);

  /* rotvec about each axis equals the closed-form axis rotation; it maps
   * e.g. +x to +y for +90 deg about z (right-handed) */
  for (int axis = 0; axis < 3; axis++) {
    for (double ang = -3.0; ang <= 3.0; ang += 0.37) {
      double w[3] = {0, 0, 0}, R[9], Rc[9], wb[3];
      w[axis] = ang;
      hearth_rotvec_to_matrix(w, R);
      axis_rotation(axis, ang, Rc);
      CHECK(max_abs_diff(R, Rc, 9) < 1e-14);
      hearth_matrix_to_rotvec(R, wb);
      CHECK(max_abs_diff(w, wb, 3) < 1e-13);
    }
  }
  {
    double w[3] = {0, 0, pi / 2}, R[9], x[3] = {1, 0, 0}, y[3];
    hearth_rotvec_to_matrix(w, R);
    hearth_rigid T;
    hearth_rigid_identity(&T);
    for (int i = 0; i < 9; i++) T.R[i] = R[i];
    hearth_rigid_rotate(&T, x, y);
    CHECK_NEAR(y[0], 0.0, 1e-15);
    CHECK_NEAR(y[1], 1.0, 1e-15);
    CHECK_NEAR(y[2], 0.0, 1e-15);
  }

  /* Rodrigues round trip: random, tiny and near-pi angles */
  hearth_rng rng;
  hearth_rng_seed(&rng, 42);
  double worst_rt = 0.0, worst_pi = 0.0;
  for (int i = 0; i < 3000; i++) {
    double w[3], R[9], wb[3], Rb[9];
    if (i < 1000) {
      random_rotvec(&rng, pi - 1e-9, w);
    } else if (i < 2000) {
      random_rotvec(&rng, 1e-6, w);
      double s = pow(10.0, -hearth_rng_range(&rng, 0, 10));
      for (int k = 0; k < 3; k++) w[k] *= s;
    } else {
      /* within 1e-3 .. 1e-12 of pi */
      random_rotvec(&rng, 1.0, w);
      double n = hearth_norm3(w), th = pi - pow(10.0, -hearth_rng_range(&rng, 3, 12));
      for (int k = 0; k < 3; k++) w[k] *= th / n;
    }
    hearth_rotvec_to_matrix(w, R);
    CHECK(hearth_is_rotation(R, 1e-14));
    hearth_matrix_to_rotvec(R, wb);
    hearth_rotvec_to_matrix(wb, Rb);
    double e = max_abs_diff(R, Rb, 9);
    if (i >= 2000) {
      /* near pi the vector itself is recovered up to the matrix's own precision */
      worst_pi = fmax(worst_pi, max_abs_diff(w, wb, 3));
      CHECK_MSG(e < 1e-14, "near-pi matrix round trip %g", e);
    } else {
      double d = max_abs_diff(w, wb, 3) / fmax(hearth_norm3(w), 1e-300);
      worst_rt = fmax(worst_rt, d);
      CHECK_MSG(d < 1e-9, "relative rotvec round trip %g at |w|=%g", d, hearth_norm3(w));
    }
    CHECK_NEAR(hearth_norm3(wb), hearth_norm3(w), 1e-7);
  }
  printf("rodrigues round trip: rel err %.3g (angles < pi), abs err near pi %.3g\n", worst_rt,
         worst_pi);
  CHECK(worst_pi < 1e-7);
  /* exactly pi about a diagonal axis */
  {
    double w[3] = {pi / sqrt(3.0), pi / sqrt(3.0), -pi / sqrt(3.0)}, R[9], wb[3], Rb[9];
    hearth_rotvec_to_matrix(w, R);
    hearth_matrix_to_rotvec(R, wb);
    CHECK_NEAR(hearth_norm3(wb), pi, 1e-12);
    hearth_rotvec_to_matrix(wb, Rb);
    CHECK(max_abs_diff(R, Rb, 9) < 1e-14);
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    CHECK_NEAR(hearth_rotation_angle_between(I, R), pi, 1e-12);
  }
  /* identity and zero */
  {
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, w[3];
    hearth_matrix_to_rotvec(I, w);
    CHECK(w[0] == 0.0 && w[1] == 0.0 && w[2] == 0.0);
  }

  /* Jacobian of the rotation vector map vs central differences */
  for (int i = 0; i < 200; i++) {
    double w[3], R[9], dR[27], R0[9];
    random_rotvec(&rng, i < 50 ? 1e-3 : 3.0, w);
    hearth_rotvec_to_matrix_jac(w, R, dR);
    hearth_rotvec_to_matrix(w, R0);
    CHECK(max_abs_diff(R, R0, 9) < 1e-15);
    for (int k = 0; k < 3; k++) {
      double h = 1e-6, wp[3] = {w[0], w[1], w[2]}, wm[3] = {w[0], w[1], w[2]}, Rp[9], Rm[9];
      wp[k] += h;
      wm[k] -= h;
      hearth_rotvec_to_matrix(wp, Rp);
      hearth_rotvec_to_matrix(wm, Rm);
      for (int e = 0; e < 9; e++) {
        double fd = (Rp[e] - Rm[e]) / (2 * h);
        CHECK_MSG(fabs(fd - dR[k * 9 + e]) < 1e-8, "dR[%d][%d] %g vs fd %g", k, e, dR[k * 9 + e],
                  fd);
      }
    }
  }
  /* at w = 0 the derivative is the skew generator */
  {
    double w[3] = {0, 0, 0}, dR[27];
    hearth_rotvec_to_matrix_jac(w, NULL, dR);
    CHECK(dR[0 * 9 + 7] == 1.0 && dR[0 * 9 + 5] == -1.0);
    CHECK(dR[1 * 9 + 2] == 1.0 && dR[1 * 9 + 6] == -1.0);
    CHECK(dR[2 * 9 + 3] == 1.0 && dR[2 * 9 + 1] == -1.0);
  }

  /* compose with the inverse gives identity; compose associates with apply */
  for (int i = 0; i < 100; i++) {
    hearth_rigid A, B, Ai, I, AB;
    double w[3];
    random_rotvec(&rng, pi, w);
    hearth_rotvec_to_matrix(w, A.R);
    random_rotvec(&rng, pi, w);
    hearth_rotvec_to_matrix(w, B.R);
    for (int k = 0; k < 3; k++) {
      A.t[k] = hearth_rng_range(&rng, -5, 5);
      B.t[k] = hearth_rng_range(&rng, -5, 5);
    }
    hearth_rigid_inverse(&A, &Ai);
    hearth_rigid_compose(&A, &Ai, &I);
    hearth_rigid Id;
    hearth_rigid_identity(&Id);
    CHECK(max_abs_diff(I.R, Id.R, 9) < 1e-14 && max_abs_diff(I.t, Id.t, 3) < 1e-14);
    hearth_rigid_compose(&Ai, &A, &I);
    CHECK(max_abs_diff(I.R, Id.R, 9) < 1e-14 && max_abs_diff(I.t, Id.t, 3) < 1e-14);
    double x[3] = {hearth_rng_normal(&rng), hearth_rng_normal(&rng), hearth_rng_normal(&rng)};
    double y1[3], y2[3];
    hearth_rigid_compose(&A, &B, &AB);
    hearth_rigid_apply(&AB, x, y1);
    hearth_rigid_apply(&B, x, y2);
    hearth_rigid_apply(&A, y2, y2); /* aliasing allowed */
    CHECK(max_abs_diff(y1, y2, 3) < 1e-13);
    /* aliasing: compose into a */
    hearth_rigid C = A;
    hearth_rigid_compose(&C, &B, &C);
    CHECK(max_abs_diff(C.R, AB.R, 9) == 0.0 && max_abs_diff(C.t, AB.t, 3) == 0.0);
    C = A;
    hearth_rigid_inverse(&C, &C);
    CHECK(max_abs_diff(C.R, Ai.R, 9) == 0.0 && max_abs_diff(C.t, Ai.t, 3) == 0.0);
    /* mat4 round trip */
    double M[16];
    hearth_rigid_to_mat4(&A, M);
    CHECK(M[3] == A.t[0] && M[7] == A.t[1] && M[11] == A.t[2] && M[15] == 1.0 && M[12] == 0.0);
    hearth_rigid A2;
    CHECK(hearth_rigid_from_mat4(M, 1e-9, &A2));
    CHECK(max_abs_diff(A2.R, A.R, 9) == 0.0 && max_abs_diff(A2.t, A.t, 3) == 0.0);
    /* angle between: relative rotation about a known axis */
    double d[3];
    random_rotvec(&rng, pi, d);
    double Rd[9], Rb[9];
    hearth_rotvec_to_matrix(d, Rd);
    hearth_mat3_mul(A.R, Rd, Rb);
    CHECK_NEAR(hearth_rotation_angle_between(A.R, Rb), hearth_norm3(d), 1e-12);
  }
  /* from_mat4 rejects non-rotations */
  {
    double M[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    hearth_rigid T;
    CHECK(hearth_rigid_from_mat4(M, 1e-9, &T));
    M[0] = -1; /* reflection: det -1 */
    CHECK(!hearth_rigid_from_mat4(M, 1e-9, &T));
    M[0] = 1.01; /* scaled */
    CHECK(!hearth_rigid_from_mat4(M, 1e-9, &T));
    CHECK(hearth_rigid_from_mat4(M, 0.05, &T));
    M[0] = 1;
    M[14] = 0.5; /* bad last row */
    CHECK(!hearth_rigid_from_mat4(M, 1e-9, &T));
    M[14] = 0;
    M[5] = NAN;
    CHECK(!hearth_rigid_from_mat4(M, 1e-9, &T));
  }
  /* orthonormalize: a perturbed rotation comes back to a rotation near it */
  for (int i = 0; i < 100; i++) {
    double w[3], R[9], P[9];
    random_rotvec(&rng, pi, w);
    hearth_rotvec_to_matrix(w, R);
    for (int k = 0; k < 9; k++) P[k] = R[k] + 1e-4 * hearth_rng_normal(&rng);
    hearth_orthonormalize(P);
    CHECK(hearth_is_rotation(P, 1e-14));
    CHECK(max_abs_diff(P, R, 9) < 1e-3);
    /* a rotation is a fixed point */
    double Q[9];
    for (int k = 0; k < 9; k++) Q[k] = R[k];
    hearth_orthonormalize(Q);
    CHECK(max_abs_diff(Q, R, 9) < 1e-15);
  }
  /* the polar factor of a symmetric positive scaling of a rotation is that rotation */
  {
    double R[9], S[9] = {2, 0.1, 0, 0.1, 1.5, 0, 0, 0, 1}, M[9], w[3] = {0.3, -0.2, 0.9};
    hearth_rotvec_to_matrix(w, R);
    hearth_mat3_mul(R, S, M);
    hearth_orthonormalize(M);
    CHECK(max_abs_diff(M, R, 9) < 1e-13);
  }
  /* transpose */
  {
    double A[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}, At[9];
    hearth_mat3_transpose(A, At);
    CHECK(At[1] == 4 && At[2] == 7 && At[5] == 8 && At[0] == 1);
    hearth_mat3_transpose(A, A);
    CHECK(max_abs_diff(A, At, 9) == 0.0);
  }
  TEST_MAIN_END();
}
