/* The arm's operational-space pose controller: joint torques that drive
 * the grip site to the env's goal pose, and the finger servo targets. */
#include <math.h>
#include <string.h>

#include "hearth/geom.h"
#include "sim/sim_control.h"
#include "sim/sim_env.h"
#include "sim/sim_robot.h"

/* B = A^-1 of a 3 x 3 matrix by cofactors; 0 if nearly singular */
static int inv3(const double A[9], double B[9]) {
  double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
               A[2] * (A[3] * A[7] - A[4] * A[6]);
  if (fabs(det) < 1e-12) return 0;
  double id = 1.0 / det;
  B[0] = (A[4] * A[8] - A[5] * A[7]) * id, B[1] = (A[2] * A[7] - A[1] * A[8]) * id;
  B[2] = (A[1] * A[5] - A[2] * A[4]) * id, B[3] = (A[5] * A[6] - A[3] * A[8]) * id;
  B[4] = (A[0] * A[8] - A[2] * A[6]) * id, B[5] = (A[2] * A[3] - A[0] * A[5]) * id;
  B[6] = (A[3] * A[7] - A[4] * A[6]) * id, B[7] = (A[1] * A[6] - A[0] * A[7]) * id;
  B[8] = (A[0] * A[4] - A[1] * A[3]) * id;
  return 1;
}
/* in-place Gauss-Jordan inverse of an n x n matrix (n <= 7) with pivoting */
static int invn(double *A, int n) {
  double M[7][14];
  for (int i = 0; i < n; i++)
    for (int j = 0; j < 2 * n; j++) M[i][j] = j < n ? A[i * n + j] : (j - n == i);
  for (int c = 0; c < n; c++) {
    int p = c;
    for (int r = c + 1; r < n; r++)
      if (fabs(M[r][c]) > fabs(M[p][c])) p = r;
    if (fabs(M[p][c]) < 1e-12) return 0;
    if (p != c)
      for (int j = 0; j < 2 * n; j++) {
        double t = M[p][j];
        M[p][j] = M[c][j], M[c][j] = t;
      }
    double iv = 1.0 / M[c][c];
    for (int j = 0; j < 2 * n; j++) M[c][j] *= iv;
    for (int r = 0; r < n; r++)
      if (r != c && M[r][c] != 0) {
        double f = M[r][c];
        for (int j = 0; j < 2 * n; j++) M[r][j] -= f * M[c][j];
      }
  }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) A[i * n + j] = M[i][j + n];
  return 1;
}

/* robosuite's OSC_POSE: kp 150, critical damping, decoupled task-space
 * inertia, gravity/bias compensation, posture null space, torque limits */
