/* Stereo calibration: the rigid T_b_from_a and the plate pose of every pair
 * in camera a, refined jointly by Levenberg-Marquardt over the reprojection
 * errors in both cameras (Schur complement on the per-pair blocks), with
 * outlier pairs dropped. With opts->rolling_shutter, camera a may read its
 * rows in turn while the plate moves: each pair then also has a plate
 * velocity in camera a (a twist per frame readout, first order in the row's
 * time) and the time camera b saw it (the trigger offset, under a weak
 * prior), kept only when they explain more than 7 free parameters per pair
 * would fit of noise. hearth_calib_stereo_joint then refines camera b's
 * intrinsics with the rest, from the pairs and camera b's own frames, and
 * optionally the target's hole positions; with the rolling-shutter model
 * it does so under the rigid model first and tries the moving model from
 * the refined camera b. The RMS reported is the points' alone (the trigger
 * prior's term left out). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

/* the largest per-pair block: pose (rotation vector, translation), then the
 * plate's velocity in camera a (angular, linear; per frame readout), then
 * the time camera b saw the plate (frames of camera a's readout from its
 * middle row: the two cameras' trigger offset) */
#define NQ_MAX 13
/* the trigger offset's prior: zero, 1 sigma this many frames (weak: the
 * data fix it where the plate moves, the prior where it does not) */
#define TB_SIGMA 1.0

typedef struct stereo_prob {
  const hearth_camera *ca, *cb;
  const double (*obj)[3];
  size_t n_pts, n_pairs;
  const double *img_a, *img_b;
  const int *used;
  int nq; /* parameters per pair: 6 (rigid pose) or 13 (pose, velocity, trigger time) */
} stereo_prob;

/* when camera a reads pixel row v, in frames from its middle row */
static double row_time(const hearth_camera *c, double v) {
  return (v + 0.5) / (double)c->height - 0.5;
}

/* the plate point Xa (camera a, at the middle row's time) as row time s
 * sees it under velocity q (w, u): Xa + s (w x Xa + u) */
static void rs_move(const double q[6], double s, const double Xa[3], double out[3]) {
  const double *w = q, *u = q + 3;
  out[0] = Xa[0] + s * (w[1] * Xa[2] - w[2] * Xa[1] + u[0]);
  out[1] = Xa[1] + s * (w[2] * Xa[0] - w[0] * Xa[2] + u[1]);
  out[2] = Xa[2] + s * (w[0] * Xa[1] - w[1] * Xa[0] + u[2]);
}

/* plate point X of pair block p (nq parameters, rotation R and its
 * derivatives dR from p) in camera a's frame at time s (camera b: s = its
 * trigger time p[12], with_s: that column filled), and its 3 x nq
 * Jacobian dX (row-major) when dX is non-NULL */
static void block_point(const double *p, int nq, const double R[9], const double dR[27], double s,
                        int with_s, const double X[3], double Xm[3], double *dX) {
  double Xa[3];
  for (int k = 0; k < 3; k++)
    Xa[k] = R[3 * k] * X[0] + R[3 * k + 1] * X[1] + R[3 * k + 2] * X[2] + p[3 + k];
  if (nq == 6) {
    memcpy(Xm, Xa, sizeof Xa);
  } else {
    rs_move(p + 6, s, Xa, Xm);
  }
  if (!dX) return;
  memset(dX, 0, sizeof(double) * 3 * (size_t)nq);
  /* d Xa / d pose = [dR X | I] */
  double G[3][6];
  for (int k = 0; k < 3; k++) {
    const double *D = dR + 9 * k;
    for (int c = 0; c < 3; c++) {
      G[c][k] = D[3 * c] * X[0] + D[3 * c + 1] * X[1] + D[3 * c + 2] * X[2];
      G[c][3 + k] = c == k;
    }
  }
  if (nq == 6) {
    for (int c = 0; c < 3; c++) memcpy(dX + 6 * c, G[c], sizeof G[c]);
    return;
  }
  const double *w = p + 6;
  /* d Xm / d Xa = I + s [w]x */
  const double A[9] = {1, -s * w[2], s * w[1], s * w[2], 1, -s * w[0], -s * w[1], s * w[0], 1};
  for (int c = 0; c < 3; c++) {
    double *row = dX + nq * c;
    for (int k = 0; k < 6; k++)
      row[k] = A[3 * c] * G[0][k] + A[3 * c + 1] * G[1][k] + A[3 * c + 2] * G[2][k];
  }
  /* d Xm / d w = -s [Xa]x, d Xm / d u = s I */
  const double B[9] = {0,         s * Xa[2], -s * Xa[1], -s * Xa[2], 0,
                       s * Xa[0], s * Xa[1], -s * Xa[0], 0};
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < 3; k++) {
      dX[nq * c + 6 + k] = B[3 * c + k];
      dX[nq * c + 9 + k] = c == k ? s : 0.0;
    }
  if (with_s && nq > 12) {
    /* d Xm / d s = w x Xa + u */
    const double *u = p + 9;
    dX[nq * 0 + 12] = w[1] * Xa[2] - w[2] * Xa[1] + u[0];
    dX[nq * 1 + 12] = w[2] * Xa[0] - w[0] * Xa[2] + u[1];
    dX[nq * 2 + 12] = w[0] * Xa[1] - w[1] * Xa[0] + u[2];
  }
}

/* camera b's time of pair block p */
static double tb_time(const double *p, int nq) { return nq > 12 ? p[12] : 0.0; }

/* squared error of pair i (both cameras, and the trigger prior); INFINITY
 * if behind a camera */
static double pair_cost(const stereo_prob *P, size_t i, const hearth_rigid *Tba, const double *p) {
  double R[9];
  hearth_rotvec_to_matrix(p, R);
  double s = 0;
  for (size_t j = 0; j < P->n_pts; j++) {
    double Xm[3], Xb[3], uv[2];
    const double *m = P->img_a + 2 * (i * P->n_pts + j);
    block_point(p, P->nq, R, NULL, row_time(P->ca, m[1]), 0, P->obj[j], Xm, NULL);
    if (!hearth_camera_project(P->ca, Xm, uv, NULL)) return INFINITY;
    s += (uv[0] - m[0]) * (uv[0] - m[0]) + (uv[1] - m[1]) * (uv[1] - m[1]);
    block_point(p, P->nq, R, NULL, tb_time(p, P->nq), 0, P->obj[j], Xm, NULL);
    hearth_rigid_apply(Tba, Xm, Xb);
    if (!hearth_camera_project(P->cb, Xb, uv, NULL)) return INFINITY;
    m = P->img_b + 2 * (i * P->n_pts + j);
    s += (uv[0] - m[0]) * (uv[0] - m[0]) + (uv[1] - m[1]) * (uv[1] - m[1]);
  }
  if (P->nq > 12) s += (p[12] / TB_SIGMA) * (p[12] / TB_SIGMA);
  return s;
}

/* Levenberg-Marquardt's step rule for a trial of cost cn: a lower cost is
 * taken (*cost = cn, lambda ten times smaller, not below 1e-12) and 1
 * returned, *done set when the relative gain is under 1e-14; otherwise
 * lambda grows ten-fold and 0 is returned. */
static int lm_take(double *cost, double cn, double *lambda, int *done) {
  *done = 0;
  if (!(cn < *cost)) {
    *lambda *= 10;
    return 0;
  }
  double rel = (*cost - cn) / (*cost > 0 ? *cost : 1);
  *cost = cn;
  *lambda = *lambda / 10 > 1e-12 ? *lambda / 10 : 1e-12;
  *done = rel < 1e-14;
  return 1;
}

