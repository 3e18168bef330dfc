/* Automatic thermal-pose refinement (include/hearth/refine.h).
 *
 * The object is hotter or colder than the ambient background, so the
 * projected silhouette of the mesh must lie on the thermal image's edges.
 * Each iteration casts the mesh from the current pose, finds its outer
 * silhouette to a sixteenth of a pixel (bisection between hit and miss
 * rays), keeps the 3-D surface point there, searches along the silhouette
 * normal for the strongest image edge of the expected polarity, and takes a
 * damped Gauss-Newton step on the 6-DoF camera twist with Huber weights.
 * The search window shrinks from coarse to fine; a start that already lies
 * on the edges along part of its silhouette is instead refined within the
 * criterion's window under Tukey weights, so that edges inside the object
 * (a painted band against bare metal reading near ambient) cannot pull
 * it off. The criterion (mean
 * truncated squared distance of the silhouette to the edges) is evaluated at
 * the start and at the end; the start pose is kept unless the criterion
 * improved, the image has enough contrast and enough edges were found. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "poses/poses_internal.h"

#define RF_BISECT 5        /* silhouette to 1/32 px */
#define RF_EVAL_WINDOW 3.0 /* px: edge search window of the criterion */
#define RF_TRUNC 1.5       /* px: truncation of the criterion */
#define RF_HUBER 1.0       /* px */
#define RF_STEP 0.5        /* px: profile sampling step */
#define RF_COARSE 4        /* px: coarse grid of the hit mask */
#define RF_MAX_NODES 4096
#define RF_PRIOR_PX 0.1 /* px: see the prior in refine_one */
/* a start with at least this share of its silhouette samples within RF_HUBER
   of an edge is also refined locally (see refine_one) */
#define RF_LOCAL_SHARE 0.2
#define RF_LOCAL_C 1.5     /* px: Tukey scale of the local refinement */
#define RF_LOCAL_PRIOR 0.2 /* the local prior: this share of the coarse one's 1 deg, 5 mm */
/* the coarse result replaces the local one only if at least this share of its
   silhouette samples lies within RF_HUBER of an edge (see refine_one) */
#define RF_FULL_SHARE 0.9

void hearth_refine_opts_default(hearth_refine_opts *o) {
  memset(o, 0, sizeof *o);
  o->search_px = 14.0;
  o->iterations = 12;
  o->max_samples = 400;
  o->min_contrast_c = 1.5;
  o->max_rot_deg = 3.0;
  o->max_t_mm = 15.0;
}

float *rf_pixel_rays(const hearth_camera *cam) {
  size_t n = (size_t)cam->width * (size_t)cam->height;
  float *d = hearth_alloc_array(n ? n : 1, 3 * sizeof *d);
  if (!d) return NULL;
  hearth_camera_ray_grid(cam, 1, d);
  return d;
}

int rf_mesh_box(const hearth_mesh *mesh, const hearth_camera *cam,
                const hearth_rigid *T_world_from_cam, int margin, int box[4]) {
  hearth_rigid Tcw;
  hearth_rigid_inverse(T_world_from_cam, &Tcw);
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  int any = 0, behind = 0;
  if (cam->model == HEARTH_LENS_BROWN5) {
    /* hearth_rigid_apply and hearth_camera_project written out, operation
       for operation (the same numbers, hence the same box), without a call
       per vertex: this runs for every vertex of the mesh at every pose */
    const double *R = Tcw.R, *t = Tcw.t, fx = cam->fx, fy = cam->fy, cx = cam->cx, cy = cam->cy;
    for (size_t i = 0; i < mesh->n_vertices; i++) {
      const float *p = mesh->positions + 3 * i;
      double X0 = p[0], X1 = p[1], X2 = p[2];
      double Z = (R[6] * X0 + R[7] * X1 + R[8] * X2) + t[2];
      if (!(Z > 0.0)) {
        behind = 1;
        continue;
      }
      double iz = 1.0 / Z, x = ((R[0] * X0 + R[1] * X1 + R[2] * X2) + t[0]) * iz,
             y = ((R[3] * X0 + R[4] * X1 + R[5] * X2) + t[1]) * iz, xd, yd;
      hearth_distort_xy(cam->dist, x, y, &xd, &yd);
      double u = fx * xd + cx, v = fy * yd + cy;
      lo[0] = u < lo[0] ? u : lo[0];
      hi[0] = u > hi[0] ? u : hi[0];
      lo[1] = v < lo[1] ? v : lo[1];
      hi[1] = v > hi[1] ? v : hi[1];
      any = 1;
    }
  } else {
    for (size_t i = 0; i < mesh->n_vertices; i++) {
      double X[3] = {mesh->positions[3 * i], mesh->positions[3 * i + 1],
                     mesh->positions[3 * i + 2]},
             Xc[3], uv[2];
      hearth_rigid_apply(&Tcw, X, Xc);
      if (!hearth_camera_project(cam, Xc, uv, NULL)) {
        behind = 1;
        continue;
      }
      any = 1;
      for (int k = 0; k < 2; k++) {
        if (uv[k] < lo[k]) lo[k] = uv[k];
        if (uv[k] > hi[k]) hi[k] = uv[k];
      }
    }
  }
  if (!any) return 0;
  if (behind) { /* part of the mesh behind the camera: cast everything */
    lo[0] = lo[1] = -1e9;
    hi[0] = hi[1] = 1e9;
  }
  double b[4] = {floor(lo[0]) - margin, floor(lo[1]) - margin, ceil(hi[0]) + margin + 1,
                 ceil(hi[1]) + margin + 1};
  box[0] = b[0] < 0 ? 0 : b[0] > cam->width ? cam->width : (int)b[0];
  box[1] = b[1] < 0 ? 0 : b[1] > cam->height ? cam->height : (int)b[1];
  box[2] = b[2] < 0 ? 0 : b[2] > cam->width ? cam->width : (int)b[2];
  box[3] = b[3] < 0 ? 0 : b[3] > cam->height ? cam->height : (int)b[3];
  return box[2] > box[0] && box[3] > box[1];
}

