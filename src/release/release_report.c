/* A static HTML report of a built release: per state, the thermal texture
 * beside the colour texture, the ground truth and the error (virtual rig),
 * the before/after overlays, and the numbers. Everything it links is copied
 * or drawn into the report directory, so it opens from disk in any browser. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"
#include "hearth/npy.h"
#include "hearth/dataset.h"
#include "hearth/release.h"
#include "release/release_internal.h"

#define PATH_SZ 4096

void hearth_report_free(hearth_report *r) {
  if (!r) return;
  free(r->entries);
  memset(r, 0, sizeof *r);
}

static hearth_status copy_file(const char *from, const char *to, hearth_err *err) {
  uint8_t *d = NULL;
  size_t n = 0;
  hearth_status s = hearth_read_file(from, (size_t)256 << 20, &d, &n, err);
  if (s) return s;
  s = hearth_write_file_atomic(to, d, n, err);
  free(d);
  return s;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* the k-th smallest of n sorted values at quantile q (nearest rank) */
static double quantile(const double *v, size_t n, double q) {
  if (!n) return NAN;
  size_t k = (size_t)ceil(q * (double)n);
  if (k < 1) k = 1;
  if (k > n) k = n;
  return v[k - 1];
}

/* a float map as a Turbo PNG over [lo, hi]; texels where keep is 0 get bg */
static hearth_status write_turbo(const char *path, const float *v, const uint8_t *keep, size_t R,
                                 double lo, double hi, const uint8_t bg[3], hearth_err *err) {
  hearth_image img = {0};
  hearth_status s = hearth_image_alloc(&img, R, R, 3, HEARTH_PIX_U8, err);
  if (s) return s;
  uint8_t *px = img.data;
  for (size_t i = 0; i < R * R; i++) {
    if ((keep && !keep[i]) || !isfinite(v[i])) memcpy(px + 3 * i, bg, 3);
    else hearth_turbo((v[i] - lo) / (hi - lo), px + 3 * i);
  }
  s = hearth_png_write(path, &img, err);
  hearth_image_free(&img);
  return s;
}

/* Registration: whether the apparent truth a[] changes by at least d
   between texel i and a surface texel (mask 1 or 2) within EDGE_REACH
   texels of it, i.e. whether texel i lies so near a material or thermal
   edge (or a silhouette between parts) that a reading moved by that much
   along the surface, by a pose error or the thermal camera's blur, is off
   by d. EDGE_REACH is 2 texels: about 1 mm on the rig's objects at R =
   1024, the order of the thermal pixel's footprint and of the refined
   poses' centre error. */
#define EDGE_REACH 2
static int near_edge(const uint8_t *m, const float *a, size_t R, size_t i, double d) {
  const long x = (long)(i % R), y = (long)(i / R), r = EDGE_REACH;
  for (long dy = -r; dy <= r; dy++)
    for (long dx = -r; dx <= r; dx++) {
      const long px = x + dx, py = y + dy;
      if (px < 0 || py < 0 || px >= (long)R || py >= (long)R) continue;
      const size_t p = (size_t)py * R + (size_t)px;
      if ((m[p] == 1 || m[p] == 2) && isfinite(a[p]) && fabs((double)a[p] - a[i]) >= d) return 1;
    }
  return 0;
}

/* the errors against the apparent truth a[] and where the largest sit,
   with the truth's viewing conditions c[] (3 per texel); all in the map's
   UV layout. A texel counts as seen within 60 degrees where away[] is 1
   (hearth's mesh and poses: hearth_truth_match), or without away[] where
   the truth's best viewing cosine c[0] is at least 0.5 (the stand-in) */
