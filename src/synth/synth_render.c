/* Forward rendering of the turntable scene: the placed object (Embree rays),
 * the turntable/table plane and a backdrop (analytic planes), seen by the
 * thermal, colour and depth cameras through the rig's own lens model.
 *
 * Every pixel row is rendered independently; random numbers come from a
 * stream forked per (view, row), so output does not depend on threads. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "synth/synth_rig.h"

#define BACKDROP_DIST 0.45 /* metres behind the turntable axis */
#define FAR_T 50.0

enum { BG_NONE = 0, BG_TURNTABLE, BG_TABLE, BG_BACKDROP };

hearth_status synth_scene_init(synth_scene *s, const synth_object *obj,
                               const hearth_rigid *T_world_from_obj, double ambient_c,
                               hearth_err *err) {
  memset(s, 0, sizeof *s);
  s->obj = obj;
  s->T_world_from_obj = *T_world_from_obj;
  s->ambient_c = ambient_c;
  const hearth_mesh *m = &obj->mesh;
  hearth_status st = hearth_mesh_alloc(&s->world, m->n_vertices, m->n_triangles, 0, err);
  if (st) return st;
  memcpy(s->world.indices, m->indices, m->n_triangles * 3 * sizeof(uint32_t));
  for (size_t i = 0; i < m->n_vertices; i++) {
    double p[3] = {m->positions[3 * i], m->positions[3 * i + 1], m->positions[3 * i + 2]}, q[3];
    hearth_rigid_apply(T_world_from_obj, p, q);
    for (int k = 0; k < 3; k++) s->world.positions[3 * i + k] = (float)q[k];
  }
  /* area-weighted vertex normals for smooth shading */
  s->normals = hearth_calloc_array(m->n_vertices, 3 * sizeof(float));
  if (!s->normals) {
    synth_scene_free(s);
    return hearth_err_set(err, HEARTH_E_NOMEM, "scene normals: out of memory");
  }
  const float *P = s->world.positions;
  for (size_t t = 0; t < m->n_triangles; t++) {
    const uint32_t *id = m->indices + 3 * t;
    double a[3], b[3], n[3];
    for (int k = 0; k < 3; k++) {
      a[k] = P[3 * id[1] + k] - P[3 * id[0] + k];
      b[k] = P[3 * id[2] + k] - P[3 * id[0] + k];
    }
    hearth_cross3(a, b, n);
    for (int v = 0; v < 3; v++)
      for (int k = 0; k < 3; k++) s->normals[3 * id[v] + k] += (float)n[k];
  }
  for (size_t i = 0; i < m->n_vertices; i++) {
    float *n = s->normals + 3 * i;
    double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (l > 0)
      for (int k = 0; k < 3; k++) n[k] = (float)(n[k] / l);
  }
  /* bounding sphere around the box centre */
  double lo[3], hi[3];
  hearth_mesh_bounds(&s->world, lo, hi);
  for (int k = 0; k < 3; k++) s->centre[k] = 0.5 * (lo[k] + hi[k]);
  double r2 = 0;
  for (size_t i = 0; i < m->n_vertices; i++) {
    double d2 = 0;
    for (int k = 0; k < 3; k++) {
      double d = P[3 * i + k] - s->centre[k];
      d2 += d * d;
    }
    if (d2 > r2) r2 = d2;
  }
  s->radius = sqrt(r2) * 1.001 + 1e-4;
  double rr = 0;
  for (size_t i = 0; i < m->n_vertices; i++) {
    double d = hypot(P[3 * i], P[3 * i + 1]);
    if (d > rr) rr = d;
  }
  s->turntable_radius = fmax(0.15, rr + 0.04);
  st = hearth_raycaster_new(&s->world, &s->rc, err);
  if (st) {
    synth_scene_free(s);
    return st;
  }
  return HEARTH_OK;
}

void synth_scene_free(synth_scene *s) {
  if (s->rc) hearth_raycaster_free(s->rc);
  hearth_mesh_free(&s->world);
  free(s->normals);
  memset(s, 0, sizeof *s);
}