static double total_cost(const stereo_prob *P, const double pT[6], const double *poses,
                         double *per_pair) {
  hearth_rigid Tba;
  calib_rigid_from_params(pT, &Tba);
  double s = 0;
  for (size_t i = 0; i < P->n_pairs; i++) {
    double c = P->used[i] || per_pair ? pair_cost(P, i, &Tba, poses + P->nq * i) : 0.0;
    if (per_pair) per_pair[i] = c;
    if (P->used[i]) s += c;
  }
  return s;
}

/* one pair's residual rows: camera a's (ra, 2 x nq block Jacobian ja)
 * and camera b's (rb, block Jacobian jb, extrinsic Jacobian jT 2 x 6 and
 * the projection's jac for camera b's intrinsics); returns 0 if behind a
 * camera */
static int pair_rows(const stereo_prob *P, const hearth_camera *cb, const double RT[9],
                     const double dRT[27], const double tT[3], const double *p, const double R[9],
                     const double dR[27], size_t i, size_t j, double ra[2], double *ja,
                     double rb[2], double *jb, double jT[12], hearth_project_jac *jacb) {
  const int D = P->nq;
  const double *X = P->obj[j];
  double Xm[3], dX[3 * NQ_MAX], uv[2];
  hearth_project_jac jac;
  const double *m = P->img_a + 2 * (i * P->n_pts + j);
  block_point(p, D, R, dR, row_time(P->ca, m[1]), 0, X, Xm, dX);
  if (!hearth_camera_project(P->ca, Xm, uv, &jac)) return 0;
  for (int row = 0; row < 2; row++) {
    const double *J = jac.d_point + 3 * row;
    ra[row] = uv[row] - m[row];
    for (int k = 0; k < D; k++)
      ja[D * row + k] = J[0] * dX[k] + J[1] * dX[D + k] + J[2] * dX[2 * D + k];
  }
  block_point(p, D, R, dR, tb_time(p, D), 1, X, Xm, dX);
  if (!calib_project_pose(cb, RT, dRT, tT, Xm, uv, jacb, jT, NULL)) return 0;
  m = P->img_b + 2 * (i * P->n_pts + j);
  for (int row = 0; row < 2; row++) {
    const double *J = jacb->d_point + 3 * row;
    double JR[3];
    for (int k = 0; k < 3; k++) JR[k] = J[0] * RT[k] + J[1] * RT[3 + k] + J[2] * RT[6 + k];
    rb[row] = uv[row] - m[row];
    for (int k = 0; k < D; k++)
      jb[D * row + k] = JR[0] * dX[k] + JR[1] * dX[D + k] + JR[2] * dX[2 * D + k];
  }
  return 1;
}

/* normal equations: U (T block), V_i (nq x nq), W_i (T rows x nq cols),
 * g = -J^T r */
static int stereo_normal(const stereo_prob *P, const double pT[6], const double *poses,
                         double U[36], double gT[6], double *V, double *W, double *gp) {
  const int D = P->nq;
  double RT[9], dRT[27];
  hearth_rotvec_to_matrix_jac(pT, RT, dRT);
  memset(U, 0, sizeof(double) * 36);
  memset(gT, 0, sizeof(double) * 6);
  for (size_t i = 0; i < P->n_pairs; i++) {
    double *Vi = V + D * D * i, *Wi = W + 6 * D * i, *g = gp + D * i;
    memset(Vi, 0, sizeof(double) * (size_t)(D * D));
    memset(Wi, 0, sizeof(double) * (size_t)(6 * D));
    memset(g, 0, sizeof(double) * (size_t)D);
    if (!P->used[i]) continue;
    const double *p = poses + D * i;
    double R[9], dR[27];
    hearth_rotvec_to_matrix_jac(p, R, dR);
    for (size_t j = 0; j < P->n_pts; j++) {
      double ra[2], rb[2], ja[2 * NQ_MAX], jb[2 * NQ_MAX], jT[12];
      hearth_project_jac jac;
      if (!pair_rows(P, P->cb, RT, dRT, pT + 3, p, R, dR, i, j, ra, ja, rb, jb, jT, &jac)) return 0;
      for (int row = 0; row < 2; row++) {
        const double *a_ = ja + D * row, *b_ = jb + D * row, *t_ = jT + 6 * row;
        for (int a = 0; a < D; a++) {
          for (int b = 0; b < D; b++) Vi[a * D + b] += a_[a] * a_[b] + b_[a] * b_[b];
          g[a] -= a_[a] * ra[row] + b_[a] * rb[row];
        }
        for (int a = 0; a < 6; a++) {
          for (int b = 0; b < 6; b++) U[a * 6 + b] += t_[a] * t_[b];
          for (int b = 0; b < D; b++) Wi[a * D + b] += t_[a] * b_[b];
          gT[a] -= t_[a] * rb[row];
        }
      }
    }
    if (D > 12) {
      /* the trigger prior */
      Vi[12 * D + 12] += 1.0 / (TB_SIGMA * TB_SIGMA);
      g[12] -= p[12] / (TB_SIGMA * TB_SIGMA);
    }
  }
  return 1;
}

