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
#define PLATE_W 0.200
#define PLATE_H 0.150
#define HOLE_R 0.004

enum { C_OUT = 0, C_PLATE = 1, C_HOLE = 2 };

void synth_plate_centre(double c[3]) {
  c[0] = 5.0 * HEARTH_PLATE_PITCH_M;
  c[1] = 3.5 * HEARTH_PLATE_ROW_STEP_M;
  c[2] = 0.0;
}

/* hole (r, c) through the shared pattern definition (rows of 11 and 10) */
static void hole_xy(int r, int c, double *x, double *y) {
  double p[3];
  hearth_plate_hole((r / 2) * 21 + ((r & 1) ? 11 : 0) + c, p);
  *x = p[0];
  *y = p[1];
}

static int classify_plate(const double (*holes)[2], double x, double y) {
  const double cx = 5.0 * HEARTH_PLATE_PITCH_M, cy = 3.5 * HEARTH_PLATE_ROW_STEP_M;
  if (fabs(x - cx) > 0.5 * PLATE_W || fabs(y - cy) > 0.5 * PLATE_H) return C_OUT;
  /* quick accept of the margin around the pattern */
  if (x < -HOLE_R || y < -HOLE_R || x > 10 * HEARTH_PLATE_PITCH_M + HOLE_R ||
      y > 7 * HEARTH_PLATE_ROW_STEP_M + HOLE_R)
    return C_PLATE;
  int r0 = (int)lrint(y / HEARTH_PLATE_ROW_STEP_M);
  for (int r = r0 - 1; r <= r0 + 1; r++) {
    if (r < 0 || r >= HEARTH_PLATE_ROWS) continue;
    int ncol = (r & 1) ? 10 : 11;
    double off = (r & 1) ? 0.5 * HEARTH_PLATE_PITCH_M : 0.0;
    int c0 = (int)lrint((x - off) / HEARTH_PLATE_PITCH_M);
    for (int cc = c0 - 1; cc <= c0 + 1; cc++) {
      if (cc < 0 || cc >= ncol) continue;
      const double *h = holes[(r / 2) * 21 + ((r & 1) ? 11 : 0) + cc];
      if ((x - h[0]) * (x - h[0]) + (y - h[1]) * (y - h[1]) < HOLE_R * HOLE_R) return C_HOLE;
    }
  }
  return C_PLATE;
}

typedef struct plate_view {
  const hearth_camera *cam;
  hearth_rigid T; /* camera from plate */
  double n[3];    /* plate normal in the camera */
  double nt;      /* n . t */
  /* thermal */
  double ambient, plate_dt, hole_dt;
  /* colour */
  double white;
  double holes[HEARTH_PLATE_HOLES][2]; /* plate coordinates of the holes */
} plate_view;

static inline double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void plate_view_init(plate_view *v, const hearth_camera *cam, const hearth_rigid *T) {
  v->cam = cam;
  v->T = *T;
  for (int i = 0; i < 3; i++) v->n[i] = T->R[i * 3 + 2];
  v->nt = dot3(v->n, T->t);
  for (int i = 0; i < HEARTH_PLATE_HOLES; i++) {
    double p[3];
    hearth_plate_hole(i, p);
    v->holes[i][0] = p[0];
    v->holes[i][1] = p[1];
  }
}

/* class of the ray d (camera frame) and the plate point it meets */
static int classify_ray(const plate_view *v, const double d[3], double p[2]) {
  double dn = dot3(v->n, d);
  if (fabs(dn) < 1e-12) return C_OUT;
  double t = v->nt / dn;
  if (t <= 0) return C_OUT;
  double q[3] = {t * d[0] - v->T.t[0], t * d[1] - v->T.t[1], t * d[2] - v->T.t[2]};
  /* plate coordinates: R^T q */
  p[0] = v->T.R[0] * q[0] + v->T.R[3] * q[1] + v->T.R[6] * q[2];
  p[1] = v->T.R[1] * q[0] + v->T.R[4] * q[1] + v->T.R[7] * q[2];
  return classify_plate((const double(*)[2])v->holes, p[0], p[1]);
}