/* ---- background planes ------------------------------------------------------ */
typedef struct bg_hit {
  double t;
  int kind;
  double n[3], p[3];
} bg_hit;

/* bd: unit horizontal direction from the axis towards the camera */
static void background(const synth_scene *s, const double bd[3], const double o[3],
                       const double d[3], bg_hit *h) {
  h->t = FAR_T;
  h->kind = BG_NONE;
  if (d[2] < -1e-9) {
    double t = -o[2] / d[2];
    if (t > 0 && t < h->t) {
      h->t = t;
      double x = o[0] + t * d[0], y = o[1] + t * d[1];
      h->kind = x * x + y * y < s->turntable_radius * s->turntable_radius ? BG_TURNTABLE : BG_TABLE;
      h->n[0] = 0;
      h->n[1] = 0;
      h->n[2] = 1;
    }
  }
  /* the backdrop: through -BACKDROP_DIST bd on the turntable top, its
     normal bd turned up by the tilt (leaning back) */
  const double ct = cos(s->backdrop_tilt), st = sin(s->backdrop_tilt);
  double dn = ct * (bd[0] * d[0] + bd[1] * d[1]) + st * d[2];
  if (dn < -1e-9) {
    double on = ct * (bd[0] * o[0] + bd[1] * o[1]) + st * o[2];
    double t = (-ct * BACKDROP_DIST - on) / dn;
    if (t > 0 && t < h->t) {
      h->t = t;
      h->kind = BG_BACKDROP;
      h->n[0] = ct * bd[0];
      h->n[1] = ct * bd[1];
      h->n[2] = st;
    }
  }
  for (int k = 0; k < 3; k++) h->p[k] = o[k] + h->t * d[k];
}

/* apparent temperature of the surroundings: ambient with slight variation */
static double background_temp(const synth_scene *s, const bg_hit *h) {
  double a = s->ambient_c;
  switch (h->kind) {
    case BG_TURNTABLE: return a - 0.25 + 0.1 * sin(40.0 * hypot(h->p[0], h->p[1]));
    case BG_TABLE: return a - 0.1 + 0.15 * sin(6.0 * h->p[0]) * cos(5.0 * h->p[1]);
    case BG_BACKDROP: return a + 0.2 + 0.4 * h->p[2] + 0.1 * sin(7.0 * (h->p[0] + h->p[1]));
    default: return a - 1.0;
  }
}

static void background_rgb(const synth_scene *s, const bg_hit *h, double rgb[3]) {
  switch (h->kind) {
    case BG_TURNTABLE:
      rgb[0] = 0.20;
      rgb[1] = 0.20;
      rgb[2] = 0.21;
      break;
    case BG_TABLE:
      rgb[0] = 0.55;
      rgb[1] = 0.50;
      rgb[2] = 0.45;
      break;
    case BG_BACKDROP: {
      double g = 0.52 - 0.15 * fmin(fmax(h->p[2], -0.3), 0.6);
      rgb[0] = g;
      rgb[1] = g;
      rgb[2] = g * 1.02;
      break;
    }
    default: rgb[0] = rgb[1] = rgb[2] = 0.3;
  }
  (void)s;
}

/* ---- shared per-view geometry ---------------------------------------------- */
typedef struct view_geom {
  hearth_rigid T; /* world from camera */
  double bd[3];   /* backdrop direction */
} view_geom;

static void view_geom_make(const hearth_rigid *T_world_from_cam, view_geom *g) {
  g->T = *T_world_from_cam;
  double h = hypot(g->T.t[0], g->T.t[1]);
  if (h < 1e-9) {
    g->bd[0] = 1;
    g->bd[1] = 0;
  } else {
    g->bd[0] = g->T.t[0] / h;
    g->bd[1] = g->T.t[1] / h;
  }
  g->bd[2] = 0;
}

/* world direction of a camera ray */
static void to_world(const hearth_rigid *T, const float *dc, double dw[3]) {
  for (int i = 0; i < 3; i++)
    dw[i] = T->R[i * 3] * dc[0] + T->R[i * 3 + 1] * dc[1] + T->R[i * 3 + 2] * dc[2];
}