/* ---- per-view machinery ------------------------------------------------------ */

typedef struct rf_sample {
  double X[3]; /* world point on the silhouette */
  double n[2]; /* outward silhouette normal in the image at extraction */
} rf_sample;

typedef struct rf_scratch {
  uint8_t *hit;     /* per image pixel */
  rf_sample *samp;  /* candidates */
  rf_sample *samp0; /* the start pose's silhouette (refine_one) */
  size_t cap;
  float *smooth; /* smoothed image */
  int box[4];    /* pixel box of the last extraction */
} rf_scratch;

typedef struct rf_ctx {
  const hearth_mesh *mesh;
  const hearth_raycaster *rc;
  const hearth_camera *cam;
  const hearth_map_view *views;
  const hearth_refine_opts *o;
  const float *rays;
  rf_scratch *scratch; /* per thread */
  hearth_refine_view_result *out;
  int failed;
} rf_ctx;

/* cast at pixel p + m * (q - p) for 4-neighbours p, q: the ray is the
 * normalised blend of the two pixels' rays (distortion is smooth at this scale) */
static int cast_px(const rf_ctx *c, const hearth_rigid *T, size_t p, size_t q, double m,
                   hearth_ray_hit *h, double X[3]) {
  double dc[3], dw[3];
  const float *a = c->rays + 3 * p, *b = c->rays + 3 * q;
  if (isnan(a[0]) || isnan(b[0])) return 0;
  for (int k = 0; k < 3; k++) dc[k] = (1 - m) * a[k] + m * b[k];
  double l = hearth_norm3(dc);
  for (int k = 0; k < 3; k++) dc[k] /= l;
  hearth_rigid_rotate(T, dc, dw);
  if (!hearth_raycast(c->rc, T->t, dw, 0.0, INFINITY, h)) return 0;
  for (int k = 0; k < 3; k++) X[k] = T->t[k] + (double)h->t * dw[k];
  return 1;
}

/* 1 if the ray of pixel (x, y) from T hits the mesh */
static uint8_t cast_hit(const rf_ctx *c, const hearth_rigid *T, int x, int y) {
  const float *d = c->rays + 3 * ((size_t)y * (size_t)c->cam->width + (size_t)x);
  if (isnan(d[0])) return 0;
  double dc[3] = {d[0], d[1], d[2]}, dw[3];
  hearth_rigid_rotate(T, dc, dw);
  return (uint8_t)hearth_raycast_any(c->rc, T->t, dw, 0.0, INFINITY);
}

