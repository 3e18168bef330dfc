/* recon_turntable.c - colour poses from a turntable capture without an
 * outside tool: each view's table plane and object points from its depth
 * map, the turntable geometry as the start, then joint point-to-plane ICP
 * over the views' angles about the axis and horizontal positions. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/recon_geom.h"
#include "recon_internal.h"

#define TT_PI 3.14159265358979323846
#define TT_DEG (TT_PI / 180.0)
/* depth step (mm) between 4-neighbours taken as a depth edge */
#define TT_EDGE_MM 8
/* half window (depth pixels) of the normal fit */
#define TT_NORMAL_R 3
/* fewest object points / plane inliers a view must have */
#define TT_MIN_POINTS 200
#define TT_MIN_PLANE 300
/* RANSAC for the table plane */
#define TT_RANSAC_ITER 300
#define TT_PLANE_TOL_M 0.004
/* table-plane points each view keeps for the ICP's plane term */
#define TT_PLANE_SAMPLES 1500
/* table points farther than this from the object's points are left out */
#define TT_PLANE_NEAR_M 0.25
/* table planes fitting within this rms get the full weight */
#define TT_PLANE_GOOD_M 0.0004
/* the object stands on the table: this share of its points within this
 * height above the plane */
#define TT_ON_TABLE_M 0.05
#define TT_ON_TABLE_SHARE 0.002
/* a table plane of fewer inliers (a thin band seen at grazing incidence)
 * tilts its view less well than a wall it sees */
#define TT_WEAK_PLANE 2000
/* a plane fitting its inliers worse than this is not the turntable top */
#define TT_PLANE_MAX_RMS_M 0.002
/* Huber threshold of the ICP distances */
#define TT_HUBER_M 0.0015
/* correspondences must have normals within this angle */
#define TT_NORMAL_COS 0.7
/* Huber threshold and gate of the photometric residuals (band-passed grey,
 * 0..1) */
#define TT_COLOUR_HUBER 0.02
#define TT_COLOUR_GATE 0.15

void hearth_turntable_opts_default(hearth_turntable_opts *o) {
  memset(o, 0, sizeof *o);
  o->azimuth_step_deg = 36.0;
  o->ring_shift_deg = 12.0;
  o->direction = 1;
  o->iterations = 30;
  o->max_points = 3000;
  o->max_pair_deg = 65.0;
  o->erode_px = 8.0;
  o->azimuth_prior = 3e-3;
  o->encoder_prior = 1.0;
  o->colour_weight = 0;
  o->aim_prior = 0.1;
  o->aim_depth_tol = 0.012;
  o->aim_side_m = 0.0005;
  o->aim_per_ring = 0;
  o->aim_height_tol = 0.6;
  o->ring_tilt_prior = 0;
  o->roll_prior = 1.0;
  o->wall_prior = 1.0;
}

void hearth_turntable_result_free(hearth_turntable_result *r) {
  if (!r) return;
  free(r->views);
  free(r->aim_states);
  free(r->aim_places);
  memset(r, 0, sizeof *r);
}

/* One view: object points and normals in its colour camera's frame, the
 * crop of its depth image that indexes them, its levelling and pose. */
typedef struct tt_view {
  char state[HEARTH_NAME_MAX], view[HEARTH_NAME_MAX];
  char depth_path[1400];
  int elevation_index, azimuth_index;
  hearth_camera dcam;
  hearth_rigid T_depth_from_rgb;
  int x0, y0, cw, ch; /* crop of the depth image */
  int32_t *index;     /* cw * ch: point index or -1 */
  size_t n;
  float *p, *nrm; /* 3 * n each, colour camera frame */
  double centroid[3];
  double L[9];    /* R_level_from_cam: rows forward, side, up */
  double height;  /* camera above the plane, metres */
  size_t n_plane; /* 0: none found, the ring's plane is taken */
  int free_ring;  /* no view of its ring found one: started from the others */
  size_t n_wall;  /* without a table (or a weak one): the backdrop's inliers */
  double wall[3]; /* its unit normal (colour frame), towards the camera */
  size_t bg_points;
  double plane_rms;
  size_t npl;
  float *pl; /* 3 * npl: table-plane inliers (a subsample), colour frame */
  /* pose parameters: T_world_from_cam = (Rz(psi) L, (x, y, height)) */
  double psi, x, y;
  /* the heading of the tilt axis (world) the priors pull towards: the
   * nominal azimuth's, or the encoder's aligned to it; enc: its state's
   * views all carry the encoder angle */
  double target, target_nominal;
  int enc;
  size_t state_index; /* its encoder group: its state's index, or 0 for all */
  size_t state_no;    /* its state's index */
  int ring;           /* its group in the aim term, -1: none */
  hearth_rigid T;     /* current pose */
  /* the photometric term's view (without the encoder) and each point's
   * band-passed grey in it (NaN: none) */
  rc_photo photo;
  float *col;
} tt_view;

static void tt_view_free(tt_view *v) {
  rc_photo_free(&v->photo);
  free(v->col);
  free(v->pl);
  free(v->index);
  free(v->p);
  free(v->nrm);
}

/* eigen decomposition of a symmetric 3x3 (cyclic Jacobi); eigenvalues in
 * w, eigenvectors in the columns of V */
static void sym3_eigen(const double A[9], double w[3], double V[9]) {
  double a[9];
  memcpy(a, A, sizeof a);
  for (int i = 0; i < 9; i++) V[i] = i % 4 == 0;
  for (int sweep = 0; sweep < 30; sweep++) {
    double off = fabs(a[1]) + fabs(a[2]) + fabs(a[5]);
    if (off < 1e-300) break;
    for (int p = 0; p < 2; p++)
      for (int q = p + 1; q < 3; q++) {
        double apq = a[3 * p + q];
        if (fabs(apq) < 1e-300) continue;
        double th = 0.5 * (a[3 * q + q] - a[3 * p + p]) / apq;
        double t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
        double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; k++) { /* columns p, q */
          double akp = a[3 * k + p], akq = a[3 * k + q];
          a[3 * k + p] = c * akp - s * akq;
          a[3 * k + q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; k++) { /* rows p, q */
          double apk = a[3 * p + k], aqk = a[3 * q + k];
          a[3 * p + k] = c * apk - s * aqk;
          a[3 * q + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; k++) {
          double vkp = V[3 * k + p], vkq = V[3 * k + q];
          V[3 * k + p] = c * vkp - s * vkq;
          V[3 * k + q] = s * vkp + c * vkq;
        }
      }
  }
  for (int i = 0; i < 3; i++) w[i] = a[4 * i];
}

/* the unit normal (eigenvector of the smallest eigenvalue) of points'
 * covariance C about their mean */
static void smallest_axis(const double C[9], double n[3]) {
  double w[3], V[9];
  sym3_eigen(C, w, V);
  int k = 0;
  for (int i = 1; i < 3; i++)
    if (w[i] < w[k]) k = i;
  for (int i = 0; i < 3; i++) n[i] = V[3 * i + k];
}

/* least-squares plane n.x + d = 0 through pts[idx[0..m)] */
static void fit_plane(const float *pts, const size_t *idx, size_t m, double n[3], double *d) {
  double mu[3] = {0, 0, 0}, C[9] = {0};
  for (size_t i = 0; i < m; i++)
    for (int a = 0; a < 3; a++) mu[a] += pts[3 * idx[i] + a];
  for (int a = 0; a < 3; a++) mu[a] /= (double)m;
  for (size_t i = 0; i < m; i++) {
    double q[3];
    for (int a = 0; a < 3; a++) q[a] = pts[3 * idx[i] + a] - mu[a];
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) C[3 * a + b] += q[a] * q[b];
  }
  smallest_axis(C, n);
  *d = -hearth_dot3(n, mu);
}

static void set_level(tt_view *v, const double n[3]);

/* The backdrop is taken as vertical only where the views that see both it
 * and the table show it so: the median over them of the wall's departure
 * from normal to the table above this, and no view is levelled by a wall.
 * A wall no view with a table sees is taken as vertical unchecked. */
#define TT_WALL_VERTICAL_DEG 1.0

/* The RANSAC plane among bg[0..nb) (colour frame) whose normal, turned
 * towards the camera, has -n[axis] >= facing, with the most inliers,
 * refit three times to them (within TT_PLANE_TOL_M, then 2.5 times the
 * fit's rms, at least 0.5 mm): n and d (n.x + d = 0, the camera on the
 * positive side), the inliers' rms and their indices in idx (the caller's,
 * nb entries). Their count; below TT_MIN_PLANE, none was found. */
static size_t facing_plane(const float *bg, size_t nb, uint64_t seed, int axis, double facing,
                           size_t *idx, double n[3], double *d, double *rms) {
  *rms = 0;
  if (nb < TT_MIN_PLANE) return 0;
  hearth_rng r;
  hearth_rng_seed(&r, seed);
  double best_n[3] = {0}, best_d = 0;
  size_t best = 0;
  for (int it = 0; it < TT_RANSAC_ITER; it++) {
    size_t i0 = hearth_rng_u64(&r) % nb, i1 = hearth_rng_u64(&r) % nb, i2 = hearth_rng_u64(&r) % nb;
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; k++) {
      a[k] = bg[3 * i1 + k] - bg[3 * i0 + k];
      b[k] = bg[3 * i2 + k] - bg[3 * i0 + k];
    }
    hearth_cross3(a, b, c);
    double ln = hearth_norm3(c);
    if (ln < 1e-9) continue;
    for (int k = 0; k < 3; k++) c[k] /= ln;
    double p0[3] = {bg[3 * i0], bg[3 * i0 + 1], bg[3 * i0 + 2]};
    double dc = -hearth_dot3(c, p0);
    if (dc < 0) { /* the camera (origin) on the positive side */
      for (int k = 0; k < 3; k++) c[k] = -c[k];
      dc = -dc;
    }
    if (-c[axis] < facing) continue;
    size_t cnt = 0;
    for (size_t i = 0; i < nb; i += 2) {
      double q[3] = {bg[3 * i], bg[3 * i + 1], bg[3 * i + 2]};
      if (fabs(hearth_dot3(c, q) + dc) < TT_PLANE_TOL_M) cnt++;
    }
    if (cnt > best) {
      best = cnt;
      memcpy(best_n, c, sizeof best_n);
      best_d = dc;
    }
  }
  if (2 * best < TT_MIN_PLANE) return 0;
  memcpy(n, best_n, sizeof best_n);
  *d = best_d;
  size_t m = 0;
  for (int pass = 0; pass < 3; pass++) {
    double tol = pass == 0 ? TT_PLANE_TOL_M : 2.5 * (*rms > 5e-4 ? *rms : 5e-4);
    m = 0;
    for (size_t i = 0; i < nb; i++) {
      double q[3] = {bg[3 * i], bg[3 * i + 1], bg[3 * i + 2]};
      if (fabs(hearth_dot3(n, q) + *d) < tol) idx[m++] = i;
    }
    if (m < TT_MIN_PLANE) break;
    fit_plane(bg, idx, m, n, d);
    if (*d < 0) {
      for (int k = 0; k < 3; k++) n[k] = -n[k];
      *d = -*d;
    }
    double ss = 0;
    for (size_t i = 0; i < m; i++) {
      double q[3] = {bg[3 * idx[i]], bg[3 * idx[i] + 1], bg[3 * idx[i] + 2]};
      double e = hearth_dot3(n, q) + *d;
      ss += e * e;
    }
    *rms = sqrt(ss / (double)m);
  }
  return m;
}