hearth_status hb_report_effects(const uint8_t *m, const float *o, const float *t, const float *a,
                                const float *c, const uint8_t *away, size_t R,
                                hearth_report_entry *e, hearth_err *err) {
  const size_t n = R * R;
  double *da = hearth_alloc_array(n, sizeof *da), *dt = hearth_alloc_array(n, sizeof *dt);
  double *all = hearth_alloc_array(n, sizeof *all);
  if (!da || !dt || !all) {
    free(da);
    free(dt);
    free(all);
    return hearth_err_set(err, HEARTH_E_NOMEM, "report: out of memory");
  }
  size_t na = 0, nall = 0;
  for (size_t i = 0; i < n; i++) {
    if (m[i] != 1 || !isfinite(o[i]) || !isfinite(a[i])) continue;
    all[nall++] = fabs((double)o[i] - a[i]);
    if (away ? away[i] != 0 : c[3 * i] >= 0.5f) {
      da[na] = fabs((double)o[i] - a[i]);
      dt[na++] = isfinite(t[i]) ? fabs((double)o[i] - t[i]) : 0.0;
    }
  }
  e->has_apparent = 1;
  e->n_away = na;
  qsort(da, na, sizeof *da, cmp_double);
  qsort(dt, na, sizeof *dt, cmp_double);
  e->app_median_abs_c = quantile(da, na, 0.5);
  e->app_p95_abs_c = quantile(da, na, 0.95);
  e->away_true_median_abs_c = quantile(dt, na, 0.5);
  e->away_true_p95_abs_c = quantile(dt, na, 0.95);
  /* the worst 5 % of all observed texels */
  qsort(all, nall, sizeof *all, cmp_double);
  const double cut = quantile(all, nall, 0.95);
  size_t nw = 0, ng = 0, nm = 0, nc = 0, nr = 0, nn = 0;
  for (size_t i = 0; nall && i < n; i++) {
    if (m[i] != 1 || !isfinite(o[i]) || !isfinite(a[i]) || fabs((double)o[i] - a[i]) < cut)
      continue;
    nw++;
    const int g = away ? !away[i] : c[3 * i]<0.5f, mi = c[3 * i + 1]> 0.0f,
              co = c[3 * i + 2] > 1.0f, re = near_edge(m, a, R, i, cut);
    ng += g;
    nm += mi;
    nc += co;
    nr += re;
    nn += !(g || mi || co || re);
  }
  e->worst_grazing = nw ? (double)ng / (double)nw : NAN;
  e->worst_mirror = nw ? (double)nm / (double)nw : NAN;
  e->worst_cooling = nw ? (double)nc / (double)nw : NAN;
  e->worst_registration = nw ? (double)nr / (double)nw : NAN;
  e->worst_none = nw ? (double)nn / (double)nw : NAN;
  free(da);
  free(dt);
  free(all);
  return HEARTH_OK;
}

/* the apparent truth and conditions of the stand-in (the map's own UV
   layout at R); leaves e->has_apparent 0 without them */
static hearth_status report_effects_files(const char *root, const char *inst, const char *state,
                                          const uint8_t *m, const float *o, const float *t,
                                          size_t R, hearth_report_entry *e, hearth_err *err) {
  char path[PATH_SZ];
  hearth_npy app = {0}, cond = {0};
  hearth_status s = HEARTH_OK;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/temperature_apparent.npy", root,
           inst, state);
  if (!hearth_path_exists(path)) return HEARTH_OK;
  if ((s = hearth_npy_read(path, &app, err))) return s;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/conditions.npy", root, inst, state);
  if ((s = hearth_npy_read(path, &cond, err))) goto done;
  if (app.ndim != 2 || app.dtype != HEARTH_NPY_F32 || app.shape[0] != R || app.shape[1] != R ||
      cond.ndim != 3 || cond.dtype != HEARTH_NPY_F32 || cond.shape[0] != R || cond.shape[1] != R ||
      cond.shape[2] != 3)
    goto done; /* another layout: not compared */
  s = hb_report_effects(m, o, t, app.data, cond.data, NULL, R, e, err);
done:
  hearth_npy_free(&app);
  hearth_npy_free(&cond);
  return s;
}

/* the figures through surface correspondence: observed texels seen within
   60 degrees of the normal, against the matched true temperature */