/* LM from (pT, poses) in place; returns 0 on numeric failure */
static int stereo_lm(const stereo_prob *P, double pT[6], double *poses, int max_it,
                     double *scratch) {
  const size_t n = P->n_pairs, D = (size_t)P->nq;
  double *V = scratch, *Vi = V + D * D * n, *W = Vi + D * D * n, *gp = W + 6 * D * n,
         *trial = gp + D * n;
  double cost = total_cost(P, pT, poses, NULL), lambda = 1e-3;
  if (!isfinite(cost)) return 0;
  for (int it = 0; it < max_it; it++) {
    double U[36], gT[6];
    if (!stereo_normal(P, pT, poses, U, gT, V, W, gp)) return 0;
    int improved = 0;
    for (int tries = 0; tries < 12 && !improved; tries++) {
      double S[36], rhs[6];
      memcpy(S, U, sizeof S);
      memcpy(rhs, gT, sizeof rhs);
      for (int a = 0; a < 6; a++) S[a * 6 + a] *= 1.0 + lambda;
      int ok = 1;
      for (size_t i = 0; i < n && ok; i++) {
        if (!P->used[i]) continue;
        double *Vd = Vi + D * D * i;
        memcpy(Vd, V + D * D * i, sizeof(double) * D * D);
        for (size_t a = 0; a < D; a++) Vd[a * D + a] *= 1.0 + lambda;
        if (!calib_chol_invert(Vd, (int)D)) {
          ok = 0;
          break;
        }
        const double *Wi = W + 6 * D * i;
        double WV[6 * NQ_MAX];
        for (size_t a = 0; a < 6; a++)
          for (size_t b = 0; b < D; b++) {
            double s = 0;
            for (size_t k = 0; k < D; k++) s += Wi[a * D + k] * Vd[k * D + b];
            WV[a * D + b] = s;
          }
        for (size_t a = 0; a < 6; a++) {
          for (size_t b = 0; b < 6; b++) {
            double s = 0;
            for (size_t k = 0; k < D; k++) s += WV[a * D + k] * Wi[b * D + k];
            S[a * 6 + b] -= s;
          }
          double s = 0;
          for (size_t k = 0; k < D; k++) s += WV[a * D + k] * gp[D * i + k];
          rhs[a] -= s;
        }
      }
      if (ok) ok = calib_chol_solve(S, rhs, 6);
      if (!ok) {
        lambda *= 10;
        continue;
      }
      double pTn[6];
      for (int a = 0; a < 6; a++) pTn[a] = pT[a] + rhs[a];
      memcpy(trial, poses, sizeof(double) * D * n);
      for (size_t i = 0; i < n; i++) {
        if (!P->used[i]) continue;
        const double *Vd = Vi + D * D * i, *Wi = W + 6 * D * i;
        double r6[NQ_MAX];
        for (size_t b = 0; b < D; b++) {
          double s = gp[D * i + b];
          for (size_t a = 0; a < 6; a++) s -= Wi[a * D + b] * rhs[a];
          r6[b] = s;
        }
        for (size_t a = 0; a < D; a++) {
          double s = 0;
          for (size_t b = 0; b < D; b++) s += Vd[a * D + b] * r6[b];
          trial[D * i + a] += s;
        }
      }
      int done;
      if (lm_take(&cost, total_cost(P, pTn, trial, NULL), &lambda, &done)) {
        memcpy(pT, pTn, sizeof(double) * 6);
        memcpy(poses, trial, sizeof(double) * D * n);
        improved = 1;
        if (done) it = max_it;
      }
    }
    if (!improved) break;
  }
  return 1;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* solve, drop outlier pairs (RMS over the rule), solve again until stable;
 * used is updated; returns 0 on numeric failure */
static int stereo_rounds(stereo_prob *P, int *used, double pT[6], double *poses,
                         const hearth_calib_opts *o, double *scratch, double *tmp, double *pc) {
  const size_t n_pts = P->n_pts;
  for (int round = 0; round < 5; round++) {
    if (!stereo_lm(P, pT, poses, o->max_iterations, scratch)) return 0;
    total_cost(P, pT, poses, pc);
    size_t m = 0;
    for (size_t i = 0; i < P->n_pairs; i++)
      if (used[i]) tmp[m++] = sqrt(pc[i] / (2.0 * (double)n_pts));
    qsort(tmp, m, sizeof(double), cmp_double);
    double med = m % 2 ? tmp[m / 2] : 0.5 * (tmp[m / 2 - 1] + tmp[m / 2]);
    double lim = o->outlier_factor * med;
    if (lim < o->outlier_min_px) lim = o->outlier_min_px;
    int dropped = 0;
    for (size_t i = 0; i < P->n_pairs; i++)
      if (used[i] && sqrt(pc[i] / (2.0 * (double)n_pts)) > lim && m - (size_t)dropped > 1) {
        used[i] = 0;
        dropped++;
      }
    if (!dropped) break;
  }
  return 1;
}

/* the rolling-shutter model of camera a, tried from the rigid solution
 * (pT, poses, used): kept when the velocities and trigger times lower the
 * cost by more than twice what 7 parameters per pair would take off pure
 * noise (the expected drop is 7 sigma^2 per pair); then solved again, with
 * the outlier rule, from every pair with a pose start (with_pose). On
 * success pT, poses (13 per pair) and used hold that solution and *moving
 * is 1. */
static int stereo_try_moving(const stereo_prob *P0, const int *with_pose, int *used, double pT[6],
                             const double *poses, double *poses_m, const hearth_calib_opts *o,
                             double *scratch, double *tmp, double *pc, int *moving) {
  *moving = 0;
  stereo_prob Q = *P0;
  Q.nq = NQ_MAX;
  size_t n = P0->n_pairs, m = 0;
  memset(poses_m, 0, sizeof(double) * NQ_MAX * n);
  for (size_t i = 0; i < n; i++) {
    memcpy(poses_m + NQ_MAX * i, poses + 6 * i, sizeof(double) * 6);
    m += used[i] != 0;
  }
  double c0 = total_cost(P0, pT, poses, NULL), qT[6];
  memcpy(qT, pT, sizeof qT);
  if (!stereo_lm(&Q, qT, poses_m, o->max_iterations, scratch)) return 1;
  double c1 = total_cost(&Q, qT, poses_m, NULL);
  double dof = 4.0 * (double)(m * P0->n_pts) - 6.0 - 13.0 * (double)m;
  if (!(dof > 0 && isfinite(c1)) || c0 - c1 <= 2.0 * 7.0 * (double)m * c1 / dof) return 1;
  /* kept: every pair with a pose start again, under the moving model */
  int *cand = hearth_alloc_array(n, sizeof(int));
  if (!cand) return 0;
  memcpy(cand, with_pose, sizeof(int) * n);
  Q.used = cand;
  if (!stereo_rounds(&Q, cand, qT, poses_m, o, scratch, tmp, pc)) {
    free(cand);
    return 1;
  }
  memcpy(used, cand, sizeof(int) * n);
  memcpy(pT, qT, sizeof qT);
  free(cand);
  *moving = 1;
  return 1;
}

/* the stereo solve: outputs pT (T_b_from_a), the pair blocks of the
 * chosen model in *sol (stride *nq, malloc'ed, the caller frees) and used */
static hearth_status stereo_core(const hearth_camera *cam_a, const hearth_camera *cam_b,
                                 const double (*obj)[3], size_t n_pts, const double *img_a,
                                 const double *img_b, size_t n_pairs, const hearth_calib_opts *o,
                                 double pT_out[6], double **sol_out, int *nq_out, int *used_out,
                                 hearth_err *err) {
  hearth_calib_opts def;
  if (!o) {
    hearth_calib_opts_default(&def);
    o = &def;
  }
  hearth_status st = HEARTH_OK;
  double *poses = hearth_calloc_array(6 * n_pairs, sizeof(double));
  double *poses_m = hearth_calloc_array(NQ_MAX * n_pairs, sizeof(double));
  double *scratch =
      hearth_alloc_array((2 * NQ_MAX * NQ_MAX + 8 * NQ_MAX) * n_pairs, sizeof(double));
  double *rel = hearth_alloc_array(6 * n_pairs, sizeof(double));
  double *tmp = hearth_alloc_array(n_pairs, sizeof(double));
  double *pc = hearth_alloc_array(n_pairs, sizeof(double));
  int *used = hearth_calloc_array(n_pairs, sizeof(int));
  int *with_pose = hearth_calloc_array(n_pairs, sizeof(int));
  if (!poses || !poses_m || !scratch || !rel || !tmp || !pc || !used || !with_pose) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "stereo calibration: out of memory");
    goto done;
  }
  /* each pair's own plate poses give a candidate T_b_from_a */
  size_t n_ok = 0;
  for (size_t i = 0; i < n_pairs; i++) {
    hearth_rigid Ta, Tb, Tai, Tr;
    hearth_err e2;
    if (hearth_calib_pose(cam_a, obj, n_pts, img_a + 2 * i * n_pts, &Ta, NULL, &e2) ||
        hearth_calib_pose(cam_b, obj, n_pts, img_b + 2 * i * n_pts, &Tb, NULL, &e2))
      continue;
    calib_params_from_rigid(&Ta, poses + 6 * i);
    hearth_rigid_inverse(&Ta, &Tai);
    hearth_rigid_compose(&Tb, &Tai, &Tr);
    calib_params_from_rigid(&Tr, rel + 6 * n_ok);
    used[i] = with_pose[i] = 1;
    n_ok++;
  }
  if (n_ok == 0) {
    st = hearth_err_set(err, HEARTH_E_NUMERIC, "stereo calibration: no pair gave a plate pose");
    goto done;
  }
  /* robust start: component-wise median of the candidates */
  double pT[6];
  for (int k = 0; k < 6; k++) {
    for (size_t i = 0; i < n_ok; i++) tmp[i] = rel[6 * i + k];
    qsort(tmp, n_ok, sizeof(double), cmp_double);
    pT[k] = n_ok % 2 ? tmp[n_ok / 2] : 0.5 * (tmp[n_ok / 2 - 1] + tmp[n_ok / 2]);
  }
  stereo_prob P = {cam_a, cam_b, obj, n_pts, n_pairs, img_a, img_b, used, 6};
  if (!stereo_rounds(&P, used, pT, poses, o, scratch, tmp, pc)) {
    st = hearth_err_set(err, HEARTH_E_NUMERIC, "stereo calibration: did not converge");
    goto done;
  }
  int moving = 0;
  if (o->rolling_shutter &&
      !stereo_try_moving(&P, with_pose, used, pT, poses, poses_m, o, scratch, tmp, pc, &moving)) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "stereo calibration: out of memory");
    goto done;
  }
  /* hand over the chosen model's blocks */
  *nq_out = moving ? NQ_MAX : 6;
  if (moving) {
    *sol_out = poses_m;
    poses_m = NULL;
  } else {
    *sol_out = poses;
    poses = NULL;
  }
  memcpy(pT_out, pT, sizeof pT);
  memcpy(used_out, used, sizeof(int) * n_pairs);
