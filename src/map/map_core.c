/* Temperature / colour mapping onto a UV layout (see include/hearth/map.h):
 * the entry points, which check their inputs, make each phase's state and
 * run the phases of map_internal.h in turn (the layout, the views' cast
 * and splat, the fusion across views, the fill within islands). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "map/map_internal.h"

void hearth_map_opts_default(hearth_map_opts *o) {
  memset(o, 0, sizeof *o);
  o->resolution = 1024;
  o->fusion = HEARTH_FUSE_MAX;
  o->min_cos = 0.0;
  o->pixel_stride = 1;
}

void hearth_map_result_free(hearth_map_result *r) {
  if (!r) return;
  free(r->observed);
  free(r->filled);
  free(r->mask);
  free(r->best_cos);
  free(r->view_hits);
  memset(r, 0, sizeof *r);
}

/* the views' channels in *C (1: F32 gray temperatures, 3: U8 RGB; 1 when
   there is no view), each view's image checked against the camera */
static hearth_status view_channels(const hearth_camera *cam, const hearth_map_view *views,
                                   size_t n_views, const hearth_map_opts *o, int *C_out,
                                   hearth_err *err) {
  int C = 0;
  for (size_t v = 0; v < n_views; v++) {
    const hearth_image *im = views[v].image;
    if (!im && o->load) {
      /* made when its cast reaches it */
      if (o->load_channels != 1 && o->load_channels != 3)
        return hearth_err_set(err, HEARTH_E_ARG, "map: loaded views need 1 or 3 channels, not %d",
                              o->load_channels);
      if (C && o->load_channels != C)
        return hearth_err_set(err, HEARTH_E_INCONSISTENT, "map: views mix image kinds");
      C = o->load_channels;
      continue;
    }
    if (!im || !im->data) return hearth_err_set(err, HEARTH_E_ARG, "map: view %zu has no image", v);
    if (im->width != (size_t)cam->width || im->height != (size_t)cam->height)
      return hearth_err_set(err, HEARTH_E_SIZE, "map: view %zu is %zux%zu, the camera is %dx%d", v,
                            im->width, im->height, cam->width, cam->height);
    int c = im->type == HEARTH_PIX_F32 && im->channels == 1  ? 1
            : im->type == HEARTH_PIX_U8 && im->channels >= 3 ? 3
                                                             : 0;
    if (!c)
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "map: view %zu: need F32 gray or U8 RGB", v);
    if (C && c != C)
      return hearth_err_set(err, HEARTH_E_INCONSISTENT, "map: views mix image kinds");
    C = c;
  }
  *C_out = C ? C : 1;
  return HEARTH_OK;
}

/* A view whose camera has the whole mesh (its bounding sphere, with a
   margin) in front is rasterised through the fan; any other view casts
   rays. Sets view_fan[v]; returns whether any view casts rays. */
static int choose_fan_views(const hearth_map_layout *l, const hearth_map_view *views,
                            size_t n_views, const hearth_map_opts *opts, uint8_t *view_fan) {
  const double *sphere = l->sphere;
  int need_rays = 0;
  for (size_t v = 0; v < n_views; v++) {
    const hearth_rigid *T = &views[v].T_world_from_cam;
    double d[3] = {sphere[0] - T->t[0], sphere[1] - T->t[1], sphere[2] - T->t[2]};
    double z = T->R[2] * d[0] + T->R[5] * d[1] + T->R[8] * d[2];
    view_fan[v] = l->fan && !opts->trace_rays && z > sphere[3] * (1.0 + 1e-6) + 1e-9;
    need_rays |= !view_fan[v];
  }
  return need_rays;
}

/* The workers' scratch, the views' hit counts and the fusion rule's state
   (mx for max fusion, rec otherwise); max fusion's worker 0 maps are out's
   observed and best_cos. Returns 0 out of memory. */