/* A wall (the backdrop) among the background points bg[0..nb) (colour
 * frame) of a view: the plane facing the camera (its normal within 45
 * degrees of the optical axis) with the most inliers; its normal, towards
 * the camera, into w. Its inliers, 0 when fewer than TT_MIN_PLANE or it
 * fits worse than TT_PLANE_MAX_RMS_M. */
static size_t wall_plane(const float *bg, size_t nb, uint64_t seed, double w[3]) {
  if (nb < TT_MIN_PLANE) return 0;
  size_t *idx = malloc(nb * sizeof *idx);
  if (!idx) return 0;
  double n[3], d, rms;
  size_t m = facing_plane(bg, nb, seed, 2, 0.7, idx, n, &d, &rms);
  free(idx);
  if (m < TT_MIN_PLANE || rms > TT_PLANE_MAX_RMS_M) return 0;
  memcpy(w, n, sizeof n);
  return m;
}

/* The table plane among the background points bg[0..nb) (colour frame):
 * the plane facing up in the image (normal towards the camera with
 * -y > 0.3) with the most inliers (facing_plane). Fills v's plane fields
 * and levelling; 0 when none is found. */
static int table_plane(tt_view *v, const float *bg, size_t nb, uint64_t seed) {
  if (nb < TT_MIN_PLANE) return 0;
  size_t *idx = malloc(nb * sizeof *idx);
  if (!idx) return 0;
  double n[3], d;
  size_t m = facing_plane(bg, nb, seed, 1, 0.3, idx, n, &d, &v->plane_rms);
  if (m >= TT_MIN_PLANE) {
    size_t step = m > TT_PLANE_SAMPLES ? (m + TT_PLANE_SAMPLES - 1) / TT_PLANE_SAMPLES : 1;
    v->pl = malloc((m / step + 1) * 3 * sizeof(float));
    for (size_t i = 0; v->pl && i < m; i += step) {
      for (int a = 0; a < 3; a++) v->pl[3 * v->npl + a] = bg[3 * idx[i] + a];
      v->npl++;
    }
  }
  free(idx);
  if (m < TT_MIN_PLANE || !v->pl) return 0;
  v->n_plane = m;
  v->height = d;
  set_level(v, n);
  return 1;
}

/* levelling from the table normal n (colour frame): forward = the optical
 * axis made horizontal, up = n */
static void set_level(tt_view *v, const double n[3]) {
  double z[3] = {0, 0, 1}, f[3], s[3];
  double zn = hearth_dot3(z, n);
  for (int k = 0; k < 3; k++) f[k] = z[k] - zn * n[k];
  double lf = hearth_norm3(f);
  for (int k = 0; k < 3; k++) f[k] /= lf;
  hearth_cross3(n, f, s);
  for (int k = 0; k < 3; k++) {
    v->L[k] = f[k];
    v->L[3 + k] = s[k];
    v->L[6 + k] = n[k];
  }
}

/* Whether v's plane fits within TT_PLANE_MAX_RMS_M and the object stands
 * on it: at least TT_ON_TABLE_SHARE of
 * its points (cls 1 of pts) lie within TT_ON_TABLE_M above it and few
 * below it. A backdrop or a far floor found instead of a turntable seen at
 * grazing incidence fails. */
static int plane_holds_object(const tt_view *v, const float *pts, const uint8_t *cls, size_t n) {
  size_t no = 0, low = 0, under = 0;
  for (size_t p = 0; p < n; p++) {
    if (cls[p] != 1) continue;
    double q[3] = {pts[3 * p], pts[3 * p + 1], pts[3 * p + 2]};
    double h = hearth_dot3(&v->L[6], q) + v->height;
    no++;
    low += h < TT_ON_TABLE_M;
    under += h < -TT_ON_TABLE_M;
  }
  return no && v->plane_rms <= TT_PLANE_MAX_RMS_M &&
         (double)low >= TT_ON_TABLE_SHARE * (double)no && 20 * under <= no;
}

static void tilt_axis(const tt_view *v, size_t nv, int planed, double u[3]);

static int cmp_double(const void *a, const void *b);

/* The walls against the table (TT_WALL_VERTICAL_DEG): the check's figures
 * into res; afterwards only the views without a table, or with a weak one,
 * keep their wall, and none when the check fails or o->wall_prior is 0. */
static hearth_status check_walls(tt_view *v, size_t nv, const hearth_turntable_opts *o,
                                 hearth_turntable_result *res, hearth_err *err) {
  double *ang = malloc((nv ? nv : 1) * sizeof *ang);
  if (!ang) return hearth_err_set(err, HEARTH_E_NOMEM, "turntable: walls");
  size_t k = 0;
  for (size_t i = 0; i < nv; i++)
    if (v[i].n_plane >= TT_WEAK_PLANE && v[i].n_wall)
      ang[k++] = asin(fmin(1.0, fabs(hearth_dot3(v[i].wall, &v[i].L[6])))) / TT_DEG;
  qsort(ang, k, sizeof *ang, cmp_double);
  res->n_wall_check_views = k;
  res->wall_tilt_deg = k ? (k % 2 ? ang[k / 2] : 0.5 * (ang[k / 2 - 1] + ang[k / 2])) : NAN;
  free(ang);
  /* the term off: no wall levels a view, not even its start */
  int vertical = o->wall_prior > 0 && (!k || res->wall_tilt_deg <= TT_WALL_VERTICAL_DEG);
  res->n_wall_views = 0;
  for (size_t i = 0; i < nv; i++) {
    if (v[i].n_plane >= TT_WEAK_PLANE || !vertical) v[i].n_wall = 0;
    res->n_wall_views += v[i].n_wall != 0;
  }
  return HEARTH_OK;
}

/* The table normal n (colour frame) of a view without a table that sees
 * a wall (taken as vertical, its normal w): normal to w and to the rig's
 * tilt axis u (both horizontal), up in the image. 0 when it sees none or
 * the two are too close to parallel. */
static int wall_level(const tt_view *v, const double u[3], double n[3]) {
  if (!v->n_wall) return 0;
  double c[3];
  hearth_cross3(u, v->wall, c);
  double ln = hearth_norm3(c);
  if (ln < 0.5) return 0;
  if (c[1] > 0) ln = -ln;
  for (int a = 0; a < 3; a++) n[a] = c[a] / ln;
  return 1;
}

/* Rings where no view found the table (a flat object seen low: the
 * turntable at grazing incidence): each of their views levelled as a wall
 * it sees has it (wall_level), else at the elevation the rings with
 * planes give its index (their mean elevations fit linearly in the index,
 * or the one such ring's) with its table normal normal to the rig's tilt
 * axis u; placed at the height where its object points' mean stands as
 * high over the table as in the planed views. No plane term holds them:
 * the joint ICP against the other rings' views (with the wall and roll
 * terms) settles them. An error naming the first view when no view at all
 * has a plane. */
static hearth_status free_rings(tt_view *v, size_t nv, const double u[3], size_t *n_free,
                                hearth_err *err) {
  double hobj = 0, wobj = 0, roll = 0, S0 = 0, S1 = 0, S2 = 0, T0 = 0, T1 = 0;
  size_t bg = 0;
  for (size_t i = 0; i < nv; i++) {
    bg += v[i].bg_points;
    if (!v[i].n_plane) continue;
    double w = (double)v[i].n_plane;
    hobj += w * (v[i].height + hearth_dot3(&v[i].L[6], v[i].centroid));
    roll += w * v[i].L[6];
    wobj += w;
    int first = 1;
    for (size_t j = 0; j < i && first; j++)
      first = !(v[j].n_plane && v[j].elevation_index == v[i].elevation_index);
    if (!first) continue;
    /* the ring's mean elevation (the optical axis below the horizon) */
    double el = 0, we = 0;
    for (size_t j = i; j < nv; j++)
      if (v[j].n_plane && v[j].elevation_index == v[i].elevation_index) {
        el += (double)v[j].n_plane * asin(fmax(-1.0, fmin(1.0, -v[j].L[8])));
        we += (double)v[j].n_plane;
      }
    double e = v[i].elevation_index;
    S0 += 1;
    S1 += e;
    S2 += e * e;
    T0 += el / we;
    T1 += e * el / we;
  }
  if (!(wobj > 0))
    return hearth_err_set(err, HEARTH_E_NUMERIC,
                          "%s: no turntable plane found in any of the %zu views' depth (%zu "
                          "pixels off the cut-outs in all): the views cannot be levelled",
                          nv ? v[0].depth_path : "turntable", nv, bg);
  hobj /= wobj;
  roll /= wobj;
  double den = S0 * S2 - S1 * S1, slope = den > 1e-9 ? (S0 * T1 - S1 * T0) / den : 0;
  double icpt = (T0 - slope * S1) / S0;
  for (size_t i = 0; i < nv; i++) {
    int any = 0;
    for (size_t j = 0; j < nv && !any; j++)
      any = v[j].n_plane && v[j].elevation_index == v[i].elevation_index;
    if (any) continue;
    double el = fmax(1.0 * TT_DEG, fmin(85.0 * TT_DEG, icpt + slope * v[i].elevation_index));
    double n[3] = {roll, 0, -sin(el)};
    n[1] = -sqrt(fmax(0.0, 1.0 - n[0] * n[0] - n[2] * n[2]));
    double nu = hearth_dot3(n, u), ln = 0;
    for (int a = 0; a < 3; a++) n[a] -= nu * u[a];
    ln = hearth_norm3(n);
    for (int a = 0; a < 3; a++) n[a] /= ln;
    double nw[3];
    if (wall_level(&v[i], u, nw)) memcpy(n, nw, sizeof n);
    set_level(&v[i], n);
    v[i].height = hobj - hearth_dot3(n, v[i].centroid);
    v[i].free_ring = 1;
    (*n_free)++;
  }
  return HEARTH_OK;
}