done:
  free(poses);
  free(poses_m);
  free(scratch);
  free(rel);
  free(tmp);
  free(pc);
  free(used);
  free(with_pose);
  return st;
}

/* the stereo RMS and per-pair outputs of a solution */
static void stereo_report(const stereo_prob *P, const double pT[6], const double *sol, double *pc,
                          double *rms_px, double *pair_rms, int *pair_used) {
  total_cost(P, pT, sol, pc);
  double sum = 0;
  size_t m = 0;
  for (size_t i = 0; i < P->n_pairs; i++) {
    /* the points' error only: the trigger prior is no pixel error */
    if (P->nq > 12) {
      const double tb = tb_time(sol + (size_t)P->nq * i, P->nq) / TB_SIGMA;
      pc[i] = fmax(0.0, pc[i] - tb * tb);
    }
    /* a pair without a pose start has no meaningful residual */
    double r = isfinite(pc[i]) ? sqrt(pc[i] / (2.0 * (double)P->n_pts)) : NAN;
    if (pair_rms) pair_rms[i] = r;
    if (pair_used) pair_used[i] = P->used[i];
    if (P->used[i]) {
      sum += pc[i];
      m++;
    }
  }
  if (rms_px) *rms_px = sqrt(sum / (2.0 * (double)(m * P->n_pts)));
}

hearth_status hearth_calib_stereo(const hearth_camera *cam_a, const hearth_camera *cam_b,
                                  const double (*obj)[3], size_t n_pts, const double *img_a,
                                  const double *img_b, size_t n_pairs, const hearth_calib_opts *o,
                                  hearth_rigid *T_b_from_a, double *rms_px, double *pair_rms,
                                  int *pair_used, hearth_err *err) {
  if (!cam_a || !cam_b || !obj || !img_a || !img_b || !T_b_from_a)
    return hearth_err_set(err, HEARTH_E_ARG, "stereo calibration: missing argument");
  if (n_pairs < 1)
    return hearth_err_set(err, HEARTH_E_SIZE, "stereo calibration: no usable stereo pairs");
  if (n_pts < 4 || n_pts > 100000 || n_pairs > 100000)
    return hearth_err_set(err, HEARTH_E_SIZE, "stereo calibration: %zu points per pair", n_pts);
  int *used = hearth_calloc_array(n_pairs, sizeof(int));
  double *pc = hearth_alloc_array(n_pairs, sizeof(double));
  double *sol = NULL, pT[6];
  int nq = 6;
  hearth_status st = HEARTH_OK;
  if (!used || !pc) st = hearth_err_set(err, HEARTH_E_NOMEM, "stereo calibration: out of memory");
  else
    st = stereo_core(cam_a, cam_b, obj, n_pts, img_a, img_b, n_pairs, o, pT, &sol, &nq, used, err);
  if (!st) {
    stereo_prob P = {cam_a, cam_b, obj, n_pts, n_pairs, img_a, img_b, used, nq};
    calib_rigid_from_params(pT, T_b_from_a);
    stereo_report(&P, pT, sol, pc, rms_px, pair_rms, pair_used);
  }
  free(sol);
  free(used);
  free(pc);
  return st;
}

/* ---- stereo with camera b's intrinsics refined ---------------------------- */
/* The extrinsic, camera b's fx fy cx cy k1 k2 p1 p2 k3 (the global block,
 * JG parameters; with the target model also every hole's in-plane offset
 * from its nominal position, 2 per hole after them) and the blocks of the
 * pairs (stride nq, from the stereo solve) and of camera b's own frames (a
 * pose each, stride 6, after the pairs), solved together through the Schur
 * complement of the blocks. */
#define NB_INTR 9
#define JG (6 + NB_INTR)
/* the target model's prior: each offset N(0, sigma^2), sigma the drilling
 * tolerance (hearth_calib_opts.target_sigma_m), weighed against image
 * points of this many pixels of noise (the order the rig leaves with its
 * target known) */
#define TARGET_PX_SIGMA 0.02
typedef struct joint_prob {
  stereo_prob P;            /* the pairs; P.cb is replaced by the trial camera */
  const hearth_camera *cb0; /* camera b's size, model and k4..k6 */
  const double *img_c;      /* camera b's own frames */
  size_t n_c;
  int ng; /* global parameters: JG, or JG + 2 n_pts with the target model */
  /* with the target model: the nominal points, the current ones (scratch:
   * nominal + offsets, P.obj points there), the prior's weight (px^2 per
   * m^2 of offset) and the gauge: the offsets (interleaved x, y) are B z,
   * B (2 n_pts x nb, orthonormal columns) a basis of the offsets without a
   * similarity part (the 4 directions the plate poses and the scale trade
   * with them exactly) */
  const double (*nom)[3];
  double (*pts)[3];
  double prior;
  const double *B;
  int nb; /* B's columns */
} joint_prob;

static void joint_cam(const joint_prob *J, const double *g, hearth_camera *c) {
  *c = *J->cb0;
  c->fx = g[6];
  c->fy = g[7];
  c->cx = g[8];
  c->cy = g[9];
  for (int k = 0; k < 5; k++) c->dist[k] = g[10 + k];
}

/* with the target model: the points at g's offsets into J->pts, and the
 * prior's cost */
static double joint_points(const joint_prob *J, const double *g) {
  if (J->ng == JG) return 0.0;
  double s = 0;
  for (size_t j = 0; j < J->P.n_pts; j++) {
    const double *d = g + JG + 2 * j;
    J->pts[j][0] = J->nom[j][0] + d[0];
    J->pts[j][1] = J->nom[j][1] + d[1];
    J->pts[j][2] = J->nom[j][2];
    s += J->prior * (d[0] * d[0] + d[1] * d[1]);
  }
  return s;
}

