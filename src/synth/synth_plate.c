/* Calibration captures of the heated circle-grid plate: a white plate with
 * 84 holes in front of a warmed black backing, seen by the thermal camera
 * alone (intrinsics) and by both cameras together (stereo). The plate is an
 * analytic plane, so pixels straddling an edge are integrated finely
 * (adaptive supersampling) and detections can be judged to hundredths of a
 * pixel against the true projected centres. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/thermal.h"
#include "synth/synth_rig.h"

#define DEG (3.14159265358979323846 / 180.0)

/* C_WALL: a ray that enters a hole's front opening but meets its wall
 * before the back opening (a plate of real thickness) */
enum { C_OUT = 0, C_PLATE = 1, C_HOLE = 2, C_WALL = 3 };

void synth_plate_geom_init(synth_plate_geom *g, const hearth_target *target) {
  hearth_target tdef;
  const hearth_target *t = hearth_target_or_default(target, &tdef);
  memset(g, 0, sizeof *g);
  g->t = *t;
  g->n = hearth_target_holes(t);
  g->step = hearth_target_row_step(t);
  g->r = 0.5 * t->hole_diameter_m;
  g->row_start[0] = 0;
  for (int r = 0; r < t->rows; r++)
    g->row_start[r + 1] = g->row_start[r] + hearth_target_row_holes(t, r);
  double xyz[HEARTH_TARGET_MAX_HOLES][3];
  hearth_target_points(t, xyz);
  for (size_t i = 0; i < g->n; i++) {
    g->holes[i][0] = xyz[i][0];
    g->holes[i][1] = xyz[i][1];
  }
  int shifted = t->lattice == HEARTH_LATTICE_HEX && t->rows > 1;
  g->ext_x = (t->cols - 1) * t->pitch_m + (shifted ? 0.5 * t->pitch_m : 0.0);
  g->ext_y = (t->rows - 1) * g->step;
  g->cx = 0.5 * g->ext_x;
  g->cy = 0.5 * g->ext_y;
  if (hearth_target_is_default(t)) {
    /* the paper's plate: 200 x 150 mm */
    g->half_w = 0.5 * 0.200;
    g->half_h = 0.5 * 0.150;
  } else {
    /* other targets: 40 mm of plate around the outer holes' centres */
    g->half_w = g->cx + 0.040;
    g->half_h = g->cy + 0.040;
  }
}

void synth_plate_centre(const synth_plate_geom *g, double c[3]) {
  c[0] = g->cx;
  c[1] = g->cy;
  c[2] = 0.0;
}

/* the rim radius of hole i towards plate direction (dx, dy) from its centre */
static double hole_radius(const synth_plate_geom *g, size_t i, double dx, double dy) {
  if (g->burr_max <= 0) return g->r;
  const float *b = g->burr[i];
  double ph = atan2(dy, dx), r = g->r;
  for (int k = 1; k <= 3; k++) r += b[2 * k - 2] * cos(k * ph) + b[2 * k - 1] * sin(k * ph);
  return r;
}

/* the front face's offset along the plate normal at (x, y) (the bow) */
static double plate_sag(const synth_plate_geom *g, double x, double y) {
  if (g->bow == 0 && g->twist == 0) return 0.0;
  double dx = x - g->cx, dy = y - g->cy;
  return g->bow * (1.0 - (dx * dx + dy * dy) / (g->half_w * g->half_w + g->half_h * g->half_h)) +
         g->twist * dx * dy / (g->half_w * g->half_h);
}

static int classify_plate(const synth_plate_geom *g, double x, double y, size_t *hole) {
  if (fabs(x - g->cx) > g->half_w || fabs(y - g->cy) > g->half_h) return C_OUT;
  const double R = g->r + g->burr_max + g->pos_max, P = g->t.pitch_m;
  /* quick accept of the margin around the pattern */
  if (x < -R || y < -R || x > g->ext_x + R || y > g->ext_y + R) return C_PLATE;
  int r0 = (int)lrint(y / g->step);
  for (int r = r0 - 1; r <= r0 + 1; r++) {
    if (r < 0 || r >= g->t.rows) continue;
    int ncol = hearth_target_row_holes(&g->t, r);
    double off = (g->t.lattice != HEARTH_LATTICE_GRID && (r & 1)) ? 0.5 * P : 0.0;
    int c0 = (int)lrint((x - off) / P);
    for (int cc = c0 - 1; cc <= c0 + 1; cc++) {
      if (cc < 0 || cc >= ncol) continue;
      size_t i = (size_t)(g->row_start[r] + cc);
      const double *h = g->holes[i];
      double dx = x - h[0], dy = y - h[1], d2 = dx * dx + dy * dy;
      if (d2 < R * R) {
        /* R is the search radius; the hole is its own rim (drilled off the
         * lattice by pos_max at most) */
        if (g->burr_max > 0 || g->pos_max > 0) {
          double rr = hole_radius(g, i, dx, dy);
          if (d2 >= rr * rr) continue;
        }
        if (hole) *hole = i;
        return C_HOLE;
      }
    }
  }
  return C_PLATE;
}

/* what lies behind the plate, in normalised image coordinates of the
 * camera (x = d0 / d2, y = d1 / d2): a window of panes, a desk edge, a
 * person, a few small round spots (screws, LEDs) the size of a hole */
typedef struct clutter {
  int on;
  double wx0, wx1, wy0, wy1; /* window */
  int wnx, wny;
  double mull;               /* mullion half width (normalised) */
  double desk_y, desk_slope; /* below the line: desk */
  double px, py, prx, pry;   /* person ellipse */
  int n_spots;
  double spots[8][3]; /* x, y, radius */
} clutter;

/* the thermal lens's departure from its 5-parameter model: a smooth field
 * of image displacement (pixels), a sum of plane waves of 2.5..6 cycles
 * across the image with random directions and phases (higher orders than
 * any Brown-Conrady term); n = 0: the model lens */
enum { LENS_RES_TERMS = 8 };
typedef struct lens_res {
  int n;
  double k[LENS_RES_TERMS][2];  /* wave vector (radians per pixel) */
  double ph[LENS_RES_TERMS][2]; /* phases of the u and v displacement */
  double a[LENS_RES_TERMS][2];  /* amplitudes (pixels) of the u and v displacement */
} lens_res;

/* displacement of the image point (u, v) */
static void lens_res_at(const lens_res *L, double u, double v, double d[2]) {
  d[0] = d[1] = 0.0;
  for (int i = 0; i < L->n; i++) {
    double q = L->k[i][0] * u + L->k[i][1] * v;
    d[0] += L->a[i][0] * cos(q + L->ph[i][0]);
    d[1] += L->a[i][1] * cos(q + L->ph[i][1]);
  }
}