/* could the ray from o along d meet the object's bounding sphere? */
static int sphere_may_hit(const synth_scene *s, const double o[3], const double d[3]) {
  double oc[3] = {s->centre[0] - o[0], s->centre[1] - o[1], s->centre[2] - o[2]};
  double tca = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
  double d2 = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - tca * tca;
  return d2 <= s->radius * s->radius && tca + s->radius > 0;
}

/* scratch for one batch of rays */
typedef struct ray_batch {
  size_t cap, n;
  float *org, *dir;
  uint32_t *slot;
  hearth_ray_hit *hits;
} ray_batch;

static int batch_init(ray_batch *b, size_t cap) {
  b->cap = cap;
  b->n = 0;
  b->org = hearth_alloc_array(cap, 3 * sizeof(float));
  b->dir = hearth_alloc_array(cap, 3 * sizeof(float));
  b->slot = hearth_alloc_array(cap, sizeof(uint32_t));
  b->hits = hearth_alloc_array(cap, sizeof(hearth_ray_hit));
  return b->org && b->dir && b->slot && b->hits;
}

static void batch_free(ray_batch *b) {
  free(b->org);
  free(b->dir);
  free(b->slot);
  free(b->hits);
}

static void batch_add(ray_batch *b, const double o[3], const double d[3], uint32_t slot) {
  size_t i = b->n++;
  for (int k = 0; k < 3; k++) {
    b->org[3 * i + k] = (float)o[k];
    b->dir[3 * i + k] = (float)d[k];
  }
  b->slot[i] = slot;
}

/* surface point (object frame) of a hit */
static void hit_point_obj(const synth_object *obj, const hearth_ray_hit *h, double p[3]) {
  const uint32_t *id = obj->mesh.indices + 3 * (size_t)h->prim;
  const float *P = obj->mesh.positions;
  double b0 = 1.0 - h->b1 - h->b2;
  for (int k = 0; k < 3; k++)
    p[k] = b0 * P[3 * id[0] + k] + h->b1 * P[3 * id[1] + k] + h->b2 * P[3 * id[2] + k];
}

/* ---- thermal ------------------------------------------------------------------ */
typedef struct thermal_ctx {
  const synth_view_job *job;
  view_geom g;
  float *img;
  int failed;
} thermal_ctx;

#define TSS 4

/* the radiance of a surface the camera would read as t_app (degC) */
static double apparent_radiance(const synth_thermal_fx *f, double t_app) {
  return synth_camera_radiance(f->band, f->fx->camera_emissivity, f->ambient_c, t_app);
}

/* the temperature the camera shows for band radiance L */
static double camera_reading(const synth_thermal_fx *f, double L) {
  return synth_camera_reading(f->band, f->fx->camera_emissivity, f->ambient_c, L);
}

/* The radiance leaving the object towards the camera at hit h of the ray
 * from o along d: the surface at its temperature cooled to the view's time (t0
 * the field's, at the start of the scan), emitting with its directional
 * emissivity, and reflecting the rest of the surroundings: the room at
 * ambient, and where a glossy surface mirrors it, the warm source. */