/* the outer silhouette of the mesh seen from T: samples in s (at most max) */
static size_t extract_contour(const rf_ctx *c, rf_scratch *sc, const hearth_rigid *T, size_t max) {
  const hearth_camera *cam = c->cam;
  int box[4];
  if (!rf_mesh_box(c->mesh, cam, T, 3, box)) return 0;
  memcpy(sc->box, box, sizeof box);
  size_t W = (size_t)cam->width;
  /* coarse-to-fine hit mask: cast a grid every RF_COARSE pixels; cells whose
     four corners agree take that value, the others (the silhouette's cells)
     are cast pixel by pixel. Inferred cells are written first so that exact
     casts on shared cell borders win. */
  int xs[RF_MAX_NODES], ys[RF_MAX_NODES], nx = 0, ny = 0;
  for (int x = box[0]; x < box[2] && nx < RF_MAX_NODES - 1; x += RF_COARSE) xs[nx++] = x;
  if (xs[nx - 1] != box[2] - 1) xs[nx++] = box[2] - 1;
  for (int y = box[1]; y < box[3] && ny < RF_MAX_NODES - 1; y += RF_COARSE) ys[ny++] = y;
  if (ys[ny - 1] != box[3] - 1) ys[ny++] = box[3] - 1;
  int exact = nx >= RF_MAX_NODES - 1 || ny >= RF_MAX_NODES - 1 || nx < 2 || ny < 2;
  if (exact) { /* huge box: cast everything */
    for (int y = box[1]; y < box[3]; y++)
      for (int x = box[0]; x < box[2]; x++)
        sc->hit[(size_t)y * W + (size_t)x] = cast_hit(c, T, x, y);
  } else {
    for (int j = 0; j < ny; j++)
      for (int i = 0; i < nx; i++)
        sc->hit[(size_t)ys[j] * W + (size_t)xs[i]] = cast_hit(c, T, xs[i], ys[j]);
    for (int pass = 0; pass < 2; pass++)
      for (int j = 0; j + 1 < ny; j++)
        for (int i = 0; i + 1 < nx; i++) {
          uint8_t a = sc->hit[(size_t)ys[j] * W + (size_t)xs[i]],
                  b = sc->hit[(size_t)ys[j] * W + (size_t)xs[i + 1]],
                  cc = sc->hit[(size_t)ys[j + 1] * W + (size_t)xs[i]],
                  dd = sc->hit[(size_t)ys[j + 1] * W + (size_t)xs[i + 1]];
          int uniform = a == b && a == cc && a == dd;
          if (uniform != (pass == 0)) continue;
          for (int y = ys[j]; y <= ys[j + 1]; y++)
            for (int x = xs[i]; x <= xs[i + 1]; x++) {
              int node = (x == xs[i] || x == xs[i + 1]) && (y == ys[j] || y == ys[j + 1]);
              if (node) continue;
              sc->hit[(size_t)y * W + (size_t)x] = uniform ? a : cast_hit(c, T, x, y);
            }
        }
  }
  /* count hit/miss pairs first so the subsampling is even and deterministic */
  const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
  size_t n_pairs = 0;
  for (int pass = 0; pass < 2; pass++) {
    size_t every = n_pairs > max ? (n_pairs + max - 1) / max : 1, k = 0, ns = 0;
    for (int y = box[1]; y < box[3]; y++)
      for (int x = box[0]; x < box[2]; x++) {
        if (!sc->hit[(size_t)y * W + (size_t)x]) continue;
        for (int j = 0; j < 4; j++) {
          int qx = x + dx[j], qy = y + dy[j];
          if (qx < 0 || qy < 0 || qx >= cam->width || qy >= cam->height) continue;
          int qhit = (qx >= box[0] && qx < box[2] && qy >= box[1] && qy < box[3]) &&
                     sc->hit[(size_t)qy * W + (size_t)qx];
          if (qhit) continue;
          if (pass == 0) {
            n_pairs++;
            continue;
          }
          if (k++ % every) continue;
          if (ns >= sc->cap) continue;
          /* bisect the hit -> miss segment */
          double a = 0, b = 1, X[3] = {0, 0, 0};
          hearth_ray_hit h, hl;
          size_t pi = (size_t)y * W + (size_t)x, qi = (size_t)qy * W + (size_t)qx;
          if (!cast_px(c, T, pi, qi, 0.0, &hl, X)) continue;
          for (int it = 0; it < RF_BISECT; it++) {
            double m = 0.5 * (a + b), Xm[3];
            if (cast_px(c, T, pi, qi, m, &h, Xm)) {
              a = m;
              hl = h;
              memcpy(X, Xm, sizeof X);
            } else {
              b = m;
            }
          }
          /* image normal: projection of the surface normal, else the pixel step */
          rf_sample *s = &sc->samp[ns];
          memcpy(s->X, X, sizeof X);
          s->n[0] = dx[j];
          s->n[1] = dy[j];
          const uint32_t *ix = c->mesh->indices + 3 * (size_t)hl.prim;
          const float *p0 = c->mesh->positions + 3 * (size_t)ix[0],
                      *p1 = c->mesh->positions + 3 * (size_t)ix[1],
                      *p2 = c->mesh->positions + 3 * (size_t)ix[2];
          double e1[3], e2[3], nw[3];
          for (int k2 = 0; k2 < 3; k2++) {
            e1[k2] = (double)p1[k2] - p0[k2];
            e2[k2] = (double)p2[k2] - p0[k2];
          }
          hearth_cross3(e1, e2, nw);
          double nl = hearth_norm3(nw);
          if (nl > 0) {
            hearth_rigid Tcw;
            hearth_rigid_inverse(T, &Tcw);
            double Xc[3], Xe[3], Xce[3], uv0[2], uv1[2];
            double eps =
                1e-3 * hearth_norm3((double[3]){X[0] - T->t[0], X[1] - T->t[1], X[2] - T->t[2]});
            for (int k2 = 0; k2 < 3; k2++) Xe[k2] = X[k2] + eps * nw[k2] / nl;
            hearth_rigid_apply(&Tcw, X, Xc);
            hearth_rigid_apply(&Tcw, Xe, Xce);
            if (hearth_camera_project(c->cam, Xc, uv0, NULL) &&
                hearth_camera_project(c->cam, Xce, uv1, NULL)) {
              double gx = uv1[0] - uv0[0], gy = uv1[1] - uv0[1], gl = sqrt(gx * gx + gy * gy);
              if (gl > 0 && (gx * dx[j] + gy * dy[j]) / gl > 0.3) {
                s->n[0] = gx / gl;
                s->n[1] = gy / gl;
              }
            }
          }
          ns++;
        }
      }
    if (pass == 1) return ns;
  }
  return 0;
}

