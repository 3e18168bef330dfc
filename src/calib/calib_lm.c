/* Levenberg-Marquardt for single-camera calibration: intrinsics (fx, fy,
 * cx, cy), 5- or 8-parameter distortion and one pose per frame, solved
 * through the Schur complement of the per-frame pose blocks (9 x 9 or
 * 12 x 12 reduced system), and the 6-parameter pose of a plate seen by a
 * calibrated camera. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

void hearth_calib_opts_default(hearth_calib_opts *o) {
  memset(o, 0, sizeof *o);
  o->max_iterations = 100;
  o->outlier_factor = 2.5;
  o->outlier_min_px = 0.01;
  o->perspective_correction = 1;
  o->wall_correction = 1;
  o->hole_radius_m = 0.004;
  o->rolling_shutter = 1;
  o->stereo_intrinsics = 1;
  o->target_sigma_m = 4e-5;
}

#define NI_MAX 12 /* fx fy cx cy k1 k2 p1 p2 k3 [k4 k5 k6] */

/* base carries the size and the lens model (how many of q are distortion) */
static void cam_from_params(const hearth_camera *base, const double *q, hearth_camera *c) {
  *c = *base;
  c->fx = q[0];
  c->fy = q[1];
  c->cx = q[2];
  c->cy = q[3];
  for (int k = 0; k < hearth_lens_n_coeffs(base->model); k++) c->dist[k] = q[4 + k];
}

/* sum of squared residuals; per-frame sums into fsum if non-NULL; returns
 * INFINITY when a point falls behind the camera */
static double intr_cost(const hearth_camera *cam, const double (*obj)[3], size_t n_pts,
                        const double *img, size_t n_frames, const double *poses, double *fsum) {
  double total = 0;
  for (size_t f = 0; f < n_frames; f++) {
    hearth_rigid T;
    calib_rigid_from_params(poses + 6 * f, &T);
    double s = 0;
    for (size_t j = 0; j < n_pts; j++) {
      double Xc[3], uv[2];
      hearth_rigid_apply(&T, obj[j], Xc);
      if (!hearth_camera_project(cam, Xc, uv, NULL)) return INFINITY;
      const double *m = img + 2 * (f * n_pts + j);
      double du = uv[0] - m[0], dv = uv[1] - m[1];
      s += du * du + dv * dv;
    }
    if (fsum) fsum[f] = s;
    total += s;
  }
  return isfinite(total) ? total : INFINITY;
}

/* accumulate the normal equations: U (NI x NI), V (6x6 per frame),
 * W (NI x 6 per frame), gi (NI), gf (6 per frame); g = -J^T r; NI = 4 +
 * the model's coefficients */
static int intr_normal(const hearth_camera *cam, const double (*obj)[3], size_t n_pts,
                       const double *img, size_t n_frames, const double *poses, double *U,
                       double *V, double *W, double *gi, double *gf) {
  const int NI = 4 + hearth_lens_n_coeffs(cam->model);
  memset(U, 0, sizeof(double) * NI * NI);
  memset(gi, 0, sizeof(double) * NI);
  for (size_t f = 0; f < n_frames; f++) {
    double R[9], dR[27];
    const double *p = poses + 6 * f;
    hearth_rotvec_to_matrix_jac(p, R, dR);
    double *Vf = V + 36 * f, *Wf = W + NI_MAX * 6 * f, *g = gf + 6 * f;
    memset(Vf, 0, sizeof(double) * 36);
    memset(Wf, 0, sizeof(double) * NI * 6);
    memset(g, 0, sizeof(double) * 6);
    for (size_t j = 0; j < n_pts; j++) {
      double uv[2], dp[12];
      hearth_project_jac jac;
      if (!calib_project_pose(cam, R, dR, p + 3, obj[j], uv, &jac, dp, NULL)) return 0;
      const double *m = img + 2 * (f * n_pts + j);
      double r[2] = {uv[0] - m[0], uv[1] - m[1]};
      for (int row = 0; row < 2; row++) {
        double ji[NI_MAX];
        ji[0] = jac.d_intr[4 * row + 0];
        ji[1] = jac.d_intr[4 * row + 1];
        ji[2] = jac.d_intr[4 * row + 2];
        ji[3] = jac.d_intr[4 * row + 3];
        for (int k = 0; k < 5; k++) ji[4 + k] = jac.d_dist[5 * row + k];
        for (int k = 9; k < NI; k++) ji[k] = jac.d_rat[3 * row + k - 9];
        const double *jp = dp + 6 * row;
        for (int a = 0; a < NI; a++) {
          for (int b = a; b < NI; b++) U[a * NI + b] += ji[a] * ji[b];
          for (int b = 0; b < 6; b++) Wf[a * 6 + b] += ji[a] * jp[b];
          gi[a] -= ji[a] * r[row];
        }
        for (int a = 0; a < 6; a++) {
          for (int b = a; b < 6; b++) Vf[a * 6 + b] += jp[a] * jp[b];
          g[a] -= jp[a] * r[row];
        }
      }
    }
    for (int a = 0; a < 6; a++)
      for (int b = 0; b < a; b++) Vf[a * 6 + b] = Vf[b * 6 + a];
  }
  for (int a = 0; a < NI; a++)
    for (int b = 0; b < a; b++) U[a * NI + b] = U[b * NI + a];
  return 1;
}