/* a field of rms `rms` pixels per axis for a width x height image, from r */
static void lens_res_draw(lens_res *L, double rms, int width, int height, hearth_rng *r) {
  memset(L, 0, sizeof *L);
  if (rms <= 0) return;
  L->n = LENS_RES_TERMS;
  double size = width > height ? width : height;
  for (int i = 0; i < L->n; i++) {
    double dir = hearth_rng_range(r, 0, 2 * 3.14159265358979323846);
    double cyc = hearth_rng_range(r, 2.5, 6.0);
    L->k[i][0] = 2 * 3.14159265358979323846 * cyc / size * cos(dir);
    L->k[i][1] = 2 * 3.14159265358979323846 * cyc / size * sin(dir);
    for (int c = 0; c < 2; c++) {
      L->ph[i][c] = hearth_rng_range(r, 0, 2 * 3.14159265358979323846);
      /* a cosine has rms amplitude / sqrt 2: n terms of equal amplitude */
      L->a[i][c] = rms * sqrt(2.0 / L->n);
    }
  }
}

/* the model-lens pixel whose ray the true lens images at (u, v): q with
 * q + d(q) = (u, v), by fixed-point steps (the field's slope is ~0.03) */
static void lens_res_undo(const lens_res *L, double u, double v, double q[2]) {
  q[0] = u;
  q[1] = v;
  for (int it = 0; it < 4 && L->n; it++) {
    double d[2];
    lens_res_at(L, q[0], q[1], d);
    q[0] = u - d[0];
    q[1] = v - d[1];
  }
}

/* synth_pixel_warp of a lens residual: the model's pixel a true pixel shows */
static void lens_res_warp(const void *L, double u, double v, double q[2]) {
  lens_res_undo(L, u, v, q);
}

/* the bench's physics of one frame (docs/virtual-rig.md, "Calibration
 * physics"); all zero: the ideal bench */
typedef struct plate_fx {
  double thickness;              /* plate thickness (m); the back face is at plate z = +thickness */
  double lamp_spot;              /* hot spot's excess, a fraction of the hole contrast */
  double lamp_xy[2], lamp_sigma; /* its centre and width on the backing (plate coordinates) */
  double lamp_grad[2];           /* gradient: fraction of the hole contrast per metre */
  double vignetting;             /* blend of cos^4 */
  double fpn_offset, fpn_gain;
  uint64_t fpn_seed;            /* the thermal camera's fixed pattern */
  double motion_px, motion_dir; /* colour: linear blur length (px) and direction (rad) */
  /* colour: the hand-held plate's motion. At time t after the thermal
   * exposure the plate (camera from plate T0 then) is turned by
   * turn t w / |w| about pivot (camera coordinates) and moved by
   * speed t a / |a|; the frame's middle row is read at trigger_s, row y at
   * trigger_s + readout_s ((y + 0.5) / height - 0.5) */
  hearth_rigid T0;
  double mv_a[3], mv_na, mv_w[3], mv_nw, mv_speed, mv_turn, mv_pivot[3];
  double trigger_s, readout_s;
  const lens_res *lens; /* thermal: the true lens's residual (NULL: none) */
  /* thermal: the backing's mm-scale non-uniformity, a fraction of the hole
   * contrast: sum of plane waves (plate coordinates, rad/m; phases) */
  int tex_n;
  double tex_amp, tex_k[8][2], tex_ph[8];
} plate_fx;

typedef struct plate_view {
  const hearth_camera *cam;
  const synth_plate_geom *g;
  hearth_rigid T; /* camera from plate */
  double n[3];    /* plate normal in the camera */
  double nt;      /* n . t */
  plate_fx fx;
  /* thermal */
  double ambient, plate_dt, hole_dt;
  /* colour */
  double white, hole_grey;
  clutter cl;
} plate_view;

static inline double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* camera from plate at time t of the hand-held motion */
static void plate_moved(const plate_fx *fx, double t, hearth_rigid *T) {
  double tr[3], w[3], RC[3];
  for (int k = 0; k < 3; k++) {
    tr[k] = fx->mv_speed * t * fx->mv_a[k] / (fx->mv_na > 0 ? fx->mv_na : 1);
    w[k] = fx->mv_turn * t * fx->mv_w[k] / (fx->mv_nw > 0 ? fx->mv_nw : 1);
  }
  hearth_rigid M;
  hearth_rotvec_to_matrix(w, M.R);
  hearth_rigid_rotate(&M, fx->mv_pivot, RC);
  for (int k = 0; k < 3; k++) M.t[k] = fx->mv_pivot[k] - RC[k] + tr[k];
  hearth_rigid_compose(&M, &fx->T0, T);
}

static void plate_view_set_pose(plate_view *v, const hearth_rigid *T) {
  v->T = *T;
  for (int i = 0; i < 3; i++) v->n[i] = T->R[i * 3 + 2];
  v->nt = dot3(v->n, T->t);
}

/* the view as row `row` of a rolling-shutter frame sees the plate (a copy
 * of v without a rolling shutter) */
static void plate_view_at(const plate_view *v, double row, plate_view *out) {
  *out = *v;
  if (v->fx.readout_s <= 0) return;
  double t = v->fx.trigger_s + v->fx.readout_s * ((row + 0.5) / v->cam->height - 0.5);
  hearth_rigid T;
  plate_moved(&v->fx, t, &T);
  plate_view_set_pose(out, &T);
}

static void plate_view_init(plate_view *v, const hearth_camera *cam, const synth_plate_geom *g,
                            const hearth_rigid *T) {
  memset(v, 0, sizeof *v);
  v->cam = cam;
  v->g = g;
  v->T = *T;
  for (int i = 0; i < 3; i++) v->n[i] = T->R[i * 3 + 2];
  v->nt = dot3(v->n, T->t);
  v->hole_grey = 0.05;
}

/* clutter drawn for one frame (its own stream, so frames without clutter
 * draw nothing from the frame's streams) */
static void clutter_draw(clutter *cl, hearth_rng *r) {
  cl->on = 1;
  cl->wx0 = hearth_rng_range(r, -0.9, -0.1);
  cl->wx1 = cl->wx0 + hearth_rng_range(r, 0.4, 0.9);
  cl->wy0 = hearth_rng_range(r, -0.8, -0.3);
  cl->wy1 = cl->wy0 + hearth_rng_range(r, 0.3, 0.6);
  cl->wnx = 2 + (int)(hearth_rng_uniform(r) * 3);
  cl->wny = 2 + (int)(hearth_rng_uniform(r) * 2);
  cl->mull = hearth_rng_range(r, 0.006, 0.015);
  cl->desk_y = hearth_rng_range(r, 0.25, 0.55);
  cl->desk_slope = hearth_rng_range(r, -0.15, 0.15);
  cl->px = hearth_rng_range(r, -0.7, 0.7);
  cl->py = hearth_rng_range(r, -0.4, 0.2);
  cl->prx = hearth_rng_range(r, 0.12, 0.22);
  cl->pry = cl->prx * hearth_rng_range(r, 1.8, 2.6);
  cl->n_spots = 3 + (int)(hearth_rng_uniform(r) * 5);
  for (int i = 0; i < cl->n_spots; i++) {
    cl->spots[i][0] = hearth_rng_range(r, -0.8, 0.8);
    cl->spots[i][1] = hearth_rng_range(r, -0.6, 0.6);
    cl->spots[i][2] = hearth_rng_range(r, 0.006, 0.02);
  }
}

/* the background at ray d: 0 plain, 1 window pane, 2 mullion, 3 desk,
 * 4 person, 5 spot */