static double sample_img(const float *img, int w, int h, double x, double y) {
  if (x < 0) x = 0;
  if (y < 0) y = 0;
  if (x > w - 1) x = w - 1;
  if (y > h - 1) y = h - 1;
  int x0 = (int)x, y0 = (int)y;
  int x1 = x0 + 1 < w ? x0 + 1 : x0, y1 = y0 + 1 < h ? y0 + 1 : y0;
  double fx = x - x0, fy = y - y0;
  const float *r0 = img + (size_t)y0 * (size_t)w, *r1 = img + (size_t)y1 * (size_t)w;
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x1]);
}

/* strongest edge of polarity pol (inside - outside sign) along n from uv
 * within +-win; returns 1 and the offset, 0 if none above thr */
static int find_edge(const float *img, int w, int h, const double uv[2], const double n[2],
                     double pol, double win, double thr, double *off) {
  int m = (int)ceil(win / RF_STEP);
  double best = -INFINITY, gm1 = 0, gp1 = 0;
  int bi = 0;
  double prev_g = 0;
  double gs[161];
  if (m > 80) m = 80;
  for (int i = -m; i <= m; i++) {
    double s = i * RF_STEP;
    double a = sample_img(img, w, h, uv[0] + (s - 0.5) * n[0], uv[1] + (s - 0.5) * n[1]);
    double b = sample_img(img, w, h, uv[0] + (s + 0.5) * n[0], uv[1] + (s + 0.5) * n[1]);
    double g = pol * (a - b); /* temperature falls outward for a hot object */
    gs[i + m] = g;
    if (g > best) {
      best = g;
      bi = i;
    }
    prev_g = g;
  }
  (void)prev_g;
  if (!(best > thr) || bi == -m || bi == m) return 0;
  gm1 = gs[bi + m - 1];
  gp1 = gs[bi + m + 1];
  double den = gm1 - 2 * best + gp1, frac = 0;
  if (den < 0) frac = 0.5 * (gm1 - gp1) / den;
  if (frac > 0.5) frac = 0.5;
  if (frac < -0.5) frac = -0.5;
  *off = (bi + frac) * RF_STEP;
  return 1;
}

/* 3x3 binomial smoothing (edges replicated) */
static void smooth3(const float *in, int w, int h, float *out) {
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double s = 0;
      for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++) {
          int xx = x + i < 0 ? 0 : x + i >= w ? w - 1 : x + i;
          int yy = y + j < 0 ? 0 : y + j >= h ? h - 1 : y + j;
          s += (double)((i ? 1 : 2) * (j ? 1 : 2)) * in[(size_t)yy * (size_t)w + (size_t)xx];
        }
      out[(size_t)y * (size_t)w + (size_t)x] = (float)(s / 16.0);
    }
}

/* median temperature of the pixels the mesh covers minus that of the
 * uncovered pixels of the box around it (robust to a start several pixels off) */
static double contour_contrast(const rf_ctx *c, const rf_scratch *sc, size_t ns,
                               const hearth_rigid *T) {
  (void)T;
  if (!ns) return 0;
  const int *b = sc->box;
  size_t W = (size_t)c->cam->width, n = (size_t)(b[2] - b[0]) * (size_t)(b[3] - b[1]);
  double *in = malloc((n ? n : 1) * sizeof *in), *out = malloc((n ? n : 1) * sizeof *out);
  size_t ni = 0, no = 0;
  double med = 0;
  if (in && out) {
    for (int y = b[1]; y < b[3]; y++)
      for (int x = b[0]; x < b[2]; x++) {
        size_t p = (size_t)y * W + (size_t)x;
        if (sc->hit[p]) in[ni++] = sc->smooth[p];
        else out[no++] = sc->smooth[p];
      }
    if (ni && no) med = rf_select(in, ni, ni / 2) - rf_select(out, no, no / 2);
  }
  free(in);
  free(out);
  return med;
}

/* the criterion at pose T: mean over silhouette samples of min(d^2, c^2),
 * d = distance to the edge found within the evaluation window */
static double eval_cost_on(const rf_ctx *c, const rf_scratch *sc, size_t ns, const hearth_rigid *T,
                           double pol, double thr, size_t *n_in, size_t *n_s) {
  hearth_rigid Tcw;
  hearth_rigid_inverse(T, &Tcw);
  double sum = 0;
  size_t in = 0;
  for (size_t i = 0; i < ns; i++) {
    double Xc[3], uv[2], off;
    hearth_rigid_apply(&Tcw, sc->samp[i].X, Xc);
    double cost = RF_TRUNC * RF_TRUNC;
    if (hearth_camera_project(c->cam, Xc, uv, NULL) &&
        find_edge(sc->smooth, c->cam->width, c->cam->height, uv, sc->samp[i].n, pol, RF_EVAL_WINDOW,
                  thr, &off)) {
      if (off * off < cost) cost = off * off;
      if (fabs(off) < RF_HUBER) in++;
    }
    sum += cost;
  }
  if (n_in) *n_in = in;
  if (n_s) *n_s = ns;
  return ns ? sum / (double)ns : INFINITY;
}

/* eval_cost_on the silhouette extracted at T */
static double eval_cost(const rf_ctx *c, rf_scratch *sc, const hearth_rigid *T, double pol,
                        double thr, size_t *n_in, size_t *n_s) {
  size_t ns = extract_contour(c, sc, T, c->o->max_samples);
  return eval_cost_on(c, sc, ns, T, pol, thr, n_in, n_s);
}