/* pose from the parameters */
static void tt_pose(tt_view *v) {
  double c = cos(v->psi), s = sin(v->psi);
  double Rz[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
  hearth_mat3_mul(Rz, v->L, v->T.R);
  v->T.t[0] = v->x;
  v->T.t[1] = v->y;
  v->T.t[2] = v->height;
}

/* Load one view: depth, its intrinsics, the cut-out; object points (inside
 * the cut-out by erode_px colour pixels, off depth edges) with normals from
 * a window fit, background points for the table plane. */
/* The depth rays of the last camera asked for, kept while views share
 * their intrinsics (undistorting every pixel is most of a view's load). */
typedef struct tt_rays {
  hearth_camera cam;
  float *dirs; /* 3 * width * height, or NULL */
} tt_rays;

static const float *rays_for(tt_rays *r, const hearth_camera *cam) {
  if (r->dirs && !memcmp(&r->cam, cam, sizeof *cam)) return r->dirs;
  free(r->dirs);
  r->cam = *cam;
  r->dirs = malloc((size_t)cam->width * cam->height * 3 * sizeof(float));
  if (r->dirs) hearth_camera_ray_grid(cam, 1, r->dirs);
  return r->dirs;
}

static hearth_status load_view(tt_view *v, const char *dir, const hearth_view_files *vf,
                               const hearth_camera *rgb, double erode_px, uint64_t seed,
                               tt_rays *rays, hearth_err *err) {
  char path[1400];
  hearth_depth_intrinsics di;
  snprintf(path, sizeof path, "%s/%s", dir, vf->depth_intrinsics);
  if (!hearth_path_exists(path))
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: view %s has no depth intrinsics", path,
                          vf->view);
  hearth_status s = hearth_depth_intrinsics_read(path, &di, err);
  if (s) return s;
  v->dcam = di.depth;
  v->T_depth_from_rgb = di.T_depth_from_rgb;
  snprintf(v->depth_path, sizeof v->depth_path, "%s/%s", dir, vf->depth);
  if (!hearth_path_exists(v->depth_path))
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: view %s has no depth map", v->depth_path,
                          vf->view);
  hearth_image depth = {0}, cut = {0};
  if ((s = hearth_png_read(v->depth_path, &depth, err))) return s;
  const int W = v->dcam.width, H = v->dcam.height;
  if (depth.type != HEARTH_PIX_U16 || depth.channels != 1 || depth.width != (size_t)W ||
      depth.height != (size_t)H) {
    hearth_image_free(&depth);
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: expected a %dx%d 1-channel 16-bit depth image",
                          v->depth_path, W, H);
  }
  snprintf(path, sizeof path, "%s/%s", dir, vf->cutout);
  if ((s = hearth_png_read(path, &cut, err))) {
    hearth_image_free(&depth);
    return s;
  }
  if (cut.width != (size_t)rgb->width || cut.height != (size_t)rgb->height) {
    s = hearth_err_set(err, HEARTH_E_SIZE, "%s: %zux%zu, the colour camera is %dx%d", path,
                       cut.width, cut.height, rgb->width, rgb->height);
    hearth_image_free(&depth);
    hearth_image_free(&cut);
    return s;
  }
  const int CW = rgb->width, CH = rgb->height;
  uint8_t *on = malloc((size_t)CW * CH);
  const float *rd = rays_for(rays, &v->dcam);
  float *dirs = malloc((size_t)W * H * 3 * sizeof(float)); /* background points */
  float *pts = malloc((size_t)W * H * 3 * sizeof(float));  /* colour frame, NaN: none */
  uint8_t *cls = calloc((size_t)W * H, 1);                 /* 1 object, 2 + margin background */
  if (!on || !rd || !dirs || !pts || !cls) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s", v->depth_path);
    goto done;
  }
  size_t n_cut = 0;
  for (size_t p = 0; p < (size_t)CW * CH; p++) n_cut += on[p] = (uint8_t)rc_cutout_at(&cut, p);
  if (!n_cut) {
    s = hearth_err_set(err, HEARTH_E_INCONSISTENT, "%s: the cut-out is empty", path);
    goto done;
  }
  hearth_rigid T_rgb_from_depth;
  hearth_rigid_inverse(&v->T_depth_from_rgb, &T_rgb_from_depth);
  const uint16_t *dp = depth.data;
  const int E = (int)ceil(erode_px);
  int bx0 = W, by0 = H, bx1 = -1, by1 = -1;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      size_t p = (size_t)y * W + x;
      pts[3 * p] = NAN;
      const float *d = rd + 3 * p;
      if (!dp[p] || !isfinite(d[0]) || d[2] <= 0) continue;
      double z = dp[p] * 0.001;
      double pd[3] = {d[0] / d[2] * z, d[1] / d[2] * z, z}, pr[3], uv[2];
      hearth_rigid_apply(&T_rgb_from_depth, pd, pr);
      for (int a = 0; a < 3; a++) pts[3 * p + a] = (float)pr[a];
      int edge = x == 0 || y == 0 || x == W - 1 || y == H - 1;
      for (int q = 0; q < 4 && !edge; q++) {
        size_t pn = q == 0 ? p - 1 : q == 1 ? p + 1 : q == 2 ? p - W : p + W;
        int dd = (int)dp[pn] - (int)dp[p];
        edge = !dp[pn] || dd > TT_EDGE_MM || dd < -TT_EDGE_MM;
      }
      int in = 0, near = 0, margin = -1;
      if (hearth_camera_project(rgb, pr, uv, NULL)) {
        long u = lround(uv[0]), w = lround(uv[1]);
        if (u >= 0 && w >= 0 && u < CW && w < CH && on[(size_t)w * CW + u]) {
          near = 1;
          in = 1;
          const int off[4][2] = {{E, 0}, {-E, 0}, {0, E}, {0, -E}};
          for (int k = 0; k < 4 && in; k++) {
            long uu = u + off[k][0], ww = w + off[k][1];
            in = uu >= 0 && ww >= 0 && uu < CW && ww < CH && on[(size_t)ww * CW + uu];
          }
        } else if (u >= 0 && w >= 0 && u < CW && w < CH) {
          /* background; its margin: 2 beyond 3 E of the cut-out, 1
           * beyond E, 0 closer */
          for (int reach = 3; reach >= 1 && margin < 0; reach -= 2) {
            const int off[4][2] = {{reach * E, 0}, {-reach * E, 0}, {0, reach * E}, {0, -reach * E}};
            int hit = 0;
            for (int k = 0; k < 4 && !hit; k++) {
              long uu = u + off[k][0], ww = w + off[k][1];
              hit = uu >= 0 && ww >= 0 && uu < CW && ww < CH && on[(size_t)ww * CW + uu];
            }
            if (!hit) margin = reach == 3 ? 2 : 1;
          }
          if (margin < 0) margin = 0;
        } else {
          near = 1;
        }
      }
      if (in && !edge) {
        cls[p] = 1;
        if (x < bx0) bx0 = x;
        if (y < by0) by0 = y;
        if (x > bx1) bx1 = x;
        if (y > by1) by1 = y;
      } else if (!near && margin >= 0 && !edge && (x % 2 == 0) && (y % 2 == 0)) {
        cls[p] = (uint8_t)(2 + margin);
      }
    }
  /* background points for the plane: those within TT_PLANE_NEAR_M of the
   * object's points' mean (the turntable top around it, not a backdrop or
   * far table seen at grazing incidence), or all when too few are */
  double om[3] = {0, 0, 0};
  size_t no = 0;
  for (size_t p = 0; p < (size_t)W * H; p++)
    if (cls[p] == 1) {
      for (int a = 0; a < 3; a++) om[a] += pts[3 * p + a];
      no++;
    }
  for (int a = 0; a < 3; a++) om[a] /= no ? (double)no : 1.0;
  /* the background kept clear of the cut-out by 3 E first (its blurred
   * rim), then by E, then all of it: a flat object seen low may leave only
   * a thin band of turntable around it inside the depth camera's range */
  size_t nb = 0, nb_all = 0;
  int found = 0;
  for (int pass = 0; pass < 2 && !found; pass++)
    for (int margin = 2; margin >= 0 && !found; margin--) {
      nb = 0;
      for (size_t p = 0; p < (size_t)W * H; p++) {
        if (cls[p] < 2 + margin) continue;
        double d[3] = {pts[3 * p] - om[0], pts[3 * p + 1] - om[1], pts[3 * p + 2] - om[2]};
        if (pass == 0 && no && hearth_norm3(d) > TT_PLANE_NEAR_M) continue;
        for (int a = 0; a < 3; a++) dirs[3 * nb + a] = pts[3 * p + a];
        nb++;
      }
      if (nb > nb_all) nb_all = nb;
      found = table_plane(v, dirs, nb, seed) && plane_holds_object(v, pts, cls, (size_t)W * H);
      if (!found) { /* a plane the object does not stand on is no table */
        free(v->pl);
        v->pl = NULL;
        v->npl = v->n_plane = 0;
        v->plane_rms = 0;
      }
    }
  /* none: the view takes its ring's plane once every view is loaded; a
   * wall (the backdrop) it sees, taken as vertical, tilts it, and one
   * with a weak plane. Every view looks for the wall: those with a table
   * check that it stands vertical (check_walls) */
  v->bg_points = nb_all;
  {
    /* off the table: a turntable seen from above faces the camera too */
    nb = 0;
    for (size_t p = 0; p < (size_t)W * H; p++) {
      if (cls[p] < 2) continue;
      if (v->n_plane) {
        double q[3] = {pts[3 * p], pts[3 * p + 1], pts[3 * p + 2]};
        if (fabs(hearth_dot3(&v->L[6], q) + v->height) < TT_PLANE_TOL_M) continue;
      }
      for (int a = 0; a < 3; a++) dirs[3 * nb + a] = pts[3 * p + a];
      nb++;
    }
    v->n_wall = wall_plane(dirs, nb, seed ^ 0x77616c6cULL, v->wall);
  }
  if (bx1 < 0) {
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                       "%s: no depth pixel lies inside the cut-out %s (of view %s)", v->depth_path,
                       path, vf->view);
    goto done;
  }
  v->x0 = bx0;
  v->y0 = by0;
  v->cw = bx1 - bx0 + 1;
  v->ch = by1 - by0 + 1;
  v->index = malloc((size_t)v->cw * v->ch * sizeof *v->index);
  size_t cnt = 0;
  for (size_t p = 0; p < (size_t)W * H; p++) cnt += cls[p] == 1;
  v->p = malloc(cnt * 3 * sizeof(float));
  v->nrm = malloc(cnt * 3 * sizeof(float));
  if (!v->index || !v->p || !v->nrm) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s", v->depth_path);
    goto done;
  }
  double csum[3] = {0, 0, 0};
  for (int y = by0; y <= by1; y++)
    for (int x = bx0; x <= bx1; x++) {
      size_t p = (size_t)y * W + x;
      int32_t *ix = &v->index[(size_t)(y - by0) * v->cw + (x - bx0)];
      *ix = -1;
      if (cls[p] != 1) continue;
      /* normal: the window's points within 2 * TT_EDGE_MM of the centre */
      double mu[3] = {0, 0, 0}, C[9] = {0};
      int m = 0;
      for (int dy = -TT_NORMAL_R; dy <= TT_NORMAL_R; dy++)
        for (int dx = -TT_NORMAL_R; dx <= TT_NORMAL_R; dx++) {
          int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
          size_t q = (size_t)yy * W + xx;
          if (!dp[q] || abs((int)dp[q] - (int)dp[p]) > 2 * TT_EDGE_MM || !isfinite(pts[3 * q]))
            continue;
          for (int a = 0; a < 3; a++) mu[a] += pts[3 * q + a];
          m++;
        }
      if (m < 12) continue;
      for (int a = 0; a < 3; a++) mu[a] /= m;
      for (int dy = -TT_NORMAL_R; dy <= TT_NORMAL_R; dy++)
        for (int dx = -TT_NORMAL_R; dx <= TT_NORMAL_R; dx++) {
          int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
          size_t q = (size_t)yy * W + xx;
          if (!dp[q] || abs((int)dp[q] - (int)dp[p]) > 2 * TT_EDGE_MM || !isfinite(pts[3 * q]))
            continue;
          double e[3];
          for (int a = 0; a < 3; a++) e[a] = pts[3 * q + a] - mu[a];
          for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) C[3 * a + b] += e[a] * e[b];
        }
      double n[3], pc[3] = {pts[3 * p], pts[3 * p + 1], pts[3 * p + 2]};
      smallest_axis(C, n);
      if (hearth_dot3(n, pc) > 0)
        for (int a = 0; a < 3; a++) n[a] = -n[a];
      /* grazing points are noisy: keep those facing the camera */
      if (-hearth_dot3(n, pc) < 0.2 * hearth_norm3(pc)) continue;
      *ix = (int32_t)v->n;
      for (int a = 0; a < 3; a++) {
        v->p[3 * v->n + a] = (float)pc[a];
        v->nrm[3 * v->n + a] = (float)n[a];
        csum[a] += pc[a];
      }
      v->n++;
    }
  if (v->n < TT_MIN_POINTS) {
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                       "%s: only %zu depth pixels inside the cut-out %s (at least %d needed)",
                       v->depth_path, v->n, path, TT_MIN_POINTS);
    goto done;
  }
  for (int a = 0; a < 3; a++) v->centroid[a] = csum[a] / (double)v->n;