static int clutter_at(const clutter *cl, const double d[3]) {
  if (!cl->on || d[2] <= 0) return 0;
  double x = d[0] / d[2], y = d[1] / d[2];
  for (int i = 0; i < cl->n_spots; i++) {
    double dx = x - cl->spots[i][0], dy = y - cl->spots[i][1];
    if (dx * dx + dy * dy < cl->spots[i][2] * cl->spots[i][2]) return 5;
  }
  double ex = (x - cl->px) / cl->prx, ey = (y - cl->py) / cl->pry;
  if (ex * ex + ey * ey < 1) return 4;
  if (y > cl->desk_y + cl->desk_slope * x) return 3;
  if (x > cl->wx0 && x < cl->wx1 && y > cl->wy0 && y < cl->wy1) {
    double fx = (x - cl->wx0) / (cl->wx1 - cl->wx0) * cl->wnx;
    double fy = (y - cl->wy0) / (cl->wy1 - cl->wy0) * cl->wny;
    double mx = fabs(fx - lrint(fx)) * (cl->wx1 - cl->wx0) / cl->wnx;
    double my = fabs(fy - lrint(fy)) * (cl->wy1 - cl->wy0) / cl->wny;
    return (mx < cl->mull || my < cl->mull) ? 2 : 1;
  }
  return 0;
}

/* class of the ray d (camera frame) and the plate point it meets */
static int classify_ray(const plate_view *v, const double d[3], double p[2]) {
  double dn = dot3(v->n, d);
  if (fabs(dn) < 1e-12) return C_OUT;
  /* a bowed plate: the plane z = sag met again at the sag of the last hit
   * (the slope is a few thousandths, so three rounds are exact to nm) */
  double z0 = 0.0;
  for (int it = 0; it < (v->g->bow != 0 || v->g->twist != 0 ? 4 : 1); it++) {
    if (it) z0 = plate_sag(v->g, p[0], p[1]);
    double t = (v->nt + z0) / dn;
    if (t <= 0) return C_OUT;
    double q[3] = {t * d[0] - v->T.t[0], t * d[1] - v->T.t[1], t * d[2] - v->T.t[2]};
    /* plate coordinates: R^T q */
    p[0] = v->T.R[0] * q[0] + v->T.R[3] * q[1] + v->T.R[6] * q[2];
    p[1] = v->T.R[1] * q[0] + v->T.R[4] * q[1] + v->T.R[7] * q[2];
  }
  size_t hi = 0;
  int cls = classify_plate(v->g, p[0], p[1], &hi);
  if (cls != C_HOLE || v->fx.thickness <= 0) return cls;
  /* a thick plate: the ray sees the backing only if it also passes the back
   * opening (the same rim at plate z = sag + thickness); p becomes the point
   * where it leaves the hole */
  const double *h = v->g->holes[hi];
  double e[3];
  for (int k = 0; k < 3; k++) e[k] = v->T.R[k] * d[0] + v->T.R[3 + k] * d[1] + v->T.R[6 + k] * d[2];
  if (fabs(e[2]) < 1e-12) return C_WALL;
  double s = v->fx.thickness / fabs(e[2]);
  double bx = p[0] + s * e[0] - h[0], by = p[1] + s * e[1] - h[1];
  double rb = hole_radius(v->g, hi, bx, by);
  if (bx * bx + by * by >= rb * rb) return C_WALL;
  p[0] += s * e[0];
  p[1] += s * e[1];
  return C_HOLE;
}

static double thermal_value(const plate_view *v, int cls, const double p[2], const double d[3]) {
  switch (cls) {
    case C_PLATE: return v->ambient + v->plate_dt + 1.5 * (p[0] - 0.06);
    case C_WALL: return v->ambient + v->plate_dt; /* the plate's own wall */
    case C_HOLE: {
      double T = v->ambient + v->hole_dt + 4.0 * (p[1] - 0.036);
      if (v->fx.lamp_spot > 0 || v->fx.lamp_grad[0] != 0 || v->fx.lamp_grad[1] != 0) {
        double dx = p[0] - v->fx.lamp_xy[0], dy = p[1] - v->fx.lamp_xy[1];
        double s2 = v->fx.lamp_sigma * v->fx.lamp_sigma;
        T += v->hole_dt *
             (v->fx.lamp_spot * exp(-(dx * dx + dy * dy) / (2 * s2)) +
              v->fx.lamp_grad[0] * (p[0] - v->g->cx) + v->fx.lamp_grad[1] * (p[1] - v->g->cy));
      }
      if (v->fx.tex_n) {
        double t = 0;
        for (int i = 0; i < v->fx.tex_n; i++)
          t += cos(v->fx.tex_k[i][0] * p[0] + v->fx.tex_k[i][1] * p[1] + v->fx.tex_ph[i]);
        T += v->hole_dt * v->fx.tex_amp * t;
      }
      return T;
    }
    default: break;
  }
  switch (clutter_at(&v->cl, d)) {
    case 1: return v->ambient - 6.0 + 0.5 * d[1]; /* glass: the cold sky */
    case 2: return v->ambient - 1.0;
    case 3: return v->ambient + 1.2 + 0.3 * d[0];
    case 4: return 33.5 - 2.0 * fabs(d[0]); /* a person */
    case 5: return v->ambient + v->hole_dt; /* a warm spot the size of a hole */
    default: return v->ambient + 0.4 * d[1] + 0.2 * d[0];
  }
}

static double rgb_value(const plate_view *v, int cls, const double p[2], const double d[3]) {
  switch (cls) {
    case C_PLATE: return v->white * (1.0 - 0.3 * (p[1] - 0.036));
    case C_WALL: return v->white * (1.0 - 0.3 * (p[1] - 0.036)); /* the plate's own white */
    case C_HOLE: return v->hole_grey;
    default: break;
  }
  switch (clutter_at(&v->cl, d)) {
    case 1: return 0.95; /* daylight through the window */
    case 2: return 0.15;
    case 3: return 0.50 + 0.05 * sin(40.0 * d[0]); /* wood */
    case 4: return 0.22;                           /* dark clothes */
    case 5: return v->hole_grey;
    default: return 0.36 + 0.08 * d[1] - 0.05 * d[0];
  }
}

/* n x n sub-samples of pixel (x, y) from its four corner rays (the lens is
 * smooth over one pixel, so bilinear interpolation of ideal coordinates is
 * exact to far below the detection accuracy) */
static double pixel_fine(const plate_view *v, int thermal, double x, double y, int n) {
  double c[4][2];
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 2; i++) {
      double q[2] = {x - 0.5 + i, y - 0.5 + j};
      if (v->fx.lens) lens_res_undo(v->fx.lens, q[0], q[1], q);
      synth_lens_unproject(v->cam, q[0], q[1], c[j * 2 + i]);
    }
  double sum = 0;
  for (int j = 0; j < n; j++) {
    double b = ((double)j + 0.5) / n;
    for (int i = 0; i < n; i++) {
      double a = ((double)i + 0.5) / n, d[3], p[2];
      for (int k = 0; k < 2; k++)
        d[k] = (1 - a) * (1 - b) * c[0][k] + a * (1 - b) * c[1][k] + (1 - a) * b * c[2][k] +
               a * b * c[3][k];
      d[2] = 1.0;
      double nn = sqrt(dot3(d, d));
      for (int k = 0; k < 3; k++) d[k] /= nn;
      int cls = classify_ray(v, d, p);
      sum += thermal ? thermal_value(v, cls, p, d) : rgb_value(v, cls, p, d);
    }
  }
  return sum / (double)(n * n);
}