static hearth_status report_correspondence(const uint8_t *m, const float *o,
                                           const hearth_truth_match *tm, hearth_report_entry *e,
                                           hearth_err *err) {
  const size_t n = tm->R * tm->R;
  double *d = hearth_alloc_array(n, sizeof *d), *dist = hearth_alloc_array(n, sizeof *dist);
  if (!d || !dist) {
    free(d);
    free(dist);
    return hearth_err_set(err, HEARTH_E_NOMEM, "report: out of memory");
  }
  size_t k = 0, ka = 0;
  if (tm->t_apparent) {
    for (size_t i = 0; i < n; i++)
      if (m[i] == 1 && isfinite(o[i]) && tm->away[i] && isfinite(tm->t_apparent[i]))
        d[ka++] = fabs((double)o[i] - (double)tm->t_apparent[i]);
    qsort(d, ka, sizeof *d, cmp_double);
    e->corr_app_median_abs_c = quantile(d, ka, 0.5);
    e->corr_app_p95_abs_c = quantile(d, ka, 0.95);
  }
  for (size_t i = 0; i < n; i++) {
    if (m[i] != 1 || !isfinite(o[i]) || !tm->away[i] || !isfinite(tm->t_true[i])) continue;
    d[k] = fabs((double)o[i] - (double)tm->t_true[i]);
    dist[k++] = tm->dist_m[i];
  }
  qsort(d, k, sizeof *d, cmp_double);
  qsort(dist, k, sizeof *dist, cmp_double);
  e->has_corr = 1;
  e->n_corr = k;
  e->corr_share = e->n_observed ? (double)k / (double)e->n_observed : 0.0;
  e->corr_median_abs_c = quantile(d, k, 0.5);
  e->corr_p95_abs_c = quantile(d, k, 0.95);
  e->corr_dist_median_mm = 1e3 * quantile(dist, k, 0.5);
  e->corr_dist_p95_mm = 1e3 * quantile(dist, k, 0.95);
  e->same_uvs = tm->same_uvs;
  free(d);
  free(dist);
  return HEARTH_OK;
}

