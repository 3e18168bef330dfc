/* Metric scale recovery: rendered reconstruction depth vs recorded depth
 * maps (include/hearth/refine.h).
 *
 * Rendering the metric mesh (s * recon) from metric poses gives depths
 * s * z_recon, so for every pixel where both exist, z_measured = s z_recon.
 * The depth camera's centre in the recon frame depends on s itself (the
 * factory baseline is metric), so the cast is repeated with the latest s
 * until it settles; the baseline is small, so this fixed point converges in
 * a few rounds. The first rounds, far from it, cast a grid SCALE_COARSE
 * times sparser in x and y (a sixteenth of the rays) until s moves by less
 * than SCALE_COARSE_TOL; the full grid's rounds then start close to the
 * fixed point and need fewer of the costly casts. */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "poses/poses_internal.h"

#define SCALE_MAX_ROUNDS 6     /* rounds on the full grid */
#define SCALE_COARSE 4         /* the coarse grid's stride, in full-grid strides */
#define SCALE_COARSE_ROUNDS 6  /* rounds on the coarse grid at most */
#define SCALE_COARSE_TOL 1e-5  /* relative change of s that ends the coarse rounds */
#define SCALE_COARSE_MIN 1000  /* fewer coarse pairs: the full grid from the start */
#define SCALE_COARSE_VSTEP 8   /* the coarse rounds' box: every 8th vertex, */
#define SCALE_COARSE_MARGIN 16 /* and this many px around them */
/* relative change of s that ends the full grid's rounds: each round takes
   the distance to the fixed point down by the baseline's leverage, about
   0.02-0.03 (bench release), so the result is within some 3e-8 of it, far
   inside the fit's own uncertainty (300,000 pixels at 3e-3 relative noise
   each: at least 6e-6); 1e-8 cost one or two more casts of every view */
#define SCALE_TOL 1e-6

void hearth_scale_opts_default(hearth_scale_opts *o) {
  memset(o, 0, sizeof *o);
  o->pixel_stride = 2;
  o->edge_rel = 0.02;
  o->inlier_sigmas = 3.0;
  o->min_band_mm = 1.0;
  o->min_pixels_per_view = 50;
}

/* one candidate pixel: measured and rendered depth */
typedef struct zpair {
  float zm; /* metres */
  float zr; /* recon units */
} zpair;

#define SCALE_BATCH 4096 /* rays per cast */
#define SCALE_MARGIN 4   /* px around the mesh's projected vertices */

/* per worker: one batch of rays */
typedef struct scale_scratch {
  float org[3 * SCALE_BATCH], dir[3 * SCALE_BATCH];
  hearth_ray_hit hits[SCALE_BATCH];
  size_t pix[SCALE_BATCH]; /* grid index of each ray */
  float dz[SCALE_BATCH];   /* z of each ray's unit direction (camera frame) */
} scale_scratch;

typedef struct scale_ctx {
  const hearth_mesh *mesh;
  const hearth_mesh *box_mesh; /* the vertices whose projection bounds the cast */
  int margin;                  /* px around them */
  const hearth_raycaster *rc;
  const hearth_scale_view *views;
  const hearth_scale_opts *o;
  double s;                /* current estimate (for the baseline) */
  size_t stride;           /* the sampled pixels: every stride-th in x and y */
  float **dirs;            /* per view: its camera's pixel rays (3 per sampled pixel), shared
                          by the views of one camera */
  scale_scratch **scratch; /* per worker */
  zpair **pairs;           /* per view */
  size_t *n_pairs;
  int failed;
} scale_ctx;

static uint16_t depth_at(const hearth_image *d, size_t x, size_t y) {
  return ((const uint16_t *)d->data)[y * d->width + x];
}

/* the grid box [b[0], b[1]) x [b[2], b[3]) being cast, and whether a hit
 * touched one of its sides that is not the grid's own border */
typedef struct scale_box {
  size_t b[4], gw, gh;
  int border_hit;
} scale_box;