/* ---- thermal plate frame ------------------------------------------------------- */
typedef struct tplate_ctx {
  const plate_view *v;
  const float *rays; /* 4 x 4 per pixel */
  float *img;
} tplate_ctx;

static void tplate_rows(void *vctx, size_t b, size_t e, int ti) {
  tplate_ctx *c = vctx;
  size_t W = (size_t)c->v->cam->width;
  for (size_t y = b; y < e; y++)
    for (size_t x = 0; x < W; x++) {
      const float *r = c->rays + (y * W + x) * 16 * 3;
      double sum = 0;
      int first = -1, mixed = 0;
      for (int k = 0; k < 16; k++) {
        double d[3] = {r[3 * k], r[3 * k + 1], r[3 * k + 2]}, p[2];
        int cls = classify_ray(c->v, d, p);
        if (first < 0) first = cls;
        if (cls != first) mixed = 1;
        sum += thermal_value(c->v, cls, p, d);
      }
      c->img[y * W + x] =
          (float)(mixed ? pixel_fine(c->v, 1, (double)x, (double)y, 16) : sum / 16.0);
    }
}

static hearth_status render_thermal_plate(const plate_view *v, const float *rays, double blur,
                                          double netd, hearth_rng *noise, int threads,
                                          hearth_image *out, hearth_err *err) {
  hearth_status st = hearth_image_alloc(out, (size_t)v->cam->width, (size_t)v->cam->height, 1,
                                        HEARTH_PIX_F32, err);
  if (st) return st;
  tplate_ctx c = {v, rays, out->data};
  hearth_parallel_for(out->height, threads, tplate_rows, &c);
  st = synth_blur_f32(out, blur, err);
  if (st) return st;
  float *px = out->data;
  for (size_t i = 0; i < out->width * out->height; i++)
    px[i] += (float)(netd * hearth_rng_normal(noise));
  const plate_fx *fx = &v->fx;
  if (fx->vignetting > 0 || fx->fpn_offset > 0 || fx->fpn_gain > 0) {
    /* contrast to the shutter's reference (ambient) falls off as cos^4 of
     * the field angle, blended by fx->vignetting; then the camera's fixed
     * pattern of offset and gain, the same in every frame */
    hearth_rng fp;
    hearth_rng_seed(&fp, fx->fpn_seed);
    for (size_t y = 0; y < out->height; y++)
      for (size_t x = 0; x < out->width; x++) {
        double u[2];
        synth_lens_unproject(v->cam, (double)x, (double)y, u);
        double c2 = 1.0 / (1.0 + u[0] * u[0] + u[1] * u[1]);
        double vig = 1.0 - fx->vignetting * (1.0 - c2 * c2);
        double go = hearth_rng_normal(&fp), gg = hearth_rng_normal(&fp);
        size_t i = y * out->width + x;
        double dT = ((double)px[i] - v->ambient) * vig;
        px[i] = (float)(v->ambient + dT * (1.0 + fx->fpn_gain * gg) + fx->fpn_offset * go);
      }
  }
  return HEARTH_OK;
}

/* a linear motion blur of length len pixels along direction dir: the mean
 * of 9 bilinear samples along the segment centred on each pixel */
static hearth_status motion_blur_f32(hearth_image *im, double len, double dir, hearth_err *err) {
  if (len <= 0) return HEARTH_OK;
  size_t W = im->width, H = im->height;
  float *src = hearth_alloc_array(W * H, sizeof(float));
  if (!src) return hearth_err_set(err, HEARTH_E_NOMEM, "motion blur: out of memory");
  memcpy(src, im->data, W * H * sizeof(float));
  float *dst = im->data;
  enum { NT = 9 };
  double ox[NT], oy[NT];
  for (int k = 0; k < NT; k++) {
    double s = len * ((double)k / (NT - 1) - 0.5);
    ox[k] = s * cos(dir);
    oy[k] = s * sin(dir);
  }
  for (size_t y = 0; y < H; y++)
    for (size_t x = 0; x < W; x++) {
      double sum = 0;
      for (int k = 0; k < NT; k++) {
        double fx = (double)x + ox[k], fy = (double)y + oy[k];
        fx = fx < 0 ? 0 : fx > (double)W - 1 ? (double)W - 1 : fx;
        fy = fy < 0 ? 0 : fy > (double)H - 1 ? (double)H - 1 : fy;
        size_t x0 = (size_t)fx, y0 = (size_t)fy;
        size_t x1 = x0 + 1 < W ? x0 + 1 : x0, y1 = y0 + 1 < H ? y0 + 1 : y0;
        double a = fx - (double)x0, b = fy - (double)y0;
        sum += (1 - a) * (1 - b) * src[y0 * W + x0] + a * (1 - b) * src[y0 * W + x1] +
               (1 - a) * b * src[y1 * W + x0] + a * b * src[y1 * W + x1];
      }
      dst[y * W + x] = (float)(sum / NT);
    }
  free(src);
  return HEARTH_OK;
}

/* ---- colour plate frame ----------------------------------------------------------- */
typedef struct cplate_ctx {
  const plate_view *v;
  const float *rays; /* 1 per pixel */
  uint8_t *cls;
  float *img;
} cplate_ctx;

static void cplate_class_rows(void *vctx, size_t b, size_t e, int ti) {
  cplate_ctx *c = vctx;
  size_t W = (size_t)c->v->cam->width;
  for (size_t y = b; y < e; y++) {
    plate_view v;
    plate_view_at(c->v, (double)y, &v);
    for (size_t x = 0; x < W; x++) {
      const float *r = c->rays + (y * W + x) * 3;
      double d[3] = {r[0], r[1], r[2]}, p[2];
      int cls = classify_ray(&v, d, p);
      c->cls[y * W + x] = (uint8_t)cls;
      c->img[y * W + x] = (float)rgb_value(&v, cls, p, d);
    }
  }
}

static void cplate_edge_rows(void *vctx, size_t b, size_t e, int ti) {
  cplate_ctx *c = vctx;
  size_t W = (size_t)c->v->cam->width, H = (size_t)c->v->cam->height;
  for (size_t y = b; y < e; y++) {
    plate_view v;
    plate_view_at(c->v, (double)y, &v);
    for (size_t x = 0; x < W; x++) {
      uint8_t me = c->cls[y * W + x];
      int mixed = 0;
      for (long dy = -1; dy <= 1 && !mixed; dy++)
        for (long dx = -1; dx <= 1; dx++) {
          long xx = (long)x + dx, yy = (long)y + dy;
          if (xx < 0 || yy < 0 || xx >= (long)W || yy >= (long)H) continue;
          if (c->cls[(size_t)yy * W + (size_t)xx] != me) {
            mixed = 1;
            break;
          }
        }
      if (mixed) c->img[y * W + x] = (float)pixel_fine(&v, 0, (double)x, (double)y, 8);
    }
  }
}