done:
  free(on);
  free(dirs);
  free(pts);
  free(cls);
  hearth_image_free(&depth);
  hearth_image_free(&cut);
  return s;
}

/* the view's colour image for the photometric term, and each object
 * point's band-passed grey in it */
static hearth_status load_colour(tt_view *v, const char *dir, const hearth_view_files *vf,
                                 const hearth_camera *rgb, hearth_err *err) {
  char rgb_path[1400], cut_path[1400];
  snprintf(rgb_path, sizeof rgb_path, "%s/%s", dir, vf->rgb);
  snprintf(cut_path, sizeof cut_path, "%s/%s", dir, vf->cutout);
  hearth_status s = rc_photo_load(rgb_path, cut_path, rgb, &v->photo, err);
  if (s) return s;
  if (!(v->col = malloc((v->n ? v->n : 1) * sizeof *v->col)))
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s", rgb_path);
  for (size_t k = 0; k < v->n; k++) {
    double p[3] = {v->p[3 * k], v->p[3 * k + 1], v->p[3 * k + 2]}, uv[2], val;
    v->col[k] =
        hearth_camera_project(rgb, p, uv, NULL) && rc_photo_sample(&v->photo, uv, &val, NULL)
            ? (float)val
            : NAN;
  }
  return HEARTH_OK;
}

/* ---- joint ICP ------------------------------------------------------------ */
typedef struct tt_pair {
  size_t i, j;
  /* this iteration's normal equations in (w_i, t_i, w_j, t_j): each view's
   * small rotation (world frame) and translation */
  double H[144], g[12];
  double ss, ss_all; /* weighted squared distances, squared distances */
  size_t m;
  float *r; /* |distance| of each match (for the median), m of them */
  /* the photometric term: the gain from view i's band-passed grey to view
   * j's (fit to the last iteration's matches), its sums, matches and
   * weighted squared residuals */
  double gain, s_cc, s_ci, ss_col;
  size_t m_col;
} tt_pair;

typedef struct tt_ctx {
  tt_view *v;
  tt_pair *pairs;
  size_t max_points;
  double gate;
  const hearth_camera *rgb;
  double colour_w;
} tt_ctx;

/* view i's point q (world) against view j's colour image: the residual
 * I_j(project(q)) - gain * c with its Jacobian in (w_i, t_i, w_j, t_j) */
static void colour_term(const tt_ctx *c, tt_pair *pr, const hearth_rigid *Tb_inv, const double q[3],
                        double col) {
  const tt_view *a = &c->v[pr->i], *b = &c->v[pr->j];
  double X[3], uv[2], val, gr[2];
  hearth_project_jac jac;
  hearth_rigid_apply(Tb_inv, q, X);
  if (!hearth_camera_project(c->rgb, X, uv, &jac)) return;
  if (!rc_photo_sample(&b->photo, uv, &val, gr)) return;
  pr->s_cc += col * col;
  pr->s_ci += col * val;
  double r = val - pr->gain * col;
  if (fabs(r) > TT_COLOUR_GATE) return;
  /* dI/dX (camera j), then world: g = R_j (J^T grad) */
  double gX[3], g[3];
  for (int k = 0; k < 3; k++) gX[k] = gr[0] * jac.d_point[k] + gr[1] * jac.d_point[3 + k];
  hearth_rigid_rotate(&b->T, gX, g);
  double qa[3] = {q[0] - a->T.t[0], q[1] - a->T.t[1], q[2] - a->T.t[2]};
  double qb[3] = {q[0] - b->T.t[0], q[1] - b->T.t[1], q[2] - b->T.t[2]};
  double J[12], ci[3], cj[3];
  hearth_cross3(qa, g, ci);
  hearth_cross3(qb, g, cj);
  for (int x = 0; x < 3; x++) {
    J[x] = ci[x];
    J[3 + x] = g[x];
    J[6 + x] = -cj[x];
    J[9 + x] = -g[x];
  }
  double wgt = c->colour_w * (fabs(r) <= TT_COLOUR_HUBER ? 1.0 : TT_COLOUR_HUBER / fabs(r));
  for (int x = 0; x < 12; x++) {
    pr->g[x] += wgt * J[x] * r;
    for (int y = 0; y < 12; y++) pr->H[12 * x + y] += wgt * J[x] * J[y];
  }
  pr->ss_col += r * r;
  pr->m_col++;
}

/* matches of view i's points in view j's depth image, accumulated */
static void pair_system(const tt_ctx *c, tt_pair *pr) {
  const tt_view *a = &c->v[pr->i], *b = &c->v[pr->j];
  memset(pr->H, 0, sizeof pr->H);
  memset(pr->g, 0, sizeof pr->g);
  pr->ss = pr->ss_all = 0;
  pr->m = 0;
  pr->s_cc = pr->s_ci = pr->ss_col = 0;
  pr->m_col = 0;
  int colour = c->colour_w > 0 && a->col && b->photo.img;
  hearth_rigid Tb_inv, T_depth_from_world;
  hearth_rigid_inverse(&b->T, &Tb_inv);
  hearth_rigid_compose(&b->T_depth_from_rgb, &Tb_inv, &T_depth_from_world);
  size_t step = a->n > c->max_points ? (a->n + c->max_points - 1) / c->max_points : 1;
  for (size_t k = 0; k < a->n; k += step) {
    double pa[3] = {a->p[3 * k], a->p[3 * k + 1], a->p[3 * k + 2]}, q[3], qd[3], uv[2];
    hearth_rigid_apply(&a->T, pa, q);
    hearth_rigid_apply(&T_depth_from_world, q, qd);
    if (!hearth_camera_project(&b->dcam, qd, uv, NULL)) continue;
    long u = lround(uv[0]) - b->x0, w = lround(uv[1]) - b->y0;
    if (u < 0 || w < 0 || u >= b->cw || w >= b->ch) continue;
    int32_t t = b->index[(size_t)w * b->cw + u];
    if (t < 0) continue;
    double pb[3] = {b->p[3 * t], b->p[3 * t + 1], b->p[3 * t + 2]};
    double nb[3] = {b->nrm[3 * t], b->nrm[3 * t + 1], b->nrm[3 * t + 2]};
    double na[3] = {a->nrm[3 * k], a->nrm[3 * k + 1], a->nrm[3 * k + 2]};
    double qb[3], nw[3], naw[3];
    hearth_rigid_apply(&b->T, pb, qb);
    hearth_rigid_rotate(&b->T, nb, nw);
    hearth_rigid_rotate(&a->T, na, naw);
    if (hearth_dot3(nw, naw) < TT_NORMAL_COS) continue;
    double e[3] = {q[0] - qb[0], q[1] - qb[1], q[2] - qb[2]};
    double r = hearth_dot3(nw, e);
    if (fabs(r) > c->gate || hearth_norm3(e) > 2.0 * c->gate) continue;
    double wgt = fabs(r) <= TT_HUBER_M ? 1.0 : TT_HUBER_M / fabs(r);
    /* q moves by w_i x (q - t_i) + d_i; the target point and normal turn
     * with view j: d r / d w_j = -(q - t_j) x n, d r / d t_j = -n */
    double qa_rel[3] = {q[0] - a->T.t[0], q[1] - a->T.t[1], q[2] - a->T.t[2]};
    double qj_rel[3] = {q[0] - b->T.t[0], q[1] - b->T.t[1], q[2] - b->T.t[2]};
    double J[12], ci[3], cj[3];
    hearth_cross3(qa_rel, nw, ci);
    hearth_cross3(qj_rel, nw, cj);
    for (int x = 0; x < 3; x++) {
      J[x] = ci[x];
      J[3 + x] = nw[x];
      J[6 + x] = -cj[x];
      J[9 + x] = -nw[x];
    }
    for (int x = 0; x < 12; x++) {
      pr->g[x] += wgt * J[x] * r;
      for (int y = 0; y < 12; y++) pr->H[12 * x + y] += wgt * J[x] * J[y];
    }
    pr->ss += wgt * r * r;
    pr->ss_all += r * r;
    if (pr->r) pr->r[pr->m] = (float)fabs(r);
    pr->m++;
    if (colour && !isnan(a->col[k])) colour_term(c, pr, &Tb_inv, q, a->col[k]);
  }
  /* the gain for the next iteration */
  if (colour && pr->s_cc > 0) pr->gain = fmin(2.0, fmax(0.5, pr->s_ci / pr->s_cc));
}

static void pairs_range(void *vctx, size_t b, size_t e, int ti) {
  (void)ti;
  const tt_ctx *c = vctx;
  for (size_t k = b; k < e; k++) pair_system(c, &c->pairs[k]);
}

/* Cholesky solve of the n x n system A x = b in place (A overwritten);
 * 0 when A is not positive definite */
static int chol_solve(double *A, double *b, size_t n) {
  for (size_t j = 0; j < n; j++) {
    double s = A[j * n + j];
    for (size_t k = 0; k < j; k++) s -= A[j * n + k] * A[j * n + k];
    if (!(s > 0)) return 0;
    double d = sqrt(s);
    A[j * n + j] = d;
    for (size_t i = j + 1; i < n; i++) {
      double t = A[i * n + j];
      for (size_t k = 0; k < j; k++) t -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = t / d;
    }
  }
  for (size_t i = 0; i < n; i++) {
    double t = b[i];
    for (size_t k = 0; k < i; k++) t -= A[i * n + k] * b[k];
    b[i] = t / A[i * n + i];
  }
  for (size_t i = n; i-- > 0;) {
    double t = b[i];
    for (size_t k = i + 1; k < n; k++) t -= A[k * n + i] * b[k];
    b[i] = t / A[i * n + i];
  }
  return 1;
}

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

static void mat3_vec(const double R[9], const double x[3], double y[3]) {
  for (int a = 0; a < 3; a++) y[a] = R[3 * a] * x[0] + R[3 * a + 1] * x[1] + R[3 * a + 2] * x[2];
}

/* the heading about the vertical of the tilt axis u (camera frame) of view
 * v in the world */