/* solve the 6x6 SPD system A x = b by Cholesky; 0 if not positive definite */
static int chol6(const double A[36], const double b[6], double x[6]) {
  double L[36] = {0};
  for (int i = 0; i < 6; i++)
    for (int j = 0; j <= i; j++) {
      double s = A[6 * i + j];
      for (int k = 0; k < j; k++) s -= L[6 * i + k] * L[6 * j + k];
      if (i == j) {
        if (!(s > 0)) return 0;
        L[6 * i + i] = sqrt(s);
      } else {
        L[6 * i + j] = s / L[6 * j + j];
      }
    }
  double y[6];
  for (int i = 0; i < 6; i++) {
    double s = b[i];
    for (int k = 0; k < i; k++) s -= L[6 * i + k] * y[k];
    y[i] = s / L[6 * i + i];
  }
  for (int i = 5; i >= 0; i--) {
    double s = y[i];
    for (int k = i + 1; k < 6; k++) s -= L[6 * k + i] * x[k];
    x[i] = s / L[6 * i + i];
  }
  return 1;
}

/* T * (R(w), v) */
static void apply_twist(const hearth_rigid *T, const double d[6], hearth_rigid *out) {
  hearth_rigid D;
  hearth_rotvec_to_matrix(d, D.R);
  D.t[0] = d[3];
  D.t[1] = d[4];
  D.t[2] = d[5];
  hearth_rigid_compose(T, &D, out);
}

/* twist d with b = a * (R(d_rot), d_t) */
static void twist_between(const hearth_rigid *a, const hearth_rigid *b, double d[6]) {
  hearth_rigid ai, D;
  hearth_rigid_inverse(a, &ai);
  hearth_rigid_compose(&ai, b, &D);
  hearth_matrix_to_rotvec(D.R, d);
  d[3] = D.t[0];
  d[4] = D.t[1];
  d[5] = D.t[2];
}

static void pose_change(const hearth_rigid *a, const hearth_rigid *b, double *rot_deg,
                        double *t_mm) {
  *rot_deg = hearth_rotation_angle_between(a->R, b->R) * 180.0 / M_PI;
  double d[3] = {a->t[0] - b->t[0], a->t[1] - b->t[1], a->t[2] - b->t[2]};
  *t_mm = hearth_norm3(d) * 1e3;
}

/* Gauss-Newton from T0 on the silhouette samples in sc (ns of them, made
 * at T0), to *T; H and *sigma2 are the last normal equations and residual
 * variance. Coarse (local 0): the edge search window shrinks from
 * search_px, Huber weights, the prior of a start off by about a degree and
 * a few millimetres. Local (local 1): the criterion's window, Tukey
 * weights (no pull from edges beyond RF_LOCAL_C), a tighter prior. */
static void solve(const rf_ctx *c, rf_scratch *sc, const hearth_rigid *T0, size_t ns, int local,
                  double pol, double thr, hearth_rigid *T_out, double H[36], double *sigma2_out) {
  const hearth_camera *cam = c->cam;
  const hearth_refine_opts *o = c->o;
  hearth_rigid T = *T0;
  double g[6], sigma2 = 0;
  size_t n_used = 0;
  memset(H, 0, 36 * sizeof *H);
  for (int it = 0; it < o->iterations; it++) {
    double win = local ? RF_EVAL_WINDOW : o->search_px * pow(0.6, it);
    if (win < 2.0) win = 2.0;
    /* silhouette points move little per step: re-extract every third step */
    if (it % 3 == 0 && it > 0) ns = extract_contour(c, sc, &T, o->max_samples);
    hearth_rigid Tcw;
    hearth_rigid_inverse(&T, &Tcw);
    memset(H, 0, 36 * sizeof *H);
    memset(g, 0, sizeof g);
    double zsum = 0, rsum = 0, wsum = 0;
    n_used = 0;
    for (size_t i = 0; i < ns; i++) {
      double Xc[3], uv[2], off;
      hearth_project_jac jac;
      hearth_rigid_apply(&Tcw, sc->samp[i].X, Xc);
      if (!hearth_camera_project(cam, Xc, uv, &jac)) continue;
      const double *n = sc->samp[i].n;
      if (!find_edge(sc->smooth, cam->width, cam->height, uv, n, pol, win, thr, &off)) continue;
      double r = -off, w;
      if (local) {
        /* Tukey's biweight: no pull from edges beyond RF_LOCAL_C */
        double u = r / RF_LOCAL_C;
        w = fabs(u) < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
        if (w <= 0.0) continue;
      } else {
        w = fabs(r) <= RF_HUBER ? 1.0 : RF_HUBER / fabs(r);
      }
      /* d r / d Xc = n^T J_point; Xc' = R(w)^T (Xc - v) ~ Xc + Xc x w - v */
      double a[3];
      for (int k = 0; k < 3; k++) a[k] = n[0] * jac.d_point[k] + n[1] * jac.d_point[3 + k];
      double J[6] = {a[1] * Xc[2] - a[2] * Xc[1],
                     a[2] * Xc[0] - a[0] * Xc[2],
                     a[0] * Xc[1] - a[1] * Xc[0],
                     -a[0],
                     -a[1],
                     -a[2]};
      for (int p = 0; p < 6; p++) {
        g[p] += w * J[p] * r;
        for (int q = 0; q < 6; q++) H[6 * p + q] += w * J[p] * J[q];
      }
      zsum += Xc[2];
      rsum += w * r * r;
      wsum += w;
      n_used++;
    }
    if (n_used < 12) break;
    sigma2 = rsum / (wsum > 0 ? wsum : 1);
    /* damping: a little LM plus a weak pull to the current pose so that
       directions the silhouette cannot see stay where they are */
    double tr = 0;
    for (int p = 0; p < 6; p++) tr += H[7 * p];
    double A[36], b[6], d[6];
    memcpy(A, H, sizeof A);
    for (int p = 0; p < 6; p++) {
      A[7 * p] += 1e-3 * H[7 * p] + 1e-6 * tr / 6;
      b[p] = -g[p];
    }
    (void)zsum;
    /* prior: the start is off by about a degree and a few millimetres, so a
       soft pull towards it (1 deg or 5 mm cost as much as RF_PRIOR_PX on every
       sample) pins
       the directions the silhouette cannot see (rotation about a body of
       revolution's axis) without biasing the ones it sees */
    {
      double dev[6];
      twist_between(T0, &T, dev);
      const double pr = local ? RF_LOCAL_PRIOR : 1.0;
      const double lr = wsum * RF_PRIOR_PX * RF_PRIOR_PX / pow(pr * M_PI / 180.0, 2),
                   lt = wsum * RF_PRIOR_PX * RF_PRIOR_PX / pow(pr * 0.005, 2);
      for (int p = 0; p < 6; p++) {
        double l = p < 3 ? lr : lt;
        A[7 * p] += l;
        b[p] -= l * dev[p];
      }
    }
    if (!chol6(A, b, d)) break;
    hearth_rigid Tn;
    apply_twist(&T, d, &Tn);
    T = Tn;
    double step = hearth_norm3(d) * 180 / M_PI, stept = hearth_norm3(d + 3) * 1e3;
    if (win <= 2.0 && step < 1e-4 && stept < 1e-3) break;
  }
  *T_out = T;
  *sigma2_out = sigma2;
}

