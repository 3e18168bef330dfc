/* The similarity between two pose sets from their camera centres (Horn's
 * quaternion form of the closed-form least-squares fit, which gives the same
 * rotation as Umeyama's SVD form), and the pose errors left after it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/recon.h"

/* eigen-decomposition of the symmetric n x n matrix a (n <= 4, row-major,
 * destroyed) by cyclic Jacobi rotations: eigenvalues in w, eigenvectors in
 * the columns of v */
static void jacobi_eigen(int n, double *a, double *w, double *v) {
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) v[i * n + j] = i == j;
  for (int sweep = 0; sweep < 64; sweep++) {
    double off = 0, diag = 0;
    for (int i = 0; i < n; i++) {
      diag += a[i * n + i] * a[i * n + i];
      for (int j = i + 1; j < n; j++) off += a[i * n + j] * a[i * n + j];
    }
    if (off <= 1e-30 * (diag + 1e-300)) break;
    for (int p = 0; p < n; p++)
      for (int q = p + 1; q < n; q++) {
        double apq = a[p * n + q];
        if (apq == 0) continue;
        double theta = (a[q * n + q] - a[p * n + p]) / (2 * apq);
        double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
        double c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < n; k++) {
          double akp = a[k * n + p], akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (int k = 0; k < n; k++) {
          double apk = a[p * n + k], aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < n; k++) {
          double vkp = v[k * n + p], vkq = v[k * n + q];
          v[k * n + p] = c * vkp - s * vkq;
          v[k * n + q] = s * vkp + c * vkq;
        }
      }
  }
  for (int i = 0; i < n; i++) w[i] = a[i * n + i];
}

static int cmp_double(const void *pa, const void *pb) {
  double a = *(const double *)pa, b = *(const double *)pb;
  return (a > b) - (a < b);
}