static double heading(const tt_view *v, const double u[3]) {
  double d[3];
  mat3_vec(v->T.R, u, d);
  return atan2(d[1], d[0]);
}

/* The camera's tilt axis in its own frame: the direction that stays
 * horizontal in every view, the one normal to all the views' table normals
 * (their scatter's smallest axis) when the elevations differ enough to fix
 * it, else the camera's x axis made normal to their mean; signed along +x.
 * A turntable camera tilts about it between rings, so its heading moves
 * with the turntable angle alone at every elevation. */
static void tilt_axis(const tt_view *v, size_t nv, int planed, double u[3]) {
  double C[9] = {0}, m[3] = {0, 0, 0};
  size_t cnt = 0;
  for (size_t i = 0; i < nv; i++) {
    if (planed && !v[i].n_plane) continue;
    cnt++;
    for (int a = 0; a < 3; a++) {
      m[a] += v[i].L[6 + a];
      for (int b = 0; b < 3; b++) C[3 * a + b] += v[i].L[6 + a] * v[i].L[6 + b];
    }
  }
  double w[3], V[9];
  sym3_eigen(C, w, V);
  int k = 0;
  for (int i = 1; i < 3; i++)
    if (w[i] < w[k]) k = i;
  double w1 = INFINITY;
  for (int i = 0; i < 3; i++)
    if (i != k && w[i] < w1) w1 = w[i];
  /* normals spread by 10 degrees or more about the mean */
  if (!cnt) {
    u[0] = 1;
    u[1] = u[2] = 0;
    return;
  }
  if (w1 > (double)cnt * pow(sin(10.0 * TT_DEG), 2) / 2.0) {
    for (int a = 0; a < 3; a++) u[a] = V[3 * a + k];
  } else {
    double lm = hearth_norm3(m);
    for (int a = 0; a < 3; a++) m[a] /= lm;
    for (int a = 0; a < 3; a++) u[a] = (a == 0) - m[0] * m[a];
  }
  double lu = hearth_norm3(u);
  for (int a = 0; a < 3; a++) u[a] /= (u[0] < 0 ? -lu : lu);
}

/* view v's optical axis (unit, world) */
static void view_dir(const tt_view *v, double d[3]) {
  for (int a = 0; a < 3; a++) d[a] = v->T.R[3 * a + 2];
}

/* ---- the aim term -----------------------------------------------------------
 * The rig aims its cameras at the object and the turntable turns the
 * object under them, so a point C on the axis (where the aim meets it)
 * lies at one place P in every camera's frame: sideways and up in the
 * image (x, y) all but exactly, along the optical axis (z) within the
 * cameras' distance spread. Unknowns beside the poses: C per state (the
 * object may move between states) and P, one for all views (the rig aims
 * every ring at one point) or one per ring (aim_per_ring). */
typedef struct tt_aim {
  size_t n_states, n_groups;
  double C[3 * HEARTH_MAX_STATES];
  double *P; /* 3 * n_groups, camera frame */
} tt_aim;

/* view i's group, -1: not in the term (a ring of fewer than 3 views) */
static int aim_group(const tt_view *v, size_t nv, size_t i, int per_ring, int *elev, size_t *ne) {
  if (!per_ring) return 0;
  size_t cnt = 0, k = 0;
  for (size_t j = 0; j < nv; j++) cnt += v[j].elevation_index == v[i].elevation_index;
  if (cnt < 3) return -1;
  while (k < *ne && elev[k] != v[i].elevation_index) k++;
  if (k == *ne) elev[(*ne)++] = v[i].elevation_index;
  return (int)k;
}

/* The groups, and C and P started from the current poses by least squares
 * (sum over views of |C - t_i - R_i P|^2, a small ridge for a state or group
 * that fixes nothing). 0: no term (too few views, or no memory). */
static int aim_setup(tt_view *v, size_t nv, size_t n_states, int per_ring, tt_aim *am) {
  memset(am, 0, sizeof *am);
  am->n_states = n_states < HEARTH_MAX_STATES ? n_states : HEARTH_MAX_STATES;
  int *elev = malloc((nv ? nv : 1) * sizeof *elev);
  if (!elev) return 0;
  size_t ne = 0, used = 0;
  for (size_t i = 0; i < nv; i++) {
    v[i].ring = v[i].state_no < am->n_states ? aim_group(v, nv, i, per_ring, elev, &ne) : -1;
    used += v[i].ring >= 0;
  }
  free(elev);
  am->n_groups = per_ring ? ne : 1;
  if (used < 3 || !am->n_groups) return 0;
  const size_t n = 3 * (am->n_states + am->n_groups), p0 = 3 * am->n_states;
  double *M = calloc(n * n, sizeof *M), *r = calloc(n, sizeof *r);
  am->P = calloc(3 * am->n_groups, sizeof *am->P);
  int ok = M && r && am->P;
  for (size_t i = 0; ok && i < nv; i++) {
    if (v[i].ring < 0) continue;
    /* residual C - t - R P: rows a, unknowns C_a (+1) and P_b (-R_ab) */
    size_t c = 3 * v[i].state_no, q = p0 + 3 * (size_t)v[i].ring;
    for (int a = 0; a < 3; a++) {
      double J[4] = {1.0, -v[i].T.R[3 * a], -v[i].T.R[3 * a + 1], -v[i].T.R[3 * a + 2]};
      size_t ix[4] = {c + (size_t)a, q, q + 1, q + 2};
      for (int x = 0; x < 4; x++) {
        r[ix[x]] += J[x] * v[i].T.t[a];
        for (int y = 0; y < 4; y++) M[ix[x] * n + ix[y]] += J[x] * J[y];
      }
    }
  }
  for (size_t d = 0; ok && d < n; d++) M[d * n + d] += 1e-9;
  ok = ok && chol_solve(M, r, n);
  if (ok) {
    memcpy(am->C, r, 3 * am->n_states * sizeof *r);
    memcpy(am->P, r + p0, 3 * am->n_groups * sizeof *r);
  }
  free(M);
  free(r);
  if (!ok) {
    free(am->P);
    am->P = NULL;
  }
  return ok;
}

/* The aim term's normal equations, added to A (nu x nu) and b: per view
 * the residuals g_k . (C - t) - P_k along its camera axes g_k (columns of
 * R): sigma aim_side_m across the optical axis, aim_depth_tol of |P| along
 * it; in the view's rotation and place, its state's C and its group's P
 * (the unknowns after the 6 nv of the poses: C by state, then P by group),
 * each weighted as aim_prior times a view's matches at TT_HUBER_M per
 * sigma. */
static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The object's top: the 99.5th percentile of its points' heights over all
 * views (every 8th point); 0 when there are none */
static double object_top(const tt_view *v, size_t nv) {
  size_t n = 0;
  for (size_t i = 0; i < nv; i++) n += (v[i].n + 7) / 8;
  double *z = malloc((n ? n : 1) * sizeof *z);
  if (!z || !n) {
    free(z);
    return 0;
  }
  size_t m = 0;
  for (size_t i = 0; i < nv; i++)
    for (size_t k = 0; k < v[i].n; k += 8) {
      double p[3] = {v[i].p[3 * k], v[i].p[3 * k + 1], v[i].p[3 * k + 2]}, q[3];
      hearth_rigid_apply(&v[i].T, p, q);
      z[m++] = q[2];
    }
  qsort(z, m, sizeof *z, cmp_double);
  double top = z[(size_t)(0.995 * (double)(m - 1))];
  free(z);
  return top;
}

static void aim_system(const tt_view *v, size_t nv, const tt_aim *am,
                       const hearth_turntable_opts *o, double w_view, double *A, double *b,
                       size_t nu) {
  const size_t c0 = 6 * nv, p0 = c0 + 3 * am->n_states;
  /* the height aimed at: the object's middle (half its top above the
   * turntable), within aim_height_tol of its top (and 2 mm), weighted as
   * all views' matches; without it the aim's height trades against the
   * rings' radii */
  double top = object_top(v, nv);
  double sig_h = fmax(o->aim_height_tol * top, 0.002);
  for (size_t st = 0; st < am->n_states && o->aim_height_tol > 0; st++) {
    size_t ns = 0;
    for (size_t i = 0; i < nv; i++) ns += v[i].ring >= 0 && v[i].state_no == st;
    double w = o->aim_prior * w_view * (double)ns * (TT_HUBER_M / sig_h) * (TT_HUBER_M / sig_h);
    size_t ix = c0 + 3 * st + 2;
    b[ix] -= w * (am->C[3 * st + 2] - 0.5 * top);
    A[ix * nu + ix] += w;
  }
  for (size_t i = 0; i < nv; i++) {
    if (v[i].ring < 0) continue;
    const size_t st = v[i].state_no, g = (size_t)v[i].ring;
    const double *C = &am->C[3 * st], *P = &am->P[3 * g];
    double d[3] = {C[0] - v[i].T.t[0], C[1] - v[i].T.t[1], C[2] - v[i].T.t[2]};
    for (int k = 0; k < 3; k++) {
      double sig = k < 2 ? o->aim_side_m : o->aim_depth_tol * hearth_norm3(P);
      if (!(sig > 0)) continue;
      double gk[3] = {v[i].T.R[k], v[i].T.R[3 + k], v[i].T.R[6 + k]}, gx[3];
      double res = hearth_dot3(gk, d) - P[k];
      /* d g / d w = w x g: d res / d w = g x d */
      hearth_cross3(gk, d, gx);
      double J[10] = {gx[0], gx[1], gx[2], -gk[0], -gk[1], -gk[2], gk[0], gk[1], gk[2], -1.0};
      size_t ix[10] = {6 * i,           6 * i + 1,
                       6 * i + 2,       6 * i + 3,
                       6 * i + 4,       6 * i + 5,
                       c0 + 3 * st,     c0 + 3 * st + 1,
                       c0 + 3 * st + 2, p0 + 3 * g + (size_t)k};
      double w = o->aim_prior * w_view * (TT_HUBER_M / sig) * (TT_HUBER_M / sig);
      for (int x = 0; x < 10; x++) {
        b[ix[x]] -= w * J[x] * res;
        for (int y = 0; y < 10; y++) A[ix[x] * nu + ix[y]] += w * J[x] * J[y];
      }
    }
  }
}

static void aim_sigma(const tt_view *v, size_t nv, const tt_aim *am, const hearth_turntable_opts *o,
                      hearth_turntable_result *res);

/* The aim term's estimate into res: C per state, P per group with the
 * spread of the views' residuals about it (the final poses, C and P). */