static void refine_one(rf_ctx *c, size_t v, int t) {
  rf_scratch *sc = &c->scratch[t];
  hearth_refine_view_result *res = &c->out[v];
  const hearth_image *img = c->views[v].image;
  const hearth_camera *cam = c->cam;
  const hearth_refine_opts *o = c->o;
  double t0 = hearth_now();
  memset(res, 0, sizeof *res);
  const hearth_rigid T0 = c->views[v].T_world_from_cam;
  res->T_world_from_cam = T0;
  smooth3(img->data, cam->width, cam->height, sc->smooth);
  size_t ns = extract_contour(c, sc, &T0, o->max_samples);
  if (ns < 20) {
    snprintf(res->reason, sizeof res->reason, "kept: only %zu silhouette samples", ns);
    res->seconds = hearth_now() - t0;
    return;
  }
  double contrast = contour_contrast(c, sc, ns, &T0);
  res->contrast_c = contrast;
  double pol = contrast >= 0 ? 1.0 : -1.0, thr = 0.08 * fabs(contrast);
  /* the criterion at the start, on the start's silhouette just extracted
     (extraction is a function of the pose alone); the silhouette is kept
     for the local refinement, which starts from T0 again */
  size_t n_in0 = 0;
  res->cost_start = eval_cost_on(c, sc, ns, &T0, pol, thr, &n_in0, &ns);
  const size_t ns0 = ns;
  memcpy(sc->samp0, sc->samp, ns0 * sizeof *sc->samp);
  res->cost_final = res->cost_start;
  if (fabs(contrast) < o->min_contrast_c) {
    snprintf(res->reason, sizeof res->reason, "kept: contrast %.2f degC below %.2f", fabs(contrast),
             o->min_contrast_c);
    res->seconds = hearth_now() - t0;
    return;
  }
  /* A start that already lies on the edges along a fifth of its silhouette
     or more is also refined locally (see solve): edges inside the object (a
     painted body against a bare-metal rim that reads near ambient, so the
     rim's own silhouette shows no edge) cannot pull it inwards there, as
     they can pull the coarse search. The coarse result is taken only where
     it fits better and lies on edges along nearly all of its silhouette
     (RF_FULL_SHARE): a start that lies on part of its edges by chance
     (shifted along a straight edge) and stalls in the local search is still
     found by the coarse one, while a coarse result pulled onto interior
     edges keeps the samples of the edgeless metal (measured: 0.93-0.99 of
     the samples on edges for such stalled starts 5 mm off, 0.58-0.83 where
     interior edges pulled the coarse search in tests/poses/test_refine_metal.c
     and on the virtual rig's iced can). */
  hearth_rigid T;
  double H[36], sigma2 = 0;
  solve(c, sc, &T0, ns, 0, pol, thr, &T, H, &sigma2);
  size_t n_in = 0, n_s = 0;
  double cost;
  if ((double)n_in0 >= RF_LOCAL_SHARE * (double)ns) {
    size_t in_c = 0, ns_c = 0, in_l = 0, ns_l = 0;
    double cost_coarse = eval_cost(c, sc, &T, pol, thr, &in_c, &ns_c);
    hearth_rigid Tl;
    double Hl[36], sigma2_l = 0;
    ns = ns0;
    memcpy(sc->samp, sc->samp0, ns0 * sizeof *sc->samp);
    solve(c, sc, &T0, ns, 1, pol, thr, &Tl, Hl, &sigma2_l);
    double cost_local = eval_cost(c, sc, &Tl, pol, thr, &in_l, &ns_l);
    /* the final criterion is the one just evaluated at the pose kept */
    if (!(cost_coarse < cost_local && (double)in_c >= RF_FULL_SHARE * (double)ns_c)) {
      T = Tl;
      memcpy(H, Hl, sizeof H);
      sigma2 = sigma2_l;
      cost = cost_local;
      n_in = in_l;
      n_s = ns_l;
    } else {
      cost = cost_coarse;
      n_in = in_c;
      n_s = ns_c;
    }
  } else {
    cost = eval_cost(c, sc, &T, pol, thr, &n_in, &n_s);
  }
  double dr, dt;
  pose_change(&T0, &T, &dr, &dt);
  res->n_samples = n_s;
  res->n_inliers = n_in;
  /* weakest-direction standard deviations from the last normal equations */
  double Hi[36], e[6];
  int ok_cov = 1;
  for (int p = 0; p < 6 && ok_cov; p++) {
    memset(e, 0, sizeof e);
    e[p] = 1;
    double col[6];
    if (!chol6(H, e, col)) ok_cov = 0;
    for (int q = 0; q < 6; q++) Hi[6 * q + p] = col[q];
  }
  if (ok_cov) {
    double sr = 0, st = 0;
    for (int p = 0; p < 3; p++) {
      if (Hi[7 * p] > sr) sr = Hi[7 * p];
      if (Hi[7 * (p + 3)] > st) st = Hi[7 * (p + 3)];
    }
    res->sigma_rot_deg = sqrt(sigma2 * sr) * 180 / M_PI;
    res->sigma_t_mm = sqrt(sigma2 * st) * 1e3;
  }
  double inl = n_s ? (double)n_in / (double)n_s : 0;
  if (!(cost < res->cost_start)) {
    snprintf(res->reason, sizeof res->reason, "kept: criterion %.4f not better than start %.4f",
             cost, res->cost_start);
  } else if (dr > o->max_rot_deg || dt > o->max_t_mm) {
    snprintf(res->reason, sizeof res->reason, "kept: moved %.2f deg %.1f mm, beyond the limits", dr,
             dt);
  } else if (n_in < 20) {
    snprintf(res->reason, sizeof res->reason, "kept: only %zu edge inliers", n_in);
  } else {
    res->accepted = 1;
    res->T_world_from_cam = T;
    res->cost_final = cost;
    res->d_rot_deg = dr;
    res->d_t_mm = dt;
    snprintf(res->reason, sizeof res->reason, "refined");
  }
  /* confidence: inlier fraction, lowered where a direction is poorly seen */
  double cond = ok_cov ? 1.0 / (1.0 + res->sigma_rot_deg / 0.05 + res->sigma_t_mm / 0.5) : 0.0;
  res->confidence = res->accepted ? inl * (0.5 + 0.5 * cond) : 0.0;
  res->seconds = hearth_now() - t0;
}