/* squared error of camera b's own frame k at pose p */
static double own_cost(const joint_prob *J, const hearth_camera *cb, size_t k, const double *p) {
  hearth_rigid T;
  calib_rigid_from_params(p, &T);
  double s = 0;
  for (size_t j = 0; j < J->P.n_pts; j++) {
    double X[3], uv[2];
    hearth_rigid_apply(&T, J->P.obj[j], X);
    if (!hearth_camera_project(cb, X, uv, NULL)) return INFINITY;
    const double *m = J->img_c + 2 * (k * J->P.n_pts + j);
    s += (uv[0] - m[0]) * (uv[0] - m[0]) + (uv[1] - m[1]) * (uv[1] - m[1]);
  }
  return s;
}

static double joint_cost(const joint_prob *J, const double *g, const double *x) {
  hearth_camera cb;
  joint_cam(J, g, &cb);
  double prior = joint_points(J, g);
  stereo_prob P = J->P;
  P.cb = &cb;
  double s = total_cost(&P, g, x, NULL);
  const double *xc = x + (size_t)P.nq * P.n_pairs;
  for (size_t k = 0; k < J->n_c && isfinite(s); k++) s += own_cost(J, &cb, k, xc + 6 * k);
  return isfinite(s) ? s + prior : INFINITY;
}

/* a residual row's global Jacobian, sparse: its nonzero entries in
 * increasing index order */
typedef struct sparse_row {
  int n;
  int idx[JG + 2];
  double val[JG + 2];
} sparse_row;

/* the nonzero entries of a dense global row (m entries) into s */
static void sparse_dense(sparse_row *s, const double *jg, int m) {
  s->n = 0;
  for (int a = 0; a < m; a++)
    if (jg[a] != 0) {
      s->idx[s->n] = a;
      s->val[s->n++] = jg[a];
    }
}

/* with the target model: hole j's offsets, from a row's derivatives dt by
 * its block's translation (the plate point moves with it through R) */
static void sparse_hole(sparse_row *s, const joint_prob *J, size_t j, const double dt[3],
                        const double R[9]) {
  if (J->ng == JG) return;
  for (int k = 0; k < 2; k++) {
    double v = dt[0] * R[k] + dt[1] * R[3 + k] + dt[2] * R[6 + k];
    if (v == 0) continue;
    s->idx[s->n] = JG + 2 * (int)j + k;
    s->val[s->n++] = v;
  }
}

/* one residual row: global Jacobian jg (ng columns, sparse), block
 * Jacobian jb (d) and residual r into U, gg and the block's V, W, gb */
static void joint_row(int d, int ng, const sparse_row *jg, const double *jb, double r, double *U,
                      double *gg, double *V, double *W, double *gb) {
  for (int a = 0; a < d; a++) {
    for (int b = 0; b < d; b++) V[a * d + b] += jb[a] * jb[b];
    gb[a] -= jb[a] * r;
  }
  for (int q = 0; q < jg->n; q++) {
    const int a = jg->idx[q];
    const double va = jg->val[q];
    for (int e = 0; e < jg->n; e++) U[a * ng + jg->idx[e]] += va * jg->val[e];
    for (int b = 0; b < d; b++) W[a * d + b] += va * jb[b];
    gg[a] -= va * r;
  }
}

/* camera b's projection with intrinsic rows ji (2 x NB_INTR) */
static void intr_rows(const hearth_project_jac *jac, double ji[2][NB_INTR]) {
  for (int row = 0; row < 2; row++) {
    for (int k = 0; k < 4; k++) ji[row][k] = jac->d_intr[4 * row + k];
    for (int k = 0; k < 5; k++) ji[row][4 + k] = jac->d_dist[5 * row + k];
  }
}

/* normal equations of the joint problem at (g, x); block b's V at
 * V + NQ_MAX^2 b, W (ng x d) at W + ng NQ_MAX b, gradient at gb + NQ_MAX b */
static int joint_normal(const joint_prob *J, const double *g, const double *x, double *U,
                        double *gg, double *V, double *W, double *gb) {
  const stereo_prob *P = &J->P;
  const int D = P->nq, ng = J->ng;
  hearth_camera cb;
  joint_cam(J, g, &cb);
  joint_points(J, g);
  double RT[9], dRT[27];
  hearth_rotvec_to_matrix_jac(g, RT, dRT);
  memset(U, 0, sizeof(double) * (size_t)(ng * ng));
  memset(gg, 0, sizeof(double) * (size_t)ng);
  size_t nb = P->n_pairs + J->n_c;
  memset(V, 0, sizeof(double) * NQ_MAX * NQ_MAX * nb);
  memset(W, 0, sizeof(double) * (size_t)ng * NQ_MAX * nb);
  memset(gb, 0, sizeof(double) * NQ_MAX * nb);
  for (size_t i = 0; i < P->n_pairs; i++) {
    if (!P->used[i]) continue;
    const double *p = x + D * i;
    double *Vi = V + NQ_MAX * NQ_MAX * i, *Wi = W + (size_t)ng * NQ_MAX * i, *g6 = gb + NQ_MAX * i;
    double R[9], dR[27];
    hearth_rotvec_to_matrix_jac(p, R, dR);
    for (size_t j = 0; j < P->n_pts; j++) {
      double ra[2], rb[2], ja[2 * NQ_MAX], jb[2 * NQ_MAX], jT[12], ji[2][NB_INTR], jgr[JG];
      hearth_project_jac jac;
      sparse_row sr;
      if (!pair_rows(P, &cb, RT, dRT, g + 3, p, R, dR, i, j, ra, ja, rb, jb, jT, &jac)) return 0;
      intr_rows(&jac, ji);
      for (int row = 0; row < 2; row++) {
        sr.n = 0;
        sparse_hole(&sr, J, j, ja + D * row + 3, R);
        joint_row(D, ng, &sr, ja + D * row, ra[row], U, gg, Vi, Wi, g6);
        memcpy(jgr, jT + 6 * row, sizeof(double) * 6);
        memcpy(jgr + 6, ji[row], sizeof(double) * NB_INTR);
        sparse_dense(&sr, jgr, JG);
        sparse_hole(&sr, J, j, jb + D * row + 3, R);
        joint_row(D, ng, &sr, jb + D * row, rb[row], U, gg, Vi, Wi, g6);
      }
    }
    if (D > 12) {
      Vi[12 * D + 12] += 1.0 / (TB_SIGMA * TB_SIGMA);
      g6[12] -= p[12] / (TB_SIGMA * TB_SIGMA);
    }
  }
  const double *xc = x + (size_t)D * P->n_pairs;
  for (size_t k = 0; k < J->n_c; k++) {
    size_t b = P->n_pairs + k;
    const double *p = xc + 6 * k;
    double *Vb = V + NQ_MAX * NQ_MAX * b, *Wb = W + (size_t)ng * NQ_MAX * b, *g6 = gb + NQ_MAX * b;
    double R[9], dR[27];
    hearth_rotvec_to_matrix_jac(p, R, dR);
    for (size_t j = 0; j < P->n_pts; j++) {
      double uv[2], dp[12], ji[2][NB_INTR], jgr[JG];
      hearth_project_jac jac;
      sparse_row sr;
      if (!calib_project_pose(&cb, R, dR, p + 3, P->obj[j], uv, &jac, dp, NULL)) return 0;
      intr_rows(&jac, ji);
      const double *m = J->img_c + 2 * (k * P->n_pts + j);
      for (int row = 0; row < 2; row++) {
        memset(jgr, 0, sizeof(double) * 6);
        memcpy(jgr + 6, ji[row], sizeof(double) * NB_INTR);
        sparse_dense(&sr, jgr, JG);
        sparse_hole(&sr, J, j, dp + 6 * row + 3, R);
        joint_row(6, ng, &sr, dp + 6 * row, uv[row] - m[row], U, gg, Vb, Wb, g6);
      }
    }
  }
  /* the offsets' prior */
  for (int a = JG; a < ng; a++) {
    U[a * ng + a] += J->prior;
    gg[a] -= J->prior * g[a];
  }
  return 1;
}