/* cast the batch's n rays: the rendered depth of each front-facing hit */
static void scale_flush(const scale_ctx *c, scale_scratch *sc, size_t n, size_t gw, float *zr,
                        scale_box *bx) {
  hearth_raycast_batch_mt(c->rc, n, sc->org, sc->dir, 0.0f, INFINITY, sc->hits, 1);
  for (size_t i = 0; i < n; i++) {
    const hearth_ray_hit *h = &sc->hits[i];
    if (h->prim == UINT32_MAX) continue;
    size_t p = sc->pix[i], gx = p % gw, gy = p / gw;
    if ((gx == bx->b[0] && gx > 0) || (gx + 1 == bx->b[1] && gx + 1 < bx->gw) ||
        (gy == bx->b[2] && gy > 0) || (gy + 1 == bx->b[3] && gy + 1 < bx->gh))
      bx->border_hit = 1;
    if (h->front) zr[p] = (float)((double)h->t * (double)sc->dz[i]);
  }
}

/* cast the sampled pixels of bx from T into zr, in 4 x 4 tiles so that
 * each packet of 16 rays is a tight bundle */
static void scale_cast(const scale_ctx *c, scale_scratch *sc, const float *dirs,
                       const hearth_rigid *T, float *zr, scale_box *bx) {
  const float o[3] = {(float)T->t[0], (float)T->t[1], (float)T->t[2]};
  const size_t gw = bx->gw;
  size_t n = 0;
  for (size_t ty = bx->b[2]; ty < bx->b[3]; ty += 4)
    for (size_t tx = bx->b[0]; tx < bx->b[1]; tx += 4)
      for (size_t gy = ty; gy < ty + 4 && gy < bx->b[3]; gy++)
        for (size_t gx = tx; gx < tx + 4 && gx < bx->b[1]; gx++) {
          const float *d = dirs + 3 * (gy * gw + gx);
          if (isnan(d[0])) continue;
          double dc[3] = {(double)d[0], (double)d[1], (double)d[2]}, dw[3];
          hearth_rigid_rotate(T, dc, dw);
          for (int i = 0; i < 3; i++) {
            sc->org[3 * n + (size_t)i] = o[i];
            sc->dir[3 * n + (size_t)i] = (float)dw[i];
          }
          sc->dz[n] = d[2];
          sc->pix[n++] = gy * gw + gx;
          if (n == SCALE_BATCH) {
            scale_flush(c, sc, n, gw, zr, bx);
            n = 0;
          }
        }
  if (n) scale_flush(c, sc, n, gw, zr, bx);
}