static int alloc_phase_state(map_ctx *m, max_maps *mx, view_records *rec, hearth_map_result *out) {
  const int nt = m->n_threads, max = m->opts->fusion == HEARTH_FUSE_MAX;
  m->workers = calloc((size_t)nt, sizeof *m->workers);
  m->view_hits = calloc(m->n_views ? m->n_views : 1, sizeof *m->view_hits);
  if (!m->workers || !m->view_hits) return 0;
  const int kind = max                                   ? WORKER_MAXIMA
                   : m->opts->fusion == HEARTH_FUSE_MEAN ? WORKER_SPLATS
                                                         : WORKER_RECORDS;
  for (int t = 0; t < nt; t++)
    if (!map_worker_alloc(&m->workers[t], m->l, m->C, kind)) return 0;
  if (max) {
    m->max = mx;
    return map_max_alloc(mx, nt, m->l->R, m->C, !m->opts->skip_best_cos, out);
  }
  m->rec = rec;
  return map_records_alloc(rec, m->n_views, m->opts->fusion == HEARTH_FUSE_MEAN, m->l->R, m->C,
                           !m->opts->skip_best_cos);
}

/* the workers' scratch (per pixel of the camera's grid), which only the
   cast reads */
static void free_cast_state(map_ctx *m) {
  for (int t = 0; m->workers && t < m->n_threads; t++) map_worker_free(&m->workers[t]);
}

/* the fusion rule's state (max fusion's other workers' maps, the records
   and sums, the corrected fusion's best cosines), which the fill does not
   read; max fusion's worker 0 maps are the result's and stay */
static void free_fusion_state(map_ctx *m) {
  if (m->max) map_max_free(m->max);
  if (m->rec) map_records_free(m->rec);
  m->max = NULL;
  m->rec = NULL;
  free(m->corr_best);
  m->corr_best = NULL;
}

static void free_phase_state(map_ctx *m) {
  free_cast_state(m);
  free(m->workers);
  free(m->view_hits);
  free_fusion_state(m);
}

/* The result's arrays (observed and best_cos made here unless max fusion's
   maps are them) and the fusion into them, band by band, gathering the
   islands' boxes for the fill into *parts (n_threads sets, made here). */
static hearth_status fuse_views(map_ctx *m, hearth_map_result *out, island_box **parts,
                                hearth_err *err) {
  const size_t R = m->l->R, N = R * R, C = (size_t)m->C;
  const int nt = m->n_threads, want_cos = !m->opts->skip_best_cos;
  out->R = R;
  out->channels = m->C;
  out->n_views = m->n_views;
  if (m->rec && m->rec->acc) {
    /* mean fusion: the sums become the means in place */
    out->observed = m->rec->acc;
    m->rec->acc_owned = 0;
  } else if (!m->max) {
    out->observed = hearth_alloc_array(N, C * sizeof(float));
  }
  /* without observed, the fill makes filled in its place: it copies only
     observed texels' values, which stay as they are */
  if (m->opts->skip_observed) out->filled = out->observed;
  else out->filled = hearth_alloc_array(N, C * sizeof(float));
  /* every texel of these is written by the fusion */
  out->mask = hearth_alloc_array(N, 1);
  if (!m->max && want_cos) out->best_cos = hearth_alloc_array(N, sizeof(float));
  out->view_hits = m->view_hits;
  m->view_hits = NULL;
  /* per worker of the fusion: the islands' boxes, empty */
  const size_t nparts = (size_t)nt * ((size_t)m->l->n_islands + 1);
  island_box *p = *parts = hearth_alloc_array(nparts, sizeof *p);
  for (size_t i = 0; p && i < nparts; i++) p[i] = (island_box){INT32_MAX, INT32_MAX, -1, -1, 0, 0};
  if (!out->observed || !out->filled || !out->mask || (want_cos && !out->best_cos) || !p)
    return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  const size_t rows = R < BAND_TEXELS ? BAND_TEXELS / R : 1;
  int *nomem = calloc((size_t)nt, sizeof *nomem), failed = !nomem;
  fuse_pass fp = {m, out, p, nomem};
  if (nomem && m->opts->fusion == HEARTH_FUSE_CORRECTED && !map_correction_estimate(m, nt))
    failed = 1;
  if (nomem && !failed) hearth_parallel_chunks((R + rows - 1) / rows, 4, nt, map_fuse_bands, &fp);
  for (int t = 0; nomem && t < nt; t++) failed |= nomem[t];
  free(nomem);
  if (failed) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory while fusing");
  return HEARTH_OK;
}