static hearth_status aim_result(const tt_view *v, size_t nv, const tt_aim *am,
                                const hearth_turntable_opts *o, hearth_turntable_result *res,
                                hearth_err *err) {
  const int per_ring = o->aim_per_ring;
  res->aim_states = calloc(am->n_states ? am->n_states : 1, sizeof *res->aim_states);
  res->aim_places = calloc(am->n_groups, sizeof *res->aim_places);
  if (!res->aim_states || !res->aim_places) {
    free(res->aim_states);
    free(res->aim_places);
    res->aim_states = NULL;
    res->aim_places = NULL;
    return hearth_err_set(err, HEARTH_E_NOMEM, "turntable: aim point");
  }
  res->n_aim_states = am->n_states;
  res->n_aim_places = am->n_groups;
  for (size_t st = 0; st < am->n_states; st++) {
    hearth_turntable_aim_state *a = &res->aim_states[st];
    for (int k = 0; k < 3; k++) a->point_m[k] = am->C[3 * st + k];
    a->axis_m[0] = a->point_m[0];
    a->axis_m[1] = a->point_m[1];
    a->axis_m[2] = 0;
  }
  for (size_t i = 0; i < nv; i++)
    if (v[i].state_no < am->n_states && !res->aim_states[v[i].state_no].state[0])
      snprintf(res->aim_states[v[i].state_no].state, HEARTH_NAME_MAX, "%s", v[i].state);
  for (size_t g = 0; g < am->n_groups; g++) res->aim_places[g].elevation_index = -1;
  double *ss = calloc(2 * am->n_groups, sizeof *ss);
  if (!ss) return hearth_err_set(err, HEARTH_E_NOMEM, "turntable: aim point");
  for (size_t i = 0; i < nv; i++) {
    if (v[i].ring < 0) continue;
    const size_t st = v[i].state_no, g = (size_t)v[i].ring;
    hearth_turntable_aim_state *a = &res->aim_states[st];
    hearth_turntable_aim_place *pl = &res->aim_places[g];
    a->n_views++;
    pl->n_views++;
    if (per_ring) pl->elevation_index = v[i].elevation_index;
    const double *C = &am->C[3 * st], *P = &am->P[3 * g];
    double d[3] = {C[0] - v[i].T.t[0], C[1] - v[i].T.t[1], C[2] - v[i].T.t[2]}, r[3];
    for (int k = 0; k < 3; k++)
      r[k] = v[i].T.R[k] * d[0] + v[i].T.R[3 + k] * d[1] + v[i].T.R[6 + k] * d[2] - P[k];
    ss[2 * g] += r[0] * r[0] + r[1] * r[1];
    ss[2 * g + 1] += r[2] * r[2];
  }
  for (size_t g = 0; g < am->n_groups; g++) {
    hearth_turntable_aim_place *pl = &res->aim_places[g];
    for (int k = 0; k < 3; k++) pl->camera_m[k] = am->P[3 * g + k];
    double n = pl->n_views ? (double)pl->n_views : 1.0, len = hearth_norm3(pl->camera_m);
    pl->side_rms_m = sqrt(ss[2 * g] / n);
    pl->depth_rms_m = sqrt(ss[2 * g + 1] / n);
    pl->depth_rms_rel = len > 0 ? pl->depth_rms_m / len : 0;
  }
  free(ss);
  aim_sigma(v, nv, am, o, res);
  return HEARTH_OK;
}

/* The standard deviation of each state's C along the axis and across it,
 * into res->aim_states (NAN where it cannot be had). C along the axis is
 * fixed only by the rings' relative placement: raising C by d and moving a
 * ring at elevation e in by d cot e leaves its views' image places of C as
 * they were and shortens their distances by d / sin e, so the rings'
 * different distances (held only within aim_depth_tol) carry it, and the
 * rings' radii are what the depth barely fixes about a surface of
 * revolution (the can's "breathing"). The model: the linearised aim term
 * in C per state, P per group and a free radius per ring (state and
 * elevation: its views moved along their own horizontal direction from
 * the axis), each view's residual weighted by its group's fitted spread
 * (across: side_rms / sqrt 2 per axis, along: depth_rms), with the height
 * prior; the variances are the diagonal of the inverse normal matrix.
 * Where the depth fixes the radii better it should be an upper estimate. */
static void aim_sigma(const tt_view *v, size_t nv, const tt_aim *am, const hearth_turntable_opts *o,
                      hearth_turntable_result *res) {
  for (size_t st = 0; st < am->n_states; st++)
    res->aim_states[st].sigma_along_m = res->aim_states[st].sigma_across_m = NAN;
  /* the rings: (state, elevation) pairs of the views in the term */
  int *ring = malloc((nv ? nv : 1) * sizeof *ring), *key_e = malloc((nv ? nv : 1) * sizeof *key_e);
  size_t *key_s = malloc((nv ? nv : 1) * sizeof *key_s), nr = 0;
  if (!ring || !key_e || !key_s) goto out;
  for (size_t i = 0; i < nv; i++) {
    ring[i] = -1;
    if (v[i].ring < 0) continue;
    size_t k = 0;
    while (k < nr && !(key_s[k] == v[i].state_no && key_e[k] == v[i].elevation_index)) k++;
    if (k == nr) {
      key_s[nr] = v[i].state_no;
      key_e[nr++] = v[i].elevation_index;
    }
    ring[i] = (int)k;
  }
  const size_t p0 = 3 * am->n_states, r0 = p0 + 3 * am->n_groups, n = r0 + nr;
  double *N = calloc(n * n, sizeof *N), *A = malloc(n * n * sizeof *A), *e = malloc(n * sizeof *e);
  if (!N || !A || !e) {
    free(N);
    free(A);
    free(e);
    goto out;
  }
  double top = object_top(v, nv);
  for (size_t i = 0; i < nv; i++) {
    if (ring[i] < 0) continue;
    const size_t st = v[i].state_no, g = (size_t)v[i].ring;
    const hearth_turntable_aim_place *pl = &res->aim_places[g];
    const double floor_m = 1e-6;
    double sx = fmax(pl->side_rms_m / sqrt(2.0), floor_m), sz = fmax(pl->depth_rms_m, floor_m);
    const double *C = &am->C[3 * st];
    double h[3] = {v[i].T.t[0] - C[0], v[i].T.t[1] - C[1], 0}, lh = hypot(h[0], h[1]);
    if (lh > 0) h[0] /= lh, h[1] /= lh;
    for (int k = 0; k < 3; k++) {
      /* residual k = g_k . (C - t) - P_k; the radius moves t along h */
      double gk[3] = {v[i].T.R[k], v[i].T.R[3 + k], v[i].T.R[6 + k]};
      double J[5] = {gk[0], gk[1], gk[2], -1.0, -hearth_dot3(gk, h)};
      size_t ix[5] = {3 * st, 3 * st + 1, 3 * st + 2, p0 + 3 * g + (size_t)k, r0 + (size_t)ring[i]};
      double w = 1.0 / ((k < 2 ? sx : sz) * (k < 2 ? sx : sz));
      for (int a = 0; a < 5; a++)
        for (int b = 0; b < 5; b++) N[ix[a] * n + ix[b]] += w * J[a] * J[b];
    }
  }
  if (o->aim_height_tol > 0) {
    double sig_h = fmax(o->aim_height_tol * top, 0.002);
    for (size_t st = 0; st < am->n_states; st++)
      N[(3 * st + 2) * n + 3 * st + 2] += 1 / (sig_h * sig_h);
  }
  /* a ring or group that fixes nothing: held within 0.1 m */
  for (size_t d = p0; d < n; d++) N[d * n + d] += 100.0;
  for (size_t st = 0; st < am->n_states; st++) {
    if (!res->aim_states[st].n_views) continue;
    double var[3];
    int ok = 1;
    for (int k = 0; k < 3 && ok; k++) {
      memcpy(A, N, n * n * sizeof *A);
      memset(e, 0, n * sizeof *e);
      e[3 * st + (size_t)k] = 1;
      ok = chol_solve(A, e, n);
      var[k] = e[3 * st + (size_t)k];
    }
    if (!ok) continue;
    res->aim_states[st].sigma_along_m = sqrt(var[2]);
    res->aim_states[st].sigma_across_m = sqrt(0.5 * (var[0] + var[1]));
  }
  free(N);
  free(A);
  free(e);
out:
  free(ring);
  free(key_e);
  free(key_s);
}

/* d(R^T e_z) / d w of a view turned by w (world frame) on the left:
 * R^T [e_z]x */
static void up_jacobian(const double R[9], double J[9]) {
  for (int a = 0; a < 3; a++) {
    J[3 * a] = R[3 + a];  /* column 0 of [e_z]x is e_y */
    J[3 * a + 1] = -R[a]; /* column 1 is -e_x */
    J[3 * a + 2] = 0;
  }
}

/* The priors on the tilt of the views without a plane of their own (the
 * wall and roll: or with a weak one, of fewer than TT_WEAK_PLANE inliers),
 * each weighted as its option times a view's matches (w_view), in
 * radians:
 *  - the wall: the normal w of the wall (backdrop) it sees held
 *    horizontal, (R w)_z = 0; its Jacobian in the rotation (R w) x e_z;
 *  - the roll: its table normal in its frame (R^T e_z) held normal to
 *    the rig's tilt axis u (from the views with a table): the rig turns
 *    its cameras between rings about that axis, and the virtual rig's
 *    aim has no roll; with the wall it fixes the tilt;
 *  - the ring: in each ring (elevation index) with such a view that sees
 *    no wall (or with the wall term off), every view's R^T e_z held to the
 *    ring's mean, r_i = n_i - mean(n) (the Jacobian: the centring
 *    projection times each view's R^T [e_z]x), so the ring's views pool
 *    their evidence for one tilt. Off by default: the virtual rig jitters
 *    each view's elevation by up to 0.7 degrees, which the term pulls
 *    together (phone seed 3, 30 views, over all views: rotation max 0.35
 *    degrees at 1 against 0.12 with the walls); without the walls it
 *    lowers the max (seed 3 0.82 to 0.66 degrees, seed 2 1.50 to 1.39)
 *    but not always the median (seed 3 at 10 views: 0.11 to 0.18). */