/* cast one view's sampled pixels and keep the pairs that are off edges */
static void scale_view(scale_ctx *c, size_t v, scale_scratch *sc) {
  const hearth_scale_view *sv = &c->views[v];
  const hearth_image *D = sv->depth;
  size_t st = c->stride;
  size_t gw = (D->width + st - 1) / st, gh = (D->height + st - 1) / st, n = gw * gh;
  float *zr = hearth_alloc_array(n ? n : 1, sizeof *zr);
  zpair *out = hearth_alloc_array(n ? n : 1, sizeof *out);
  if (!zr || !out) {
    free(zr);
    free(out);
    c->failed = 1;
    return;
  }
  /* depth camera pose in recon units: the metric baseline divided by s */
  hearth_rigid T_rgb_from_depth, Tb = sv->T_depth_from_rgb, T_world_from_depth;
  for (int i = 0; i < 3; i++) Tb.t[i] /= c->s;
  hearth_rigid_inverse(&Tb, &T_rgb_from_depth);
  hearth_rigid_compose(&sv->T_world_from_rgb, &T_rgb_from_depth, &T_world_from_depth);
  for (size_t i = 0; i < n; i++) zr[i] = INFINITY;
  /* only the samples inside the box the mesh projects to can hit it; the
   * whole grid when a hit touches the box's border */
  scale_box bx = {{0, gw, 0, gh}, gw, gh, 0};
  int pb[4];
  if (rf_mesh_box(c->box_mesh, &sv->depth_cam, &T_world_from_depth, c->margin, pb)) {
    bx.b[0] = ((size_t)pb[0] + st - 1) / st;
    bx.b[1] = ((size_t)pb[2] + st - 1) / st;
    bx.b[2] = ((size_t)pb[1] + st - 1) / st;
    bx.b[3] = ((size_t)pb[3] + st - 1) / st;
  }
  scale_cast(c, sc, c->dirs[v], &T_world_from_depth, zr, &bx);
  if (bx.border_hit) {
    bx = (scale_box){{0, gw, 0, gh}, gw, gh, 0};
    scale_cast(c, sc, c->dirs[v], &T_world_from_depth, zr, &bx);
  }
  double er = c->o->edge_rel;
  size_t k = 0;
  for (size_t gy = 0; gy < gh; gy++)
    for (size_t gx = 0; gx < gw; gx++) {
      float z = zr[gy * gw + gx];
      uint16_t dm = depth_at(D, gx * st, gy * st);
      if (!isfinite(z) || z <= 0 || dm == 0) continue;
      /* edges: a neighbour (rendered or measured) missing or at another depth */
      int edge = 0;
      const long dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int j = 0; j < 4 && !edge; j++) {
        long nx = (long)gx + dx[j], ny = (long)gy + dy[j];
        if (nx < 0 || ny < 0 || nx >= (long)gw || ny >= (long)gh) continue;
        float zn = zr[(size_t)ny * gw + (size_t)nx];
        uint16_t dn = depth_at(D, (size_t)nx * st, (size_t)ny * st);
        if (!isfinite(zn) || fabs((double)zn - (double)z) > er * (double)z) edge = 1;
        else if (dn == 0 || fabs((double)dn - (double)dm) > er * (double)dm) edge = 1;
      }
      if (edge) continue;
      out[k++] = (zpair){(float)(dm * 1e-3), z};
    }
  free(zr);
  c->pairs[v] = out;
  c->n_pairs[v] = k;
}

static void scale_range(void *ctx, size_t b, size_t e, int t) {
  scale_ctx *c = ctx;
  for (size_t v = b; v < e; v++) scale_view(c, v, c->scratch[t]);
}

/* the pixel rays of the views' depth cameras: one grid per distinct camera
 * (views with the same intrinsics share it) */
typedef struct grid_job {
  const hearth_scale_view *views;
  size_t *owner; /* the distinct cameras' first views */
  float **dirs;
  size_t stride;
  int failed;
} grid_job;

static void grid_range(void *ctx, size_t b, size_t e, int t) {
  grid_job *g = ctx;
  (void)t;
  for (size_t i = b; i < e; i++) {
    size_t v = g->owner[i];
    const hearth_image *D = g->views[v].depth;
    size_t gw = (D->width + g->stride - 1) / g->stride,
           gh = (D->height + g->stride - 1) / g->stride;
    size_t n = gw * gh;
    if (!(g->dirs[v] = hearth_alloc_array(n ? n : 1, 3 * sizeof(float)))) {
      g->failed = 1;
      continue;
    }
    /* undistorted rays of the sampled pixels (NaN: not invertible) */
    hearth_camera_ray_grid(&g->views[v].depth_cam, g->stride, g->dirs[v]);
  }
}