static double surface_radiance(const synth_view_job *job, const hearth_ray_hit *h,
                               const double o[3], const double d[3], double t0) {
  const synth_thermal_fx *f = job->tfx;
  const synth_scene *s = job->scene;
  const hearth_synth_effects *fx = f->fx;
  double amb = f->ambient_c, t = amb + (t0 - amb) * f->decay;
  const uint32_t *id = s->world.indices + 3 * (size_t)h->prim;
  double b0 = 1.0 - h->b1 - h->b2, bw[3] = {b0, h->b1, h->b2}, n[3] = {0, 0, 0};
  for (int v = 0; v < 3; v++)
    for (int k = 0; k < 3; k++) n[k] += bw[v] * s->normals[3 * id[v] + k];
  double nn = hearth_norm3(n);
  if (nn > 0)
    for (int k = 0; k < 3; k++) n[k] /= nn;
  double dn = hearth_dot3(n, d);
  if (dn > 0) {
    for (int k = 0; k < 3; k++) n[k] = -n[k];
    dn = -dn;
  }
  const synth_object *obj = s->obj;
  int style =
      obj->style_of_tri && h->prim < obj->mesh.n_triangles ? obj->style_of_tri[h->prim] : -1;
  const synth_ir *m = synth_ir_of_style(style);
  double eps = synth_ir_emissivity(m, -dn, fx->emissivity, fx->grazing);
  double env = synth_band_radiance(f->band, amb);
  if (m->glossy && fx->warm_source_c > 0) {
    /* the mirror direction, and whether it meets the source */
    double r[3], p[3], oc[3];
    for (int k = 0; k < 3; k++) {
      r[k] = d[k] - 2.0 * dn * n[k];
      p[k] = o[k] + h->t * d[k];
      oc[k] = f->source[k] - p[k];
    }
    double tca = hearth_dot3(oc, r), d2 = hearth_dot3(oc, oc) - tca * tca;
    if (tca > 0 && d2 < f->source[3] * f->source[3])
      env = synth_band_radiance(f->band, f->source_c);
  }
  return eps * synth_band_radiance(f->band, t) + (1.0 - eps) * env;
}

static void thermal_rows(void *vctx, size_t b, size_t e, int ti) {
  thermal_ctx *c = vctx;
  const synth_view_job *job = c->job;
  const synth_scene *s = job->scene;
  const hearth_camera *cam = &job->rig->thermal;
  size_t W = (size_t)cam->width, per = TSS * TSS, nrow = W * per;
  ray_batch rb;
  double *val = hearth_alloc_array(nrow, sizeof(double));
  if (!batch_init(&rb, nrow) || !val) {
    batch_free(&rb);
    free(val);
    c->failed = 1;
    return;
  }
  const double *o = c->g.T.t;
  for (size_t y = b; y < e; y++) {
    rb.n = 0;
    const float *rays = job->thermal_rays + y * nrow * 3;
    double *bgt = val; /* background t, then the sample value */
    for (size_t i = 0; i < nrow; i++) {
      double d[3];
      to_world(&c->g.T, rays + 3 * i, d);
      bg_hit h;
      background(s, c->g.bd, o, d, &h);
      bgt[i] = background_temp(s, &h);
      if (job->tfx) bgt[i] = apparent_radiance(job->tfx, bgt[i]);
      if (sphere_may_hit(s, o, d)) {
        batch_add(&rb, o, d, (uint32_t)i);
        rb.hits[rb.n - 1].t = (float)h.t; /* remember the plane distance */
      }
    }
    if (rb.n) {
      float *tmax = hearth_alloc_array(rb.n, sizeof(float));
      if (!tmax) {
        c->failed = 1;
        break;
      }
      for (size_t i = 0; i < rb.n; i++) tmax[i] = rb.hits[i].t;
      hearth_raycast_batch(s->rc, rb.n, rb.org, rb.dir, 0.0f, (float)FAR_T, rb.hits);
      for (size_t i = 0; i < rb.n; i++) {
        const hearth_ray_hit *h = &rb.hits[i];
        if (h->prim == UINT32_MAX || !(h->t < tmax[i])) continue;
        double p[3];
        hit_point_obj(s->obj, h, p);
        double t = synth_field_eval(job->field, s->obj, h->prim, p);
        if (job->tfx) {
          double d[3] = {rb.dir[3 * i], rb.dir[3 * i + 1], rb.dir[3 * i + 2]};
          val[rb.slot[i]] = surface_radiance(job, h, o, d, t);
        } else {
          val[rb.slot[i]] = t;
        }
      }
      free(tmax);
    }
    /* integrate over the pixel footprint (radiance with the effects: what
       the sensor integrates; the temperature it shows, after) */
    for (size_t x = 0; x < W; x++) {
      double sum = 0;
      for (size_t k = 0; k < per; k++) sum += val[x * per + k];
      if (job->tfx) c->img[y * W + x] = (float)camera_reading(job->tfx, sum / (double)per);
      else c->img[y * W + x] = (float)(sum / (double)per);
    }
  }
  batch_free(&rb);
  free(val);
}