hearth_status hearth_calib_intrinsics(const double (*obj)[3], size_t n_pts, const double *img,
                                      size_t n_frames, int width, int height,
                                      const hearth_calib_opts *o, hearth_camera *cam,
                                      double *rms_px, double *frame_rms,
                                      hearth_rigid *T_cam_from_plate, hearth_err *err) {
  hearth_calib_opts def;
  if (!o) {
    hearth_calib_opts_default(&def);
    o = &def;
  }
  if (!obj || !img || !cam || width <= 0 || height <= 0)
    return hearth_err_set(err, HEARTH_E_ARG, "intrinsic calibration: missing argument");
  if (n_frames < 3)
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "intrinsic calibration: %zu usable frames, at least 3 needed", n_frames);
  if (n_pts < 6 || n_pts > 100000)
    return hearth_err_set(err, HEARTH_E_SIZE, "intrinsic calibration: %zu points per frame", n_pts);
  for (size_t j = 0; j < n_pts; j++)
    if (obj[j][2] != 0.0)
      return hearth_err_set(err, HEARTH_E_ARG, "intrinsic calibration: object point %zu off z = 0",
                            j);
  hearth_status st = HEARTH_OK;
  double *H = hearth_alloc_array(9 * n_frames, sizeof(double));
  double *poses = hearth_alloc_array(6 * n_frames, sizeof(double));
  double *trial = hearth_alloc_array(6 * n_frames, sizeof(double));
  double *V = hearth_alloc_array(36 * n_frames, sizeof(double));
  double *Vi = hearth_alloc_array(36 * n_frames, sizeof(double));
  double *W = hearth_alloc_array(NI_MAX * 6 * n_frames, sizeof(double));
  double *gf = hearth_alloc_array(6 * n_frames, sizeof(double));
  double *fsum = hearth_alloc_array(n_frames, sizeof(double));
  double *plane = hearth_alloc_array(2 * n_pts, sizeof(double));
  if (!H || !poses || !trial || !V || !Vi || !W || !gf || !fsum || !plane) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "intrinsic calibration: out of memory");
    goto done;
  }
  for (size_t j = 0; j < n_pts; j++) {
    plane[2 * j] = obj[j][0];
    plane[2 * j + 1] = obj[j][1];
  }
  /* closed-form start */
  for (size_t f = 0; f < n_frames; f++)
    if (!calib_homography(plane, img + 2 * f * n_pts, n_pts, H + 9 * f)) {
      st = hearth_err_set(err, HEARTH_E_NUMERIC,
                          "intrinsic calibration: frame %zu: degenerate homography", f);
      goto done;
    }
  double fx, fy, cx, cy;
  if (!calib_zhang_intrinsics(H, n_frames, &fx, &fy, &cx, &cy)) {
    st = hearth_err_set(err, HEARTH_E_NUMERIC,
                        "intrinsic calibration: Zhang's closed form is degenerate (views too "
                        "similar or too few tilted views)");
    goto done;
  }
  double Kinv[9] = {1 / fx, 0, -cx / fx, 0, 1 / fy, -cy / fy, 0, 0, 1};
  for (size_t f = 0; f < n_frames; f++) {
    double Hn[9];
    hearth_rigid T;
    hearth_mat3_mul(Kinv, H + 9 * f, Hn);
    if (!calib_pose_from_homography(Hn, &T)) {
      st = hearth_err_set(err, HEARTH_E_NUMERIC, "intrinsic calibration: frame %zu: no pose", f);
      goto done;
    }
    calib_params_from_rigid(&T, poses + 6 * f);
  }
  double q[NI_MAX] = {fx, fy, cx, cy, 0, 0, 0, 0, 0, 0, 0, 0};
  hearth_camera base;
  memset(&base, 0, sizeof base);
  base.width = width;
  base.height = height;
  const int NI = o->lens_model == HEARTH_LENS_RATIONAL8 ? 12 : 9;
  if (NI == 12) {
    /* the rational model starts from the 5-parameter solution (its
     * k1 k2 p1 p2 k3, k4 k5 k6 = 0: the same lens) */
    hearth_calib_opts o5 = *o;
    o5.lens_model = HEARTH_LENS_BROWN5;
    hearth_camera c5;
    hearth_rigid *T5 = hearth_alloc_array(n_frames, sizeof(hearth_rigid));
    if (!T5) {
      st = hearth_err_set(err, HEARTH_E_NOMEM, "intrinsic calibration: out of memory");
      goto done;
    }
    st = hearth_calib_intrinsics(obj, n_pts, img, n_frames, width, height, &o5, &c5, NULL, NULL, T5,
                                 err);
    for (size_t f = 0; !st && f < n_frames; f++) calib_params_from_rigid(&T5[f], poses + 6 * f);
    free(T5);
    if (st) goto done;
    q[0] = c5.fx;
    q[1] = c5.fy;
    q[2] = c5.cx;
    q[3] = c5.cy;
    for (int k = 0; k < 5; k++) q[4 + k] = c5.dist[k];
    base.model = HEARTH_LENS_RATIONAL8;
  }
  hearth_camera c;
  cam_from_params(&base, q, &c);
  double cost = intr_cost(&c, obj, n_pts, img, n_frames, poses, NULL);
  if (!isfinite(cost)) {
    st = hearth_err_set(err, HEARTH_E_NUMERIC,
                        "intrinsic calibration: initial poses put points behind the camera");
    goto done;
  }
  /* Levenberg-Marquardt with Marquardt's diagonal scaling */
  double lambda = 1e-3;
  for (int it = 0; it < o->max_iterations; it++) {
    double U[NI_MAX * NI_MAX], gi[NI_MAX];
    if (!intr_normal(&c, obj, n_pts, img, n_frames, poses, U, V, W, gi, gf)) {
      st = hearth_err_set(err, HEARTH_E_NUMERIC, "intrinsic calibration: point behind camera");
      goto done;
    }
    int improved = 0;
    for (int tries = 0; tries < 12 && !improved; tries++) {
      double S[NI_MAX * NI_MAX], rhs[NI_MAX];
      memcpy(S, U, sizeof(double) * NI * NI);
      for (int a = 0; a < NI; a++) S[a * NI + a] *= 1.0 + lambda;
      memcpy(rhs, gi, sizeof(double) * NI);
      int ok = 1;
      for (size_t f = 0; f < n_frames && ok; f++) {
        double *Vd = Vi + 36 * f;
        memcpy(Vd, V + 36 * f, sizeof(double) * 36);
        for (int a = 0; a < 6; a++) Vd[a * 6 + a] *= 1.0 + lambda;
        if (!calib_chol_invert(Vd, 6)) {
          ok = 0;
          break;
        }
        /* S -= W Vd^-1 W^T, rhs -= W Vd^-1 gf */
        const double *Wf = W + NI_MAX * 6 * f;
        double WV[NI_MAX * 6];
        for (int a = 0; a < NI; a++)
          for (int b = 0; b < 6; b++) {
            double s = 0;
            for (int k = 0; k < 6; k++) s += Wf[a * 6 + k] * Vd[k * 6 + b];
            WV[a * 6 + b] = s;
          }
        for (int a = 0; a < NI; a++) {
          for (int b = 0; b < NI; b++) {
            double s = 0;
            for (int k = 0; k < 6; k++) s += WV[a * 6 + k] * Wf[b * 6 + k];
            S[a * NI + b] -= s;
          }
          double s = 0;
          for (int k = 0; k < 6; k++) s += WV[a * 6 + k] * gf[6 * f + k];
          rhs[a] -= s;
        }
      }
      if (ok) ok = calib_chol_solve(S, rhs, NI);
      if (!ok) {
        lambda *= 10;
        continue;
      }
      double qn[NI_MAX];
      for (int a = 0; a < NI; a++) qn[a] = q[a] + rhs[a];
      for (size_t f = 0; f < n_frames; f++) {
        const double *Vd = Vi + 36 * f, *Wf = W + NI_MAX * 6 * f;
        double r6[6];
        for (int b = 0; b < 6; b++) {
          double s = gf[6 * f + b];
          for (int a = 0; a < NI; a++) s -= Wf[a * 6 + b] * rhs[a];
          r6[b] = s;
        }
        for (int a = 0; a < 6; a++) {
          double s = 0;
          for (int b = 0; b < 6; b++) s += Vd[a * 6 + b] * r6[b];
          trial[6 * f + a] = poses[6 * f + a] + s;
        }
      }
      hearth_camera cn;
      cam_from_params(&base, qn, &cn);
      double cn_cost = intr_cost(&cn, obj, n_pts, img, n_frames, trial, NULL);
      if (cn_cost < cost) {
        double rel = (cost - cn_cost) / (cost > 0 ? cost : 1);
        memcpy(q, qn, sizeof(double) * NI);
        memcpy(poses, trial, sizeof(double) * 6 * n_frames);
        c = cn;
        cost = cn_cost;
        lambda = lambda / 10 > 1e-12 ? lambda / 10 : 1e-12;
        improved = 1;
        if (rel < 1e-14) it = o->max_iterations; /* converged */
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break; /* no downhill step left: at the minimum to precision */
  }
  if (!(c.fx > 0) || !(c.fy > 0)) {
    st = hearth_err_set(err, HEARTH_E_NUMERIC, "intrinsic calibration: did not converge");
    goto done;
  }
  cost = intr_cost(&c, obj, n_pts, img, n_frames, poses, fsum);
  *cam = c;
  if (rms_px) *rms_px = sqrt(cost / (double)(n_frames * n_pts));
  for (size_t f = 0; f < n_frames; f++) {
    if (frame_rms) frame_rms[f] = sqrt(fsum[f] / (double)n_pts);
    if (T_cam_from_plate) calib_rigid_from_params(poses + 6 * f, &T_cam_from_plate[f]);
  }
done:
  free(H);
  free(poses);
  free(trial);
  free(V);
  free(Vi);
  free(W);
  free(gf);
  free(fsum);
  free(plane);
  return st;
}

/* ---- single pose ------------------------------------------------------------- */
static double pose_cost(const hearth_camera *cam, const double (*obj)[3], size_t n,
                        const double *img, const double p[6]) {
  hearth_rigid T;
  calib_rigid_from_params(p, &T);
  double s = 0;
  for (size_t j = 0; j < n; j++) {
    double Xc[3], uv[2];
    hearth_rigid_apply(&T, obj[j], Xc);
    if (!hearth_camera_project(cam, Xc, uv, NULL)) return INFINITY;
    double du = uv[0] - img[2 * j], dv = uv[1] - img[2 * j + 1];
    s += du * du + dv * dv;
  }
  return s;
}

hearth_status hearth_calib_pose(const hearth_camera *cam, const double (*obj)[3], size_t n_pts,
                                const double *img, hearth_rigid *T_cam_from_plate, double *rms_px,
                                hearth_err *err) {
  if (!cam || !obj || !img || !T_cam_from_plate || n_pts < 4 || n_pts > 100000)
    return hearth_err_set(err, HEARTH_E_ARG, "plate pose: bad arguments");
  double *plane = hearth_alloc_array(4 * n_pts, sizeof(double));
  if (!plane) return hearth_err_set(err, HEARTH_E_NOMEM, "plate pose: out of memory");
  double *norm = plane + 2 * n_pts;
  /* homography plate -> ideal normalised coordinates gives the start, from
   * the points the lens model can undistort */
  size_t k = 0;
  for (size_t j = 0; j < n_pts; j++) {
    double xy[2];
    if (hearth_camera_undistort(cam, img[2 * j], img[2 * j + 1], xy) < 0) continue;
    plane[2 * k] = obj[j][0];
    plane[2 * k + 1] = obj[j][1];
    norm[2 * k] = xy[0];
    norm[2 * k + 1] = xy[1];
    k++;
  }
  double Hn[9];
  hearth_rigid T;
  int ok = k >= 4 && calib_homography(plane, norm, k, Hn) && calib_pose_from_homography(Hn, &T);
  free(plane);
  if (!ok) return hearth_err_set(err, HEARTH_E_NUMERIC, "plate pose: degenerate homography");
  double p[6];
  calib_params_from_rigid(&T, p);
  double cost = pose_cost(cam, obj, n_pts, img, p), lambda = 1e-3;
  if (!isfinite(cost)) return hearth_err_set(err, HEARTH_E_NUMERIC, "plate pose: behind camera");
  for (int it = 0; it < 50; it++) {
    double A[36] = {0}, g[6] = {0}, R[9], dR[27];
    hearth_rotvec_to_matrix_jac(p, R, dR);
    for (size_t j = 0; j < n_pts; j++) {
      double uv[2], dp[12];
      hearth_project_jac jac;
      if (!calib_project_pose(cam, R, dR, p + 3, obj[j], uv, &jac, dp, NULL))
        return hearth_err_set(err, HEARTH_E_NUMERIC, "plate pose: behind camera");
      double r[2] = {uv[0] - img[2 * j], uv[1] - img[2 * j + 1]};
      for (int row = 0; row < 2; row++)
        for (int a = 0; a < 6; a++) {
          for (int b = 0; b < 6; b++) A[a * 6 + b] += dp[6 * row + a] * dp[6 * row + b];
          g[a] -= dp[6 * row + a] * r[row];
        }
    }
    int improved = 0;
    for (int tries = 0; tries < 12 && !improved; tries++) {
      double M[36], d[6], pn[6];
      memcpy(M, A, sizeof M);
      memcpy(d, g, sizeof d);
      for (int a = 0; a < 6; a++) M[a * 6 + a] *= 1.0 + lambda;
      if (!calib_chol_solve(M, d, 6)) {
        lambda *= 10;
        continue;
      }
      for (int a = 0; a < 6; a++) pn[a] = p[a] + d[a];
      double cn = pose_cost(cam, obj, n_pts, img, pn);
      if (cn < cost) {
        double rel = (cost - cn) / (cost > 0 ? cost : 1);
        memcpy(p, pn, sizeof p);
        cost = cn;
        lambda = lambda / 10 > 1e-12 ? lambda / 10 : 1e-12;
        improved = 1;
        if (rel < 1e-14) it = 50;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  calib_rigid_from_params(p, T_cam_from_plate);
  if (rms_px) *rms_px = sqrt(cost / (double)n_pts);
  return HEARTH_OK;
}

/* ---- perspective bias of circle centres -------------------------------------- */
/* The centroid of a hole's image (what detection measures) is not the image
 * of the hole's centre: perspective and distortion move it by up to a few
 * hundredths of a pixel, the same way for every hole of a tilted plate, so
 * it biases the calibration. With a camera and a plate pose, the bias is the
 * area centroid of the projected rim (a fine polygon) minus the projected
 * centre. */
/* clip the convex polygon p (n points, counter-clockwise or clockwise as
 * q) by the half-plane left of (or right of, s = -1) the edge a->b into out;
 * returns the new count */
static int clip_edge(const double (*p)[2], int n, const double a[2], const double b[2], double s,
                     double (*out)[2]) {
  /* each vertex's side once (an edge's far end is the next one's near
     end), with the same arithmetic as per edge */
  double d[256];
  if (n > 256) return 0;
  int inside = 0;
  for (int i = 0; i < n; i++) {
    d[i] = s * ((b[0] - a[0]) * (p[i][1] - a[1]) - (b[1] - a[1]) * (p[i][0] - a[0]));
    inside += d[i] >= 0;
  }
  if (inside == n) {
    /* the edge cuts nothing: the polygon as it is */
    memcpy(out, p, sizeof(double) * 2 * (size_t)n);
    return n;
  }
  int m = 0;
  for (int i = 0; i < n; i++) {
    const double *P = p[i], *Q = p[(i + 1) % n];
    double dp = d[i], dq = d[(i + 1) % n];
    if (dp >= 0) {
      out[m][0] = P[0];
      out[m][1] = P[1];
      m++;
    }
    if ((dp >= 0) != (dq >= 0)) {
      double t = dp / (dp - dq);
      out[m][0] = P[0] + t * (Q[0] - P[0]);
      out[m][1] = P[1] + t * (Q[1] - P[1]);
      m++;
    }
  }
  return m;
}

/* area centroid of the overlap of two convex polygons (relative
 * coordinates), by clipping a with every edge of b; 0 if empty */
static int overlap_centroid(const double (*a)[2], int na, const double (*b)[2], int nb,
                            double c[2]) {
  enum { MAXP = 256 };
  double buf[2][MAXP][2];
  int n = na;
  memcpy(buf[0], a, sizeof(double) * 2 * (size_t)na);
  double orient = 0;
  for (int k = 0; k < nb; k++)
    orient += b[k][0] * b[(k + 1) % nb][1] - b[(k + 1) % nb][0] * b[k][1];
  double s = orient >= 0 ? 1.0 : -1.0;
  int cur = 0;
  for (int k = 0; k < nb && n > 0; k++) {
    if (n + 1 >= MAXP) return 0;
    n = clip_edge((const double(*)[2])buf[cur], n, b[k], b[(k + 1) % nb], s, buf[1 - cur]);
    cur = 1 - cur;
  }
  double A = 0, sx = 0, sy = 0;
  for (int k = 0; k < n; k++) {
    const double *P = buf[cur][k], *Q = buf[cur][(k + 1) % n];
    double cr = P[0] * Q[1] - Q[0] * P[1];
    A += cr;
    sx += (P[0] + Q[0]) * cr;
    sy += (P[1] + Q[1]) * cr;
  }
  if (fabs(A) < 1e-12) return 0;
  c[0] = sx / (3 * A);
  c[1] = sy / (3 * A);
  return 1;
}

void calib_circle_bias(const hearth_camera *cam, const hearth_rigid *T, const double (*obj)[3],
                       size_t n, double radius, double thickness, double *bias) {
  enum { NR = 48 };
  if (thickness > 0) {
    /* the overlap of the front and back openings; finer rims, since the
     * overlap's edge is made of two arcs */
    enum { NW = 96 };
    double cw[NW][2];
    for (int k = 0; k < NW; k++) {
      cw[k][0] = cos(2 * M_PI * k / NW);
      cw[k][1] = sin(2 * M_PI * k / NW);
    }
    for (size_t j = 0; j < n; j++) {
      double f[NW][2], b[NW][2], c[2], Xc[3], z[2];
      int ok = 1;
      hearth_rigid_apply(T, obj[j], Xc);
      ok &= hearth_camera_project(cam, Xc, c, NULL);
      for (int k = 0; k < NW && ok; k++) {
        double P[3] = {obj[j][0] + radius * cw[k][0], obj[j][1] + radius * cw[k][1], obj[j][2]};
        hearth_rigid_apply(T, P, Xc);
        ok &= hearth_camera_project(cam, Xc, f[k], NULL);
        P[2] += thickness;
        hearth_rigid_apply(T, P, Xc);
        ok &= hearth_camera_project(cam, Xc, b[k], NULL);
        f[k][0] -= c[0];
        f[k][1] -= c[1];
        b[k][0] -= c[0];
        b[k][1] -= c[1];
      }
      bias[2 * j] = bias[2 * j + 1] = 0;
      if (!ok || !overlap_centroid((const double(*)[2])f, NW, (const double(*)[2])b, NW, z))
        continue;
      bias[2 * j] = z[0];
      bias[2 * j + 1] = z[1];
    }
    return;
  }
  double cs[NR][2];
  for (int k = 0; k < NR; k++) {
    cs[k][0] = cos(2 * M_PI * k / NR);
    cs[k][1] = sin(2 * M_PI * k / NR);
  }
  for (size_t j = 0; j < n; j++) {
    double uv[NR][2], c[2], Xc[3];
    int ok = 1;
    hearth_rigid_apply(T, obj[j], Xc);
    ok &= hearth_camera_project(cam, Xc, c, NULL);
    for (int k = 0; k < NR && ok; k++) {
      double P[3] = {obj[j][0] + radius * cs[k][0], obj[j][1] + radius * cs[k][1], obj[j][2]};
      hearth_rigid_apply(T, P, Xc);
      ok &= hearth_camera_project(cam, Xc, uv[k], NULL);
    }
    bias[2 * j] = bias[2 * j + 1] = 0;
    if (!ok) continue;
    /* shoelace centroid, relative to the projected centre for precision */
    double A = 0, sx = 0, sy = 0;
    for (int k = 0; k < NR; k++) {
      double x0 = uv[k][0] - c[0], y0 = uv[k][1] - c[1];
      double x1 = uv[(k + 1) % NR][0] - c[0], y1 = uv[(k + 1) % NR][1] - c[1];
      double cr = x0 * y1 - x1 * y0;
      A += cr;
      sx += (x0 + x1) * cr;
      sy += (y0 + y1) * cr;
    }
    if (fabs(A) < 1e-12) continue;
    bias[2 * j] = sx / (3 * A);
    bias[2 * j + 1] = sy / (3 * A);
  }
}