/* dirs[v] for every view; own[v] = 1 where the grid is view v's own to free */
static hearth_status make_grids(const hearth_scale_view *views, size_t n_views, size_t stride,
                                int threads, float **dirs, uint8_t *own) {
  size_t *owner = hearth_alloc_array(n_views, sizeof *owner),
         *same = hearth_alloc_array(n_views, sizeof *same);
  if (!owner || !same) {
    free(owner);
    free(same);
    return HEARTH_E_NOMEM;
  }
  size_t n_own = 0;
  for (size_t v = 0; v < n_views; v++) {
    same[v] = v;
    for (size_t i = 0; i < n_own && same[v] == v; i++)
      if (!memcmp(&views[owner[i]].depth_cam, &views[v].depth_cam, sizeof views[v].depth_cam))
        same[v] = owner[i];
    if (same[v] == v) owner[n_own++] = v;
  }
  grid_job g = {views, owner, dirs, stride, 0};
  hearth_status s = hearth_parallel_for(n_own, threads, grid_range, &g);
  if (!s && g.failed) s = HEARTH_E_NOMEM;
  for (size_t v = 0; v < n_views; v++) {
    own[v] = same[v] == v;
    if (!own[v]) dirs[v] = dirs[same[v]];
  }
  free(owner);
  free(same);
  return s;
}

/* robust fit of zm = s zr over all pairs: median ratio, then trimmed least
 * squares with a MAD-based band; fills res (scale, inliers, residuals) */
static void robust_fit(zpair *const *pairs, const size_t *n_pairs, size_t n_views,
                       const hearth_scale_opts *o, double *tmp, hearth_scale_result *res) {
  size_t n = 0;
  for (size_t v = 0; v < n_views; v++)
    for (size_t i = 0; i < n_pairs[v]; i++)
      tmp[n++] = (double)pairs[v][i].zm / (double)pairs[v][i].zr;
  res->n_candidates = n;
  double s = rf_quantile(tmp, n, 0.5);
  double band = 0;
  for (int it = 0; it < 4; it++) {
    /* band from the residuals of every candidate around the current fit */
    size_t m = 0;
    for (size_t v = 0; v < n_views; v++)
      for (size_t i = 0; i < n_pairs[v]; i++)
        tmp[m++] = fabs((double)pairs[v][i].zm - s * (double)pairs[v][i].zr);
    double mad = rf_quantile(tmp, m, 0.5);
    band = o->inlier_sigmas * 1.4826 * mad;
    if (band < o->min_band_mm * 1e-3) band = o->min_band_mm * 1e-3;
    double sxy = 0, sxx = 0;
    for (size_t v = 0; v < n_views; v++)
      for (size_t i = 0; i < n_pairs[v]; i++) {
        double zm = pairs[v][i].zm, zr = pairs[v][i].zr;
        if (fabs(zm - s * zr) > band) continue;
        sxy += zm * zr;
        sxx += zr * zr;
      }
    if (sxx > 0) s = sxy / sxx;
  }
  /* final statistics over inliers */
  size_t m = 0;
  double ss = 0;
  int used = 0;
  for (size_t v = 0; v < n_views; v++) {
    size_t nv = 0;
    for (size_t i = 0; i < n_pairs[v]; i++) {
      double e = fabs((double)pairs[v][i].zm - s * (double)pairs[v][i].zr);
      if (e > band) continue;
      tmp[m++] = e * 1e3;
      ss += e * e * 1e6;
      nv++;
    }
    if (nv >= (size_t)o->min_pixels_per_view) used++;
  }
  res->scale = s;
  res->n_inliers = m;
  res->views_used = used;
  res->inlier_fraction = n ? (double)m / (double)n : 0.0;
  res->residual_rms_mm = m ? sqrt(ss / (double)m) : 0.0;
  res->residual_p90_mm = rf_quantile(tmp, m, 0.9);
  res->residual_median_mm = rf_quantile(tmp, m, 0.5);
}

/* one round: every view's pairs cast from the baseline at c->s into
 * c->pairs, their count into *total */
static hearth_status scale_round(scale_ctx *c, size_t n_views, int nt, size_t *total,
                                 hearth_err *err) {
  for (size_t v = 0; v < n_views; v++) {
    free(c->pairs[v]);
    c->pairs[v] = NULL;
    c->n_pairs[v] = 0;
  }
  hearth_status s = hearth_parallel_for(n_views, nt, scale_range, c);
  if (s) return hearth_err_set(err, s, "scale: cannot start worker threads");
  if (c->failed) return hearth_err_set(err, HEARTH_E_NOMEM, "scale: out of memory");
  *total = 0;
  for (size_t v = 0; v < n_views; v++) *total += c->n_pairs[v];
  return HEARTH_OK;
}