void sim_osc(hearth_sim_env *e) {
  mjModel *m = e->m;
  mjData *d = e->d;
  int nv = m->nv;
  double jp[3 * SIM_MAXNV], jr[3 * SIM_MAXNV];
  mj_jacSite(m, d, jp, jr, e->site_grip);
  double J[6][7], Ma[7][7], Mfull[SIM_MAXNV * SIM_MAXNV];
  for (int i = 0; i < 7; i++) {
    int c = e->arm_dadr[i];
    for (int r = 0; r < 3; r++) J[r][i] = jp[r * nv + c], J[r + 3][i] = jr[r * nv + c];
  }
  mj_fullM(m, Mfull, d->qM);
  for (int i = 0; i < 7; i++)
    for (int j = 0; j < 7; j++) Ma[i][j] = Mfull[e->arm_dadr[i] * nv + e->arm_dadr[j]];
  double Mi[49];
  memcpy(Mi, Ma, sizeof Mi);
  if (!invn(Mi, 7)) return;
  /* Lambda^-1 = J Mi J^T */
  double MiJt[7][6], Li[36];
  for (int i = 0; i < 7; i++)
    for (int r = 0; r < 6; r++) {
      double s = 0;
      for (int k = 0; k < 7; k++) s += Mi[i * 7 + k] * J[r][k];
      MiJt[i][r] = s;
    }
  for (int r = 0; r < 6; r++)
    for (int c = 0; c < 6; c++) {
      double s = 0;
      for (int k = 0; k < 7; k++) s += J[r][k] * MiJt[k][c];
      Li[r * 6 + c] = s;
    }
  double Lp_in[9], Lo_in[9], Lp[9], Lo[9], L[36];
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++)
      Lp_in[r * 3 + c] = Li[r * 6 + c], Lo_in[r * 3 + c] = Li[(r + 3) * 6 + c + 3];
  if (!inv3(Lp_in, Lp) || !inv3(Lo_in, Lo)) return;
  memcpy(L, Li, sizeof L);
  if (!invn(L, 6)) return;
  /* errors and velocities at the grip site */
  const double *x = d->site_xpos + 3 * e->site_grip, *R = d->site_xmat + 9 * e->site_grip;
  double qd[7], v[6];
  for (int i = 0; i < 7; i++) qd[i] = d->qvel[e->arm_dadr[i]];
  for (int r = 0; r < 6; r++) {
    v[r] = 0;
    for (int k = 0; k < 7; k++) v[r] += J[r][k] * qd[k];
  }
  double ep[3], eo[3] = {0, 0, 0};
  for (int i = 0; i < 3; i++) ep[i] = e->goal_pos[i] - x[i];
  for (int c = 0; c < 3; c++) {
    double rc[3] = {R[c], R[3 + c], R[6 + c]},
           rd[3] = {e->goal_R[c], e->goal_R[3 + c], e->goal_R[6 + c]}, cr[3];
    hearth_cross3(rc, rd, cr);
    for (int i = 0; i < 3; i++) eo[i] += 0.5 * cr[i];
  }
  const double kp = 150.0, kv = 2.0 * sqrt(150.0);
  double fdes[3], tdes[3], w[6];
  for (int i = 0; i < 3; i++)
    fdes[i] = kp * ep[i] - kv * v[i], tdes[i] = kp * eo[i] - kv * v[3 + i];
  for (int i = 0; i < 3; i++) {
    w[i] = Lp[i * 3] * fdes[0] + Lp[i * 3 + 1] * fdes[1] + Lp[i * 3 + 2] * fdes[2];
    w[3 + i] = Lo[i * 3] * tdes[0] + Lo[i * 3 + 1] * tdes[1] + Lo[i * 3 + 2] * tdes[2];
  }
  double tau[7];
  for (int i = 0; i < 7; i++) {
    tau[i] = 0;
    for (int r = 0; r < 6; r++) tau[i] += J[r][i] * w[r];
  }
  /* null space: p = M (kn (q0 - q) - kvn qd); tau += (I - J^T Jbar^T) p,
   * Jbar = Mi J^T Lambda */
  const double kn = 10.0, kvn = 2.0 * sqrt(10.0);
  double pr[7], p[7], MiP[7], JMiP[6], LJ[6];
  for (int i = 0; i < 7; i++)
    pr[i] = kn * (sim_robot_q_start[i] - d->qpos[e->arm_qadr[i]]) - kvn * qd[i];
  for (int i = 0; i < 7; i++) {
    p[i] = 0;
    for (int k = 0; k < 7; k++) p[i] += Ma[i][k] * pr[k];
  }
  for (int i = 0; i < 7; i++) {
    MiP[i] = 0;
    for (int k = 0; k < 7; k++) MiP[i] += Mi[i * 7 + k] * p[k];
  }
  for (int r = 0; r < 6; r++) {
    JMiP[r] = 0;
    for (int k = 0; k < 7; k++) JMiP[r] += J[r][k] * MiP[k];
  }
  for (int r = 0; r < 6; r++) {
    LJ[r] = 0;
    for (int c = 0; c < 6; c++) LJ[r] += L[r * 6 + c] * JMiP[c];
  }
  for (int i = 0; i < 7; i++) {
    double s = 0;
    for (int r = 0; r < 6; r++) s += J[r][i] * LJ[r];
    tau[i] += p[i] - s;
  }
  for (int i = 0; i < 7; i++) {
    double t = tau[i] + d->qfrc_bias[e->arm_dadr[i]];
    if (t > sim_robot_tau_max[i]) t = sim_robot_tau_max[i];
    if (t < -sim_robot_tau_max[i]) t = -sim_robot_tau_max[i];
    d->ctrl[i] = t;
  }
  double g = e->grip_cmd < -1 ? -1 : e->grip_cmd > 1 ? 1 : e->grip_cmd;
  d->ctrl[7] = d->ctrl[8] = 0.04 * (1.0 - g) / 2.0;
}