/* the texels of each kind, counted by rows */
typedef struct count_pass {
  const uint8_t *mask;
  size_t R;
  size_t (*counts)[4]; /* per worker: observed, filled, unobserved, surface */
} count_pass;
static void count_rows(void *ctx, size_t b, size_t e, int t) {
  const count_pass *cp = ctx;
  const uint8_t *mask = cp->mask;
  size_t R = cp->R, n_obs = 0, n_fill = 0, n_unobs = 0, n_none = 0;
  for (size_t q = b * R; q < e * R; q++) {
    uint8_t mk = mask[q];
    n_obs += mk == HEARTH_TEXEL_OBSERVED;
    n_fill += mk == HEARTH_TEXEL_FILLED;
    n_unobs += mk == HEARTH_TEXEL_UNOBSERVED;
    n_none += mk == HEARTH_TEXEL_NONE;
  }
  size_t *cnt = cp->counts[t];
  cnt[0] += n_obs;
  cnt[1] += n_fill;
  cnt[2] += n_unobs;
  cnt[3] += (e - b) * R - n_none;
}

/* out's counters from its mask, on nt workers */
static hearth_status count_texels(hearth_map_result *out, int nt, hearth_err *err) {
  count_pass cp = {out->mask, out->R, calloc((size_t)nt, sizeof *cp.counts)};
  if (!cp.counts) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  hearth_parallel_chunks(out->R, 32, nt, count_rows, &cp);
  for (int t = 0; t < nt; t++) {
    out->n_observed += cp.counts[t][0];
    out->n_filled += cp.counts[t][1];
    out->n_unobserved += cp.counts[t][2];
    out->n_surface += cp.counts[t][3];
  }
  free(cp.counts);
  return HEARTH_OK;
}