/* robust_fit of the round's total pairs, with scratch *tmp made for them */
static hearth_status scale_fit(zpair *const *pairs, const size_t *n_pairs, size_t n_views,
                               const hearth_scale_opts *o, size_t total, double **tmp,
                               hearth_scale_result *res, hearth_err *err) {
  free(*tmp);
  if (!(*tmp = hearth_alloc_array(total, sizeof **tmp)))
    return hearth_err_set(err, HEARTH_E_NOMEM, "scale: out of memory");
  robust_fit(pairs, n_pairs, n_views, o, *tmp, res);
  return HEARTH_OK;
}

hearth_status hearth_scale_estimate(const hearth_mesh *recon_mesh, const hearth_raycaster *rc,
                                    const hearth_scale_view *views, size_t n_views,
                                    const hearth_scale_opts *opts, hearth_scale_result *out,
                                    hearth_err *err) {
  hearth_scale_opts def;
  if (!opts) {
    hearth_scale_opts_default(&def);
    opts = &def;
  }
  memset(out, 0, sizeof *out);
  if (!recon_mesh || !views || !n_views)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "scale: a mesh and at least one depth view are needed");
  for (size_t v = 0; v < n_views; v++) {
    const hearth_image *D = views[v].depth;
    if (!D || D->type != HEARTH_PIX_U16 || D->channels != 1)
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                            "scale: depth view %zu: expected a 16-bit single-channel image", v);
    if (D->width != (size_t)views[v].depth_cam.width ||
        D->height != (size_t)views[v].depth_cam.height)
      return hearth_err_set(err, HEARTH_E_SIZE,
                            "scale: depth view %zu: image is %zux%zu, its intrinsics say %dx%d", v,
                            D->width, D->height, views[v].depth_cam.width,
                            views[v].depth_cam.height);
  }
  hearth_raycaster *own = NULL;
  hearth_status s = HEARTH_OK;
  if (!rc) {
    if ((s = hearth_raycaster_new(recon_mesh, &own, err))) return s;
    rc = own;
  }
  zpair **pairs = calloc(n_views, sizeof *pairs);
  float **dirs = calloc(n_views, sizeof *dirs);
  uint8_t *own_dirs = calloc(n_views, 1);
  float **dirs_c = calloc(n_views, sizeof *dirs_c); /* the coarse grid's */
  uint8_t *own_c = calloc(n_views, 1);
  size_t *n_pairs = calloc(n_views, sizeof *n_pairs);
  double *tmp = NULL;
  float *box_positions = NULL; /* the coarse rounds' vertex sample */
  int nt = opts->threads > 0 ? opts->threads : hearth_default_threads();
  if ((size_t)nt > n_views) nt = (int)n_views;
  scale_scratch **scratch = calloc((size_t)nt, sizeof *scratch);
  int nomem = !pairs || !n_pairs || !dirs || !own_dirs || !dirs_c || !own_c || !scratch;
  for (int t = 0; t < nt && !nomem; t++) nomem = !(scratch[t] = malloc(sizeof **scratch));
  if (nomem) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "scale: out of memory");
    goto done;
  }
  size_t stride = (size_t)(opts->pixel_stride > 0 ? opts->pixel_stride : 1);
  if ((s = make_grids(views, n_views, stride, nt, dirs, own_dirs))) {
    hearth_err_set(err, s,
                   s == HEARTH_E_NOMEM ? "scale: out of memory"
                                       : "scale: cannot start worker threads");
    goto done;
  }
  /* the coarse grid's rays (none where the fine grid is too small for one) */
  size_t cstride = stride * SCALE_COARSE;
  int coarse = views[0].depth->width >= 16 * cstride && views[0].depth->height >= 16 * cstride;
  /* the coarse rounds bound their casts by a sample of the vertices with a
     wider margin (a box too small shows as hits on its border, and then the
     whole grid is cast) */
  hearth_mesh box_mesh = {0};
  box_mesh.n_vertices = (recon_mesh->n_vertices + SCALE_COARSE_VSTEP - 1) / SCALE_COARSE_VSTEP;
  if (coarse && !(box_positions = hearth_alloc_array(box_mesh.n_vertices ? box_mesh.n_vertices : 1,
                                                     3 * sizeof *box_positions))) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "scale: out of memory");
    goto done;
  }
  for (size_t i = 0; coarse && i < box_mesh.n_vertices; i++)
    memcpy(box_positions + 3 * i, recon_mesh->positions + 3 * i * SCALE_COARSE_VSTEP,
           3 * sizeof *box_positions);
  box_mesh.positions = box_positions;
  if (coarse && (s = make_grids(views, n_views, cstride, nt, dirs_c, own_c))) {
    hearth_err_set(err, s,
                   s == HEARTH_E_NOMEM ? "scale: out of memory"
                                       : "scale: cannot start worker threads");
    goto done;
  }
  /* first round: the baseline taken as if recon units were metres; each
     later round uses the latest scale. The coarse rounds only bring s near
     the fixed point; the result is that of the full grid's rounds. */
  double scale = 1.0;
  int rounds = 0, from_coarse = 0;
  for (int round = 0; coarse && round < SCALE_COARSE_ROUNDS; round++) {
    scale_ctx c = {.mesh = recon_mesh,
                   .box_mesh = &box_mesh,
                   .margin = SCALE_COARSE_MARGIN,
                   .rc = rc,
                   .views = views,
                   .o = opts,
                   .s = scale,
                   .stride = cstride,
                   .dirs = dirs_c,
                   .scratch = scratch,
                   .pairs = pairs,
                   .n_pairs = n_pairs};
    size_t total;
    if ((s = scale_round(&c, n_views, nt, &total, err))) goto done;
    rounds++;
    if (total < SCALE_COARSE_MIN) break; /* too few to go by */
    if ((s = scale_fit(pairs, n_pairs, n_views, opts, total, &tmp, out, err))) goto done;
    if (!(out->scale > 0) || !isfinite(out->scale)) break;
    double change = fabs(out->scale - scale) / out->scale;
    scale = out->scale;
    from_coarse = 1;
    if (round > 0 && change < SCALE_COARSE_TOL) break;
  }
  for (int round = 0; round < SCALE_MAX_ROUNDS; round++) {
    scale_ctx c = {.mesh = recon_mesh,
                   .box_mesh = recon_mesh,
                   .margin = SCALE_MARGIN,
                   .rc = rc,
                   .views = views,
                   .o = opts,
                   .s = scale,
                   .stride = stride,
                   .dirs = dirs,
                   .scratch = scratch,
                   .pairs = pairs,
                   .n_pairs = n_pairs};
    size_t total;
    if ((s = scale_round(&c, n_views, nt, &total, err))) goto done;
    if (total < 10) {
      s = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                         "scale: only %zu depth pixels see the mesh away from edges (expected at "
                         "least 10): do the poses, depth frames and mesh belong together?",
                         total);
      goto done;
    }
    if ((s = scale_fit(pairs, n_pairs, n_views, opts, total, &tmp, out, err))) goto done;
    out->iterations = ++rounds;
    if (!(out->scale > 0) || !isfinite(out->scale)) {
      s = hearth_err_set(err, HEARTH_E_NUMERIC, "scale: the fit gave a non-positive scale");
      goto done;
    }
    double change = fabs(out->scale - scale) / out->scale;
    scale = out->scale;
    if ((round > 0 || from_coarse) && change < SCALE_TOL) break;
  }