static hearth_status render_rgb_plate(const plate_view *v, const float *rays, double blur,
                                      hearth_rng *noise, int threads, hearth_image *out,
                                      hearth_err *err) {
  size_t W = (size_t)v->cam->width, H = (size_t)v->cam->height;
  hearth_image f = {0};
  hearth_status st = hearth_image_alloc(&f, W, H, 1, HEARTH_PIX_F32, err);
  if (st) return st;
  uint8_t *cls = hearth_alloc_array(W * H, 1);
  if (!cls) {
    hearth_image_free(&f);
    return hearth_err_set(err, HEARTH_E_NOMEM, "plate render: out of memory");
  }
  cplate_ctx c = {v, rays, cls, f.data};
  hearth_parallel_for(H, threads, cplate_class_rows, &c);
  hearth_parallel_for(H, threads, cplate_edge_rows, &c);
  free(cls);
  st = synth_blur_f32(&f, blur, err);
  if (!st) st = motion_blur_f32(&f, v->fx.motion_px, v->fx.motion_dir, err);
  if (!st) st = hearth_image_alloc(out, W, H, 3, HEARTH_PIX_U8, err);
  if (st) {
    hearth_image_free(&f);
    return st;
  }
  const float *src = f.data;
  uint8_t *dst = out->data;
  const double tint[3] = {1.0, 0.985, 0.95};
  for (size_t i = 0; i < W * H; i++)
    for (int k = 0; k < 3; k++) {
      double val = src[i] * tint[k] * 255.0 + 1.5 * synth_fast_normal(noise);
      dst[3 * i + (size_t)k] = (uint8_t)lrint(val < 0 ? 0 : val > 255 ? 255 : val);
    }
  hearth_image_free(&f);
  return HEARTH_OK;
}

/* ---- truth ----------------------------------------------------------------------- */
int synth_plate_truth(const hearth_camera *c, const synth_plate_geom *g, const hearth_rigid *T,
                      double (*centres)[2]) {
  int inside = 0;
  for (size_t i = 0; i < g->n; i++) {
    double hx = g->holes[i][0], hy = g->holes[i][1], hz = plate_sag(g, hx, hy);
    double P[3] = {hx, hy, hz}, Q[3];
    hearth_rigid_apply(T, P, Q);
    if (!synth_lens_project(c, Q, centres[i])) {
      centres[i][0] = centres[i][1] = -1e9;
      continue;
    }
    /* the whole rim must be inside the image */
    int ok = 1;
    for (int k = 0; k < 12 && ok; k++) {
      double a = k * (2.0 * 3.14159265358979323846 / 12.0), uv[2];
      double R[3] = {hx + g->r * cos(a), hy + g->r * sin(a), hz}, S[3];
      hearth_rigid_apply(T, R, S);
      if (!synth_lens_project(c, S, uv) || uv[0] < 0.5 || uv[1] < 0.5 || uv[0] > c->width - 1.5 ||
          uv[1] > c->height - 1.5)
        ok = 0;
    }
    inside += ok;
  }
  return inside;
}

void synth_plate_pose(const synth_plate_geom *g, hearth_rng *r, double d, double ox, double oy,
                      hearth_rigid *T) {
  synth_plate_pose_rolled(g, r, d, ox, oy, 12.0, T);
}

void synth_plate_pose_rolled(const synth_plate_geom *g, hearth_rng *r, double d, double ox,
                             double oy, double roll_deg, hearth_rigid *T) {
  double phi = hearth_rng_range(r, 0, 2 * 3.14159265358979323846);
  double tilt = hearth_rng_range(r, 5.0, 40.0) * DEG,
         roll = hearth_rng_range(r, -roll_deg, roll_deg) * DEG;
  double w1[3] = {cos(phi) * tilt, sin(phi) * tilt, 0}, w2[3] = {0, 0, roll}, R1[9], R2[9];
  hearth_rotvec_to_matrix(w1, R1);
  hearth_rotvec_to_matrix(w2, R2);
  hearth_mat3_mul(R1, R2, T->R);
  double pc[3], Rpc[3];
  synth_plate_centre(g, pc);
  hearth_rigid_rotate(T, pc, Rpc);
  double C[3] = {d * ox, d * oy, d};
  for (int k = 0; k < 3; k++) T->t[k] = C[k] - Rpc[k];
}

/* how far the plate is held: the paper plate's distances, scaled with the
 * plate's size, and nearer for a sensor narrower than 256 pixels */
static double distance_scale(const synth_plate_geom *g, const hearth_camera *thermal) {
  double s = hearth_target_is_default(&g->t) ? 1.0 : g->half_w / 0.100;
  if (thermal->width < 256) s *= sqrt(thermal->width / 256.0);
  return s;
}

/* lens: the true lens's residual over the model (NULL: none) */
static void det_fill(hearth_detection *det, const char *frame, const char *camera,
                     const hearth_camera *cam, const synth_plate_geom *g, const hearth_rigid *T,
                     const lens_res *lens) {
  memset(det, 0, sizeof *det);
  snprintf(det->frame, sizeof det->frame, "%s", frame);
  snprintf(det->camera, sizeof det->camera, "%s", camera);
  int n = synth_plate_truth(cam, g, T, det->centres);
  if ((size_t)n == g->n) {
    det->found = 1;
    for (size_t i = 0; lens && i < g->n; i++) {
      double d[2];
      lens_res_at(lens, det->centres[i][0], det->centres[i][1], d);
      det->centres[i][0] += d[0];
      det->centres[i][1] += d[1];
    }
  } else {
    memset(det->centres, 0, sizeof det->centres);
    det->found = 0;
    snprintf(det->reason, sizeof det->reason, "only %d holes visible", n);
  }
}

/* a rolling-shutter colour frame's true centres: each hole at the pose of
 * the row its centre is read in (fixed point from the middle row) */
static void rs_truth(const plate_view *v, hearth_detection *det) {
  const synth_plate_geom *g = v->g;
  for (size_t i = 0; i < g->n; i++) {
    double P[3] = {g->holes[i][0], g->holes[i][1], plate_sag(g, g->holes[i][0], g->holes[i][1])};
    double row = 0.5 * (v->cam->height - 1), uv[2] = {0, 0};
    for (int it = 0; it < 4; it++) {
      plate_view vr;
      plate_view_at(v, row, &vr);
      double Q[3];
      hearth_rigid_apply(&vr.T, P, Q);
      if (!synth_lens_project(v->cam, Q, uv)) break;
      if (v->fx.lens) {
        double d[2];
        lens_res_at(v->fx.lens, uv[0], uv[1], d);
        uv[0] += d[0];
        uv[1] += d[1];
      }
      row = uv[1];
    }
    det->centres[i][0] = uv[0];
    det->centres[i][1] = uv[1];
  }
}

static hearth_status write_thermal(const char *path, const plate_view *v, const float *rays,
                                   double blur, double netd, hearth_rng *noise, int threads,
                                   hearth_err *err) {
  hearth_image img = {0};
  hearth_status st = render_thermal_plate(v, rays, blur, netd, noise, threads, &img, err);
  if (!st) st = hearth_thermal_write_csv(path, &img, 2, err);
  hearth_image_free(&img);
  return st;
}

/* the frame's look: contrast, polarity and clutter of the options (each
 * with its own stream, so the paper's look draws nothing extra) */