/* LM over (g, x) in place; returns 0 on numeric failure */
static int joint_lm(const joint_prob *J, double *g, double *x, int max_it) {
  const stereo_prob *P = &J->P;
  const size_t np = P->n_pairs, nb = np + J->n_c, D = (size_t)P->nq, ng = (size_t)J->ng;
  const size_t nx = D * np + 6 * J->n_c;
  double *V = hearth_alloc_array(NQ_MAX * NQ_MAX * nb, sizeof(double));
  double *Vi = hearth_alloc_array(NQ_MAX * NQ_MAX * nb, sizeof(double));
  double *W = hearth_alloc_array(ng * NQ_MAX * nb, sizeof(double));
  double *gb = hearth_alloc_array(NQ_MAX * nb, sizeof(double));
  double *trial = hearth_alloc_array(nx, sizeof(double));
  /* U, S (ng x ng), gg, rhs, gn (ng), WV (ng x NQ_MAX); with the target
   * model ST (ng x nr), Sr (nr x nr), rr (nr) */
  double *U = hearth_alloc_array(2 * ng * ng + 3 * ng + ng * NQ_MAX, sizeof(double));
  double *ST = ng > JG ? hearth_alloc_array(2 * ng * ng + ng, sizeof(double)) : NULL;
  int ok_all = V && Vi && W && gb && trial && U && (ng == JG || ST);
  double *S = U + ng * ng, *gg = S + ng * ng, *rhs = gg + ng, *gn = rhs + ng, *WV = gn + ng;
  double *Sr = ST ? ST + ng * ng : U, *rr = ST ? Sr + ng * ng : U; /* U: not used */
  double cost = ok_all ? joint_cost(J, g, x) : INFINITY, lambda = 1e-3;
  if (!isfinite(cost)) ok_all = 0;
  for (int it = 0; ok_all && it < max_it; it++) {
    if (!joint_normal(J, g, x, U, gg, V, W, gb)) {
      ok_all = 0;
      break;
    }
    int improved = 0;
    for (int tries = 0; tries < 12 && !improved; tries++) {
      memcpy(S, U, sizeof(double) * ng * ng);
      memcpy(rhs, gg, sizeof(double) * ng);
      for (size_t a = 0; a < ng; a++) S[a * ng + a] *= 1.0 + lambda;
      int ok = 1;
      for (size_t b = 0; b < nb && ok; b++) {
        size_t d = b < np ? D : 6;
        if (b < np && !P->used[b]) continue;
        double *Vd = Vi + NQ_MAX * NQ_MAX * b;
        memcpy(Vd, V + NQ_MAX * NQ_MAX * b, sizeof(double) * d * d);
        for (size_t a = 0; a < d; a++) Vd[a * d + a] *= 1.0 + lambda;
        if (!calib_chol_invert(Vd, (int)d)) {
          ok = 0;
          break;
        }
        const double *Wb = W + ng * NQ_MAX * b, *gv = gb + NQ_MAX * b;
        for (size_t a = 0; a < ng; a++)
          for (size_t c = 0; c < d; c++) {
            double s = 0;
            for (size_t k = 0; k < d; k++) s += Wb[a * d + k] * Vd[k * d + c];
            WV[a * d + c] = s;
          }
        for (size_t a = 0; a < ng; a++) {
          for (size_t c = 0; c < ng; c++) {
            double s = 0;
            for (size_t k = 0; k < d; k++) s += WV[a * d + k] * Wb[c * d + k];
            S[a * ng + c] -= s;
          }
          double s = 0;
          for (size_t k = 0; k < d; k++) s += WV[a * d + k] * gv[k];
          rhs[a] -= s;
        }
      }
      if (ok && ng > JG) {
        /* the step in the gauge's coordinates: (T^T S T) z = T^T rhs, then
         * T z, T = diag(I, B per axis) */
        const size_t n2 = 2 * P->n_pts, mb = (size_t)J->nb, nr = JG + mb;
        const double *B = J->B;
        for (size_t a = 0; a < ng; a++)
          for (size_t c = 0; c < nr; c++) {
            double v = 0;
            if (c < JG) v = S[a * ng + c];
            else
              for (size_t l = 0; l < n2; l++) v += S[a * ng + JG + l] * B[l * mb + c - JG];
            ST[a * nr + c] = v;
          }
        for (size_t a = 0; a < nr; a++) {
          for (size_t c = 0; c < nr; c++) {
            double v = 0;
            if (a < JG) v = ST[a * nr + c];
            else
              for (size_t l = 0; l < n2; l++) v += B[l * mb + a - JG] * ST[(JG + l) * nr + c];
            Sr[a * nr + c] = v;
          }
          double v = 0;
          if (a < JG) v = rhs[a];
          else
            for (size_t l = 0; l < n2; l++) v += B[l * mb + a - JG] * rhs[JG + l];
          rr[a] = v;
        }
        ok = calib_chol_solve(Sr, rr, (int)nr);
        if (ok) {
          memcpy(rhs, rr, sizeof(double) * JG);
          for (size_t l = 0; l < n2; l++) {
            double v = 0;
            for (size_t m = 0; m < mb; m++) v += B[l * mb + m] * rr[JG + m];
            rhs[JG + l] = v;
          }
        }
      } else if (ok) {
        ok = calib_chol_solve(S, rhs, (int)ng);
      }
      if (!ok) {
        lambda *= 10;
        continue;
      }
      for (size_t a = 0; a < ng; a++) gn[a] = g[a] + rhs[a];
      memcpy(trial, x, sizeof(double) * nx);
      for (size_t b = 0; b < nb; b++) {
        if (b < np && !P->used[b]) continue;
        size_t d = b < np ? D : 6;
        double *xb = trial + (b < np ? D * b : D * np + 6 * (b - np));
        const double *Vd = Vi + NQ_MAX * NQ_MAX * b, *Wb = W + ng * NQ_MAX * b,
                     *gv = gb + NQ_MAX * b;
        double r6[NQ_MAX];
        for (size_t c = 0; c < d; c++) {
          double s = gv[c];
          for (size_t a = 0; a < ng; a++) s -= Wb[a * d + c] * rhs[a];
          r6[c] = s;
        }
        for (size_t a = 0; a < d; a++) {
          double s = 0;
          for (size_t c = 0; c < d; c++) s += Vd[a * d + c] * r6[c];
          xb[a] += s;
        }
      }
      int done;
      if (lm_take(&cost, joint_cost(J, gn, trial), &lambda, &done)) {
        memcpy(g, gn, sizeof(double) * ng);
        memcpy(x, trial, sizeof(double) * nx);
        improved = 1;
        if (done) it = max_it;
      }
    }
    if (!improved) break;
  }
  /* the points at the solution's offsets */
  if (ok_all) joint_points(J, g);
  free(V);
  free(Vi);
  free(W);
  free(gb);
  free(trial);
  free(U);
  free(ST);
  return ok_all;
}