hearth_status synth_blur_f32(hearth_image *img, double sigma, hearth_err *err) {
  if (sigma <= 0) return HEARTH_OK;
  int r = (int)ceil(3.0 * sigma);
  if (r > 64) r = 64;
  double k[129], ks = 0;
  for (int i = -r; i <= r; i++) ks += (k[i + r] = exp(-0.5 * i * i / (sigma * sigma)));
  for (int i = 0; i <= 2 * r; i++) k[i] /= ks;
  size_t W = img->width, H = img->height;
  float *src = img->data;
  float *tmp = hearth_alloc_array(W * H, sizeof(float));
  if (!tmp) return hearth_err_set(err, HEARTH_E_NOMEM, "blur: out of memory");
  for (size_t y = 0; y < H; y++)
    for (size_t x = 0; x < W; x++) {
      double acc = 0;
      for (int i = -r; i <= r; i++) {
        long xx = (long)x + i;
        if (xx < 0) xx = 0;
        if (xx >= (long)W) xx = (long)W - 1;
        acc += k[i + r] * src[y * W + (size_t)xx];
      }
      tmp[y * W + x] = (float)acc;
    }
  for (size_t y = 0; y < H; y++)
    for (size_t x = 0; x < W; x++) {
      double acc = 0;
      for (int i = -r; i <= r; i++) {
        long yy = (long)y + i;
        if (yy < 0) yy = 0;
        if (yy >= (long)H) yy = (long)H - 1;
        acc += k[i + r] * tmp[(size_t)yy * W + x];
      }
      src[y * W + x] = (float)acc;
    }
  free(tmp);
  return HEARTH_OK;
}

hearth_status synth_render_thermal(const synth_view_job *job, hearth_image *out, hearth_err *err) {
  const hearth_camera *cam = &job->rig->thermal;
  hearth_status st =
      hearth_image_alloc(out, (size_t)cam->width, (size_t)cam->height, 1, HEARTH_PIX_F32, err);
  if (st) return st;
  thermal_ctx c = {job, {{{0}}}, out->data, 0};
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&job->rig->T_thermal_from_rgb, &T_rgb_from_th);
  hearth_rigid T;
  hearth_rigid_compose(&job->T_world_from_rgb, &T_rgb_from_th, &T);
  view_geom_make(&T, &c.g);
  hearth_parallel_for((size_t)cam->height, job->threads, thermal_rows, &c);
  if (c.failed) {
    hearth_image_free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "thermal render: out of memory");
  }
  /* optics (Gaussian PSF, sigma ~0.5 px) then sensor noise (NETD) */
  st = synth_blur_f32(out, 0.5, err);
  if (st) {
    hearth_image_free(out);
    return st;
  }
  hearth_rng base, r;
  hearth_rng_seed(&base, job->noise_seed);
  float *px = out->data;
  for (size_t y = 0; y < out->height; y++) {
    hearth_rng_fork(&base, 0x7000 + y, &r);
    for (size_t x = 0; x < out->width; x++)
      px[y * out->width + x] += (float)(job->netd_c * hearth_rng_normal(&r));
  }
  return HEARTH_OK;
}

/* ---- colour -------------------------------------------------------------------- */
typedef struct rgb_ctx {
  const synth_view_job *job;
  view_geom g;
  uint8_t *rgb, *mask;
  int failed;
} rgb_ctx;