done:
  for (size_t v = 0; v < n_views; v++) {
    if (pairs) free(pairs[v]);
    if (dirs && own_dirs && own_dirs[v]) free(dirs[v]);
    if (dirs_c && own_c && own_c[v]) free(dirs_c[v]);
  }
  if (scratch)
    for (int t = 0; t < nt; t++) free(scratch[t]);
  free(scratch);
  free(own_dirs);
  free(dirs);
  free(own_c);
  free(dirs_c);
  free(pairs);
  free(n_pairs);
  free(tmp);
  free(box_positions);
  hearth_raycaster_free(own);
  return s;
}

/* ---- the release stage ------------------------------------------------------ */

static hearth_status write_scale_json(const char *path, const hearth_scale_result *r,
                                      size_t n_frames, hearth_err *err) {
  json_t *o = json_object();
  json_object_set_new(o, "scale", json_real(r->scale));
  json_object_set_new(o, "views_used", json_integer(r->views_used));
  json_object_set_new(o, "residual_median_mm", json_real(r->residual_median_mm));
  json_object_set_new(o, "residual_rms_mm", json_real(r->residual_rms_mm));
  json_object_set_new(o, "residual_p90_mm", json_real(r->residual_p90_mm));
  json_object_set_new(o, "depth_frames", json_integer((json_int_t)n_frames));
  json_object_set_new(o, "candidate_pixels", json_integer((json_int_t)r->n_candidates));
  json_object_set_new(o, "inlier_pixels", json_integer((json_int_t)r->n_inliers));
  json_object_set_new(o, "inlier_fraction", json_real(r->inlier_fraction));
  json_object_set_new(o, "method",
                      json_string("median of z_measured/z_rendered, then trimmed "
                                  "least squares; edges, holes and background excluded"));
  char *text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
  json_decref(o);
  if (!text) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot encode", path);
  size_t len = strlen(text);
  /* the document must pass the release reader before it is written */
  hearth_scale_doc chk;
  hearth_status s = hearth_scale_doc_parse(text, len, path, &chk, err);
  if (!s) s = hearth_write_file_atomic(path, text, len, err);
  free(text);
  return s;
}