/* an orthonormal basis B (2n x (2n - nq), row-major, offsets interleaved
 * x, y per point) of the in-plane offsets of the n nominal points without
 * a part in the gauge: the similarity (nq = 4: the two translations, the
 * rotation (-y, x) and the scale (x, y)) or the affine map (nq = 6: x, y
 * and 1 on either axis); col is scratch of 2n; 0 if the points are
 * degenerate */
static int offset_basis(const double (*nom)[3], size_t n, int nq, double *B, double *col) {
  const size_t n2 = 2 * n, m = n2 - (size_t)nq;
  double *Q = B + n2 * m; /* the gauge's nq directions, orthonormalised */
  for (int a = 0; a < nq; a++) {
    double *q = Q + n2 * (size_t)a;
    for (size_t j = 0; j < n; j++) {
      const double x = nom[j][0], y = nom[j][1];
      double u = 0, v = 0;
      if (nq == 4) {
        const double ux[4] = {1, 0, x, -y}, vy[4] = {0, 1, y, x};
        u = ux[a];
        v = vy[a];
      } else {
        const double f = a % 3 == 0 ? x : a % 3 == 1 ? y : 1.0;
        u = a < 3 ? f : 0.0;
        v = a < 3 ? 0.0 : f;
      }
      q[2 * j] = u;
      q[2 * j + 1] = v;
    }
    for (int e = 0; e < a; e++) {
      const double *p = Q + n2 * (size_t)e;
      double d = 0;
      for (size_t l = 0; l < n2; l++) d += q[l] * p[l];
      for (size_t l = 0; l < n2; l++) q[l] -= d * p[l];
    }
    double s = 0;
    for (size_t l = 0; l < n2; l++) s += q[l] * q[l];
    if (!(s > 1e-300)) return 0;
    s = 1.0 / sqrt(s);
    for (size_t l = 0; l < n2; l++) q[l] *= s;
  }
  size_t k = 0;
  for (size_t u = 0; u < n2 && k < m; u++) {
    for (size_t l = 0; l < n2; l++) col[l] = l == u;
    for (int pass = 0; pass < 2; pass++) {
      for (int a = 0; a < nq; a++) {
        const double *p = Q + n2 * (size_t)a;
        double d = 0;
        for (size_t l = 0; l < n2; l++) d += p[l] * col[l];
        for (size_t l = 0; l < n2; l++) col[l] -= d * p[l];
      }
      for (size_t c = 0; c < k; c++) {
        double d = 0;
        for (size_t l = 0; l < n2; l++) d += B[l * m + c] * col[l];
        for (size_t l = 0; l < n2; l++) col[l] -= d * B[l * m + c];
      }
    }
    double s = 0;
    for (size_t l = 0; l < n2; l++) s += col[l] * col[l];
    if (s < 1e-6) continue;
    s = 1.0 / sqrt(s);
    for (size_t l = 0; l < n2; l++) B[l * m + k] = col[l] * s;
    k++;
  }
  return k == m;
}

/* the joint solve from camera b's start *cam_b (its estimate on return);
 * *cost (the final cost, prior and own frames included) and *n_used (pairs
 * used) when cost is non-NULL; arguments checked by the caller */
static hearth_status joint_solve(const hearth_camera *cam_a, hearth_camera *cam_b,
                                 const double (*obj)[3], size_t n_pts, const double *img_a,
                                 const double *img_b, size_t n_pairs, const double *img_c,
                                 size_t n_c, const hearth_calib_opts *o, hearth_rigid *T_b_from_a,
                                 double *rms_px, double *own_rms_px, double *pair_rms,
                                 int *pair_used, double *pair_time, double *rms_nominal_px,
                                 double (*pts_out)[3], double *cost, size_t *n_used,
                                 hearth_err *err) {
  int *used = hearth_calloc_array(n_pairs, sizeof(int));
  double *pc = hearth_alloc_array(n_pairs, sizeof(double));
  double *sol = NULL, *x = NULL, pT[6];
  double(*tpts)[3] = NULL;
  double *aff = NULL, *gt = NULL;
  int nq = 6;
  hearth_status st = HEARTH_OK;
  hearth_camera cb = *cam_b; /* camera b's start, then its estimate */
  if (!used || !pc) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "stereo calibration: out of memory");
    goto done;
  }
  if ((st =
           stereo_core(cam_a, &cb, obj, n_pts, img_a, img_b, n_pairs, o, pT, &sol, &nq, used, err)))
    goto done;
  const hearth_camera cb_start = cb;
  stereo_prob P = {cam_a, &cb_start, obj, n_pts, n_pairs, img_a, img_b, used, nq};
  if (o->stereo_intrinsics) {
    /* camera b's own frames: their poses at the current intrinsics */
    size_t nx = (size_t)nq * n_pairs + 6 * n_c;
    x = hearth_calloc_array(nx, sizeof(double));
    if (!x) {
      st = hearth_err_set(err, HEARTH_E_NOMEM, "stereo calibration: out of memory");
      goto done;
    }
    memcpy(x, sol, sizeof(double) * (size_t)nq * n_pairs);
    for (size_t k = 0; k < n_c; k++) {
      hearth_rigid T;
      hearth_err e2;
      if (hearth_calib_pose(&cb_start, obj, n_pts, img_c + 2 * k * n_pts, &T, NULL, &e2)) {
        st = hearth_err_set(err, HEARTH_E_NUMERIC, "stereo calibration: own frame %zu: no pose", k);
        goto done;
      }
      calib_params_from_rigid(&T, x + (size_t)nq * n_pairs + 6 * k);
    }
    double g[JG];
    memcpy(g, pT, sizeof pT);
    g[6] = cb_start.fx;
    g[7] = cb_start.fy;
    g[8] = cb_start.cx;
    g[9] = cb_start.cy;
    for (int k = 0; k < 5; k++) g[10 + k] = cb_start.dist[k];
    joint_prob J = {P, &cb_start, img_c, n_c, JG, NULL, NULL, 0, NULL, 0};
    int ok = joint_lm(&J, g, x, o->max_iterations);
    if (ok && rms_nominal_px) {
      /* the stereo RMS against the nominal target */
      joint_cam(&J, g, &cb);
      stereo_prob Pn = P;
      Pn.cb = &cb;
      stereo_report(&Pn, g, x, pc, rms_nominal_px, NULL, NULL);
    }
    if (ok && o->target_points && n_pts <= HEARTH_TARGET_MAX_HOLES) {
      /* the holes' in-plane offsets from the nominal lattice, solved with
       * the rest from the solution on the nominal target */
      const size_t ng = JG + 2 * n_pts;
      tpts = hearth_alloc_array(n_pts, sizeof *tpts);
      /* the gauge: the offsets' similarity part (their shear and
       * anisotropic scale are solved: held at zero they cost 0.02-0.04 deg
       * on the oracle, bench/target_oracle.sh) */
      const int ngauge = 4;
      aff = hearth_alloc_array(2 * n_pts * 2 * n_pts + 2 * n_pts, sizeof(double));
      gt = hearth_calloc_array(ng, sizeof(double));
      if (!tpts || !aff || !gt) {
        st = hearth_err_set(err, HEARTH_E_NOMEM, "stereo calibration: out of memory");
        goto done;
      }
      if (!offset_basis(obj, n_pts, ngauge, aff, aff + 4 * n_pts * n_pts)) {
        st = hearth_err_set(err, HEARTH_E_NUMERIC, "stereo calibration: degenerate target");
        goto done;
      }
      memcpy(gt, g, sizeof g);
      J.ng = (int)ng;
      J.nom = obj;
      J.pts = tpts;
      J.P.obj = P.obj = (const double(*)[3])tpts;
      const double sig = o->target_sigma_m > 0 ? o->target_sigma_m : 4e-5;
      J.prior = (TARGET_PX_SIGMA / sig) * (TARGET_PX_SIGMA / sig);
      J.B = aff;
      J.nb = (int)(2 * n_pts) - ngauge;
      ok = joint_lm(&J, gt, x, o->max_iterations);
      memcpy(g, gt, sizeof g);
    }
    if (cost) *cost = joint_cost(&J, J.ng > JG ? gt : g, x);
    memcpy(pT, g, sizeof pT);
    memcpy(sol, x, sizeof(double) * (size_t)nq * n_pairs);
    joint_cam(&J, g, &cb);
    if (own_rms_px) {
      double s = 0;
      for (size_t k = 0; k < n_c; k++) s += own_cost(&J, &cb, k, x + (size_t)nq * n_pairs + 6 * k);
      *own_rms_px = n_c ? sqrt(s / (double)(n_c * n_pts)) : NAN;
    }
  } else if (own_rms_px) {
    *own_rms_px = NAN;
  }
  *cam_b = cb;
  P.cb = cam_b;
  calib_rigid_from_params(pT, T_b_from_a);
  stereo_report(&P, pT, sol, pc, rms_px, pair_rms, pair_used);
  if (rms_nominal_px && !(o->stereo_intrinsics && o->target_points))
    stereo_report(&P, pT, sol, pc, rms_nominal_px, NULL, NULL);
  if (pts_out) memcpy(pts_out, P.obj, sizeof(double) * 3 * n_pts);
  if (pair_time)
    for (size_t i = 0; i < n_pairs; i++)
      pair_time[i] = nq > 12 && used[i] ? tb_time(sol + (size_t)nq * i, nq) : NAN;
  if (n_used) {
    *n_used = 0;
    for (size_t i = 0; i < n_pairs; i++) *n_used += used[i] != 0;
  }