static void albedo_sample(const hearth_image *a, double u, double v, double out[3]) {
  if (!a->data || !a->width || !a->height) {
    out[0] = out[1] = out[2] = 0.7;
    return;
  }
  /* bilinear, texel centres at (i + 0.5) / size, wrapped */
  double fx = u * (double)a->width - 0.5, fy = v * (double)a->height - 0.5;
  double x0 = floor(fx), y0 = floor(fy), ax = fx - x0, ay = fy - y0;
  const uint8_t *d = a->data;
  int ch = a->channels;
  for (int c = 0; c < 3; c++) out[c] = 0;
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 2; i++) {
      long xi = (long)x0 + i, yi = (long)y0 + j;
      if (xi < 0) xi = 0;
      if (yi < 0) yi = 0;
      if (xi >= (long)a->width) xi = (long)a->width - 1;
      if (yi >= (long)a->height) yi = (long)a->height - 1;
      double w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
      const uint8_t *p = d + ((size_t)yi * a->width + (size_t)xi) * (size_t)ch;
      for (int c = 0; c < 3; c++) out[c] += w * p[ch >= 3 ? c : 0] / 255.0;
    }
}

static double shade(const double n[3], const double p[3], const double cam[3]) {
  /* a ring light at the camera plus a soft light from above */
  double l[3] = {cam[0] - p[0], cam[1] - p[1], cam[2] + 0.3 - p[2]};
  double ln = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  double nl = (n[0] * l[0] + n[1] * l[1] + n[2] * l[2]) / ln;
  double up = n[2];
  return 0.22 + 0.62 * fmax(nl, 0.0) + 0.16 * fmax(up, 0.0);
}

static void rgb_rows(void *vctx, size_t b, size_t e, int ti) {
  rgb_ctx *c = vctx;
  const synth_view_job *job = c->job;
  const synth_scene *s = job->scene;
  const synth_object *obj = s->obj;
  const hearth_camera *cam = &job->rig->rgb;
  size_t W = (size_t)cam->width;
  ray_batch rb;
  float *tmax = hearth_alloc_array(W, sizeof(float));
  double *col = hearth_alloc_array(W, 3 * sizeof(double));
  if (!batch_init(&rb, W) || !tmax || !col) {
    batch_free(&rb);
    free(tmax);
    free(col);
    c->failed = 1;
    return;
  }
  const double *o = c->g.T.t;
  hearth_rng base, r;
  hearth_rng_seed(&base, job->noise_seed);
  for (size_t y = b; y < e; y++) {
    rb.n = 0;
    const float *rays = job->rgb_rays + y * W * 3;
    for (size_t x = 0; x < W; x++) {
      double d[3];
      to_world(&c->g.T, rays + 3 * x, d);
      bg_hit h;
      background(s, c->g.bd, o, d, &h);
      double base_rgb[3];
      background_rgb(s, &h, base_rgb);
      double sh = h.kind == BG_NONE ? 1.0 : shade(h.n, h.p, o);
      for (int k = 0; k < 3; k++) col[3 * x + k] = base_rgb[k] * (0.35 + 0.75 * sh);
      c->mask[y * W + x] = 0;
      if (sphere_may_hit(s, o, d)) {
        tmax[rb.n] = (float)h.t;
        batch_add(&rb, o, d, (uint32_t)x);
      }
    }
    if (rb.n) hearth_raycast_batch(s->rc, rb.n, rb.org, rb.dir, 0.0f, (float)FAR_T, rb.hits);
    for (size_t i = 0; i < rb.n; i++) {
      const hearth_ray_hit *h = &rb.hits[i];
      if (h->prim == UINT32_MAX || !(h->t < tmax[i])) continue;
      size_t x = rb.slot[i];
      const uint32_t *id = obj->mesh.indices + 3 * (size_t)h->prim;
      double b0 = 1.0 - h->b1 - h->b2, bw[3] = {b0, h->b1, h->b2};
      double uv[2] = {0, 0}, n[3] = {0, 0, 0}, p[3];
      for (int v = 0; v < 3; v++) {
        if (obj->mesh.uvs) {
          uv[0] += bw[v] * obj->mesh.uvs[2 * id[v]];
          uv[1] += bw[v] * obj->mesh.uvs[2 * id[v] + 1];
        }
        for (int k = 0; k < 3; k++) n[k] += bw[v] * s->normals[3 * id[v] + k];
      }
      double d[3] = {rb.dir[3 * i], rb.dir[3 * i + 1], rb.dir[3 * i + 2]};
      for (int k = 0; k < 3; k++) p[k] = o[k] + h->t * d[k];
      double nn = hearth_norm3(n);
      if (nn > 0)
        for (int k = 0; k < 3; k++) n[k] /= nn;
      if (hearth_dot3(n, d) > 0)
        for (int k = 0; k < 3; k++) n[k] = -n[k];
      double alb[3];
      albedo_sample(&obj->albedo, uv[0], uv[1], alb);
      double sh = shade(n, p, o);
      for (int k = 0; k < 3; k++) col[3 * x + k] = alb[k] * (0.25 + 0.95 * sh);
      c->mask[y * W + x] = 255;
    }
    /* sensor noise, then 8-bit */
    hearth_rng_fork(&base, 0x52000 + y, &r);
    for (size_t x = 0; x < W; x++)
      for (int k = 0; k < 3; k++) {
        double v = col[3 * x + k] * 255.0 + 1.2 * synth_fast_normal(&r);
        v = v < 0 ? 0 : v > 255 ? 255 : v;
        c->rgb[(y * W + x) * 3 + (size_t)k] = (uint8_t)lrint(v);
      }
  }
  batch_free(&rb);
  free(tmax);
  free(col);
}