static void refine_range(void *ctx, size_t b, size_t e, int t) {
  rf_ctx *c = ctx;
  for (size_t v = b; v < e; v++) refine_one(c, v, t);
}

hearth_status hearth_refine_views(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                  const hearth_camera *cam, const hearth_map_view *views,
                                  size_t n_views, const hearth_refine_opts *opts,
                                  hearth_refine_view_result *out, hearth_err *err) {
  hearth_refine_opts def;
  if (!opts) {
    hearth_refine_opts_default(&def);
    opts = &def;
  }
  if (!mesh || !cam || (!views && n_views) || !out)
    return hearth_err_set(err, HEARTH_E_ARG, "refine: mesh, camera, views and output are required");
  for (size_t v = 0; v < n_views; v++) {
    const hearth_image *im = views[v].image;
    if (!im || im->type != HEARTH_PIX_F32 || im->channels != 1 || im->width != (size_t)cam->width ||
        im->height != (size_t)cam->height)
      return hearth_err_set(err, HEARTH_E_SIZE,
                            "refine: view %zu: expected a %dx%d single-channel temperature image",
                            v, cam->width, cam->height);
  }
  if (!n_views) return HEARTH_OK;
  hearth_raycaster *own = NULL;
  hearth_status s;
  if (!rc) {
    if ((s = hearth_raycaster_new(mesh, &own, err))) return s;
    rc = own;
  }
  int nt = opts->threads > 0 ? opts->threads : hearth_default_threads();
  if ((size_t)nt > n_views) nt = (int)n_views;
  if (nt < 1) nt = 1;
  rf_scratch *scr = calloc((size_t)nt, sizeof *scr);
  float *rays = rf_pixel_rays(cam);
  size_t npx = (size_t)cam->width * (size_t)cam->height;
  s = HEARTH_OK;
  if (!scr || !rays) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "refine: out of memory");
    goto done;
  }
  for (int t = 0; t < nt; t++) {
    scr[t].hit = calloc(npx, 1);
    scr[t].cap = 4 * npx;
    scr[t].samp = hearth_alloc_array(scr[t].cap, sizeof *scr[t].samp);
    scr[t].samp0 = hearth_alloc_array(scr[t].cap, sizeof *scr[t].samp0);
    scr[t].smooth = hearth_alloc_array(npx, sizeof(float));
    if (!scr[t].hit || !scr[t].samp || !scr[t].samp0 || !scr[t].smooth) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "refine: out of memory");
      goto done;
    }
  }
  rf_ctx c = {mesh, rc, cam, views, opts, rays, scr, out, 0};
  if ((s = hearth_parallel_for(n_views, nt, refine_range, &c))) {
    hearth_err_set(err, s, "refine: cannot start worker threads");
    goto done;
  }
