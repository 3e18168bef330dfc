/* Stereo calibration with both intrinsics fixed: the rigid T_b_from_a and
 * the plate pose of every pair in camera a, refined jointly by
 * Levenberg-Marquardt over the reprojection errors in both cameras (Schur
 * complement on the per-pair blocks), with outlier pairs dropped. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

typedef struct stereo_prob {
  const hearth_camera *ca, *cb;
  const double (*obj)[3];
  size_t n_pts, n_pairs;
  const double *img_a, *img_b;
  const int *used;
} stereo_prob;

/* squared error of pair i (both cameras); INFINITY if behind a camera */
static double pair_cost(const stereo_prob *P, size_t i, const hearth_rigid *Tba,
                        const double p[6]) {
  hearth_rigid Ta;
  calib_rigid_from_params(p, &Ta);
  double s = 0;
  for (size_t j = 0; j < P->n_pts; j++) {
    double Xa[3], Xb[3], uv[2];
    hearth_rigid_apply(&Ta, P->obj[j], Xa);
    if (!hearth_camera_project(P->ca, Xa, uv, NULL)) return INFINITY;
    const double *m = P->img_a + 2 * (i * P->n_pts + j);
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
    double c = P->used[i] || per_pair ? pair_cost(P, i, &Tba, poses + 6 * i) : 0.0;
    if (per_pair) per_pair[i] = c;
    if (P->used[i]) s += c;
  }
  return s;
}