/* numbers and images of one state; names of written files go to the html */
static hearth_status report_state(const char *root, const char *out_dir, const char *inst,
                                  const char *state, hearth_report_entry *e, int *have_truth_png,
                                  int *have_overlay, hearth_err *err) {
  char path[PATH_SZ], dst[PATH_SZ];
  hearth_npy mask = {0}, obs = {0}, truth = {0};
  hearth_truth_match tm = {0};
  hearth_status s;
  memset(e, 0, sizeof *e);
  snprintf(e->instance, sizeof e->instance, "%s", inst);
  snprintf(e->state, sizeof e->state, "%s", state);
  e->median_abs_c = e->p95_abs_c = e->mean_signed_c = NAN;
  e->app_median_abs_c = e->app_p95_abs_c = NAN;
  e->away_true_median_abs_c = e->away_true_p95_abs_c = NAN;
  e->worst_grazing = e->worst_mirror = e->worst_cooling = NAN;
  e->worst_registration = e->worst_none = NAN;
  e->corr_median_abs_c = e->corr_p95_abs_c = e->corr_dist_median_mm = e->corr_dist_p95_mm = NAN;
  e->corr_app_median_abs_c = e->corr_app_p95_abs_c = NAN;
  *have_truth_png = *have_overlay = 0;
  snprintf(path, sizeof path, "%s/instances/%s/derived/%s/mask.npy", root, inst, state);
  if ((s = hearth_npy_read(path, &mask, err))) return s;
  snprintf(path, sizeof path, "%s/instances/%s/derived/%s/temperature_observed.npy", root, inst,
           state);
  if ((s = hearth_npy_read(path, &obs, err))) goto done;
  if (mask.ndim != 2 || obs.ndim != 2 || mask.shape[0] != obs.shape[0] ||
      mask.dtype != HEARTH_NPY_U8 || obs.dtype != HEARTH_NPY_F32 ||
      mask.shape[0] != mask.shape[1]) {
    s = hearth_err_set(err, HEARTH_E_SIZE, "%s: maps of %s/%s have inconsistent shapes", path, inst,
                       state);
    goto done;
  }
  size_t R = mask.shape[0], n = R * R;
  e->R = R;
  const uint8_t *m = mask.data;
  const float *o = obs.data;
  for (size_t i = 0; i < n; i++) {
    if (m[i] != 0) e->n_surface++;
    if (m[i] == 1) e->n_observed++;
  }
  e->coverage = e->n_surface ? (double)e->n_observed / (double)e->n_surface : 0.0;
  snprintf(path, sizeof path, "%s/instances/%s/derived/%s/thermal_turbo.png", root, inst, state);
  snprintf(dst, sizeof dst, "%s/%s_%s_thermal.png", out_dir, inst, state);
  if ((s = copy_file(path, dst, err))) goto done;

  /* ground truth: through surface correspondence (the built mesh against the
     true one), and texel for texel where the built mesh has the truth's UVs
     (the stand-in) or else resampled onto the built layout */
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/temperature_true.npy", root, inst,
           state);
  snprintf(dst, sizeof dst, "%s/ground_truth/instances/%s/mesh.glb", root, inst);
  int have_tm = 0;
  if (hearth_path_exists(path) && hearth_path_exists(dst)) {
    if ((s = hearth_truth_match_state(root, inst, state, R, NULL, &tm, err))) goto done;
    have_tm = 1;
    if ((s = report_correspondence(m, o, &tm, e, err))) goto done;
  }
  if (hearth_path_exists(path)) {
    const float *t = NULL;
    if (!have_tm || tm.same_uvs) {
      if ((s = hearth_npy_read(path, &truth, err))) goto done;
      if (truth.ndim == 2 && truth.dtype == HEARTH_NPY_F32 && truth.shape[0] == R &&
          truth.shape[1] == R)
        t = truth.data;
    } else {
      t = tm.t_true;
    }
    if (t) {
      e->has_truth = 1;
      double *ad = hearth_alloc_array(e->n_observed ? e->n_observed : 1, sizeof *ad);
      float *errmap = hearth_alloc_array(n, sizeof *errmap);
      uint8_t *keep = hearth_alloc_array(n, 1);
      if (!ad || !errmap || !keep) {
        free(ad);
        free(errmap);
        free(keep);
        s = hearth_err_set(err, HEARTH_E_NOMEM, "report: out of memory");
        goto done;
      }
      double sum = 0;
      for (size_t i = 0; i < n; i++) {
        keep[i] = m[i] == 1 && isfinite(t[i]) && isfinite(o[i]);
        errmap[i] = keep[i] ? fabsf(o[i] - t[i]) : NAN;
        if (keep[i]) {
          ad[e->n_compared++] = fabs((double)o[i] - (double)t[i]);
          sum += (double)o[i] - (double)t[i];
        }
      }
      qsort(ad, e->n_compared, sizeof *ad, cmp_double);
      e->median_abs_c = quantile(ad, e->n_compared, 0.5);
      e->p95_abs_c = quantile(ad, e->n_compared, 0.95);
      e->mean_signed_c = e->n_compared ? sum / (double)e->n_compared : NAN;
      const uint8_t black[3] = {0, 0, 0}, grey[3] = {60, 60, 60};
      uint8_t *surf = keep; /* reuse: surface texels of the truth */
      for (size_t i = 0; i < n; i++) surf[i] = isfinite(t[i]);
      snprintf(dst, sizeof dst, "%s/%s_%s_truth.png", out_dir, inst, state);
      s = write_turbo(dst, t, surf, R, 10.0, 60.0, black, err);
      if (!s) {
        snprintf(dst, sizeof dst, "%s/%s_%s_error.png", out_dir, inst, state);
        /* error 0..5 degC; texels not observed stay grey */
        for (size_t i = 0; i < n; i++) surf[i] = isfinite(errmap[i]);
        s = write_turbo(dst, errmap, surf, R, 0.0, 5.0, grey, err);
      }
      free(ad);
      free(errmap);
      free(keep);
      if (s) goto done;
      *have_truth_png = 1;
      if (!have_tm || tm.same_uvs) s = report_effects_files(root, inst, state, m, o, t, R, e, err);
      else if (tm.t_apparent && tm.conditions)
        s = hb_report_effects(m, o, t, tm.t_apparent, tm.conditions, tm.away, R, e, err);
      if (s) goto done;
    }
  }
  snprintf(dst, sizeof dst, "%s/%s_%s_contact.png", out_dir, inst, state);
  if ((s = hb_contact_picture(root, inst, state, dst, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/derived/overlay/%s/contact_sheet.png", root, inst,
           state);
  if (hearth_path_exists(path)) {
    snprintf(dst, sizeof dst, "%s/%s_%s_overlay.png", out_dir, inst, state);
    if ((s = copy_file(path, dst, err))) goto done;
    *have_overlay = 1;
  }
done:
  hearth_truth_match_free(&tm);
  hearth_npy_free(&mask);
  hearth_npy_free(&obs);
  hearth_npy_free(&truth);
  return s;
}

static void html_escape(FILE *f, const char *s) {
  for (; *s; s++) {
    if (*s == '<') fputs("&lt;", f);
    else if (*s == '>') fputs("&gt;", f);
    else if (*s == '&') fputs("&amp;", f);
    else fputc(*s, f);
  }
}

static void fmt2(char *buf, size_t n, double x) {
  if (!isfinite(x)) snprintf(buf, n, "n/a");
  else hearth_format_fixed(buf, n, x, 2);
}

hearth_status hearth_report_write(const char *root, const char *out_dir, const char *title,
                                  const char *validate_text, hearth_report *rep, hearth_err *err) {
  memset(rep, 0, sizeof *rep);
  char path[PATH_SZ];
  hearth_status s = hearth_mkdirs(out_dir, err);
  if (s) return s;
  snprintf(path, sizeof path, "%s/release.json", root);
  hearth_release_doc rel = {0};
  if ((s = hearth_release_read(path, &rel, err))) return s;
  size_t cap = rel.n_instances * HEARTH_MAX_STATES;
  rep->entries = calloc(cap ? cap : 1, sizeof *rep->entries);
  int *truth_png = calloc(cap ? cap : 1, sizeof *truth_png),
      *overlay = calloc(cap ? cap : 1, sizeof *overlay);
  int *colour = calloc(rel.n_instances ? rel.n_instances : 1, sizeof *colour);
  if (!rep->entries || !truth_png || !overlay || !colour) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "report: out of memory");
    goto done;
  }
  for (size_t i = 0; i < rel.n_instances; i++) {
    const char *inst = rel.instances[i];
    hearth_instance_doc doc;
    snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, inst);
    if ((s = hearth_instance_load(root, inst, &doc, err))) goto done;
    /* the colour texture: baked if present, else the reconstruction's */
    char dst[PATH_SZ];
    snprintf(dst, sizeof dst, "%s/%s_colour.png", out_dir, inst);
    snprintf(path, sizeof path, "%s/instances/%s/derived/rgb_texture.png", root, inst);
    if (!hearth_path_exists(path))
      snprintf(path, sizeof path, "%s/instances/%s/recon/rgb_texture.png", root, inst);
    if (hearth_path_exists(path)) {
      if ((s = copy_file(path, dst, err))) goto done;
      colour[i] = 1;
    }
    for (size_t k = 0; k < doc.n_states; k++) {
      size_t j = rep->n;
      if ((s = report_state(root, out_dir, inst, doc.states[k], &rep->entries[j], &truth_png[j],
                            &overlay[j], err)))
        goto done;
      rep->n++;
    }
  }

  /* the page */
  snprintf(path, sizeof path, "%s/index.html", out_dir);
  hearth_atomic_file af;
  if ((s = hearth_atomic_open(&af, path, err))) goto done;
  FILE *f = af.fp;
  fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>", f);
  html_escape(f, title ? title : "hearth report");
  fputs(
      "</title>\n<style>\n"
      "body{font-family:sans-serif;margin:24px;background:#fafafa;color:#222}\n"
      "table.n{border-collapse:collapse;margin:8px 0}\n"
      "table.n td,table.n th{border:1px solid #bbb;padding:3px 8px;text-align:right}\n"
      "table.n th{background:#eee}\n"
      ".row{display:flex;flex-wrap:wrap;gap:12px;align-items:flex-start}\n"
      "figure{margin:0;background:#fff;border:1px solid #ddd;padding:6px}\n"
      "figure img{width:256px;height:256px;image-rendering:pixelated;display:block}\n"
      "figure.wide img{width:auto;height:auto;max-width:780px}\n"
      "figcaption{font-size:12px;color:#555;max-width:256px}\n"
      ".bar{height:12px;width:256px;background:linear-gradient(to right,"
      "#30123b,#4662d7,#36aaf9,#1ae4b6,#72fe5e,#c8ef34,#faba39,#f66b19,#ca2a04,#7a0403)}\n"
      "pre{background:#fff;border:1px solid #ddd;padding:8px;white-space:pre-wrap}\n"
      "</style></head><body>\n<h1>",
      f);
  html_escape(f, title ? title : "hearth report");
  fputs("</h1>\n<p>Release: <code>", f);
  html_escape(f, root);
  fputs(
      "</code>. Thermal textures use the Turbo colour map over a fixed 10&ndash;60 &deg;C "
      "(<span style=\"display:inline-block;vertical-align:middle\" class=\"bar\"></span>); "
      "error maps show |observed &minus; true| over 0&ndash;5 &deg;C on observed texels "
      "(grey: not observed). Every texture is in the mesh's UV layout (row 0 at v = 0), so "
      "thermal, colour and ground truth line up texel for texel.</p>\n",
      f);
  fputs(
      "<h2>Summary</h2>\n<table class=\"n\"><tr><th>instance</th><th>state</th><th>R</th>"
      "<th>surface texels</th><th>observed</th><th>median |err| &deg;C</th>"
      "<th>p95 |err| &deg;C</th><th>mean err &deg;C</th><th>compared by correspondence</th>"
      "<th>median |err| &deg;C</th><th>p95 |err| &deg;C</th></tr>\n",
      f);
  for (size_t j = 0; j < rep->n; j++) {
    const hearth_report_entry *e = &rep->entries[j];
    char cov[32], med[32], p95[32], mean[32];
    hearth_format_fixed(cov, sizeof cov, 100.0 * e->coverage, 1);
    fmt2(med, sizeof med, e->median_abs_c);
    fmt2(p95, sizeof p95, e->p95_abs_c);
    fmt2(mean, sizeof mean, e->mean_signed_c);
    char cshare[32] = "n/a", cmed[32], cp95[32];
    if (e->has_corr) {
      hearth_format_fixed(cshare, sizeof cshare - 2, 100.0 * e->corr_share, 1);
      strcat(cshare, " %");
    }
    fmt2(cmed, sizeof cmed, e->corr_median_abs_c);
    fmt2(cp95, sizeof cp95, e->corr_p95_abs_c);
    fprintf(
        f,
        "<tr><td style=\"text-align:left\"><a href=\"#%s_%s\">%s</a></td><td style=\"text-align:left\">%s</td>"
        "<td>%zu</td><td>%zu</td><td>%s %%</td><td>%s</td><td>%s</td><td>%s</td>"
        "<td>%s</td><td>%s</td><td>%s</td></tr>\n",
        e->instance, e->state, e->instance, e->state, e->R, e->n_surface, cov, med, p95, mean,
        cshare, cmed, cp95);
  }
  fputs("</table>\n", f);
  int effects = 0;
  for (size_t j = 0; j < rep->n; j++) effects |= rep->entries[j].has_apparent;
  if (effects) {
    fputs(
        "<h2>Against both truths (the rig's object effects)</h2>\n<p>On observed texels seen "
        "within 60&deg; of the normal: |observed &minus; apparent| (what a view along the normal "
        "reads at the start of the scan) and |observed &minus; true| (the true surface "
        "temperature then). Of the worst 5 % of all observed texels against the apparent truth: "
        "the shares seen only beyond 60&deg; (grazing), mirroring the warm source in a view "
        "(reflections), drifting by more than 1 &deg;C during the scan (cooling), and lying "
        "within 2 texels of a texel whose apparent truth differs by at least the worst 5 "
        "%'s threshold (registration: a reading moved that far along the surface, by a pose "
        "error or the thermal blur, is that wrong); a texel may be in several classes, and the "
        "last column is the share in none.</p>\n"
        "<table class=\"n\"><tr><th>instance</th><th>state</th><th>texels</th>"
        "<th>median |err| apparent</th><th>p95</th><th>median |err| true</th><th>p95</th>"
        "<th>worst: grazing</th><th>reflections</th><th>cooling</th><th>registration</th>"
        "<th>none</th></tr>\n",
        f);
    for (size_t j = 0; j < rep->n; j++) {
      const hearth_report_entry *e = &rep->entries[j];
      if (!e->has_apparent) continue;
      char v[9][32];
      fmt2(v[0], sizeof v[0], e->app_median_abs_c);
      fmt2(v[1], sizeof v[1], e->app_p95_abs_c);
      fmt2(v[2], sizeof v[2], e->away_true_median_abs_c);
      fmt2(v[3], sizeof v[3], e->away_true_p95_abs_c);
      fmt2(v[4], sizeof v[4], 100.0 * e->worst_grazing);
      fmt2(v[5], sizeof v[5], 100.0 * e->worst_mirror);
      fmt2(v[6], sizeof v[6], 100.0 * e->worst_cooling);
      fmt2(v[7], sizeof v[7], 100.0 * e->worst_registration);
      fmt2(v[8], sizeof v[8], 100.0 * e->worst_none);
      fprintf(f,
              "<tr><td style=\"text-align:left\">%s</td><td style=\"text-align:left\">%s</td>"
              "<td>%zu</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s %%</td>"
              "<td>%s %%</td><td>%s %%</td><td>%s %%</td><td>%s %%</td></tr>\n",
              e->instance, e->state, e->n_away, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7],
              v[8]);
    }
    fputs("</table>\n", f);
  }
  if (validate_text) {
    fputs("<h2>Validation</h2>\n<pre>", f);
    html_escape(f, validate_text);
    fputs("</pre>\n", f);
  }
  size_t j = 0;
  for (size_t i = 0; i < rel.n_instances; i++) {
    const char *inst = rel.instances[i];
    for (; j < rep->n && !strcmp(rep->entries[j].instance, inst); j++) {
      const hearth_report_entry *e = &rep->entries[j];
      char cov[32], med[32], p95[32];
      hearth_format_fixed(cov, sizeof cov, 100.0 * e->coverage, 1);
      fmt2(med, sizeof med, e->median_abs_c);
      fmt2(p95, sizeof p95, e->p95_abs_c);
      fprintf(
          f,
          "<h2 id=\"%s_%s\">%s &mdash; %s</h2>\n<p>%s %% of the surface observed; "
          "median |error| %s &deg;C, p95 %s &deg;C against ground truth.</p>\n<div class=\"row\">\n",
          e->instance, e->state, e->instance, e->state, cov, med, p95);
      fprintf(
          f,
          "<figure><img src=\"%s_%s_thermal.png\" alt=\"thermal texture\"><figcaption>thermal "
          "texture (Turbo, 10&ndash;60 &deg;C), derived/%s/thermal_turbo.png</figcaption></figure>\n",
          inst, e->state, e->state);
      if (colour[i])
        fprintf(f,
                "<figure><img src=\"%s_colour.png\" alt=\"colour texture\"><figcaption>colour "
                "texture, same UV layout</figcaption></figure>\n",
                inst);
      if (truth_png[j]) {
        fprintf(f,
                "<figure><img src=\"%s_%s_truth.png\" alt=\"ground truth\"><figcaption>ground "
                "truth temperature (Turbo, 10&ndash;60 &deg;C)</figcaption></figure>\n",
                inst, e->state);
        fprintf(f,
                "<figure><img src=\"%s_%s_error.png\" alt=\"error\"><figcaption>|observed &minus; "
                "true| (Turbo, 0&ndash;5 &deg;C; grey not observed)</figcaption></figure>\n",
                inst, e->state);
      }
      fputs("</div>\n", f);
      if (e->has_corr) {
        char v[5][32];
        fmt2(v[0], sizeof v[0], e->corr_median_abs_c);
        fmt2(v[1], sizeof v[1], e->corr_p95_abs_c);
        hearth_format_fixed(v[2], sizeof v[2], 100.0 * e->corr_share, 1);
        fmt2(v[3], sizeof v[3], e->corr_dist_median_mm);
        fmt2(v[4], sizeof v[4], e->corr_dist_p95_mm);
        fprintf(f,
                "<p>Through surface correspondence (%s): on the %s %% of observed texels seen "
                "within 60&deg; of the normal, median |error| %s &deg;C, p95 %s &deg;C; "
                "distance to the matched true surface point median %s mm, p95 %s mm.</p>\n",
                e->same_uvs ? "the stand-in: the truth's own mesh" : "hearth's own reconstruction",
                v[2], v[0], v[1], v[3], v[4]);
      }
      fprintf(f,
              "<div class=\"row\"><figure class=\"wide\"><img src=\"%s_%s_contact.png\" "
              "alt=\"contact picture\"><figcaption style=\"max-width:780px\">the built mesh "
              "from four viewpoints: colour texture (top), thermal texture in Turbo, "
              "10&ndash;60 &deg;C (bottom)</figcaption></figure></div>\n",
              inst, e->state);
      if (overlay[j])
        fprintf(
            f,
            "<div class=\"row\"><figure class=\"wide\"><img src=\"%s_%s_overlay.png\" "
            "alt=\"overlays\"><figcaption style=\"max-width:780px\">mesh outlines on the thermal "
            "views: before (transferred poses) and after refinement</figcaption></figure></div>\n",
            inst, e->state);
    }
  }
  fputs("<p style=\"color:#777;font-size:12px\">Made by hearth " HEARTH_VERSION
        ". Static page: open it from disk, no server needed.</p>\n</body></html>\n",
        f);
  s = hearth_atomic_commit(&af, err);
done:
  free(truth_png);
  free(overlay);
  free(colour);
  hearth_release_free(&rel);
  return s;
}