static void ring_system(const tt_view *v, size_t nv, const double u[3],
                        const hearth_turntable_opts *o, double w_view, double *A, double *b,
                        size_t nu) {
  const double wr = o->ring_tilt_prior * w_view, wl = o->roll_prior * w_view,
               ww = o->wall_prior * w_view;
  /* the wall: a view without a table that sees one holds its normal
   * horizontal, (R w)_z = 0; d / d w_rot = (R w) x e_z */
  for (size_t i = 0; i < nv && ww > 0; i++) {
    if (!v[i].n_wall) continue;
    double Rw[3], J[3], ez[3] = {0, 0, 1};
    hearth_rigid_rotate(&v[i].T, v[i].wall, Rw);
    hearth_cross3(Rw, ez, J);
    for (int x = 0; x < 3; x++) {
      b[6 * i + (size_t)x] -= ww * J[x] * Rw[2];
      for (int y = 0; y < 3; y++)
        A[(6 * i + (size_t)x) * nu + 6 * i + (size_t)y] += ww * J[x] * J[y];
    }
  }
  for (size_t i = 0; i < nv && wl > 0; i++) {
    if (v[i].n_plane >= TT_WEAK_PLANE) continue;
    double Ju[9], J[3];
    up_jacobian(v[i].T.R, Ju);
    double r = hearth_dot3(&v[i].T.R[6], u);
    for (int x = 0; x < 3; x++) J[x] = u[0] * Ju[x] + u[1] * Ju[3 + x] + u[2] * Ju[6 + x];
    for (int x = 0; x < 3; x++) {
      b[6 * i + (size_t)x] -= wl * J[x] * r;
      for (int y = 0; y < 3; y++)
        A[(6 * i + (size_t)x) * nu + 6 * i + (size_t)y] += wl * J[x] * J[y];
    }
  }
  for (size_t i = 0; i < nv && wr > 0; i++) {
    /* the ring's first view starts it, once */
    int first = 1, lacking = 0;
    for (size_t j = 0; j < nv && first; j++)
      first = !(j < i && v[j].elevation_index == v[i].elevation_index);
    if (!first) continue;
    double mean[3] = {0, 0, 0};
    size_t nr = 0;
    for (size_t j = i; j < nv; j++)
      if (v[j].elevation_index == v[i].elevation_index) {
        for (int a = 0; a < 3; a++) mean[a] += v[j].T.R[6 + a];
        lacking |= !v[j].n_plane && !v[j].n_wall; /* no wall kept when ww is 0 */
        nr++;
      }
    if (!lacking || nr < 2) continue;
    for (int a = 0; a < 3; a++) mean[a] /= (double)nr;
    for (size_t j = i; j < nv; j++) {
      if (v[j].elevation_index != v[i].elevation_index) continue;
      double Jj[9], r[3];
      up_jacobian(v[j].T.R, Jj);
      for (int a = 0; a < 3; a++) r[a] = v[j].T.R[6 + a] - mean[a];
      for (int x = 0; x < 3; x++)
        for (int a = 0; a < 3; a++) b[6 * j + (size_t)x] -= wr * Jj[3 * a + x] * r[a];
      for (size_t k = i; k < nv; k++) {
        if (v[k].elevation_index != v[i].elevation_index) continue;
        double Jk[9], c = wr * ((j == k) - 1.0 / (double)nr);
        up_jacobian(v[k].T.R, Jk);
        for (int x = 0; x < 3; x++)
          for (int y = 0; y < 3; y++) {
            double h = 0;
            for (int a = 0; a < 3; a++) h += Jj[3 * a + x] * Jk[3 * a + y];
            A[(6 * j + (size_t)x) * nu + 6 * k + (size_t)y] += c * h;
          }
      }
    }
  }
}

static hearth_status run_icp(tt_view *v, size_t nv, size_t n_states, const double u[3],
                             const double u_rig[3], const hearth_camera *rgb,
                             const hearth_turntable_opts *o, hearth_turntable_result *res,
                             hearth_err *err) {
  const int iterations = o->iterations;
  const double gate0 = 0.025;
  /* pairs: views looking from within max_pair_deg */
  size_t np = 0;
  tt_pair *pairs = calloc(nv * nv, sizeof *pairs);
  if (!pairs) return hearth_err_set(err, HEARTH_E_NOMEM, "turntable: pairs");
  double cmax = cos(o->max_pair_deg * TT_DEG);
  for (size_t i = 0; i < nv; i++)
    for (size_t j = 0; j < nv; j++) {
      if (i == j) continue;
      double di[3], dj[3];
      view_dir(&v[i], di);
      view_dir(&v[j], dj);
      if (hearth_dot3(di, dj) < cmax) continue;
      pairs[np].i = i;
      pairs[np].j = j;
      pairs[np].gain = 1.0;
      np++;
    }
  tt_aim am = {0};
  int aim = o->aim_prior > 0 && aim_setup(v, nv, n_states, o->aim_per_ring, &am);
  const size_t nu = 6 * nv + (aim ? 3 * (am.n_states + am.n_groups) : 0);
  double *A = malloc(nu * nu * sizeof *A), *b = malloc(nu * sizeof *b);
  if (!A || !b) {
    free(A);
    free(b);
    free(am.P);
    free(pairs);
    return hearth_err_set(err, HEARTH_E_NOMEM, "turntable: normal equations");
  }
  hearth_progress prog;
  hearth_progress_begin(&prog, "recon: ICP", (size_t)iterations, o->quiet);
  tt_ctx c = {v, pairs, o->max_points, 0.02, rgb, o->colour_weight};
  hearth_status s = HEARTH_OK;
  double rms = 0;
  for (int it = 0; it < iterations && !s; it++) {
    c.gate = fmax(0.003, gate0 * pow(0.75, it));
    int last = it == iterations - 1;
    if (last)
      for (size_t k = 0; k < np && !s; k++)
        if (!(pairs[k].r = malloc((o->max_points + 1) * sizeof(float))))
          s = hearth_err_set(err, HEARTH_E_NOMEM, "turntable: distances");
    if (s) break;
    if ((s = hearth_parallel_for(np, o->threads, pairs_range, &c))) break;
    memset(A, 0, nu * nu * sizeof *A);
    memset(b, 0, nu * sizeof *b);
    double ss = 0;
    size_t m = 0;
    for (size_t k = 0; k < np; k++) {
      const tt_pair *pr = &pairs[k];
      ss += pr->ss_all;
      m += pr->m;
      size_t ix[2] = {pr->i, pr->j};
      for (int x = 0; x < 12; x++) {
        size_t gx = 6 * ix[x / 6] + (size_t)(x % 6);
        b[gx] -= pr->g[x];
        for (int y = 0; y < 12; y++) {
          A[gx * nu + 6 * ix[y / 6] + (size_t)(y % 6)] += pr->H[12 * x + y];
        }
      }
    }
    rms = m ? sqrt(ss / (double)m) : 0;
    if (it == 0 && res->iterations == 0) res->icp_rms_start_mm = 1000.0 * rms;
    for (size_t vi = 0; vi < nv; vi++) {
      const tt_view *tv = &v[vi];
      double *Av = A + 6 * vi * nu + 6 * vi, *bv = b + 6 * vi;
      /* the plane term: each table point at z = 0, weighted as many
       * matches as it has points, less where the plane fits worse than
       * TT_PLANE_GOOD_M (a table seen at grazing incidence) */
      double pq = TT_PLANE_GOOD_M / fmax(tv->plane_rms, TT_PLANE_GOOD_M);
      double wp = pq * pq * (double)(m / (nv ? nv : 1) + 1) / (double)(tv->npl ? tv->npl : 1);
      for (size_t k = 0; k < tv->npl; k++) {
        double p[3] = {tv->pl[3 * k], tv->pl[3 * k + 1], tv->pl[3 * k + 2]}, q[3];
        hearth_rigid_apply(&tv->T, p, q);
        double r = q[2], qr[3] = {q[0] - tv->T.t[0], q[1] - tv->T.t[1], q[2] - tv->T.t[2]};
        double w = wp * (fabs(r) <= TT_HUBER_M ? 1.0 : TT_HUBER_M / fabs(r));
        double J[6] = {qr[1], -qr[0], 0, 0, 0, 1}; /* (q - t) x ez, ez */
        for (int x = 0; x < 6; x++) {
          bv[x] -= w * J[x] * r;
          for (int y = 0; y < 6; y++) Av[x * nu + y] += w * J[x] * J[y];
        }
      }
      /* the turntable's azimuth as a prior on the heading (weight: the
       * squared ratio of the depth noise to the azimuth's spread), so an
       * angle no match constrains (about a surface of revolution) stays
       * at the turntable's */
      double dh = remainder(heading(tv, u) - tv->target, 2 * TT_PI);
      Av[2 * nu + 2] += o->azimuth_prior;
      bv[2] -= o->azimuth_prior * dh;
    }
    /* the encoder: within each state that records it, the headings'
     * differences held to the encoder's, r_k = dh_k - mean(dh) over the
     * state's views, weighted as encoder_prior times a view's matches (its
     * Jacobian in the headings is the centring projection) */
    double we = o->encoder_prior * (double)(m / (nv ? nv : 1) + 1);
    for (size_t st = 0; st < n_states && we > 0; st++) {
      double mean = 0;
      size_t ns = 0;
      for (size_t vi = 0; vi < nv; vi++)
        if (v[vi].enc && v[vi].state_index == st) {
          mean += remainder(heading(&v[vi], u) - v[vi].target, 2 * TT_PI);
          ns++;
        }
      if (ns < 2) continue;
      mean /= (double)ns;
      for (size_t vi = 0; vi < nv; vi++) {
        if (!v[vi].enc || v[vi].state_index != st) continue;
        size_t gi = 6 * vi + 2;
        b[gi] -= we * (remainder(heading(&v[vi], u) - v[vi].target, 2 * TT_PI) - mean);
        for (size_t vj = 0; vj < nv; vj++)
          if (v[vj].enc && v[vj].state_index == st)
            A[gi * nu + 6 * vj + 2] += we * ((vi == vj) - 1.0 / (double)ns);
      }
    }
    ring_system(v, nv, u_rig, o, (double)(m / (nv ? nv : 1) + 1), A, b, nu);
    /* the gauge: no view is held; the mean of the cameras' horizontal
     * steps is held at zero (weighted as a view's matches), so the frame
     * keeps the start's mean camera position and a view that starts off
     * its neighbours moves like any other */
    double wg = (double)(m / (nv ? nv : 1) + 1);
    for (int a = 3; a < 5; a++)
      for (size_t vi = 0; vi < nv; vi++)
        for (size_t vj = 0; vj < nv; vj++) A[(6 * vi + a) * nu + 6 * vj + a] += wg / (double)nv;
    if (aim) aim_system(v, nv, &am, o, wg, A, b, nu);
    /* a scaled Levenberg term and a small floor */
    for (size_t d = 0; d < nu; d++) A[d * nu + d] = A[d * nu + d] * 1.01 + 1e-6;
    if (!chol_solve(A, b, nu)) {
      s = hearth_err_set(err, HEARTH_E_NUMERIC, "turntable: ICP normal equations not definite");
      break;
    }
    for (size_t vi = 0; vi < nv; vi++) {
      const double *d = b + 6 * vi;
      double dR[9], R[9];
      hearth_rotvec_to_matrix(d, dR);
      hearth_mat3_mul(dR, v[vi].T.R, R);
      hearth_orthonormalize(R);
      memcpy(v[vi].T.R, R, sizeof R);
      for (int a = 0; a < 3; a++) v[vi].T.t[a] += d[3 + a];
    }
    if (aim) {
      for (size_t k = 0; k < 3 * am.n_states; k++) am.C[k] += b[6 * nv + k];
      for (size_t k = 0; k < 3 * am.n_groups; k++) am.P[k] += b[6 * nv + 3 * am.n_states + k];
    }
    if (last && res->views) {
      memset(res->views, 0, nv * sizeof *res->views);
      /* statistics of the final matches (before this step's update) */
      size_t tot = 0;
      for (size_t k = 0; k < np; k++) tot += pairs[k].m;
      float *all = malloc((tot + 1) * sizeof *all);
      size_t off = 0;
      for (size_t k = 0; k < np; k++) {
        tt_pair *pr = &pairs[k];
        res->views[pr->i].n_pairs++;
        res->views[pr->i].n_matches += pr->m;
        double s2 = 0;
        for (size_t q = 0; q < pr->m; q++) s2 += (double)pr->r[q] * pr->r[q];
        res->views[pr->i].icp_rms_mm += s2; /* sum for now */
        if (all) memcpy(all + off, pr->r, pr->m * sizeof *all);
        off += pr->m;
      }
      if (all && tot) {
        qsort(all, tot, sizeof *all, cmp_float);
        res->icp_median_mm = 1000.0 * all[tot / 2];
      }
      free(all);
      for (size_t i = 0; i < nv; i++) {
        hearth_turntable_view *rv = &res->views[i];
        rv->icp_rms_mm = rv->n_matches ? 1000.0 * sqrt(rv->icp_rms_mm / (double)rv->n_matches) : 0;
      }
      res->icp_rms_mm = 1000.0 * rms;
    }
    hearth_progress_step(&prog, 1);
  }
  hearth_progress_end(&prog);
  if (!s && aim) s = aim_result(v, nv, &am, o, res, err);
  res->n_pairs = np;
  res->iterations += iterations;
  for (size_t k = 0; k < np; k++) free(pairs[k].r);
  free(am.P);
  free(pairs);
  free(A);
  free(b);
  return s;
}