static void apply_look(plate_view *v, int thermal, const synth_plate_look *look, uint64_t seed) {
  if (!look) return;
  hearth_rng r;
  hearth_rng_seed(&r, seed);
  if (thermal) {
    if (look->low_contrast) {
      v->hole_dt = hearth_rng_range(&r, 2.0, 4.0);
      v->plate_dt = hearth_rng_range(&r, 0.2, 0.6);
    }
    if (look->invert) {
      double t = v->hole_dt;
      v->hole_dt = v->plate_dt;
      v->plate_dt = t;
    }
  } else {
    if (look->low_contrast) {
      v->white = hearth_rng_range(&r, 0.50, 0.60);
      v->hole_grey = v->white - hearth_rng_range(&r, 0.15, 0.22);
    }
    if (look->invert) {
      double w = v->white;
      v->white = v->hole_grey > 0.1 ? v->hole_grey : 0.12;
      v->hole_grey = w;
    }
  }
  if (look->clutter) clutter_draw(&v->cl, &r);
}

hearth_status synth_plate_frame(const hearth_camera *cam, const synth_plate_geom *g,
                                const hearth_rigid *T, int thermal, const synth_plate_look *look,
                                uint64_t seed, int threads, hearth_image *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  float *rays = synth_ray_table(cam, thermal ? 4 : 1, threads);
  if (!rays) return hearth_err_set(err, HEARTH_E_NOMEM, "plate frame: out of memory");
  plate_view v;
  plate_view_init(&v, cam, g, T);
  hearth_rng r, noise;
  hearth_rng_seed(&r, seed);
  hearth_rng_fork(&r, 1, &noise);
  v.ambient = hearth_rng_range(&r, 20.0, 24.0);
  v.plate_dt = hearth_rng_range(&r, 0.5, 1.5);
  v.hole_dt = hearth_rng_range(&r, 15.0, 25.0);
  v.white = hearth_rng_range(&r, 0.80, 0.90) * (0.85 + 0.15 * fabs(v.n[2]));
  apply_look(&v, thermal, look, seed ^ 0x9e3779b97f4a7c15ULL);
  hearth_status st = thermal ? render_thermal_plate(&v, rays, 0.5, 0.05, &noise, threads, out, err)
                             : render_rgb_plate(&v, rays, 0.6, &noise, threads, out, err);
  free(rays);
  return st;
}

hearth_status synth_tone_map8(const hearth_image *temps, hearth_image *out, hearth_err *err) {
  size_t n = temps->width * temps->height;
  const float *T = temps->data;
  float lo = T[0], hi = T[0];
  for (size_t i = 0; i < n; i++) {
    lo = fminf(lo, T[i]);
    hi = fmaxf(hi, T[i]);
  }
  hearth_status st = hearth_image_alloc(out, temps->width, temps->height, 1, HEARTH_PIX_U8, err);
  if (st) return st;
  uint8_t *q = out->data;
  double span = hi > lo ? (double)hi - lo : 1.0;
  /* a camera's automatic gain: min..max to 0..255 with a display gamma */
  for (size_t i = 0; i < n; i++)
    q[i] = (uint8_t)lrint(255.0 * pow(((double)T[i] - lo) / span, 1 / 1.4));
  return HEARTH_OK;
}

/* the hand-held plate's flex in one frame: U(-m, m) of bow or twist, from
 * the frame's own fork of base (nothing drawn when m is 0) */
static double plate_flex(const hearth_rng *base, uint64_t fork, double m) {
  if (m <= 0) return 0.0;
  hearth_rng r;
  hearth_rng_fork(base, fork, &r);
  return m * hearth_rng_range(&r, -1.0, 1.0);
}

/* N(0, sigma^2) from r, clipped to +-3 sigma */
static double normal_3sigma(hearth_rng *r, double sigma) {
  const double lim = 3.0 * sigma, a = sigma * hearth_rng_normal(r);
  return a < -lim ? -lim : a > lim ? lim : a;
}