hearth_status hearth_map_views_with_layout(const hearth_map_layout *l,
                                           const hearth_raycaster *rc_in,
                                           const hearth_map_view *views, size_t n_views,
                                           const hearth_map_opts *opts_in, hearth_map_result *out,
                                           hearth_map_timing *timing, hearth_err *err) {
  double t_start = hearth_now();
  memset(out, 0, sizeof *out);
  hearth_map_opts opts;
  if (opts_in) opts = *opts_in;
  else hearth_map_opts_default(&opts);
  if (opts.pixel_stride < 1) opts.pixel_stride = 1;
  if (!views && n_views) return hearth_err_set(err, HEARTH_E_ARG, "map: missing views");
  if (opts.resolution != l->R || (size_t)opts.pixel_stride != l->stride)
    return hearth_err_set(
        err, HEARTH_E_INCONSISTENT,
        "map: the layout was made for resolution %zu, stride %zu; asked for %zu, %d", l->R,
        l->stride, opts.resolution, opts.pixel_stride);
  if ((opts.normal_passes > 0 ? opts.normal_passes : 0) != l->normal_passes)
    return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "map: the layout was made for %d normal pass(es); asked for %d",
                          l->normal_passes, opts.normal_passes);
  int C = 0;
  hearth_status s = view_channels(&l->cam, views, n_views, &opts, &C, err);
  if (s) return s;
  if (opts.fusion != HEARTH_FUSE_MAX && opts.fusion != HEARTH_FUSE_ROBUST &&
      opts.fusion != HEARTH_FUSE_MEAN && opts.fusion != HEARTH_FUSE_CORRECTED)
    return hearth_err_set(err, HEARTH_E_ARG, "map: unknown fusion rule %d", (int)opts.fusion);
  if ((opts.fusion == HEARTH_FUSE_ROBUST || opts.fusion == HEARTH_FUSE_CORRECTED) && C != 1)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "map: robust fusion is for temperatures only");
  map_ctx m;
  memset(&m, 0, sizeof m);
  max_maps mx = {0};
  view_records rec = {0};
  hearth_raycaster *own_rc = NULL;
  island_box *parts = NULL;
  uint8_t *view_fan = calloc(n_views ? n_views : 1, 1);
  if (!view_fan) return hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  double t_cast0 = hearth_now();
  if (choose_fan_views(l, views, n_views, &opts, view_fan) && !rc_in) {
    double t0 = hearth_now();
    if ((s = hearth_raycaster_new(l->mesh, &own_rc, err))) goto done;
    if (timing) timing->build = hearth_now() - t0;
    t_cast0 = hearth_now();
  }
  int nt = opts.threads > 0 ? opts.threads : hearth_default_threads();
  if ((size_t)nt > n_views) nt = n_views ? (int)n_views : 1;
  m = (map_ctx){.l = l,
                .rc = rc_in ? rc_in : own_rc,
                .views = views,
                .n_views = n_views,
                .opts = &opts,
                .C = C,
                .n_threads = nt,
                .cast_threads = opts.threads > 0 ? opts.threads : hearth_default_threads(),
                .view_fan = view_fan};
  if (!alloc_phase_state(&m, &mx, &rec, out)) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory for %d threads at R=%zu", nt, l->R);
    goto done;
  }
  if (opts.load && !(m.load_errs = calloc(n_views ? n_views : 1, sizeof *m.load_errs))) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
    goto done;
  }
  hearth_parallel_chunks(n_views, 1, nt, map_cast_views, &m);
  /* its memory goes before the result's maps are made */
  free_cast_state(&m);
  if (m.load_errs) {
    /* every view tried its load: the lowest failure, whatever the threads */
    for (size_t v = 0; v < n_views; v++)
      if (m.load_errs[v].status) {
        s = m.load_errs[v].status;
        if (err) *err = m.load_errs[v];
        goto done;
      }
  }
  if (m.failed == 2) {
    s = hearth_err_set(err, HEARTH_E_NUMERIC,
                       "map: a view's camera does not have the mesh in front after all");
    goto done;
  }
  if (m.failed) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory while fusing views");
    goto done;
  }
  double t_fuse0 = hearth_now();
  if (timing) timing->cast = t_fuse0 - t_cast0;
  if ((s = fuse_views(&m, out, &parts, err))) goto done;
  free_fusion_state(&m); /* before the fill */
  double t_fill0 = hearth_now();
  if (timing) timing->fuse = t_fill0 - t_fuse0;
  if (map_fill_islands(l->R, (size_t)C, l->island_of_texel, l->n_islands, parts, nt, out->mask,
                       out->observed, out->filled, nt)) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory while filling");
    goto done;
  }
  if (opts.skip_observed) out->observed = NULL; /* it is filled */
  if ((s = count_texels(out, nt, err))) goto done;
  if (timing) {
    timing->fill = hearth_now() - t_fill0;
    timing->total = hearth_now() - t_start;
  }
done:
  free(view_fan);
  free(m.load_errs);
  free_phase_state(&m);
  hearth_raycaster_free(own_rc);
  free(parts);
  if (s && out->observed == out->filled) out->observed = NULL; /* one array */
  if (s) hearth_map_result_free(out);
  return s;
}
hearth_status hearth_map_views_timed(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                     const hearth_camera *cam, const hearth_map_view *views,
                                     size_t n_views, const hearth_map_opts *opts,
                                     hearth_map_result *out, hearth_map_timing *timing,
                                     hearth_err *err) {
  memset(out, 0, sizeof *out);
  if (timing) memset(timing, 0, sizeof *timing);
  if (!views && n_views) return hearth_err_set(err, HEARTH_E_ARG, "map: missing views");
  double t0 = hearth_now();
  hearth_map_layout *l = NULL;
  hearth_status s = hearth_map_layout_new(mesh, cam, opts, &l, err);
  if (s) return s;
  double t1 = hearth_now();
  s = hearth_map_views_with_layout(l, rc, views, n_views, opts, out, timing, err);
  if (timing) {
    timing->raster = t1 - t0;
    timing->total = hearth_now() - t0;
  }
  hearth_map_layout_free(l);
  return s;
}

hearth_status hearth_map_views(const hearth_mesh *mesh, const hearth_raycaster *rc,
                               const hearth_camera *cam, const hearth_map_view *views,
                               size_t n_views, const hearth_map_opts *opts, hearth_map_result *out,
                               hearth_err *err) {
  return hearth_map_views_timed(mesh, rc, cam, views, n_views, opts, out, NULL, err);
}
