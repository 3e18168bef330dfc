/* Calibration solvers against known cameras: Zhang's closed form on exact
 * points, the LM Jacobians against finite differences, full intrinsics with
 * noise, and stereo recovering a known transform with an outlier pair and
 * with a rolling-shutter camera a on a moving plate, and the joint solve
 * recovering camera b's intrinsics with the extrinsic. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"
#include "calib_test_data.h"
#include "test_util.h"

#define NP HEARTH_PLATE_HOLES

static void test_zhang_exact(void) {
  /* no distortion: the closed form must be exact */
  hearth_camera c;
  td_thermal_cam(&c);
  for (int k = 0; k < 5; k++) c.dist[k] = 0;
  hearth_rng rng;
  hearth_rng_seed(&rng, 11);
  enum { NV = 8 };
  hearth_rigid T[NV];
  static double uv[NV * NP * 2];
  CHECK(td_views(&rng, &c, NV, 0.7, T, uv) == NV);
  double obj[NP][3], plane[NP * 2], H[NV * 9];
  calib_plate_points(obj);
  for (int i = 0; i < NP; i++) {
    plane[2 * i] = obj[i][0];
    plane[2 * i + 1] = obj[i][1];
  }
  for (int v = 0; v < NV; v++) CHECK(calib_homography(plane, uv + v * NP * 2, NP, H + 9 * v));
  double fx, fy, cx, cy;
  CHECK(calib_zhang_intrinsics(H, NV, &fx, &fy, &cx, &cy));
  CHECK_NEAR(fx / c.fx, 1.0, 1e-6);
  CHECK_NEAR(fy / c.fy, 1.0, 1e-6);
  CHECK_NEAR(cx / c.cx, 1.0, 1e-6);
  CHECK_NEAR(cy / c.cy, 1.0, 1e-6);
  /* poses from K^-1 H */
  double Kinv[9] = {1 / fx, 0, -cx / fx, 0, 1 / fy, -cy / fy, 0, 0, 1};
  for (int v = 0; v < NV; v++) {
    double Hn[9];
    hearth_rigid P;
    hearth_mat3_mul(Kinv, H + 9 * v, Hn);
    CHECK(calib_pose_from_homography(Hn, &P));
    CHECK(hearth_rotation_angle_between(P.R, T[v].R) < 1e-6);
    for (int i = 0; i < 3; i++) CHECK_NEAR(P.t[i], T[v].t[i], 1e-8);
  }
  /* too few views is refused */
  CHECK(!calib_zhang_intrinsics(H, 2, &fx, &fy, &cx, &cy));
}