hearth_status synth_render_rgb(const synth_view_job *job, hearth_image *rgb, hearth_image *mask,
                               hearth_err *err) {
  const hearth_camera *cam = &job->rig->rgb;
  hearth_status st =
      hearth_image_alloc(rgb, (size_t)cam->width, (size_t)cam->height, 3, HEARTH_PIX_U8, err);
  if (st) return st;
  st = hearth_image_alloc(mask, (size_t)cam->width, (size_t)cam->height, 1, HEARTH_PIX_U8, err);
  if (st) {
    hearth_image_free(rgb);
    return st;
  }
  rgb_ctx c = {job, {{{0}}}, rgb->data, mask->data, 0};
  view_geom_make(&job->T_world_from_rgb, &c.g);
  hearth_parallel_for((size_t)cam->height, job->threads, rgb_rows, &c);
  if (c.failed) {
    hearth_image_free(rgb);
    hearth_image_free(mask);
    return hearth_err_set(err, HEARTH_E_NOMEM, "colour render: out of memory");
  }
  return HEARTH_OK;
}

/* ---- depth ---------------------------------------------------------------------- */
typedef struct depth_ctx {
  const synth_view_job *job;
  view_geom g;
  float *z_true, *z_meas; /* mm; 0 = invalid */
  int failed;
} depth_ctx;