/* normal equations: U (T block), V_i, W_i (T rows x pose cols), g = -J^T r */
static int stereo_normal(const stereo_prob *P, const double pT[6], const double *poses,
                         double U[36], double gT[6], double *V, double *W, double *gp) {
  double RT[9], dRT[27];
  hearth_rotvec_to_matrix_jac(pT, RT, dRT);
  memset(U, 0, sizeof(double) * 36);
  memset(gT, 0, sizeof(double) * 6);
  for (size_t i = 0; i < P->n_pairs; i++) {
    double *Vi = V + 36 * i, *Wi = W + 36 * i, *g = gp + 6 * i;
    memset(Vi, 0, sizeof(double) * 36);
    memset(Wi, 0, sizeof(double) * 36);
    memset(g, 0, sizeof(double) * 6);
    if (!P->used[i]) continue;
    const double *p = poses + 6 * i;
    double R[9], dR[27];
    hearth_rotvec_to_matrix_jac(p, R, dR);
    for (size_t j = 0; j < P->n_pts; j++) {
      const double *X = P->obj[j];
      double uv[2], dp[12], Xa[3];
      hearth_project_jac jac;
      /* camera a: depends on the pair pose only */
      if (!calib_project_pose(P->ca, R, dR, p + 3, X, uv, &jac, dp, Xa)) return 0;
      const double *m = P->img_a + 2 * (i * P->n_pts + j);
      double r[2] = {uv[0] - m[0], uv[1] - m[1]};
      for (int row = 0; row < 2; row++)
        for (int a = 0; a < 6; a++) {
          for (int b = 0; b < 6; b++) Vi[a * 6 + b] += dp[6 * row + a] * dp[6 * row + b];
          g[a] -= dp[6 * row + a] * r[row];
        }
      /* camera b: Xb = RT Xa + tT */
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
        const double *D = dR + 9 * k;
        double gk[3];
        for (int q = 0; q < 3; q++)
          gk[q] = D[3 * q] * X[0] + D[3 * q + 1] * X[1] + D[3 * q + 2] * X[2];
        for (int row = 0; row < 2; row++) {
          jp[6 * row + k] = JR[3 * row] * gk[0] + JR[3 * row + 1] * gk[1] + JR[3 * row + 2] * gk[2];
          jp[6 * row + 3 + k] = JR[3 * row + k];
        }
      }
      for (int row = 0; row < 2; row++)
        for (int a = 0; a < 6; a++) {
          for (int b = 0; b < 6; b++) {
            U[a * 6 + b] += jT[6 * row + a] * jT[6 * row + b];
            Vi[a * 6 + b] += jp[6 * row + a] * jp[6 * row + b];
            Wi[a * 6 + b] += jT[6 * row + a] * jp[6 * row + b];
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
  size_t n = P->n_pairs;
  double *V = scratch, *Vi = V + 36 * n, *W = Vi + 36 * n, *gp = W + 36 * n, *trial = gp + 6 * n;
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
        double *Vd = Vi + 36 * i;
        memcpy(Vd, V + 36 * i, sizeof(double) * 36);
        for (int a = 0; a < 6; a++) Vd[a * 6 + a] *= 1.0 + lambda;
        if (!calib_chol_invert(Vd, 6)) {
          ok = 0;
          break;
        }
        const double *Wi = W + 36 * i;
        double WV[36];
        for (int a = 0; a < 6; a++)
          for (int b = 0; b < 6; b++) {
            double s = 0;
            for (int k = 0; k < 6; k++) s += Wi[a * 6 + k] * Vd[k * 6 + b];
            WV[a * 6 + b] = s;
          }
        for (int a = 0; a < 6; a++) {
          for (int b = 0; b < 6; b++) {
            double s = 0;
            for (int k = 0; k < 6; k++) s += WV[a * 6 + k] * Wi[b * 6 + k];
            S[a * 6 + b] -= s;
          }
          double s = 0;
          for (int k = 0; k < 6; k++) s += WV[a * 6 + k] * gp[6 * i + k];
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
      memcpy(trial, poses, sizeof(double) * 6 * n);
      for (size_t i = 0; i < n; i++) {
        if (!P->used[i]) continue;
        const double *Vd = Vi + 36 * i, *Wi = W + 36 * i;
        double r6[6];
        for (int b = 0; b < 6; b++) {
          double s = gp[6 * i + b];
          for (int a = 0; a < 6; a++) s -= Wi[a * 6 + b] * rhs[a];
          r6[b] = s;
        }
        for (int a = 0; a < 6; a++) {
          double s = 0;
          for (int b = 0; b < 6; b++) s += Vd[a * 6 + b] * r6[b];
          trial[6 * i + a] += s;
        }
      }
      double cn = total_cost(P, pTn, trial, NULL);
      if (cn < cost) {
        double rel = (cost - cn) / (cost > 0 ? cost : 1);
        memcpy(pT, pTn, sizeof(double) * 6);
        memcpy(poses, trial, sizeof(double) * 6 * n);
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
  double *scratch = hearth_alloc_array(6 * 36 * n_pairs + 12 * n_pairs, sizeof(double));
  double *rel = hearth_alloc_array(6 * n_pairs, sizeof(double));
  double *tmp = hearth_alloc_array(n_pairs, sizeof(double));
  double *pc = hearth_alloc_array(n_pairs, sizeof(double));
  int *used = hearth_calloc_array(n_pairs, sizeof(int));
  if (!poses || !scratch || !rel || !tmp || !pc || !used) {
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
    used[i] = 1;
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
  stereo_prob P = {cam_a, cam_b, obj, n_pts, n_pairs, img_a, img_b, used};
  /* solve, drop outlier pairs, solve again until stable */
  for (int round = 0; round < 5; round++) {
    if (!stereo_lm(&P, pT, poses, o->max_iterations, scratch)) {
      st = hearth_err_set(err, HEARTH_E_NUMERIC, "stereo calibration: did not converge");
      goto done;
    }
    total_cost(&P, pT, poses, pc);
    size_t m = 0;
    for (size_t i = 0; i < n_pairs; i++)
      if (used[i]) tmp[m++] = sqrt(pc[i] / (2.0 * (double)n_pts));
    qsort(tmp, m, sizeof(double), cmp_double);
    double med = m % 2 ? tmp[m / 2] : 0.5 * (tmp[m / 2 - 1] + tmp[m / 2]);
    double lim = o->outlier_factor * med;
    if (lim < o->outlier_min_px) lim = o->outlier_min_px;
    int dropped = 0;
    for (size_t i = 0; i < n_pairs; i++)
      if (used[i] && sqrt(pc[i] / (2.0 * (double)n_pts)) > lim && m - (size_t)dropped > 1) {
        used[i] = 0;
        dropped++;
      }
    if (!dropped) break;
  }
  calib_rigid_from_params(pT, T_b_from_a);
  total_cost(&P, pT, poses, pc);
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
  free(scratch);
  free(rel);
  free(tmp);
  free(pc);
  free(used);
  return st;
}