hearth_status hearth_scale_run(const hearth_scale_job *job, hearth_scale_result *res,
                               hearth_err *err) {
  if (!job || !job->root || !job->instance)
    return hearth_err_set(err, HEARTH_E_ARG, "scale: root and instance are required");
  const char *root = job->root, *inst = job->instance;
  char path[RF_PATH], dir[RF_PATH], poses_path[RF_PATH];
  hearth_instance_doc idoc;
  hearth_poses poses = {0};
  hearth_mesh mesh = {0};
  hearth_manifest man[HEARTH_MAX_STATES];
  memset(man, 0, sizeof man);
  size_t n_states = 0, n_frames = 0;
  hearth_image *depths = NULL;
  hearth_scale_view *views = NULL;
  hearth_scale_result r;
  hearth_status s;
  if ((s = rf_pathf(path, "%s/instances/%s/instance.json", root, inst)))
    return hearth_err_set(err, s, "%s: path too long", root);
  if ((s = hearth_instance_read(path, &idoc, err))) return s;
  rf_pathf(poses_path, "%s/instances/%s/recon/poses_rgb.json", root, inst);
  if ((s = hearth_poses_read(poses_path, &poses, err))) goto done;
  rf_pathf(path, "%s/instances/%s/recon/mesh.glb", root, inst);
  hearth_glb_read_opts gopts = {.require_uvs = 0, .load_texture = 1};
  if ((s = hearth_glb_read(path, &gopts, &mesh, err))) goto done;
  /* manifests of the states to use */
  for (size_t k = 0; k < idoc.n_states; k++) {
    if (job->state && strcmp(job->state, idoc.states[k])) continue;
    rf_pathf(path, "%s/instances/%s/raw/%s/manifest.json", root, inst, idoc.states[k]);
    if ((s = hearth_manifest_read(path, &man[n_states], err))) goto done;
    n_frames += man[n_states].n_views;
    n_states++;
  }
  if (!n_states) {
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s/instances/%s/instance.json: no state '%s'",
                       root, inst, job->state ? job->state : "");
    goto done;
  }
  depths = calloc(n_frames ? n_frames : 1, sizeof *depths);
  views = calloc(n_frames ? n_frames : 1, sizeof *views);
  if (!depths || !views) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "scale: out of memory");
    goto done;
  }
  size_t f = 0;
  for (size_t k = 0; k < n_states; k++)
    for (size_t i = 0; i < man[k].n_views; i++, f++) {
      const hearth_view_files *vf = &man[k].views[i];
      const hearth_view_pose *vp = hearth_poses_find(&poses, man[k].state, vf->view);
      if (!vp) {
        s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no pose for state '%s' view '%s'",
                           poses_path, man[k].state, vf->view);
        goto done;
      }
      /* the intrinsics first: the depth PNG's header is checked against
         their size before its pixels are allocated */
      hearth_depth_intrinsics di;
      rf_pathf(path, "%s/instances/%s/raw/%s/%s", root, inst, man[k].state, vf->depth_intrinsics);
      if ((s = hearth_depth_intrinsics_read(path, &di, err))) goto done;
      char why[RF_PATH + 32];
      snprintf(why, sizeof why, "(the size in %s)", vf->depth_intrinsics);
      hearth_image_expect want = {(size_t)di.depth.width, (size_t)di.depth.height, 1, 0, 0, why};
      rf_pathf(path, "%s/instances/%s/raw/%s/%s", root, inst, man[k].state, vf->depth);
      if ((s = hearth_png_read_expect(path, &want, &depths[f], err))) goto done;
      if (depths[f].type != HEARTH_PIX_U16) {
        s = hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s: expected a 16-bit grey depth PNG", path);
        goto done;
      }
      views[f] =
          (hearth_scale_view){&depths[f], di.depth, di.T_depth_from_rgb, vp->T_world_from_cam};
    }
  if ((s = hearth_scale_estimate(&mesh, NULL, views, n_frames, &job->opts, &r, err))) {
    hearth_err_prefix(err, "%s", inst);
    goto done;
  }
  /* metric mesh (texture from recon/rgb_texture.png when not embedded) */
  if (!mesh.texture.data) {
    rf_pathf(path, "%s/instances/%s/recon/rgb_texture.png", root, inst);
    if (hearth_path_exists(path) && (s = hearth_png_read(path, &mesh.texture, err))) goto done;
  }
  const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, z[3] = {0, 0, 0};
  hearth_mesh_transform(&mesh, r.scale, I, z);
  for (size_t i = 0; i < poses.n; i++)
    for (int j = 0; j < 3; j++) poses.views[i].T_world_from_cam.t[j] *= r.scale;
  rf_pathf(dir, "%s/instances/%s/derived", root, inst);
  if ((s = hearth_mkdirs(dir, err))) goto done;
  rf_pathf(path, "%s/mesh.glb", dir);
  if ((s = hearth_glb_write(path, &mesh, err))) goto done;
  rf_pathf(path, "%s/poses_rgb.json", dir);
  if ((s = hearth_poses_write(path, &poses, err))) goto done;
  /* scale.json last: its presence says the other two are consistent with it */
  rf_pathf(path, "%s/scale.json", dir);
  if ((s = write_scale_json(path, &r, n_frames, err))) goto done;
  if (res) *res = r;
done:
  if (depths)
    for (size_t i = 0; i < n_frames; i++) hearth_image_free(&depths[i]);
  free(depths);
  free(views);
  for (size_t k = 0; k < n_states; k++) hearth_manifest_free(&man[k]);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&poses);
  return s;
}

void hearth_scale_job_default(hearth_scale_job *job) {
  memset(job, 0, sizeof *job);
  hearth_scale_opts_default(&job->opts);
}