static void depth_rows(void *vctx, size_t b, size_t e, int ti) {
  depth_ctx *c = vctx;
  const synth_view_job *job = c->job;
  const synth_scene *s = job->scene;
  const hearth_camera *cam = &job->rig->depth;
  size_t W = (size_t)cam->width;
  ray_batch rb;
  double *cosang = hearth_alloc_array(W, sizeof(double));
  double *tt = hearth_alloc_array(W, sizeof(double));
  if (!batch_init(&rb, W) || !cosang || !tt) {
    batch_free(&rb);
    free(cosang);
    free(tt);
    c->failed = 1;
    return;
  }
  const double *o = c->g.T.t;
  const float *P = s->world.positions;
  hearth_rng base, r;
  hearth_rng_seed(&base, job->noise_seed);
  for (size_t y = b; y < e; y++) {
    rb.n = 0;
    const float *rays = job->depth_rays + y * W * 3;
    for (size_t x = 0; x < W; x++) {
      double d[3];
      to_world(&c->g.T, rays + 3 * x, d);
      bg_hit h;
      background(s, c->g.bd, o, d, &h);
      tt[x] = h.kind == BG_NONE ? 0.0 : h.t;
      cosang[x] = fabs(hearth_dot3(h.n, d));
      if (sphere_may_hit(s, o, d)) batch_add(&rb, o, d, (uint32_t)x);
    }
    if (rb.n) {
      hearth_raycast_batch(s->rc, rb.n, rb.org, rb.dir, 0.0f, (float)FAR_T, rb.hits);
      for (size_t i = 0; i < rb.n; i++) {
        size_t x = rb.slot[i];
        const hearth_ray_hit *h = &rb.hits[i];
        if (h->prim == UINT32_MAX || !(h->t < tt[x] || tt[x] == 0.0)) continue;
        const uint32_t *id = s->world.indices + 3 * (size_t)h->prim;
        double a[3], bb[3], n[3], d[3] = {rb.dir[3 * i], rb.dir[3 * i + 1], rb.dir[3 * i + 2]};
        for (int k = 0; k < 3; k++) {
          a[k] = P[3 * id[1] + k] - P[3 * id[0] + k];
          bb[k] = P[3 * id[2] + k] - P[3 * id[0] + k];
        }
        hearth_cross3(a, bb, n);
        double nn = hearth_norm3(n);
        tt[x] = h->t;
        cosang[x] = nn > 0 ? fabs(hearth_dot3(n, d)) / nn : 0.0;
      }
    }
    hearth_rng_fork(&base, 0xD000 + y, &r);
    for (size_t x = 0; x < W; x++) {
      double z = tt[x] * rays[3 * x + 2] * 1000.0; /* along the optical axis, mm */
      double noise = synth_fast_normal(&r), hole = hearth_rng_uniform(&r);
      c->z_true[y * W + x] = (float)z;
      double sigma = 0.6 + 0.8 * z / 1000.0;
      int valid = tt[x] > 0 && z > 200.0 && z < 3000.0 && cosang[x] > 0.1 && hole > 0.003;
      c->z_meas[y * W + x] = valid ? (float)(z + sigma * noise) : 0.0f;
    }
  }
  batch_free(&rb);
  free(cosang);
  free(tt);
}

hearth_status synth_render_depth(const synth_view_job *job, hearth_image *out, hearth_err *err) {
  const hearth_camera *cam = &job->rig->depth;
  size_t W = (size_t)cam->width, H = (size_t)cam->height;
  hearth_status st = hearth_image_alloc(out, W, H, 1, HEARTH_PIX_U16, err);
  if (st) return st;
  depth_ctx c = {job,
                 {{{0}}},
                 hearth_alloc_array(W * H, sizeof(float)),
                 hearth_alloc_array(W * H, sizeof(float)),
                 0};
  if (!c.z_true || !c.z_meas) {
    free(c.z_true);
    free(c.z_meas);
    hearth_image_free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "depth render: out of memory");
  }
  hearth_rigid T_rgb_from_depth, T;
  hearth_rigid_inverse(&job->rig->T_depth_from_rgb, &T_rgb_from_depth);
  hearth_rigid_compose(&job->T_world_from_rgb, &T_rgb_from_depth, &T);
  view_geom_make(&T, &c.g);
  hearth_parallel_for(H, job->threads, depth_rows, &c);
  if (c.failed) {
    free(c.z_true);
    free(c.z_meas);
    hearth_image_free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "depth render: out of memory");
  }
  /* time-of-flight loses pixels that straddle a depth edge (mixed returns) */
  uint16_t *px = out->data;
  for (size_t y = 0; y < H; y++)
    for (size_t x = 0; x < W; x++) {
      float z = c.z_true[y * W + x], m = c.z_meas[y * W + x];
      int edge = 0;
      const long nb[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
      for (int k = 0; k < 4 && !edge; k++) {
        long xx = (long)x + nb[k][0], yy = (long)y + nb[k][1];
        if (xx < 0 || yy < 0 || xx >= (long)W || yy >= (long)H) continue;
        float z2 = c.z_true[(size_t)yy * W + (size_t)xx];
        if (fabsf(z2 - z) > fmaxf(12.0f, 0.03f * z)) edge = 1;
      }
      double v = edge ? 0.0 : floor((double)m + 0.5);
      px[y * W + x] = (uint16_t)(v < 0 ? 0 : v > 65535 ? 65535 : v);
    }
  free(c.z_true);
  free(c.z_meas);
  return HEARTH_OK;
}