done:
  free(sol);
  free(x);
  free(tpts);
  free(aff);
  free(gt);
  free(used);
  free(pc);
  return st;
}

hearth_status calib_stereo_joint_times(const hearth_camera *cam_a, hearth_camera *cam_b,
                                       const double (*obj)[3], size_t n_pts, const double *img_a,
                                       const double *img_b, size_t n_pairs, const double *img_c,
                                       size_t n_c, const hearth_calib_opts *o,
                                       hearth_rigid *T_b_from_a, double *rms_px, double *own_rms_px,
                                       double *pair_rms, int *pair_used, double *pair_time,
                                       double *rms_nominal_px, double (*pts_out)[3],
                                       hearth_err *err) {
  hearth_calib_opts def;
  if (!o) {
    hearth_calib_opts_default(&def);
    o = &def;
  }
  if (!cam_a || !cam_b || !obj || !img_a || !img_b || (n_c && !img_c) || !T_b_from_a)
    return hearth_err_set(err, HEARTH_E_ARG, "stereo calibration: missing argument");
  if (n_pairs < 1)
    return hearth_err_set(err, HEARTH_E_SIZE, "stereo calibration: no usable stereo pairs");
  if (n_pts < 4 || n_pts > 100000 || n_pairs > 100000 || n_c > 100000)
    return hearth_err_set(err, HEARTH_E_SIZE, "stereo calibration: %zu points per pair", n_pts);
  if (!o->stereo_intrinsics || !o->rolling_shutter)
    return joint_solve(cam_a, cam_b, obj, n_pts, img_a, img_b, n_pairs, img_c, n_c, o, T_b_from_a,
                       rms_px, own_rms_px, pair_rms, pair_used, pair_time, rms_nominal_px, pts_out,
                       NULL, NULL, err);
  /* The moving model's velocities and trigger times, tried at camera b's
   * start intrinsics, can take part of their error and settle in a false
   * minimum; tried from camera b refined under the rigid model they can
   * settle in another. Both are solved and the one with the lower mean
   * squared residual over the points it used kept (the first on a tie;
   * each drops its own outlier pairs). */
  hearth_calib_opts o1 = *o;
  o1.rolling_shutter = 0;
  o1.target_points = 0;
  hearth_camera cr = *cam_b, c0 = *cam_b;
  hearth_rigid T1;
  hearth_err e1;
  int refined = !joint_solve(cam_a, &cr, obj, n_pts, img_a, img_b, n_pairs, img_c, n_c, &o1, &T1,
                             NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, &e1);
  double cost0 = INFINITY, cost1 = INFINITY;
  size_t nu0 = 0, nu1 = 0;
  hearth_status st = joint_solve(cam_a, &c0, obj, n_pts, img_a, img_b, n_pairs, img_c, n_c, o,
                                 T_b_from_a, rms_px, own_rms_px, pair_rms, pair_used, pair_time,
                                 rms_nominal_px, pts_out, &cost0, &nu0, err);
  if (st || !refined) {
    if (!st) *cam_b = c0;
    return st;
  }
  double *d1 = hearth_alloc_array(2 * n_pairs + 3 * n_pts, sizeof(double));
  int *u1 = hearth_alloc_array(n_pairs, sizeof(int));
  double rms1, own1, nom1;
  double(*p1)[3] = d1 ? (double(*)[3])(d1 + 2 * n_pairs) : NULL;
  if (d1 && u1 &&
      !joint_solve(cam_a, &cr, obj, n_pts, img_a, img_b, n_pairs, img_c, n_c, o, &T1, &rms1, &own1,
                   d1, u1, d1 + n_pairs, &nom1, p1, &cost1, &nu1, &e1) &&
      cost1 / (double)(4 * n_pts * nu1 + 2 * n_pts * n_c) <
          cost0 / (double)(4 * n_pts * nu0 + 2 * n_pts * n_c)) {
    c0 = cr;
    *T_b_from_a = T1;
    if (rms_px) *rms_px = rms1;
    if (rms_nominal_px) *rms_nominal_px = nom1;
    if (own_rms_px) *own_rms_px = own1;
    if (pair_rms) memcpy(pair_rms, d1, sizeof(double) * n_pairs);
    if (pair_used) memcpy(pair_used, u1, sizeof(int) * n_pairs);
    if (pair_time) memcpy(pair_time, d1 + n_pairs, sizeof(double) * n_pairs);
    if (pts_out) memcpy(pts_out, p1, sizeof(double) * 3 * n_pts);
  }
  *cam_b = c0;
  free(d1);
  free(u1);
  return HEARTH_OK;
}

hearth_status hearth_calib_stereo_joint(const hearth_camera *cam_a, hearth_camera *cam_b,
                                        const double (*obj)[3], size_t n_pts, const double *img_a,
                                        const double *img_b, size_t n_pairs, const double *img_c,
                                        size_t n_c, const hearth_calib_opts *o,
                                        hearth_rigid *T_b_from_a, double *rms_px,
                                        double *own_rms_px, double *pair_rms, int *pair_used,
                                        hearth_err *err) {
  return calib_stereo_joint_times(cam_a, cam_b, obj, n_pts, img_a, img_b, n_pairs, img_c, n_c, o,
                                  T_b_from_a, rms_px, own_rms_px, pair_rms, pair_used, NULL, NULL,
                                  NULL, err);
}