static double median_sorted(const double *x, size_t n) {
  return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

hearth_status hearth_poses_align(const hearth_poses *est, const hearth_poses *ref,
                                 hearth_pose_alignment *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  size_t n = 0;
  const hearth_view_pose **pe = hearth_alloc_array(est->n ? est->n : 1, sizeof *pe);
  const hearth_view_pose **pr = hearth_alloc_array(est->n ? est->n : 1, sizeof *pr);
  double *rot = hearth_alloc_array(est->n ? est->n : 1, sizeof *rot);
  double *pos = hearth_alloc_array(est->n ? est->n : 1, sizeof *pos);
  hearth_status s = HEARTH_OK;
  if (!pe || !pr || !rot || !pos) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "out of memory aligning %zu poses", est->n);
    goto done;
  }
  for (size_t i = 0; i < est->n; i++) {
    const hearth_view_pose *r = hearth_poses_find(ref, est->views[i].state, est->views[i].view);
    if (r) {
      pe[n] = &est->views[i];
      pr[n] = r;
      n++;
    }
  }
  out->n_common = n;
  if (n < 3) {
    s = hearth_err_set(err, HEARTH_E_NUMERIC, "%zu views in common, at least 3 are needed", n);
    goto done;
  }
  double me[3] = {0}, mr[3] = {0};
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      me[k] += pe[i]->T_world_from_cam.t[k] / (double)n;
      mr[k] += pr[i]->T_world_from_cam.t[k] / (double)n;
    }
  /* M = sum (e - me)(r - mr)^T, and the spread of the estimated centres */
  double M[9] = {0}, C[9] = {0}, var_e = 0;
  for (size_t i = 0; i < n; i++) {
    double e[3], r[3];
    for (int k = 0; k < 3; k++) {
      e[k] = pe[i]->T_world_from_cam.t[k] - me[k];
      r[k] = pr[i]->T_world_from_cam.t[k] - mr[k];
    }
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) {
        M[a * 3 + b] += e[a] * r[b];
        C[a * 3 + b] += e[a] * e[b];
      }
    var_e += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
  }
  double cw[3], cv[9];
  jacobi_eigen(3, C, cw, cv);
  qsort(cw, 3, sizeof *cw, cmp_double);
  if (!(var_e > 0) || !(cw[1] > 1e-12 * cw[2])) {
    s = hearth_err_set(err, HEARTH_E_NUMERIC,
                       "the %zu common camera centres lie on one line or point; the rotation is "
                       "not determined",
                       n);
    goto done;
  }
  /* Horn: the unit quaternion maximising r . R e is the top eigenvector of N */
  double Sxx = M[0], Sxy = M[1], Sxz = M[2], Syx = M[3], Syy = M[4], Syz = M[5], Szx = M[6],
         Szy = M[7], Szz = M[8];
  double N[16] = {Sxx + Syy + Szz, Syz - Szy,       Szx - Sxz,        Sxy - Syx,
                  Syz - Szy,       Sxx - Syy - Szz, Sxy + Syx,        Szx + Sxz,
                  Szx - Sxz,       Sxy + Syx,       -Sxx + Syy - Szz, Syz + Szy,
                  Sxy - Syx,       Szx + Sxz,       Syz + Szy,        -Sxx - Syy + Szz};
  double nw[4], nv[16];
  jacobi_eigen(4, N, nw, nv);
  int top = 0;
  for (int i = 1; i < 4; i++)
    if (nw[i] > nw[top]) top = i;
  double q0 = nv[0 * 4 + top], q1 = nv[1 * 4 + top], q2 = nv[2 * 4 + top], q3 = nv[3 * 4 + top];
  double qn = sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
  q0 /= qn, q1 /= qn, q2 /= qn, q3 /= qn;
  hearth_similarity *S = &out->ref_from_est;
  double *R = S->T.R;
  R[0] = q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3;
  R[1] = 2 * (q1 * q2 - q0 * q3);
  R[2] = 2 * (q1 * q3 + q0 * q2);
  R[3] = 2 * (q1 * q2 + q0 * q3);
  R[4] = q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3;
  R[5] = 2 * (q2 * q3 - q0 * q1);
  R[6] = 2 * (q1 * q3 - q0 * q2);
  R[7] = 2 * (q2 * q3 + q0 * q1);
  R[8] = q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3;
  /* s = sum r . R e / sum |e|^2 = trace(R M) / var_e */
  double tr = 0;
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++) tr += R[a * 3 + b] * M[b * 3 + a];
  S->s = tr / var_e;
  double Rme[3];
  hearth_rigid_rotate(&S->T, me, Rme);
  for (int k = 0; k < 3; k++) S->T.t[k] = mr[k] - S->s * Rme[k];
  double sum2 = 0;
  for (size_t i = 0; i < n; i++) {
    double c[3], Ra[9];
    hearth_rigid_rotate(&S->T, pe[i]->T_world_from_cam.t, c);
    double d2 = 0;
    for (int k = 0; k < 3; k++) {
      double d = S->s * c[k] + S->T.t[k] - pr[i]->T_world_from_cam.t[k];
      d2 += d * d;
    }
    pos[i] = sqrt(d2);
    sum2 += d2;
    hearth_mat3_mul(R, pe[i]->T_world_from_cam.R, Ra);
    rot[i] = hearth_rotation_angle_between(Ra, pr[i]->T_world_from_cam.R) * 180.0 / M_PI;
  }
  qsort(rot, n, sizeof *rot, cmp_double);
  qsort(pos, n, sizeof *pos, cmp_double);
  out->rot_median_deg = median_sorted(rot, n);
  out->rot_max_deg = rot[n - 1];
  out->pos_median = median_sorted(pos, n);
  out->pos_max = pos[n - 1];
  out->pos_rms = sqrt(sum2 / (double)n);
done:
  free(pe);
  free(pr);
  free(rot);
  free(pos);
  return s;
}