done:
  if (scr)
    for (int t = 0; t < nt; t++) {
      free(scr[t].hit);
      free(scr[t].samp);
      free(scr[t].samp0);
      free(scr[t].smooth);
    }
  free(scr);
  free(rays);
  hearth_raycaster_free(own);
  return s;
}

hearth_status hearth_refine_cost(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                 const hearth_camera *cam, const hearth_image *image,
                                 const hearth_rigid *T_world_from_cam, double *cost,
                                 hearth_err *err) {
  hearth_refine_opts o;
  hearth_refine_opts_default(&o);
  o.iterations = 0;
  o.min_contrast_c = INFINITY;
  o.threads = 1;
  hearth_map_view v = {image, *T_world_from_cam};
  hearth_refine_view_result r;
  hearth_status s = hearth_refine_views(mesh, rc, cam, &v, 1, &o, &r, err);
  if (!s) *cost = r.cost_start;
  return s;
}

hearth_status hearth_reprojection_error(const hearth_raycaster *rc, const hearth_camera *cam,
                                        const hearth_rigid *T_a, const hearth_rigid *T_b,
                                        int stride, double *mean_px, hearth_err *err) {
  if (stride < 1) stride = 1;
  hearth_rigid Tbw;
  hearth_rigid_inverse(T_b, &Tbw);
  double sum = 0;
  size_t n = 0;
  for (int y = 0; y < cam->height; y += stride)
    for (int x = 0; x < cam->width; x += stride) {
      double dc[3], dw[3], X[3], Xb[3], uv[2];
      if (hearth_camera_ray(cam, x, y, dc) < 0) continue;
      hearth_rigid_rotate(T_a, dc, dw);
      hearth_ray_hit h;
      if (!hearth_raycast(rc, T_a->t, dw, 0.0, INFINITY, &h) || !h.front) continue;
      for (int k = 0; k < 3; k++) X[k] = T_a->t[k] + (double)h.t * dw[k];
      hearth_rigid_apply(&Tbw, X, Xb);
      if (!hearth_camera_project(cam, Xb, uv, NULL)) continue;
      sum += hypot(uv[0] - x, uv[1] - y);
      n++;
    }
  if (!n)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "reprojection: the mesh is not seen from the pose");
  *mean_px = sum / (double)n;
  return HEARTH_OK;
}

/* ---- manual nudges --------------------------------------------------------- */

void hearth_pose_nudge_apply(const hearth_pose_nudge *n, hearth_rigid *T) {
  double d[6];
  for (int k = 0; k < 3; k++) {
    d[k] = n->d_rot_deg[k] * M_PI / 180.0;
    d[3 + k] = n->d_t_mm[k] * 1e-3;
  }
  hearth_rigid out;
  apply_twist(T, d, &out);
  *T = out;
}

hearth_status hearth_pose_nudge_parse(const char *text, hearth_pose_nudge *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  const char *slash = strchr(text, '/'), *colon = strchr(text, ':');
  if (!slash || !colon || colon < slash || slash == text || colon == slash + 1 ||
      (size_t)(slash - text) >= sizeof out->state ||
      (size_t)(colon - slash - 1) >= sizeof out->view)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "nudge '%s': expected STATE/VIEW:rx,ry,rz,tx,ty,tz (degrees, mm)", text);
  memcpy(out->state, text, (size_t)(slash - text));
  memcpy(out->view, slash + 1, (size_t)(colon - slash - 1));
  const char *p = colon + 1;
  for (int k = 0; k < 6; k++) {
    const char *e = strchr(p, ',');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    double v;
    if ((k < 5 && !e) || (k == 5 && e) || hearth_parse_double(p, len, 0, &v) != 0)
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "nudge '%s': value %d: expected 6 comma-separated numbers "
                            "rx,ry,rz (degrees), tx,ty,tz (mm)",
                            text, k + 1);
    if (k < 3) out->d_rot_deg[k] = v;
    else out->d_t_mm[k - 3] = v;
    p = e ? e + 1 : p + len;
  }
  if (!hearth_state_valid(out->state))
    return hearth_err_set(err, HEARTH_E_PARSE, "nudge '%s': '%s' is not a state", text, out->state);
  return HEARTH_OK;
}