/* ---- the job ---------------------------------------------------------------- */
hearth_status hearth_recon_turntable(const char *root, const char *instance,
                                     const char *const *states, size_t n_states,
                                     const hearth_turntable_opts *opts, hearth_poses *out,
                                     hearth_turntable_result *res_out, hearth_err *err) {
  hearth_turntable_opts o;
  if (opts) o = *opts;
  else hearth_turntable_opts_default(&o);
  if (o.iterations < 1) o.iterations = 30;
  if (!o.max_points) o.max_points = 3000;
  if (!(o.max_pair_deg > 0)) o.max_pair_deg = 65;
  if (o.direction != -1) o.direction = 1;
  if (!o.threads) o.threads = hearth_default_threads();
  memset(out, 0, sizeof *out);
  hearth_turntable_result res = {0};
  double t0 = hearth_now();
  char path[1400];
  hearth_instance_doc inst;
  const char *own[HEARTH_MAX_STATES];
  hearth_factory_calib fac;
  hearth_status s =
      recon_instance_inputs(root, instance, &inst, own, &states, &n_states, &fac, err);
  if (s) return s;

  /* every view of every state */
  hearth_manifest *man = calloc(n_states, sizeof *man);
  if (!man) return hearth_err_set(err, HEARTH_E_NOMEM, "turntable: manifests");
  size_t nv = 0;
  for (size_t i = 0; i < n_states && !s; i++) {
    snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, instance, states[i]);
    if (!(s = hearth_manifest_read(path, &man[i], err))) nv += man[i].n_views;
  }
  /* a state whose views all carry the encoder's angle is held to it; the
   * others get the photometric term */
  int state_enc[HEARTH_MAX_STATES] = {0};
  for (size_t i = 0; i < n_states && !s && i < HEARTH_MAX_STATES; i++) {
    state_enc[i] = !o.ignore_encoder && man[i].n_views > 0;
    for (size_t j = 0; j < man[i].n_views; j++) state_enc[i] &= man[i].views[j].has_turntable;
  }
  tt_view *v = s ? NULL : calloc(nv ? nv : 1, sizeof *v);
  if (!s && !v) s = hearth_err_set(err, HEARTH_E_NOMEM, "turntable: views");
  if (!s && nv < 2)
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "recon %s: %zu view(s), at least 2 needed",
                       instance, nv);
  hearth_progress prog;
  hearth_progress_begin(&prog, "recon: depth views", nv, o.quiet);
  size_t k = 0;
  tt_rays rays = {0};
  for (size_t i = 0; i < n_states && !s; i++) {
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/instances/%s/raw/%s", root, instance, states[i]);
    for (size_t j = 0; j < man[i].n_views && !s; j++, k++) {
      const hearth_view_files *vf = &man[i].views[j];
      tt_view *tv = &v[k];
      snprintf(tv->state, sizeof tv->state, "%s", states[i]);
      snprintf(tv->view, sizeof tv->view, "%s", vf->view);
      tv->state_no = i;
      tv->elevation_index = vf->elevation_index;
      tv->azimuth_index = vf->azimuth_index;
      s = load_view(tv, dir, vf, &fac.rgb, o.erode_px, 0x7475726eULL + k, &rays, err);
      if (!s && (!state_enc[i] || o.colour_with_encoder) && o.colour_weight > 0)
        s = load_colour(tv, dir, vf, &fac.rgb, err);
      if (!s && tv->col) res.n_colour_views++;
      hearth_progress_step(&prog, 1);
    }
  }
  hearth_progress_end(&prog);
  free(rays.dirs);
  /* the rig's tilt axis in the camera frame (its x when its aim has no
   * roll) from the views with a table; a ring where none has one is
   * started from the other rings */
  double u_rig[3] = {1, 0, 0};
  if (!s) s = check_walls(v, nv, &o, &res, err);
  if (!s) {
    tilt_axis(v, nv, 1, u_rig);
    s = free_rings(v, nv, u_rig, &res.n_free_ring_views, err);
  }
  /* a view without a plane of its own takes its ring's: the mean table
   * normal (its camera frame) and height of the views of its elevation,
   * weighted by their inliers (the rig's cameras keep one tilt and roll a
   * ring) */
  for (size_t i = 0; i < nv && !s; i++) {
    if (v[i].n_plane || v[i].free_ring) continue;
    double n[3] = {0, 0, 0}, h = 0;
    size_t cnt = 0;
    for (size_t j = 0; j < nv; j++)
      if (v[j].n_plane && v[j].elevation_index == v[i].elevation_index) {
        for (int a = 0; a < 3; a++) n[a] += (double)v[j].n_plane * v[j].L[6 + a];
        h += (double)v[j].n_plane * v[j].height;
        cnt += v[j].n_plane;
      }
    double ln = hearth_norm3(n);
    for (int a = 0; a < 3; a++) n[a] /= ln;
    v[i].height = h / (double)cnt;
    /* a wall it sees levels it instead, and the wall term holds it (the
     * ring's plane, often one view's seen at grazing incidence, would
     * pull it off by as much as that plane is) */
    int wall = wall_level(&v[i], u_rig, n); /* none when --wall 0 (check_walls) */
    set_level(&v[i], n);
    res.n_ring_plane_views++;
    if (wall) continue;
    /* the plane term then holds it to that plane, at a quarter of a good
     * plane's weight (a ring's cameras differ in tilt by a fraction of a
     * degree): a grid of points on it around the object's foot */
    const int G = 20;
    const double half = 0.08;
    double c0[3], dc = hearth_dot3(n, v[i].centroid) + v[i].height;
    for (int a = 0; a < 3; a++) c0[a] = v[i].centroid[a] - dc * n[a];
    if (!(v[i].pl = malloc((size_t)G * G * 3 * sizeof(float)))) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "%s", v[i].depth_path);
      break;
    }
    for (int gy = 0; gy < G; gy++)
      for (int gx = 0; gx < G; gx++) {
        double fa = half * (2.0 * gx / (G - 1) - 1.0), sa = half * (2.0 * gy / (G - 1) - 1.0);
        for (int a = 0; a < 3; a++)
          v[i].pl[3 * v[i].npl + a] = (float)(c0[a] + fa * v[i].L[a] + sa * v[i].L[3 + a]);
        v[i].npl++;
      }
    v[i].plane_rms = 2.0 * TT_PLANE_GOOD_M;
  }
  if (!s && !(res.views = calloc(nv, sizeof *res.views)))
    s = hearth_err_set(err, HEARTH_E_NOMEM, "turntable: report");
  double u[3] = {1, 0, 0};
  if (!s) {
    tilt_axis(v, nv, 0, u);
    /* the start: nominal azimuths (or the encoder's angles, aligned to
     * them in the mean over each encoder group), the object's centroid on
     * the axis; the tilt axis of a camera at azimuth phi looking at the
     * axis heads phi + pi / 2 */
    k = 0;
    for (size_t i = 0; i < n_states; i++) {
      int enc = state_enc[i];
      for (size_t j = 0; j < man[i].n_views; j++) {
        tt_view *tv = &v[k + j];
        double phi =
            o.direction *
            (tv->azimuth_index * o.azimuth_step_deg + tv->elevation_index * o.ring_shift_deg) *
            TT_DEG;
        tv->target = tv->target_nominal = phi + TT_PI / 2;
        tv->state_index = o.encoder_per_state ? i : 0;
        tv->enc = enc;
        if (enc) tv->target = o.direction * man[i].views[j].turntable_deg * TT_DEG + TT_PI / 2;
      }
      if (enc) res.n_encoder_views += man[i].n_views;
      k += man[i].n_views;
    }
    for (size_t g = 0; g < n_states; g++) {
      double cs = 0, sn = 0;
      for (size_t i = 0; i < nv; i++)
        if (v[i].enc && v[i].state_index == g) {
          cs += cos(v[i].target_nominal - v[i].target);
          sn += sin(v[i].target_nominal - v[i].target);
        }
      double off = cs || sn ? atan2(sn, cs) : 0;
      for (size_t i = 0; i < nv; i++)
        if (v[i].enc && v[i].state_index == g) v[i].target += off;
    }
    for (size_t i = 0; i < nv; i++) {
      tt_view *tv = &v[i];
      double Lu[3];
      mat3_vec(tv->L, u, Lu);
      tv->psi = tv->target - atan2(Lu[1], Lu[0]);
      tv->x = tv->y = 0;
      tt_pose(tv);
      double cw[3];
      hearth_rigid_rotate(&tv->T, tv->centroid, cw);
      tv->x = -cw[0];
      tv->y = -cw[1];
      tt_pose(tv);
    }
    s = run_icp(v, nv, n_states, u, u_rig, &fac.rgb, &o, &res, err);
  }
  if (!s) {
    out->views = calloc(nv, sizeof *out->views);
    if (!out->views) s = hearth_err_set(err, HEARTH_E_NOMEM, "turntable: poses");
  }
  if (!s) {
    out->n = nv;
    res.n_views = nv;
    for (size_t i = 0; i < nv; i++) {
      hearth_view_pose *vp = &out->views[i];
      snprintf(vp->state, sizeof vp->state, "%s", v[i].state);
      snprintf(vp->view, sizeof vp->view, "%s", v[i].view);
      vp->T_world_from_cam = v[i].T;
      hearth_turntable_view *rv = &res.views[i];
      snprintf(rv->state, sizeof rv->state, "%s", v[i].state);
      snprintf(rv->view, sizeof rv->view, "%s", v[i].view);
      rv->n_points = v[i].n;
      rv->n_plane = v[i].n_plane;
      rv->plane_rms_mm = v[i].n_plane ? 1000.0 * v[i].plane_rms : 0.0;
      rv->height_m = v[i].height;
      /* the optical axis (third column of R) against the horizon */
      rv->elevation_deg = -asin(fmax(-1.0, fmin(1.0, v[i].T.R[8]))) / TT_DEG;
      double da = remainder(heading(&v[i], u) - v[i].target_nominal, 2 * TT_PI);
      rv->d_azimuth_deg = da / TT_DEG;
    }
  }
  for (size_t i = 0; v && i < nv; i++) tt_view_free(&v[i]);
  free(v);
  for (size_t i = 0; i < n_states; i++) hearth_manifest_free(&man[i]);
  free(man);
  res.seconds = hearth_now() - t0;
  if (s) {
    hearth_poses_free(out);
    hearth_turntable_result_free(&res);
    return hearth_err_prefix(err, "recon %s", instance);
  }
  if (res_out) *res_out = res;
  else hearth_turntable_result_free(&res);
  return HEARTH_OK;
}