static double thermal_value(const plate_view *v, int cls, const double p[2], const double d[3]) {
  switch (cls) {
    case C_PLATE: return v->ambient + v->plate_dt + 1.5 * (p[0] - 0.06);
    case C_HOLE: return v->ambient + v->hole_dt + 4.0 * (p[1] - 0.036);
    default: return v->ambient + 0.4 * d[1] + 0.2 * d[0];
  }
}

static double rgb_value(const plate_view *v, int cls, const double p[2], const double d[3]) {
  switch (cls) {
    case C_PLATE: return v->white * (1.0 - 0.3 * (p[1] - 0.036));
    case C_HOLE: return 0.05;
    default: return 0.36 + 0.08 * d[1] - 0.05 * d[0];
  }
}

/* n x n sub-samples of pixel (x, y) from its four corner rays (the lens is
 * smooth over one pixel, so bilinear interpolation of ideal coordinates is
 * exact to far below the detection accuracy) */
static double pixel_fine(const plate_view *v, int thermal, double x, double y, int n) {
  double c[4][2];
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 2; i++)
      synth_lens_unproject(v->cam, x - 0.5 + i, y - 0.5 + j, c[j * 2 + i]);
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
  for (size_t y = b; y < e; y++)
    for (size_t x = 0; x < W; x++) {
      const float *r = c->rays + (y * W + x) * 3;
      double d[3] = {r[0], r[1], r[2]}, p[2];
      int cls = classify_ray(c->v, d, p);
      c->cls[y * W + x] = (uint8_t)cls;
      c->img[y * W + x] = (float)rgb_value(c->v, cls, p, d);
    }
}