hearth_status synth_calibration_write(const char *root, const hearth_rig *rig,
                                      const hearth_synth_opts *o, uint64_t seed,
                                      const float *thermal_rays, const float *rgb_rays,
                                      double ambient_c, hearth_err *err) {
  char dir_th[4096], dir_st[4096], dir_gt[4096], path[4096];
  snprintf(dir_th, sizeof dir_th, "%s/calibration/captures/thermal", root);
  snprintf(dir_st, sizeof dir_st, "%s/calibration/captures/stereo", root);
  snprintf(dir_gt, sizeof dir_gt, "%s/ground_truth/calibration", root);
  hearth_status st;
  if ((st = hearth_mkdirs(dir_th, err)) || (st = hearth_mkdirs(dir_st, err)) ||
      (st = hearth_mkdirs(dir_gt, err)))
    return st;
  synth_plate_geom *g = malloc(sizeof *g);
  double(*c)[2] = hearth_alloc_array(HEARTH_TARGET_MAX_HOLES, sizeof *c);
  if (!g || !c) {
    free(g);
    free(c);
    return hearth_err_set(err, HEARTH_E_NOMEM, "calibration captures: out of memory");
  }
  synth_plate_geom_init(g, &o->target);
  const size_t NH = g->n;
  const double ds = distance_scale(g, &rig->thermal) * (o->thermal_wide ? 0.7 : 1.0);
  /* a wide lens sees about twice as far to the side */
  const double os = o->thermal_wide ? 2.0 : 1.0;
  synth_plate_look look = {o->calib_clutter, o->calib_low_contrast, o->calib_invert};
  const synth_plate_look *lk = (look.clutter || look.low_contrast || look.invert) ? &look : NULL;
  int nf = o->n_thermal_frames, np = o->n_stereo_pairs;
  hearth_detections dets;
  memset(&dets, 0, sizeof dets);
  dets.target = g->t;
  dets.frames = hearth_calloc_array((size_t)nf + 2 * (size_t)np + 1, sizeof(hearth_detection));
  if (!dets.frames) {
    free(g);
    free(c);
    return hearth_err_set(err, HEARTH_E_NOMEM, "detections: out of memory");
  }
  hearth_rng base;
  hearth_rng_seed(&base, seed);
  hearth_progress prog;
  hearth_progress_begin(&prog, "calibration", (size_t)(nf + np), o->quiet);
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&rig->T_thermal_from_rgb, &T_rgb_from_th);
  st = HEARTH_OK;

  /* the bench's physics, from streams of their own (the ideal bench draws
   * nothing from them) */
  const int phys = !o->ideal;
  const hearth_synth_effects *E = &o->effects;
  /* the plate turned in its own plane: every way round on the bench (the
   * paper's 11/10 rows fix the order at any turn), as the clean bench for
   * targets whose order a half turn would flip (docs/virtual-rig.md) */
  const double roll_deg = phys && hearth_target_is_default(&g->t) ? E->plate_roll_deg : 12.0;
  plate_fx fx0;
  memset(&fx0, 0, sizeof fx0);
  lens_res lres, lres_c; /* the thermal and colour lenses' residuals */
  memset(&lres, 0, sizeof lres);
  memset(&lres_c, 0, sizeof lres_c);
  const float *trays = thermal_rays, *crays = rgb_rays; /* the true lenses' rays */
  float *own_rays = NULL, *own_crays = NULL;
  double bow0 = 0.0; /* the plate's own bow; each frame adds the hand's flex */
  if (phys) {
    hearth_rng b;
    hearth_rng_fork(&base, 77001, &b);
    double th = hearth_rng_range(&b, 0.003, 0.006);
    fx0.thickness = E->plate_thickness_m < 0 ? th : E->plate_thickness_m;
    fx0.lamp_xy[0] = g->cx + hearth_rng_range(&b, -0.4, 0.4) * g->half_w;
    fx0.lamp_xy[1] = g->cy + hearth_rng_range(&b, -0.4, 0.4) * g->half_h;
    fx0.lamp_sigma = hearth_rng_range(&b, 0.3, 0.5) * g->half_w;
    fx0.lamp_spot = E->lamp * hearth_rng_range(&b, 0.15, 0.30);
    /* 10..20 % of the hole contrast across the plate's width */
    double ga = hearth_rng_range(&b, 0, 2 * 3.14159265358979323846);
    double gm = E->lamp * hearth_rng_range(&b, 0.10, 0.20) / (2 * g->half_w);
    fx0.lamp_grad[0] = gm * cos(ga);
    fx0.lamp_grad[1] = gm * sin(ga);
    fx0.vignetting = E->vignetting;
    fx0.fpn_offset = E->fpn_offset_c;
    fx0.fpn_gain = E->fpn_gain;
    fx0.fpn_seed = hearth_rng_u64(&b);
    /* the thermal lens's residual over its model, from a stream of its own */
    hearth_rng lb;
    hearth_rng_fork(&base, 77003, &lb);
    lens_res_draw(&lres, E->lens_residual_px, rig->thermal.width, rig->thermal.height, &lb);
    if (lres.n) fx0.lens = &lres;
    hearth_rng lc;
    hearth_rng_fork(&base, 77005, &lc);
    lens_res_draw(&lres_c, E->rgb_residual_px, rig->rgb.width, rig->rgb.height, &lc);
    /* the backing's texture: 8 waves of 6..15 mm in random directions,
     * rms E->backing_texture of the hole contrast */
    if (E->backing_texture > 0) {
      hearth_rng tb;
      hearth_rng_fork(&base, 77004, &tb);
      fx0.tex_n = 8;
      fx0.tex_amp = E->backing_texture * sqrt(2.0 / fx0.tex_n);
      for (int i = 0; i < fx0.tex_n; i++) {
        double dir = hearth_rng_range(&tb, 0, 2 * 3.14159265358979323846);
        double k = 2 * 3.14159265358979323846 / hearth_rng_range(&tb, 0.006, 0.015);
        fx0.tex_k[i][0] = k * cos(dir);
        fx0.tex_k[i][1] = k * sin(dir);
        fx0.tex_ph[i] = hearth_rng_range(&tb, 0, 2 * 3.14159265358979323846);
      }
    }
    /* the plate's bow and its holes' rims, from a stream of their own */
    hearth_rng wb;
    hearth_rng_fork(&base, 77002, &wb);
    bow0 = E->plate_bow_m * hearth_rng_range(&wb, 0.5, 1.0) *
           (hearth_rng_uniform(&wb) < 0.5 ? -1.0 : 1.0);
    g->bow = bow0;
    if (E->hole_burr_m > 0) {
      /* each term within 3 sigma; burr_max the largest sum of magnitudes */
      for (size_t i = 0; i < g->n; i++) {
        double sum = 0;
        for (int k = 0; k < 6; k++) {
          g->burr[i][k] = (float)normal_3sigma(&wb, E->hole_burr_m);
          sum += fabs((double)g->burr[i][k]);
        }
        if (sum > g->burr_max) g->burr_max = sum;
      }
    }
    if (E->hole_position_m > 0) {
      /* each hole drilled off its nominal position (a stream of its own):
       * the holes, their rims and the ground truth move, the target file
       * keeps the nominal lattice */
      hearth_rng hp;
      hearth_rng_fork(&base, 77006, &hp);
      for (size_t i = 0; i < g->n; i++) {
        double d2 = 0;
        for (int k = 0; k < 2; k++) {
          double a = normal_3sigma(&hp, E->hole_position_m);
          g->holes[i][k] += a;
          d2 += a * a;
        }
        if (sqrt(d2) > g->pos_max) g->pos_max = sqrt(d2);
      }
    }
    if (fx0.thickness > 0) {
      /* the plate's thickness, measured (callipers) and given to the pipeline */
      hearth_target tt = g->t;
      tt.thickness_m = fx0.thickness;
      g->t.thickness_m = fx0.thickness;
      dets.target = g->t;
      snprintf(path, sizeof path, "%s/calibration/target.json", root);
      st = hearth_target_write(path, &tt, err);
    }
  }
  if (!st && lres.n) {
    own_rays = synth_ray_table_warped(&rig->thermal, 4, o->threads, lens_res_warp, &lres);
    if (!own_rays) st = hearth_err_set(err, HEARTH_E_NOMEM, "calibration captures: out of memory");
    trays = own_rays;
  }
  if (!st && lres_c.n && np > 0) {
    own_crays = synth_ray_table_warped(&rig->rgb, 1, o->threads, lens_res_warp, &lres_c);
    if (!own_crays) st = hearth_err_set(err, HEARTH_E_NOMEM, "calibration captures: out of memory");
    crays = own_crays;
  }
  const double nframes = (double)(nf + np > 1 ? nf + np - 1 : 1);

  /* thermal-only frames for the intrinsics */
  for (int i = 0; i < nf && !st; i++) {
    hearth_rng r, noise;
    hearth_rng_fork(&base, 1000 + (uint64_t)i, &r);
    hearth_rng_fork(&base, 5000 + (uint64_t)i, &noise);
    int partial = (i % 9) == 4, blurred = (i % 9) == 7;
    if (phys) {
      g->bow = bow0 + plate_flex(&base, 11000 + (uint64_t)i, E->plate_flex_m);
      g->twist = plate_flex(&base, 13000 + (uint64_t)i, E->plate_twist_m);
    }
    hearth_rigid T;
    for (int tries = 0; tries < 200; tries++) {
      double d = hearth_rng_range(&r, 0.22, 0.40) * ds;
      double ox = hearth_rng_range(&r, -0.24, 0.24) * os,
             oy = hearth_rng_range(&r, -0.16, 0.16) * os;
      if (partial)
        ox = (hearth_rng_uniform(&r) < 0.5 ? -1 : 1) * hearth_rng_range(&r, 0.38, 0.5) * os;
      synth_plate_pose_rolled(g, &r, d, ox, oy, roll_deg, &T);
      size_t n = (size_t)synth_plate_truth(&rig->thermal, g, &T, c);
      if (partial ? (n >= 20 && n < NH) : n == NH) break;
    }
    plate_view v;
    plate_view_init(&v, &rig->thermal, g, &T);
    v.ambient = ambient_c + hearth_rng_range(&r, -0.3, 0.3);
    v.plate_dt = hearth_rng_range(&r, 0.5, 1.5);
    v.hole_dt = hearth_rng_range(&r, 15.0, 25.0);
    if (lk) apply_look(&v, 1, lk, hearth_rng_u64(&noise) ^ (uint64_t)i);
    if (phys) {
      v.fx = fx0;
      v.plate_dt += E->plate_warming_c * (double)i / nframes;
    }
    char name[16];
    snprintf(name, sizeof name, "f%03d", i);
    snprintf(path, sizeof path, "%s/%s.csv", dir_th, name);
    st = write_thermal(path, &v, trays, blurred ? 1.3 : 0.5, o->netd_c, &noise, o->threads, err);
    det_fill(&dets.frames[dets.n++], name, "thermal", &rig->thermal, g, &T, v.fx.lens);
    hearth_progress_step(&prog, 1);
  }

  /* stereo pairs: one plate pose seen by both cameras */
  for (int i = 0; i < np && !st; i++) {
    hearth_rng r, noise;
    hearth_rng_fork(&base, 2000 + (uint64_t)i, &r);
    hearth_rng_fork(&base, 6000 + (uint64_t)i, &noise);
    int partial = (i % 8) == 3, blurred = (i % 8) == 6;
    if (phys) {
      g->bow = bow0 + plate_flex(&base, 12000 + (uint64_t)i, E->plate_flex_m);
      g->twist = plate_flex(&base, 14000 + (uint64_t)i, E->plate_twist_m);
    }
    hearth_rigid T_th, T_rgb;
    for (int tries = 0; tries < 200; tries++) {
      double d = hearth_rng_range(&r, 0.27, 0.45) * ds;
      double ox = hearth_rng_range(&r, -0.14, 0.14) * os,
             oy = hearth_rng_range(&r, -0.08, 0.08) * os;
      if (partial)
        ox = (hearth_rng_uniform(&r) < 0.5 ? -1 : 1) * hearth_rng_range(&r, 0.38, 0.5) * os;
      synth_plate_pose_rolled(g, &r, d, ox, oy, roll_deg, &T_th);
      hearth_rigid_compose(&T_rgb_from_th, &T_th, &T_rgb);
      size_t n = (size_t)synth_plate_truth(&rig->thermal, g, &T_th, c);
      size_t m = (size_t)synth_plate_truth(&rig->rgb, g, &T_rgb, c);
      if (partial ? (n >= 20 && n < NH) : (n == NH && m == NH)) break;
    }
    plate_view vt, vc;
    plate_view_init(&vt, &rig->thermal, g, &T_th);
    plate_view_init(&vc, &rig->rgb, g, &T_rgb);
    vt.ambient = ambient_c + hearth_rng_range(&r, -0.3, 0.3);
    vt.plate_dt = hearth_rng_range(&r, 0.5, 1.5);
    vt.hole_dt = hearth_rng_range(&r, 15.0, 25.0);
    vc.white = hearth_rng_range(&r, 0.80, 0.90) * (0.85 + 0.15 * fabs(vc.n[2]));
    if (lk) {
      uint64_t ls = hearth_rng_u64(&noise) ^ (uint64_t)i;
      apply_look(&vt, 1, lk, ls);
      apply_look(&vc, 0, lk, ls + 1);
      /* the same room behind the plate in both cameras is not modelled:
       * each camera gets its own clutter */
    }
    if (phys) {
      hearth_rng f;
      hearth_rng_fork(&base, 9000 + (uint64_t)i, &f);
      vt.fx = fx0;
      vt.plate_dt += E->plate_warming_c * (double)(nf + i) / nframes;
      vc.fx = fx0;
      vc.fx.lens = lres_c.n ? &lres_c : NULL;
      vc.fx.motion_px = E->motion_blur_px * hearth_rng_uniform(&f);
      vc.fx.motion_dir = hearth_rng_range(&f, 0, 2 * 3.14159265358979323846);
      /* the trigger offset: the hand-held plate moves between the thermal
       * and the colour exposure, a small rigid motion about its centre; a
       * rolling shutter reads each row at its own time of that motion */
      double dt = 1e-3 * E->trigger_ms * hearth_rng_uniform(&f);
      double na = 0, nw = 0;
      for (int k = 0; k < 3; k++) {
        vc.fx.mv_a[k] = hearth_rng_normal(&f);
        vc.fx.mv_w[k] = hearth_rng_normal(&f);
        na += vc.fx.mv_a[k] * vc.fx.mv_a[k];
        nw += vc.fx.mv_w[k] * vc.fx.mv_w[k];
      }
      vc.fx.mv_na = sqrt(na);
      vc.fx.mv_nw = sqrt(nw);
      vc.fx.mv_speed = E->hand_speed_m_s;
      vc.fx.mv_turn = E->hand_turn_rad_s;
      vc.fx.T0 = T_rgb;
      double pc[3];
      synth_plate_centre(g, pc);
      hearth_rigid_apply(&T_rgb, pc, vc.fx.mv_pivot);
      vc.fx.trigger_s = dt;
      vc.fx.readout_s = 1e-3 * E->rs_readout_ms;
      plate_moved(&vc.fx, dt, &T_rgb);
      plate_view_set_pose(&vc, &T_rgb);
    }
    char name[16];
    snprintf(name, sizeof name, "p%03d", i);
    snprintf(path, sizeof path, "%s/%s_thermal.csv", dir_st, name);
    st = write_thermal(path, &vt, trays, blurred ? 1.3 : 0.5, o->netd_c, &noise, o->threads, err);
    if (!st) {
      hearth_image img = {0};
      st = render_rgb_plate(&vc, crays, blurred ? 3.0 : 0.6, &noise, o->threads, &img, err);
      snprintf(path, sizeof path, "%s/%s_rgb.jpg", dir_st, name);
      if (!st) st = hearth_jpeg_write(path, &img, phys ? E->jpeg_quality : 92, err);
      hearth_image_free(&img);
    }
    det_fill(&dets.frames[dets.n++], name, "thermal", &rig->thermal, g, &T_th, vt.fx.lens);
    det_fill(&dets.frames[dets.n], name, "rgb", &rig->rgb, g, &T_rgb, vc.fx.lens);
    if (dets.frames[dets.n].found && vc.fx.readout_s > 0) rs_truth(&vc, &dets.frames[dets.n]);
    dets.n++;
    hearth_progress_step(&prog, 1);
  }
  hearth_progress_end(&prog);
  if (!st) {
    snprintf(path, sizeof path, "%s/detections.json", dir_gt);
    st = hearth_detections_write(path, &dets, err);
  }
  hearth_detections_free(&dets);
  free(own_rays);
  free(own_crays);
  free(g);
  free(c);
  return st;
}

/* ---- for the thermal-only captures (synth_thermal_only.c) ------------------------------ */
hearth_status synth_plate_thermal_frame(const hearth_camera *cam, const synth_plate_geom *g,
                                        const hearth_rigid *T, const float *rays, double ambient,
                                        double plate_dt, double hole_dt, double blur, double netd,
                                        uint64_t noise_seed, int threads, hearth_image *out,
                                        hearth_err *err) {
  plate_view v;
  plate_view_init(&v, cam, g, T);
  v.ambient = ambient;
  v.plate_dt = plate_dt;
  v.hole_dt = hole_dt;
  hearth_rng noise;
  hearth_rng_seed(&noise, noise_seed);
  return render_thermal_plate(&v, rays, blur, netd, &noise, threads, out, err);
}
