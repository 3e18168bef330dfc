/* Stereo calibration with both intrinsics fixed: the rigid T_b_from_a and
 * the plate pose of every pair in camera a, refined jointly by
 * Levenberg-Marquardt over the reprojection errors in both cameras (Schur
 * complement on the per-pair blocks), with outlier pairs dropped. With
 * opts->rolling_shutter, camera a may read its rows in turn while the plate
 * moves: each pair then also has a plate velocity in camera a (a twist per
 * frame readout, first order in the row's time), kept only when it explains
 * more than 6 free parameters per pair would fit of noise. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

/* the largest per-pair block: pose (rotation vector, translation), then the
 * plate's velocity in camera a (angular, linear; per frame readout) */
#define NQ_MAX 12

typedef struct stereo_prob {
  const hearth_camera *ca, *cb;
  const double (*obj)[3];
  size_t n_pts, n_pairs;
  const double *img_a, *img_b;
  const int *used;
  int nq; /* parameters per pair: 6 (rigid pose) or 12 (pose and velocity) */
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

/* squared error of pair i (both cameras); INFINITY if behind a camera */
static double pair_cost(const stereo_prob *P, size_t i, const hearth_rigid *Tba, const double *p) {
  hearth_rigid Ta;
  calib_rigid_from_params(p, &Ta);
  double s = 0;
  for (size_t j = 0; j < P->n_pts; j++) {
    double Xa[3], Xb[3], uv[2];
    hearth_rigid_apply(&Ta, P->obj[j], Xa);
    const double *m = P->img_a + 2 * (i * P->n_pts + j);
    if (P->nq > 6) {
      double Xm[3];
      rs_move(p + 6, row_time(P->ca, m[1]), Xa, Xm);
      if (!hearth_camera_project(P->ca, Xm, uv, NULL)) return INFINITY;
    } else if (!hearth_camera_project(P->ca, Xa, uv, NULL)) {
      return INFINITY;
    }
    s += (uv[0] - m[0]) * (uv[0] - m[0]) + (uv[1] - m[1]) * (uv[1] - m[1]);
    hearth_rigid_apply(Tba, Xa, Xb);
    if (!hearth_camera_project(P->cb, Xb, uv, NULL)) return INFINITY;
    m = P->img_b + 2 * (i * P->n_pts + j);
    s += (uv[0] - m[0]) * (uv[0] - m[0]) + (uv[1] - m[1]) * (uv[1] - m[1]);
  }
  return s;
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

/* camera a's residual and its 2 x 12 Jacobian (pose, then velocity) with
 * the velocity q; returns 0 if behind the camera */
static int project_moving(const hearth_camera *ca, const double R[9], const double dR[27],
                          const double t[3], const double q[6], double s, const double X[3],
                          double uv[2], double dp[24]) {
  double Xa[3], Xm[3];
  for (int k = 0; k < 3; k++)
    Xa[k] = R[3 * k] * X[0] + R[3 * k + 1] * X[1] + R[3 * k + 2] * X[2] + t[k];
  rs_move(q, s, Xa, Xm);
  hearth_project_jac jac;
  if (!hearth_camera_project(ca, Xm, uv, &jac)) return 0;
  const double *J = jac.d_point, *w = q;
  /* d Xm / d Xa = I + s [w]x */
  const double A[9] = {1, -s * w[2], s * w[1], s * w[2], 1, -s * w[0], -s * w[1], s * w[0], 1};
  /* d Xm / d w = -s [Xa]x */
  const double B[9] = {0,         s * Xa[2], -s * Xa[1], -s * Xa[2], 0,
                       s * Xa[0], s * Xa[1], -s * Xa[0], 0};
  for (int row = 0; row < 2; row++) {
    const double *Jr = J + 3 * row;
    double JA[3], *d = dp + 12 * row;
    for (int k = 0; k < 3; k++) JA[k] = Jr[0] * A[k] + Jr[1] * A[3 + k] + Jr[2] * A[6 + k];
    for (int k = 0; k < 3; k++) {
      const double *D = dR + 9 * k;
      double gk[3];
      for (int c = 0; c < 3; c++)
        gk[c] = D[3 * c] * X[0] + D[3 * c + 1] * X[1] + D[3 * c + 2] * X[2];
      d[k] = JA[0] * gk[0] + JA[1] * gk[1] + JA[2] * gk[2];
      d[3 + k] = JA[k];
      d[6 + k] = Jr[0] * B[k] + Jr[1] * B[3 + k] + Jr[2] * B[6 + k];
      d[9 + k] = s * Jr[k];
    }
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
      const double *X = P->obj[j];
      double uv[2], dp[24], Xa[3];
      hearth_project_jac jac;
      const double *m = P->img_a + 2 * (i * P->n_pts + j);
      /* camera a: depends on the pair's own parameters only */
      if (D > 6) {
        if (!project_moving(P->ca, R, dR, p + 3, p + 6, row_time(P->ca, m[1]), X, uv, dp)) return 0;
        for (int k = 0; k < 3; k++)
          Xa[k] = R[3 * k] * X[0] + R[3 * k + 1] * X[1] + R[3 * k + 2] * X[2] + p[3 + k];
      } else if (!calib_project_pose(P->ca, R, dR, p + 3, X, uv, &jac, dp, Xa)) {
        return 0;
      }
      double r[2] = {uv[0] - m[0], uv[1] - m[1]};
      for (int row = 0; row < 2; row++)
        for (int a = 0; a < D; a++) {
          for (int b = 0; b < D; b++) Vi[a * D + b] += dp[D * row + a] * dp[D * row + b];
          g[a] -= dp[D * row + a] * r[row];
        }
      /* camera b: Xb = RT Xa + tT (the pose's time) */
      double jT[12], jp[12];
      if (!calib_project_pose(P->cb, RT, dRT, pT + 3, Xa, uv, &jac, jT, NULL)) return 0;
      m = P->img_b + 2 * (i * P->n_pts + j);
      r[0] = uv[0] - m[0];
      r[1] = uv[1] - m[1];
      /* d uv_b / d pose = J_b RT [dR X | I] */
      double JR[6];
      for (int row = 0; row < 2; row++)
        for (int k = 0; k < 3; k++)
          JR[3 * row + k] = jac.d_point[3 * row] * RT[k] + jac.d_point[3 * row + 1] * RT[3 + k] +
                            jac.d_point[3 * row + 2] * RT[6 + k];
      for (int k = 0; k < 3; k++) {
        const double *Dk = dR + 9 * k;
        double gk[3];
        for (int q = 0; q < 3; q++)
          gk[q] = Dk[3 * q] * X[0] + Dk[3 * q + 1] * X[1] + Dk[3 * q + 2] * X[2];
        for (int row = 0; row < 2; row++) {
          jp[6 * row + k] = JR[3 * row] * gk[0] + JR[3 * row + 1] * gk[1] + JR[3 * row + 2] * gk[2];
          jp[6 * row + 3 + k] = JR[3 * row + k];
        }
      }
      for (int row = 0; row < 2; row++)
        for (int a = 0; a < 6; a++) {
          for (int b = 0; b < 6; b++) {
            U[a * 6 + b] += jT[6 * row + a] * jT[6 * row + b];
            Vi[a * D + b] += jp[6 * row + a] * jp[6 * row + b];
            Wi[a * D + b] += jT[6 * row + a] * jp[6 * row + b];
          }
          gT[a] -= jT[6 * row + a] * r[row];
          g[a] -= jp[6 * row + a] * r[row];
        }
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
      double cn = total_cost(P, pTn, trial, NULL);
      if (cn < cost) {
        double rel = (cost - cn) / (cost > 0 ? cost : 1);
        memcpy(pT, pTn, sizeof(double) * 6);
        memcpy(poses, trial, sizeof(double) * D * n);
        cost = cn;
        lambda = lambda / 10 > 1e-12 ? lambda / 10 : 1e-12;
        improved = 1;
        if (rel < 1e-14) it = max_it;
      } else {
        lambda *= 10;
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
 * (pT, poses, used): kept when the velocities lower the cost by more than
 * twice what 6 parameters per pair would take off pure noise (the expected
 * drop is 6 sigma^2 per pair); then solved again, with the outlier rule,
 * from every pair with a pose start (with_pose). On success pT, poses
 * (12 per pair) and used hold that solution and *moving is 1. */
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
  double dof = 4.0 * (double)(m * P0->n_pts) - 6.0 - 12.0 * (double)m;
  if (!(dof > 0 && isfinite(c1)) || c0 - c1 <= 2.0 * 6.0 * (double)m * c1 / dof) return 1;
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

hearth_status hearth_calib_stereo(const hearth_camera *cam_a, const hearth_camera *cam_b,
                                  const double (*obj)[3], size_t n_pts, const double *img_a,
                                  const double *img_b, size_t n_pairs, const hearth_calib_opts *o,
                                  hearth_rigid *T_b_from_a, double *rms_px, double *pair_rms,
                                  int *pair_used, hearth_err *err) {
  hearth_calib_opts def;
  if (!o) {
    hearth_calib_opts_default(&def);
    o = &def;
  }
  if (!cam_a || !cam_b || !obj || !img_a || !img_b || !T_b_from_a)
    return hearth_err_set(err, HEARTH_E_ARG, "stereo calibration: missing argument");
  if (n_pairs < 1)
    return hearth_err_set(err, HEARTH_E_SIZE, "stereo calibration: no usable stereo pairs");
  if (n_pts < 4 || n_pts > 100000 || n_pairs > 100000)
    return hearth_err_set(err, HEARTH_E_SIZE, "stereo calibration: %zu points per pair", n_pts);
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
  const double *sol = poses;
  if (moving) {
    P.nq = NQ_MAX;
    sol = poses_m;
  }
  calib_rigid_from_params(pT, T_b_from_a);
  total_cost(&P, pT, sol, pc);
  double sum = 0;
  size_t m = 0;
  for (size_t i = 0; i < n_pairs; i++) {
    /* a pair without a pose start has no meaningful residual */
    double r = isfinite(pc[i]) ? sqrt(pc[i] / (2.0 * (double)n_pts)) : NAN;
    if (pair_rms) pair_rms[i] = r;
    if (pair_used) pair_used[i] = used[i];
    if (used[i]) {
      sum += pc[i];
      m++;
    }
  }
  if (rms_px) *rms_px = sqrt(sum / (2.0 * (double)(m * n_pts)));
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