static void test_jacobians(void) {
  hearth_camera c;
  td_thermal_cam(&c);
  double w[3] = {0.3, -0.2, 0.1}, t[3] = {-0.05, 0.02, 0.3}, X[3] = {0.04, 0.03, 0};
  double R[9], dR[27], uv[2], dp[12];
  hearth_project_jac jac;
  hearth_rotvec_to_matrix_jac(w, R, dR);
  CHECK(calib_project_pose(&c, R, dR, t, X, uv, &jac, dp, NULL));
  /* pose parameters */
  for (int k = 0; k < 6; k++) {
    double h = 1e-7, wp[3], tp[3], wm[3], tm[3], up[2], um[2], Rp[9], Rm[9], dd[27];
    memcpy(wp, w, sizeof wp);
    memcpy(tp, t, sizeof tp);
    memcpy(wm, w, sizeof wm);
    memcpy(tm, t, sizeof tm);
    if (k < 3) {
      wp[k] += h;
      wm[k] -= h;
    } else {
      tp[k - 3] += h;
      tm[k - 3] -= h;
    }
    hearth_rotvec_to_matrix_jac(wp, Rp, dd);
    hearth_rotvec_to_matrix_jac(wm, Rm, dd);
    calib_project_pose(&c, Rp, dd, tp, X, up, NULL, NULL, NULL);
    calib_project_pose(&c, Rm, dd, tm, X, um, NULL, NULL, NULL);
    for (int r = 0; r < 2; r++) {
      double fd = (up[r] - um[r]) / (2 * h);
      CHECK_NEAR(dp[6 * r + k], fd, 1e-4 * (1 + fabs(fd)));
    }
  }
  /* intrinsics and distortion */
  double Xc[3];
  for (int i = 0; i < 3; i++)
    Xc[i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + t[i];
  for (int k = 0; k < 9; k++) {
    hearth_camera cp = c, cm = c;
    double h = k < 4 ? 1e-4 : 1e-7;
    double *pp = k < 4 ? (&cp.fx) + k : cp.dist + (k - 4);
    double *pm = k < 4 ? (&cm.fx) + k : cm.dist + (k - 4);
    *pp += h;
    *pm -= h;
    double up[2], um[2];
    hearth_camera_project(&cp, Xc, up, NULL);
    hearth_camera_project(&cm, Xc, um, NULL);
    for (int r = 0; r < 2; r++) {
      double fd = (up[r] - um[r]) / (2 * h);
      double an = k < 4 ? jac.d_intr[4 * r + k] : jac.d_dist[5 * r + k - 4];
      CHECK_NEAR(an, fd, 1e-5 * (1 + fabs(fd)));
    }
  }
}

static void test_intrinsics(void) {
  hearth_camera c;
  td_thermal_cam(&c);
  hearth_rng rng;
  hearth_rng_seed(&rng, 5);
  enum { NV = 20 };
  hearth_rigid T[NV];
  static double uv[NV * NP * 2];
  CHECK(td_views(&rng, &c, NV, 0.7, T, uv) == NV);
  double obj[NP][3];
  calib_plate_points(obj);
  /* exact points: the minimum is the truth */
  hearth_camera e;
  double rms, frms[NV];
  hearth_rigid P[NV];
  hearth_err err = {0};
  CHECK_OK(hearth_calib_intrinsics((const double(*)[3])obj, NP, uv, NV, 256, 192, NULL, &e, &rms,
                                   frms, P, &err),
           &err);
  CHECK(rms < 1e-7);
  CHECK_NEAR(e.fx / c.fx, 1, 1e-8);
  CHECK_NEAR(e.fy / c.fy, 1, 1e-8);
  CHECK_NEAR(e.cx, c.cx, 1e-6);
  CHECK_NEAR(e.cy, c.cy, 1e-6);
  for (int k = 0; k < 5; k++) CHECK_NEAR(e.dist[k], c.dist[k], 1e-6);
  CHECK(hearth_rotation_angle_between(P[3].R, T[3].R) < 1e-8);
  CHECK(e.width == 256 && e.height == 192);
  /* 0.03 px noise: residual close to the noise, parameters close to truth */
  hearth_rng_seed(&rng, 6);
  for (int i = 0; i < NV * NP * 2; i++) uv[i] += 0.03 * hearth_rng_normal(&rng);
  CHECK_OK(hearth_calib_intrinsics((const double(*)[3])obj, NP, uv, NV, 256, 192, NULL, &e, &rms,
                                   frms, P, &err),
           &err);
  CHECK(rms > 0.02 && rms < 0.045);
  CHECK(fabs(e.fx / c.fx - 1) < 2e-3);
  CHECK(fabs(e.cx - c.cx) < 0.5 && fabs(e.cy - c.cy) < 0.5);
  /* bad arguments */
  CHECK(hearth_calib_intrinsics((const double(*)[3])obj, NP, uv, 2, 256, 192, NULL, &e, &rms, NULL,
                                NULL, &err) == HEARTH_E_SIZE);
  CHECK(strstr(err.msg, "at least 3") != NULL);
}

/* the test cameras, thermal a few cm beside the colour camera, slightly
   rotated */
static void stereo_rig(hearth_camera *ca, hearth_camera *cb, hearth_rigid *Tba) {
  td_rgb_cam(ca);
  td_thermal_cam(cb);
  double w[3] = {0.01, -0.02, 0.005};
  hearth_rotvec_to_matrix(w, Tba->R);
  Tba->t[0] = -0.045;
  Tba->t[1] = 0.012;
  Tba->t[2] = 0.003;
}

static void test_stereo(void) {
  hearth_camera ca, cb;
  hearth_rigid Tba;
  stereo_rig(&ca, &cb, &Tba);
  hearth_rng rng;
  hearth_rng_seed(&rng, 9);
  enum { NV = 10 };
  static double ua[NV * NP * 2], ub[NV * NP * 2];
  hearth_rigid Tb[NV];
  CHECK(td_views(&rng, &cb, NV, 0.6, Tb, ub) == NV);
  hearth_rigid Tbai;
  hearth_rigid_inverse(&Tba, &Tbai);
  for (int v = 0; v < NV; v++) {
    hearth_rigid Ta;
    hearth_rigid_compose(&Tbai, &Tb[v], &Ta);
    CHECK(td_project(&ca, &Ta, ua + v * NP * 2, 0) == NP);
  }
  double obj[NP][3];
  calib_plate_points(obj);
  for (int i = 0; i < NV * NP * 2; i++) {
    ua[i] += 0.1 * hearth_rng_normal(&rng);
    ub[i] += 0.05 * hearth_rng_normal(&rng);
  }
  /* pair 4 is an outlier: its thermal half shifted by 3 px */
  for (int i = 0; i < NP; i++) ub[4 * NP * 2 + 2 * i] += 3.0;
  hearth_rigid E;
  double rms, prms[NV];
  int used[NV];
  hearth_err err = {0};
  CHECK_OK(hearth_calib_stereo(&ca, &cb, (const double(*)[3])obj, NP, ua, ub, NV, NULL, &E, &rms,
                               prms, used, &err),
           &err);
  CHECK(!used[4]);
  for (int v = 0; v < NV; v++)
    if (v != 4) CHECK(used[v]);
  CHECK(prms[4] > 1.0);
  /* expected sqrt((2 * 0.1^2 + 2 * 0.05^2) / 2) = 0.112 */
  CHECK(rms > 0.095 && rms < 0.13);
  double ang = hearth_rotation_angle_between(E.R, Tba.R) * 180 / M_PI;
  CHECK_MSG(ang < 0.02, "rotation error %g deg", ang);
  for (int i = 0; i < 3; i++) CHECK_NEAR(E.t[i], Tba.t[i], 3e-4);
  /* no pairs */
  CHECK(hearth_calib_stereo(&ca, &cb, (const double(*)[3])obj, NP, ua, ub, 0, NULL, &E, &rms, NULL,
                            NULL, &err) == HEARTH_E_SIZE);
}

/* the plate Ta (camera a from plate at camera a's middle row) as it is
 * s frames of camera a's readout later: turned by s w about its pattern
 * centre and moved by s u (exact rigid motion) */
static void plate_at(const hearth_rigid *Ta, const double w[3], const double u[3], double s,
                     hearth_rigid *Ts) {
  double pc[3], c[3], Rc[3], ws[3] = {s * w[0], s * w[1], s * w[2]};
  td_pattern_centre(pc);
  hearth_rigid_apply(Ta, pc, c);
  hearth_rigid M;
  hearth_rotvec_to_matrix(ws, M.R);
  hearth_rigid_rotate(&M, c, Rc);
  for (int k = 0; k < 3; k++) M.t[k] = c[k] - Rc[k] + s * u[k];
  hearth_rigid_compose(&M, Ta, Ts);
}

/* a hand-held plate's velocity: random directions, |w| = turn (rad) and
 * |u| = move (m) per frame readout */
static void hand_motion(hearth_rng *rng, double turn, double move, double w[3], double u[3]) {
  double nw = 0, nu = 0;
  for (int k = 0; k < 3; k++) {
    w[k] = hearth_rng_normal(rng);
    u[k] = hearth_rng_normal(rng);
    nw += w[k] * w[k];
    nu += u[k] * u[k];
  }
  for (int k = 0; k < 3; k++) {
    w[k] *= turn / sqrt(nw);
    u[k] *= move / sqrt(nu);
  }
}

/* camera a with a rolling shutter: row v of its frame sees the plate at
 * time s = (v + 0.5) / height - 0.5 frames from the middle row, moved by
 * plate_at (each point at the row it lands in, by fixed point). */
static void rs_project(const hearth_camera *ca, const hearth_rigid *Ta, const double w[3],
                       const double u[3], const double (*obj)[3], double *uv) {
  for (int j = 0; j < NP; j++) {
    double row = 0.5 * (ca->height - 1);
    for (int it = 0; it < 6; it++) {
      double X[3];
      hearth_rigid Ts;
      plate_at(Ta, w, u, (row + 0.5) / ca->height - 0.5, &Ts);
      hearth_rigid_apply(&Ts, obj[j], X);
      CHECK(hearth_camera_project(ca, X, uv + 2 * j, NULL));
      row = uv[2 * j + 1];
    }
  }
}

/* the rolling-shutter model: pairs whose colour frame was read while the
 * plate moved (1 mm and 2 mrad per frame readout, as a 5 cm/s, 0.1 rad/s
 * hand over a 20 ms readout) give T_b_from_a to the noise with it and a
 * biased one without; with a still plate the model is not taken and the
 * result is the rigid solve's to the bit */
static void test_stereo_rolling(void) {
  hearth_camera ca, cb;
  td_rgb_cam(&ca);
  td_thermal_cam(&cb);
  hearth_rigid Tba, Tbai;
  double w0[3] = {0.012, -0.018, 0.004};
  hearth_rotvec_to_matrix(w0, Tba.R);
  Tba.t[0] = 0.004;
  Tba.t[1] = 0.05;
  Tba.t[2] = -0.002;
  hearth_rigid_inverse(&Tba, &Tbai);
  hearth_rng rng;
  hearth_rng_seed(&rng, 21);
  enum { NV = 16 };
  static double ua[NV * NP * 2], ub[NV * NP * 2], us[NV * NP * 2];
  hearth_rigid Tb[NV];
  CHECK(td_views(&rng, &cb, NV, 0.6, Tb, ub) == NV);
  double obj[NP][3];
  calib_plate_points(obj);
  for (int v = 0; v < NV; v++) {
    hearth_rigid Ta;
    hearth_rigid_compose(&Tbai, &Tb[v], &Ta);
    CHECK(td_project(&ca, &Ta, us + v * NP * 2, 0) == NP);
    double w[3], u[3];
    hand_motion(&rng, 0.002, 0.001, w, u);
    rs_project(&ca, &Ta, w, u, (const double(*)[3])obj, ua + v * NP * 2);
  }
  for (int i = 0; i < NV * NP * 2; i++) {
    double na = 0.05 * hearth_rng_normal(&rng);
    ua[i] += na;
    us[i] += na;
    ub[i] += 0.05 * hearth_rng_normal(&rng);
  }
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  CHECK(o.rolling_shutter == 1);
  hearth_rigid E, E0;
  double rms, rms0;
  hearth_err err = {0};
  CHECK_OK(hearth_calib_stereo(&ca, &cb, (const double(*)[3])obj, NP, ua, ub, NV, &o, &E, &rms,
                               NULL, NULL, &err),
           &err);
  o.rolling_shutter = 0;
  CHECK_OK(hearth_calib_stereo(&ca, &cb, (const double(*)[3])obj, NP, ua, ub, NV, &o, &E0, &rms0,
                               NULL, NULL, &err),
           &err);
  double ang = hearth_rotation_angle_between(E.R, Tba.R) * 180 / M_PI;
  double ang0 = hearth_rotation_angle_between(E0.R, Tba.R) * 180 / M_PI;
  double dt = 0, dt0 = 0;
  for (int i = 0; i < 3; i++) {
    dt += (E.t[i] - Tba.t[i]) * (E.t[i] - Tba.t[i]);
    dt0 += (E0.t[i] - Tba.t[i]) * (E0.t[i] - Tba.t[i]);
  }
  dt = sqrt(dt);
  dt0 = sqrt(dt0);
  fprintf(stderr,
          "rolling shutter: rotation %.4f (rigid %.4f) deg, translation %.3f (%.3f) mm, "
          "rms %.4f (%.4f) px\n",
          ang, ang0, 1000 * dt, 1000 * dt0, rms, rms0);
  /* the noise alone: 0.05 px per axis in each camera, rms sqrt(2) 0.05 */
  CHECK_MSG(rms < 0.08, "rms %g", rms);
  CHECK(rms0 > 1.5 * rms);
  CHECK_MSG(ang < 0.01 && dt < 1e-4, "rotation %g deg, translation %g m", ang, dt);
  CHECK(ang0 > 2 * ang || dt0 > 2 * dt);
  /* a still plate: the velocities fit noise only and are not kept */
  o.rolling_shutter = 1;
  CHECK_OK(hearth_calib_stereo(&ca, &cb, (const double(*)[3])obj, NP, us, ub, NV, &o, &E, &rms,
                               NULL, NULL, &err),
           &err);
  o.rolling_shutter = 0;
  CHECK_OK(hearth_calib_stereo(&ca, &cb, (const double(*)[3])obj, NP, us, ub, NV, &o, &E0, &rms0,
                               NULL, NULL, &err),
           &err);
  CHECK(memcmp(&E, &E0, sizeof E) == 0 && rms == rms0);
}

/* the perspective bias of a hole's image centroid against an independent
 * area integral: a fine image-space grid, each sample back-projected onto
 * the plate and tested against the hole */
static void test_circle_bias(void) {
  hearth_camera c;
  td_thermal_cam(&c);
  hearth_rigid T;
  double w[3] = {0.5, -0.3, 0.1};
  hearth_rotvec_to_matrix(w, T.R);
  T.t[0] = -0.07;
  T.t[1] = -0.03;
  T.t[2] = 0.25;
  double obj[NP][3], bias[2 * NP];
  calib_plate_points(obj);
  calib_circle_bias(&c, &T, (const double(*)[3])obj, NP, 0.004, 0.0, bias);
  hearth_rigid Ti;
  hearth_rigid_inverse(&T, &Ti);
  double n[3] = {T.R[2], T.R[5], T.R[8]}, d = hearth_dot3(n, T.t);
  int holes[3] = {0, 40, 83};
  double maxb = 0;
  for (int k = 0; k < 3; k++) {
    int i = holes[k];
    double Xc[3], uv[2];
    hearth_rigid_apply(&T, obj[i], Xc);
    hearth_camera_project(&c, Xc, uv, NULL);
    double sa = 0, su = 0, sv = 0, step = 0.02;
    for (double v = uv[1] - 6; v <= uv[1] + 6; v += step)
      for (double u = uv[0] - 6; u <= uv[0] + 6; u += step) {
        double dir[3], P[3], Q[3];
        hearth_camera_ray(&c, u, v, dir);
        double s = d / hearth_dot3(n, dir);
        for (int q = 0; q < 3; q++) P[q] = s * dir[q];
        hearth_rigid_apply(&Ti, P, Q);
        double dx = Q[0] - obj[i][0], dy = Q[1] - obj[i][1];
        if (dx * dx + dy * dy < 0.004 * 0.004) {
          sa += 1;
          su += u - uv[0];
          sv += v - uv[1];
        }
      }
    CHECK_NEAR(bias[2 * i], su / sa, 2e-3);
    CHECK_NEAR(bias[2 * i + 1], sv / sa, 2e-3);
    maxb = fmax(maxb, hypot(bias[2 * i], bias[2 * i + 1]));
  }
  /* the effect is real at this tilt (otherwise the test proves nothing) */
  CHECK(maxb > 0.01);
  /* fronto-parallel on the axis, no distortion: no bias */
  hearth_camera c0 = c;
  memset(c0.dist, 0, sizeof c0.dist);
  hearth_rigid_identity(&T);
  T.t[0] = -obj[40][0];
  T.t[1] = -obj[40][1];
  T.t[2] = 0.3;
  calib_circle_bias(&c0, &T, (const double(*)[3])obj, NP, 0.004, 0.0, bias);
  CHECK_NEAR(bias[80], 0, 1e-9);
  CHECK_NEAR(bias[81], 0, 1e-9);
}

/* a plate 5 mm thick: the bias is the centroid of what shows through both
 * openings, against the same kind of independent raster: each sample ray is
 * met with the front plane (z = 0) and the back plane (z = 5 mm) of the
 * plate and must fall inside the hole on both */
static void test_circle_bias_thick(void) {
  hearth_camera c;
  td_thermal_cam(&c);
  hearth_rigid T;
  double w[3] = {0.45, -0.25, 0.1};
  hearth_rotvec_to_matrix(w, T.R);
  T.t[0] = -0.07;
  T.t[1] = -0.03;
  T.t[2] = 0.25;
  const double h = 0.005, R = 0.004;
  double obj[NP][3], bias[2 * NP], thin[2 * NP];
  calib_plate_points(obj);
  calib_circle_bias(&c, &T, (const double(*)[3])obj, NP, R, h, bias);
  calib_circle_bias(&c, &T, (const double(*)[3])obj, NP, R, 0.0, thin);
  hearth_rigid Ti;
  hearth_rigid_inverse(&T, &Ti);
  double n[3] = {T.R[2], T.R[5], T.R[8]}, d0 = hearth_dot3(n, T.t), d1 = d0 + h;
  int holes[3] = {0, 40, 83};
  double maxd = 0;
  for (int k = 0; k < 3; k++) {
    int i = holes[k];
    double Xc[3], uv[2];
    hearth_rigid_apply(&T, obj[i], Xc);
    hearth_camera_project(&c, Xc, uv, NULL);
    double sa = 0, su = 0, sv = 0, step = 0.02;
    for (double v = uv[1] - 6; v <= uv[1] + 6; v += step)
      for (double u = uv[0] - 6; u <= uv[0] + 6; u += step) {
        double dir[3], P[3], Q[3];
        hearth_camera_ray(&c, u, v, dir);
        int in = 1;
        for (int f = 0; f < 2 && in; f++) {
          double s = (f ? d1 : d0) / hearth_dot3(n, dir);
          for (int q = 0; q < 3; q++) P[q] = s * dir[q];
          hearth_rigid_apply(&Ti, P, Q);
          double dx = Q[0] - obj[i][0], dy = Q[1] - obj[i][1];
          in = dx * dx + dy * dy < R * R;
        }
        if (in) {
          sa += 1;
          su += u - uv[0];
          sv += v - uv[1];
        }
      }
    CHECK(sa > 0);
    CHECK_NEAR(bias[2 * i], su / sa, 3e-3);
    CHECK_NEAR(bias[2 * i + 1], sv / sa, 3e-3);
    maxd = fmax(maxd, hypot(bias[2 * i] - thin[2 * i], bias[2 * i + 1] - thin[2 * i + 1]));
  }
  /* the wall's shift is much larger than the thin hole's bias here */
  CHECK(maxd > 0.1);
}

/* the joint solve: camera b's intrinsics and distortion refined with the
 * extrinsic. From intrinsics started 2 % and 3 px off, exact points give
 * the true camera and T_b_from_a to the solver's tolerance, where holding
 * the wrong intrinsics (the paper's stereo) turns the extrinsic measurably;
 * with noise the RMS is the noise's and the estimates stay within a few
 * standard errors */
/* the joint solve's data: nv still pairs (camera a's plate poses into Ta
 * when non-NULL) and nc frames of camera b alone */
static void joint_data(hearth_rng *rng, const hearth_camera *ca, const hearth_camera *cb,
                       const hearth_rigid *Tba, int nv, int nc, double *ua, double *ub, double *uc,
                       hearth_rigid *Ta) {
  hearth_rigid Tb[16], Tc[16], Tbai, Tv;
  CHECK(nv <= 16 && nc <= 16);
  CHECK(td_views(rng, cb, nv, 0.6, Tb, ub) == nv);
  CHECK(td_views(rng, cb, nc, 0.7, Tc, uc) == nc);
  hearth_rigid_inverse(Tba, &Tbai);
  for (int v = 0; v < nv; v++) {
    hearth_rigid_compose(&Tbai, &Tb[v], &Tv);
    CHECK(td_project(ca, &Tv, ua + v * NP * 2, 0) == NP);
    if (Ta) Ta[v] = Tv;
  }
}

/* the joint solve's start: camera b's intrinsics off as a separate
 * calibration might leave them */
static void joint_start(const hearth_camera *cb, hearth_camera *c0) {
  *c0 = *cb;
  c0->fx *= 1.02;
  c0->fy *= 0.985;
  c0->cx += 3.0;
  c0->cy -= 2.0;
  c0->dist[0] *= 0.8;
}

static void test_stereo_joint(void) {
  hearth_camera ca, cb, c0;
  hearth_rigid Tba;
  stereo_rig(&ca, &cb, &Tba);
  enum { NV = 12, NC = 10 };
  static double ua[NV * NP * 2], ub[NV * NP * 2], uc[NC * NP * 2];
  hearth_rng rng;
  hearth_rng_seed(&rng, 21);
  joint_data(&rng, &ca, &cb, &Tba, NV, NC, ua, ub, uc, NULL);
  double obj[NP][3];
  calib_plate_points(obj);
  joint_start(&cb, &c0);
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  o.rolling_shutter = 0;
  hearth_err err = {0};
  hearth_rigid E;
  hearth_camera cj = c0;
  double rms, own;
  CHECK_OK(hearth_calib_stereo_joint(&ca, &cj, (const double(*)[3])obj, NP, ua, ub, NV, uc, NC, &o,
                                     &E, &rms, &own, NULL, NULL, &err),
           &err);
  CHECK_MSG(rms < 1e-6 && own < 1e-6, "exact points: rms %g, own %g", rms, own);
  CHECK_NEAR(cj.fx / cb.fx, 1.0, 1e-7);
  CHECK_NEAR(cj.fy / cb.fy, 1.0, 1e-7);
  CHECK_NEAR(cj.cx, cb.cx, 1e-5);
  CHECK_NEAR(cj.cy, cb.cy, 1e-5);
  for (int k = 0; k < 5; k++) CHECK_NEAR(cj.dist[k], cb.dist[k], 1e-5);
  double ang = hearth_rotation_angle_between(E.R, Tba.R) * 180 / M_PI;
  CHECK_MSG(ang < 1e-5, "joint rotation error %g deg", ang);
  for (int i = 0; i < 3; i++) CHECK_NEAR(E.t[i], Tba.t[i], 1e-7);
  /* the paper's stereo holds the wrong intrinsics: the extrinsic turns and
     the points no longer fit, so the refinement is what recovers it */
  hearth_camera cf = c0;
  hearth_rigid Ef;
  double rmsf;
  o.stereo_intrinsics = 0;
  CHECK_OK(hearth_calib_stereo_joint(&ca, &cf, (const double(*)[3])obj, NP, ua, ub, NV, uc, NC, &o,
                                     &Ef, &rmsf, NULL, NULL, NULL, &err),
           &err);
  CHECK(cf.fx == c0.fx && cf.cx == c0.cx && cf.dist[0] == c0.dist[0]);
  const double angf = hearth_rotation_angle_between(Ef.R, Tba.R) * 180 / M_PI;
  CHECK_MSG(angf > 0.1 && rmsf > 0.1, "fixed wrong intrinsics: %g deg, rms %g", angf, rmsf);
  o.stereo_intrinsics = 1;

  /* noise: 0.1 px on colour, 0.05 px on thermal points */
  for (int i = 0; i < NV * NP * 2; i++) {
    ua[i] += 0.1 * hearth_rng_normal(&rng);
    ub[i] += 0.05 * hearth_rng_normal(&rng);
  }
  for (int i = 0; i < NC * NP * 2; i++) uc[i] += 0.05 * hearth_rng_normal(&rng);
  cj = c0;
  CHECK_OK(hearth_calib_stereo_joint(&ca, &cj, (const double(*)[3])obj, NP, ua, ub, NV, uc, NC, &o,
                                     &E, &rms, &own, NULL, NULL, &err),
           &err);
  /* sqrt((2 * 0.1^2 + 2 * 0.05^2) / 2) = 0.112 over the pairs, 0.05 over
     camera b's own frames (0.05 sqrt 2 = 0.071), less the fitted
     parameters' share */
  CHECK_MSG(rms > 0.095 && rms < 0.125, "noisy pairs rms %g", rms);
  CHECK_MSG(own > 0.06 && own < 0.075, "noisy own rms %g", own); /* 0.05 sqrt(2) = 0.071 */
  CHECK_MSG(fabs(cj.fx / cb.fx - 1) < 1e-3 && fabs(cj.cx - cb.cx) < 0.2 &&
                fabs(cj.cy - cb.cy) < 0.2,
            "noisy intrinsics fx %g (%g) cx %g (%g) cy %g (%g)", cj.fx, cb.fx, cj.cx, cb.cx, cj.cy,
            cb.cy);
  /* over seeds 21-27 these data gave fx within 0.05 %, the principal
     point within 0.42 px and the rotation within 0.095 deg (a principal
     point e px off turns the extrinsic by about atan(e / fx): 0.09 deg at
     0.42 px); the bounds leave room above those */
  ang = hearth_rotation_angle_between(E.R, Tba.R) * 180 / M_PI;
  CHECK_MSG(ang < 0.15, "noisy rotation error %g deg", ang);
  for (int i = 0; i < 3; i++) CHECK_NEAR(E.t[i], Tba.t[i], 5e-4);
  /* no pairs */
  cj = c0;
  CHECK(hearth_calib_stereo_joint(&ca, &cj, (const double(*)[3])obj, NP, ua, ub, 0, uc, NC, &o, &E,
                                  &rms, NULL, NULL, NULL, &err) == HEARTH_E_SIZE);
}

/* error of an estimated T_b_from_a: rotation (deg) and translation (m) */
static void rigid_error(const hearth_rigid *E, const hearth_rigid *T, double *deg, double *m) {
  *deg = hearth_rotation_angle_between(E->R, T->R) * 180 / M_PI;
  double d = 0;
  for (int i = 0; i < 3; i++) d += (E->t[i] - T->t[i]) * (E->t[i] - T->t[i]);
  *m = sqrt(d);
}

/* the joint solve with the trigger time. The solver's convention
 * (calib_stereo.c): camera a (colour) reads row v at s = (v + 0.5) / height
 * - 0.5 frames of its readout from its middle row, camera b (thermal) sees
 * the whole plate at its own time tb in the same frames (positive: after
 * camera a's middle row), the plate moving at a constant velocity. Truth:
 * a brisk hand (5 mm and 10 mrad per frame readout: 25 cm/s and 0.5 rad/s
 * over 20 ms), each pair's tb known (-0.25 to 0.25 frames, 5 ms either
 * way), camera b's intrinsics started off as in test_stereo_joint. */
static void test_stereo_joint_rolling(uint64_t seed) {
  hearth_camera ca, cb, c0;
  hearth_rigid Tba;
  stereo_rig(&ca, &cb, &Tba);
  enum { NV = 12, NC = 10 };
  static double ua[NV * NP * 2], ub[NV * NP * 2], uc[NC * NP * 2];
  hearth_rigid Ta[NV];
  hearth_rng rng;
  hearth_rng_seed(&rng, seed);
  joint_data(&rng, &ca, &cb, &Tba, NV, NC, ua, ub, uc, Ta);
  double obj[NP][3], tb[NV];
  calib_plate_points(obj);
  for (int v = 0; v < NV; v++) {
    double w[3], u[3];
    hand_motion(&rng, 0.01, 0.005, w, u);
    tb[v] = 0.25 * (2.0 * v / (NV - 1) - 1.0);
    rs_project(&ca, &Ta[v], w, u, (const double(*)[3])obj, ua + v * NP * 2);
    hearth_rigid Ts, Tbs;
    plate_at(&Ta[v], w, u, tb[v], &Ts);
    hearth_rigid_compose(&Tba, &Ts, &Tbs);
    CHECK(td_project(&cb, &Tbs, ub + v * NP * 2, 0) == NP);
  }
  joint_start(&cb, &c0);
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  CHECK(o.rolling_shutter && o.stereo_intrinsics);
  hearth_err err = {0};
  for (int noisy = 0; noisy < 2; noisy++) {
    if (noisy) {
      /* as test_stereo_joint: 0.1 px on colour, 0.05 px on thermal */
      for (int i = 0; i < NV * NP * 2; i++) {
        ua[i] += 0.1 * hearth_rng_normal(&rng);
        ub[i] += 0.05 * hearth_rng_normal(&rng);
      }
      for (int i = 0; i < NC * NP * 2; i++) uc[i] += 0.05 * hearth_rng_normal(&rng);
    }
    hearth_rigid E, E0;
    hearth_camera cj = c0, c00 = c0;
    double rms, own, rms0, t[NV];
    int used[NV];
    o.rolling_shutter = 1;
    CHECK_OK(calib_stereo_joint_times(&ca, &cj, (const double(*)[3])obj, NP, ua, ub, NV, uc, NC, &o,
                                      &E, &rms, &own, NULL, used, t, NULL, NULL, &err),
             &err);
    o.rolling_shutter = 0;
    CHECK_OK(hearth_calib_stereo_joint(&ca, &c00, (const double(*)[3])obj, NP, ua, ub, NV, uc, NC,
                                       &o, &E0, &rms0, NULL, NULL, NULL, &err),
             &err);
    double ang, dt, ang0, dt0, maxe = 0;
    rigid_error(&E, &Tba, &ang, &dt);
    rigid_error(&E0, &Tba, &ang0, &dt0);
    for (int v = 0; v < NV; v++) {
      CHECK_MSG(used[v] && isfinite(t[v]), "pair %d: used %d, time %g", v, used[v], t[v]);
      maxe = fmax(maxe, fabs(t[v] - tb[v]));
    }
    fprintf(stderr,
            "joint rolling (seed %d, %s): times within %.4f frames, rotation %.4f (rigid %.4f) deg, "
            "translation %.3f (%.3f) mm, rms %.4f (%.4f) px, own %.4f px, fx %.2e cx %.3f cy "
            "%.3f px\n",
            (int)seed, noisy ? "noisy" : "exact", maxe, ang, ang0, 1000 * dt, 1000 * dt0, rms, rms0,
            own, cj.fx / cb.fx - 1, cj.cx - cb.cx, cj.cy - cb.cy);
    /* rigid per pair, the motion is unexplained: the extrinsic is degrees
       and millimetres off and the RMS several times the noise's */
    CHECK_MSG(ang0 > 0.5 && dt0 > 2e-3 && rms0 > 0.4, "rigid: %g deg, %g m, rms %g", ang0, dt0,
              rms0);
    if (!noisy) {
      /* exact points: what is left is the trigger prior's pull (zero, 1
         frame), about tb / (1 + I) on a time the data inform with I
         (80-2000 px^2 per frame^2 here, from the thermal image's motion):
         measured 0.014 frames, and 0.0017 px RMS, 0.011 deg, 0.12 mm,
         fx 4e-4 and 0.05 px in the principal point; the bounds leave
         about twice that */
      CHECK_MSG(maxe < 0.03, "exact times within %g frames", maxe);
      CHECK_MSG(rms < 0.004 && own < 0.002, "exact rms %g, own %g", rms, own);
      CHECK_MSG(ang < 0.025 && dt < 2.5e-4, "exact: %g deg, %g m", ang, dt);
      CHECK(fabs(cj.fx / cb.fx - 1) < 1e-3 && fabs(cj.cx - cb.cx) < 0.1 &&
            fabs(cj.cy - cb.cy) < 0.1);
    } else {
      /* noise: each time's standard error is at least 0.05 px / sqrt(I)
         (0.001 to 0.006 frames; more where the pose and velocity share
         the information), the extrinsic's as in test_stereo_joint; measured
         0.013 frames, 0.044 deg, 0.05 mm, fx 2e-4, 0.13 px principal
         point and 0.1105 px RMS (that of test_stereo_joint's noise) */
      CHECK_MSG(maxe < 0.04, "noisy times within %g frames", maxe);
      CHECK_MSG(rms > 0.095 && rms < 0.125 && own > 0.06 && own < 0.075, "noisy rms %g, own %g",
                rms, own);
      CHECK_MSG(ang < 0.15 && dt < 5e-4, "noisy: %g deg, %g m", ang, dt);
      CHECK(fabs(cj.fx / cb.fx - 1) < 1e-3 && fabs(cj.cx - cb.cx) < 0.3 &&
            fabs(cj.cy - cb.cy) < 0.3);
    }
    CHECK(ang0 > 20 * ang && rms0 > 4 * rms);
  }
}

/* the target model (opts.target_points): the holes drilled off the nominal
 * lattice by N(0, 0.04 mm) per axis (the CNC tolerance of the virtual rig,
 * docs/virtual-rig.md), with no affine part (the model's gauge is their
 * similarity part, which the plate poses and the scale take exactly; the
 * affine part's shear and anisotropic scale are left out too, as weakly
 * seen). Exact points of the
 * drilled plate: solved against the nominal lattice the thermal camera and
 * the extrinsic come out measurably off and the RMS is the drilling's;
 * with the offsets solved jointly, the drilled positions, the camera and
 * the extrinsic come back to the solver's tolerance, and the RMS against
 * the nominal target is reported beside the modelled one. */
static void test_stereo_joint_target(void) {
  hearth_camera ca, cb, c0;
  hearth_rigid Tba;
  stereo_rig(&ca, &cb, &Tba);
  enum { NV = 12, NC = 10 };
  static double ua[NV * NP * 2], ub[NV * NP * 2], uc[NC * NP * 2];
  hearth_rng rng;
  hearth_rng_seed(&rng, 41);
  hearth_rigid Ta[NV], Tb[NV], Tc[NC], Tbai;
  CHECK(td_views(&rng, &cb, NV, 0.6, Tb, ub) == NV);
  CHECK(td_views(&rng, &cb, NC, 0.7, Tc, uc) == NC);
  hearth_rigid_inverse(&Tba, &Tbai);
  for (int v = 0; v < NV; v++) hearth_rigid_compose(&Tbai, &Tb[v], &Ta[v]);
  /* the drilled plate: white offsets less their least-squares affine part */
  double nom[NP][3], drl[NP][3], off[NP][2], M[9] = {0}, c[2][3] = {{0}};
  calib_plate_points(nom);
  for (int j = 0; j < NP; j++) {
    const double q[3] = {nom[j][0], nom[j][1], 1};
    for (int k = 0; k < 2; k++) off[j][k] = 4e-5 * hearth_rng_normal(&rng);
    for (int a = 0; a < 3; a++) {
      for (int e = 0; e < 3; e++) M[3 * a + e] += q[a] * q[e];
      c[0][a] += q[a] * off[j][0];
      c[1][a] += q[a] * off[j][1];
    }
  }
  for (int k = 0; k < 2; k++) {
    double Mk[9];
    memcpy(Mk, M, sizeof Mk);
    CHECK(calib_chol_solve(Mk, c[k], 3));
  }
  for (int j = 0; j < NP; j++) {
    for (int k = 0; k < 2; k++)
      drl[j][k] = nom[j][k] + off[j][k] - (c[k][0] * nom[j][0] + c[k][1] * nom[j][1] + c[k][2]);
    drl[j][2] = 0;
  }
  /* exact images of the drilled plate */
  for (int v = 0; v < NV + NC; v++)
    for (int j = 0; j < NP; j++) {
      double Xa[3], Xb[3];
      if (v < NV) {
        hearth_rigid_apply(&Ta[v], drl[j], Xa);
        CHECK(hearth_camera_project(&ca, Xa, ua + 2 * (v * NP + j), NULL));
        hearth_rigid_apply(&Tb[v], drl[j], Xb);
        CHECK(hearth_camera_project(&cb, Xb, ub + 2 * (v * NP + j), NULL));
      } else {
        hearth_rigid_apply(&Tc[v - NV], drl[j], Xb);
        CHECK(hearth_camera_project(&cb, Xb, uc + 2 * ((v - NV) * NP + j), NULL));
      }
    }
  joint_start(&cb, &c0);
  hearth_calib_opts o;
  hearth_calib_opts_default(&o);
  o.rolling_shutter = 0;
  hearth_err err = {0};
  hearth_rigid E;
  double rms, own, nomr, pts[NP][3], ang, dt;
  /* the nominal lattice taken as the plate */
  hearth_camera cn = c0;
  CHECK_OK(calib_stereo_joint_times(&ca, &cn, (const double(*)[3])nom, NP, ua, ub, NV, uc, NC, &o,
                                    &E, &rms, &own, NULL, NULL, NULL, &nomr, pts, &err),
           &err);
  rigid_error(&E, &Tba, &ang, &dt);
  CHECK_MSG(rms > 0.05 && nomr == rms, "nominal target: rms %g (nominal %g)", rms, nomr);
  CHECK_MSG(ang > 0.02 || fabs(cn.cx - cb.cx) > 0.1 || fabs(cn.cy - cb.cy) > 0.1,
            "nominal target: %g deg, cx %g (%g), cy %g (%g)", ang, cn.cx, cb.cx, cn.cy, cb.cy);
  for (int j = 0; j < NP; j++) CHECK(pts[j][0] == nom[j][0] && pts[j][1] == nom[j][1]);
  /* the offsets solved with the rest (the prior on them made negligible:
     exact points) */
  o.target_points = 1;
  o.target_sigma_m = 1.0;
  hearth_camera cj = c0;
  CHECK_OK(calib_stereo_joint_times(&ca, &cj, (const double(*)[3])nom, NP, ua, ub, NV, uc, NC, &o,
                                    &E, &rms, &own, NULL, NULL, NULL, &nomr, pts, &err),
           &err);
  CHECK_MSG(rms < 1e-5 && own < 1e-5, "target model: rms %g, own %g", rms, own);
  CHECK_MSG(nomr > 0.05, "target model: rms against the nominal target %g", nomr);
  double maxe = 0;
  for (int j = 0; j < NP; j++)
    maxe = fmax(maxe, hypot(pts[j][0] - drl[j][0], pts[j][1] - drl[j][1]));
  CHECK_MSG(maxe < 1e-7, "target model: holes %g m off", maxe);
  CHECK_NEAR(cj.fx / cb.fx, 1.0, 1e-6);
  CHECK_NEAR(cj.fy / cb.fy, 1.0, 1e-6);
  CHECK_NEAR(cj.cx, cb.cx, 1e-3);
  CHECK_NEAR(cj.cy, cb.cy, 1e-3);
  rigid_error(&E, &Tba, &ang, &dt);
  CHECK_MSG(ang < 1e-4 && dt < 1e-6, "target model: %g deg, %g m", ang, dt);
}

int main(void) {
  test_circle_bias();
  test_circle_bias_thick();
  test_zhang_exact();
  test_jacobians();
  test_intrinsics();
  test_stereo();
  test_stereo_rolling();
  test_stereo_joint();
  /* seed 35 settles in a false minimum when the moving model is tried at
     camera b's start intrinsics */
  test_stereo_joint_rolling(31);
  test_stereo_joint_rolling(35);
  test_stereo_joint_target();
  TEST_MAIN_END();
}