static void cplate_edge_rows(void *vctx, size_t b, size_t e, int ti) {
  cplate_ctx *c = vctx;
  size_t W = (size_t)c->v->cam->width, H = (size_t)c->v->cam->height;
  for (size_t y = b; y < e; y++)
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
      if (mixed) c->img[y * W + x] = (float)pixel_fine(c->v, 0, (double)x, (double)y, 8);
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
int synth_plate_truth(const hearth_camera *c, const hearth_rigid *T,
                      double centres[HEARTH_PLATE_HOLES][2]) {
  int inside = 0, i = 0;
  for (int r = 0; r < HEARTH_PLATE_ROWS; r++)
    for (int cc = 0; cc < ((r & 1) ? 10 : 11); cc++, i++) {
      double hx, hy;
      hole_xy(r, cc, &hx, &hy);
      double P[3] = {hx, hy, 0}, Q[3];
      hearth_rigid_apply(T, P, Q);
      if (!synth_lens_project(c, Q, centres[i])) {
        centres[i][0] = centres[i][1] = -1e9;
        continue;
      }
      /* the whole rim must be inside the image */
      int ok = 1;
      for (int k = 0; k < 12 && ok; k++) {
        double a = k * (2.0 * 3.14159265358979323846 / 12.0), uv[2];
        double R[3] = {hx + HOLE_R * cos(a), hy + HOLE_R * sin(a), 0}, S[3];
        hearth_rigid_apply(T, R, S);
        if (!synth_lens_project(c, S, uv) || uv[0] < 0.5 || uv[1] < 0.5 || uv[0] > c->width - 1.5 ||
            uv[1] > c->height - 1.5)
          ok = 0;
      }
      inside += ok;
    }
  return inside;
}

/* a plausible plate pose in front of a camera: distance d, plate centre at
 * normalised offset (ox, oy), tilted up to ~40 degrees, small roll */
static void plate_pose(hearth_rng *r, double d, double ox, double oy, hearth_rigid *T) {
  double phi = hearth_rng_range(r, 0, 2 * 3.14159265358979323846);
  double tilt = hearth_rng_range(r, 5.0, 40.0) * DEG, roll = hearth_rng_range(r, -12, 12) * DEG;
  double w1[3] = {cos(phi) * tilt, sin(phi) * tilt, 0}, w2[3] = {0, 0, roll}, R1[9], R2[9];
  hearth_rotvec_to_matrix(w1, R1);
  hearth_rotvec_to_matrix(w2, R2);
  hearth_mat3_mul(R1, R2, T->R);
  double pc[3], Rpc[3];
  synth_plate_centre(pc);
  hearth_rigid_rotate(T, pc, Rpc);
  double C[3] = {d * ox, d * oy, d};
  for (int k = 0; k < 3; k++) T->t[k] = C[k] - Rpc[k];
}

static void det_fill(hearth_detection *det, const char *frame, const char *camera,
                     const hearth_camera *cam, const hearth_rigid *T) {
  memset(det, 0, sizeof *det);
  snprintf(det->frame, sizeof det->frame, "%s", frame);
  snprintf(det->camera, sizeof det->camera, "%s", camera);
  double c[HEARTH_PLATE_HOLES][2];
  int n = synth_plate_truth(cam, T, c);
  if (n == HEARTH_PLATE_HOLES) {
    det->found = 1;
    memcpy(det->centres, c, sizeof c);
  } else {
    det->found = 0;
    snprintf(det->reason, sizeof det->reason, "only %d holes visible", n);
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
  int nf = o->n_thermal_frames, np = o->n_stereo_pairs;
  hearth_detections dets = {0, NULL};
  dets.frames = hearth_calloc_array((size_t)nf + 2 * (size_t)np + 1, sizeof(hearth_detection));
  if (!dets.frames) return hearth_err_set(err, HEARTH_E_NOMEM, "detections: out of memory");
  hearth_rng base;
  hearth_rng_seed(&base, seed);
  hearth_progress prog;
  hearth_progress_begin(&prog, "calibration", (size_t)(nf + np), o->quiet);
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&rig->T_thermal_from_rgb, &T_rgb_from_th);
  st = HEARTH_OK;

  /* thermal-only frames for the intrinsics */
  for (int i = 0; i < nf && !st; i++) {
    hearth_rng r, noise;
    hearth_rng_fork(&base, 1000 + (uint64_t)i, &r);
    hearth_rng_fork(&base, 5000 + (uint64_t)i, &noise);
    int partial = (i % 9) == 4, blurred = (i % 9) == 7;
    hearth_rigid T;
    double c[HEARTH_PLATE_HOLES][2];
    for (int tries = 0; tries < 200; tries++) {
      double d = hearth_rng_range(&r, 0.22, 0.40);
      double ox = hearth_rng_range(&r, -0.24, 0.24), oy = hearth_rng_range(&r, -0.16, 0.16);
      if (partial) ox = (hearth_rng_uniform(&r) < 0.5 ? -1 : 1) * hearth_rng_range(&r, 0.38, 0.5);
      plate_pose(&r, d, ox, oy, &T);
      int n = synth_plate_truth(&rig->thermal, &T, c);
      if (partial ? (n >= 20 && n < HEARTH_PLATE_HOLES) : n == HEARTH_PLATE_HOLES) break;
    }
    plate_view v;
    plate_view_init(&v, &rig->thermal, &T);
    v.ambient = ambient_c + hearth_rng_range(&r, -0.3, 0.3);
    v.plate_dt = hearth_rng_range(&r, 0.5, 1.5);
    v.hole_dt = hearth_rng_range(&r, 15.0, 25.0);
    char name[16];
    snprintf(name, sizeof name, "f%03d", i);
    snprintf(path, sizeof path, "%s/%s.csv", dir_th, name);
    st = write_thermal(path, &v, thermal_rays, blurred ? 1.3 : 0.5, o->netd_c, &noise, o->threads,
                       err);
    det_fill(&dets.frames[dets.n++], name, "thermal", &rig->thermal, &T);
    hearth_progress_step(&prog, 1);
  }

  /* stereo pairs: one plate pose seen by both cameras */
  for (int i = 0; i < np && !st; i++) {
    hearth_rng r, noise;
    hearth_rng_fork(&base, 2000 + (uint64_t)i, &r);
    hearth_rng_fork(&base, 6000 + (uint64_t)i, &noise);
    int partial = (i % 8) == 3, blurred = (i % 8) == 6;
    hearth_rigid T_th, T_rgb;
    double c[HEARTH_PLATE_HOLES][2];
    for (int tries = 0; tries < 200; tries++) {
      double d = hearth_rng_range(&r, 0.27, 0.45);
      double ox = hearth_rng_range(&r, -0.14, 0.14), oy = hearth_rng_range(&r, -0.08, 0.08);
      if (partial) ox = (hearth_rng_uniform(&r) < 0.5 ? -1 : 1) * hearth_rng_range(&r, 0.38, 0.5);
      plate_pose(&r, d, ox, oy, &T_th);
      hearth_rigid_compose(&T_rgb_from_th, &T_th, &T_rgb);
      int n = synth_plate_truth(&rig->thermal, &T_th, c);
      int m = synth_plate_truth(&rig->rgb, &T_rgb, c);
      if (partial ? (n >= 20 && n < HEARTH_PLATE_HOLES)
                  : (n == HEARTH_PLATE_HOLES && m == HEARTH_PLATE_HOLES))
        break;
    }
    plate_view vt, vc;
    plate_view_init(&vt, &rig->thermal, &T_th);
    plate_view_init(&vc, &rig->rgb, &T_rgb);
    vt.ambient = ambient_c + hearth_rng_range(&r, -0.3, 0.3);
    vt.plate_dt = hearth_rng_range(&r, 0.5, 1.5);
    vt.hole_dt = hearth_rng_range(&r, 15.0, 25.0);
    vc.white = hearth_rng_range(&r, 0.80, 0.90) * (0.85 + 0.15 * fabs(vc.n[2]));
    char name[16];
    snprintf(name, sizeof name, "p%03d", i);
    snprintf(path, sizeof path, "%s/%s_thermal.csv", dir_st, name);
    st = write_thermal(path, &vt, thermal_rays, blurred ? 1.3 : 0.5, o->netd_c, &noise, o->threads,
                       err);
    if (!st) {
      hearth_image img = {0};
      st = render_rgb_plate(&vc, rgb_rays, blurred ? 3.0 : 0.6, &noise, o->threads, &img, err);
      snprintf(path, sizeof path, "%s/%s_rgb.jpg", dir_st, name);
      if (!st) st = hearth_jpeg_write(path, &img, 92, err);
      hearth_image_free(&img);
    }
    det_fill(&dets.frames[dets.n++], name, "thermal", &rig->thermal, &T_th);
    det_fill(&dets.frames[dets.n++], name, "rgb", &rig->rgb, &T_rgb);
    hearth_progress_step(&prog, 1);
  }
  hearth_progress_end(&prog);
  if (!st) {
    snprintf(path, sizeof path, "%s/detections.json", dir_gt);
    st = hearth_detections_write(path, &dets, err);
  }
  hearth_detections_free(&dets);
  return st;
}

/* ---- for the thermal-only captures (synth_thermal_only.c) ------------------------------ */
void synth_plate_pose(hearth_rng *r, double d, double ox, double oy, hearth_rigid *T) {
  plate_pose(r, d, ox, oy, T);
}

hearth_status synth_plate_thermal_frame(const hearth_camera *cam, const hearth_rigid *T,
                                        const float *rays, double ambient, double plate_dt,
                                        double hole_dt, double blur, double netd,
                                        uint64_t noise_seed, int threads, hearth_image *out,
                                        hearth_err *err) {
  plate_view v;
  plate_view_init(&v, cam, T);
  v.ambient = ambient;
  v.plate_dt = plate_dt;
  v.hole_dt = hole_dt;
  hearth_rng noise;
  hearth_rng_seed(&noise, noise_seed);
  return render_thermal_plate(&v, rays, blur, netd, &noise, threads, out, err);
}
