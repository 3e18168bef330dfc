/* A thermal-only calibration root from the virtual rig: the plate seen by
 * a thermal camera alone (the rig's drawn lens, or a wide-angle lens with
 * strong barrel distortion in OpenCV's rational model), each frame written
 * in one of the formats cameras export (temperature CSV, tone-mapped 8-bit
 * or raw-count 16-bit PNG/TIFF), with the true camera and centres under
 * ground_truth/. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/thermal.h"
#include "synth/synth_rig.h"

void hearth_synth_thermal_opts_default(hearth_synth_thermal_opts *o) {
  memset(o, 0, sizeof *o);
  o->seed = 1;
  o->n_frames = 18;
  o->width = 256;
  o->height = 192;
  o->formats = "csv,png8,png16,tiff8,tiff16";
  o->netd_c = 0.05;
}

/* the frame formats, by token */
typedef enum fmt_kind {
  F_CSV,
  F_PNG8,
  F_PNG8_DARK,
  F_PNG16,
  F_PNG_RGB,
  F_TIFF8,
  F_TIFF16,
  F_TIFF_LZW,
  F_TIFF_DEFLATE,
  F_TIFF_PACKBITS
} fmt_kind;
static const struct {
  const char *name, *ext;
} k_fmt[] = {{"csv", "csv"},          {"png8", "png"},      {"png8-dark", "png"},
             {"png16", "png"},        {"png-rgb", "png"},   {"tiff8", "tif"},
             {"tiff16", "tiff"},      {"tiff-lzw", "tiff"}, {"tiff-deflate", "tif"},
             {"tiff-packbits", "tif"}};
#define N_FMT (sizeof k_fmt / sizeof k_fmt[0])

static hearth_status parse_formats(const char *s, int *out, size_t *n, hearth_err *err) {
  *n = 0;
  while (s && *s) {
    const char *e = strchr(s, ',');
    size_t len = e ? (size_t)(e - s) : strlen(s);
    size_t k = 0;
    while (k < N_FMT && (strlen(k_fmt[k].name) != len || strncmp(k_fmt[k].name, s, len))) k++;
    if (k == N_FMT || *n >= 64)
      return hearth_err_set(err, HEARTH_E_ARG, "synth: unknown frame format \"%.*s\"", (int)len, s);
    out[(*n)++] = (int)k;
    s = e ? e + 1 : NULL;
  }
  if (!*n) return hearth_err_set(err, HEARTH_E_ARG, "synth: no frame formats");
  return HEARTH_OK;
}

void hearth_synth_thermal_camera(const hearth_synth_thermal_opts *o, hearth_camera *c) {
  double sx = o->width / 256.0, sy = o->height / 192.0;
  if (o->wide_angle) {
    /* a ~100 x 80 degree lens: the radial factor falls from 1 at the centre
     * to about 0.52 in the corners */
    static const double d[8] = {2.0, 0.5, 5e-4, -4e-4, 0.0, 2.4, 1.2, 0.05};
    memset(c, 0, sizeof *c);
    c->model = HEARTH_LENS_RATIONAL8;
    memcpy(c->dist, d, sizeof d);
    c->fx = 154.0 * sx;
    c->fy = 154.6 * sy;
    c->cx = 0.5 * o->width - 0.5 + 1.3 * sx;
    c->cy = 0.5 * o->height - 0.5 - 0.8 * sy;
  } else {
    hearth_rig rig;
    synth_rig_draw(o->seed, &rig);
    *c = rig.thermal;
    c->fx *= sx;
    c->fy *= sy;
    c->cx = (c->cx + 0.5) * sx - 0.5;
    c->cy = (c->cy + 0.5) * sy - 0.5;
  }
  c->width = o->width;
  c->height = o->height;
}

/* the frame in format f */
static hearth_status write_frame(const char *path, const hearth_image *T, fmt_kind f,
                                 hearth_err *err) {
  if (f == F_CSV) return hearth_thermal_write_csv(path, T, 2, err);
  size_t n = T->width * T->height;
  const float *t = T->data;
  int wide = f == F_PNG16 || f == F_TIFF16 || f == F_TIFF_LZW;
  hearth_image img = {0};
  int ch = f == F_PNG_RGB ? 3 : 1;
  hearth_status st =
      hearth_image_alloc(&img, T->width, T->height, ch, wide ? HEARTH_PIX_U16 : HEARTH_PIX_U8, err);
  if (st) return st;
  double lo = t[0], hi = t[0];
  for (size_t i = 0; i < n; i++) {
    lo = fmin(lo, t[i]);
    hi = fmax(hi, t[i]);
  }
  if (!(hi > lo)) hi = lo + 1;
  for (size_t i = 0; i < n; i++) {
    if (wide) {
      /* raw counts: centikelvin */
      double v = round(((double)t[i] + 273.15) * 100.0);
      ((uint16_t *)img.data)[i] = (uint16_t)(v < 0 ? 0 : v > 65535 ? 65535 : v);
    } else {
      /* tone-mapped over the frame's own range (a camera's auto range) */
      double g = round(255.0 * ((double)t[i] - lo) / (hi - lo));
      if (f == F_PNG8_DARK) g = 255.0 - g;
      for (int k = 0; k < ch; k++) ((uint8_t *)img.data)[i * (size_t)ch + (size_t)k] = (uint8_t)g;
    }
  }
  switch (f) {
    case F_TIFF8: st = hearth_tiff_write(path, &img, HEARTH_TIFF_NONE, err); break;
    case F_TIFF16: st = hearth_tiff_write(path, &img, HEARTH_TIFF_NONE, err); break;
    case F_TIFF_LZW: st = hearth_tiff_write(path, &img, HEARTH_TIFF_LZW, err); break;
    case F_TIFF_DEFLATE: st = hearth_tiff_write(path, &img, HEARTH_TIFF_DEFLATE, err); break;
    case F_TIFF_PACKBITS: st = hearth_tiff_write(path, &img, HEARTH_TIFF_PACKBITS, err); break;
    default: st = hearth_png_write(path, &img, err); break;
  }
  hearth_image_free(&img);
  return st;
}

static hearth_status build(const hearth_synth_thermal_opts *o, const char *root, const int *fmts,
                           size_t nfmt, hearth_err *err) {
  char dir[4096], gt[4096], path[4096];
  snprintf(dir, sizeof dir, "%s/calibration/captures/thermal", root);
  snprintf(gt, sizeof gt, "%s/ground_truth/calibration", root);
  hearth_status st;
  if ((st = hearth_mkdirs(dir, err)) || (st = hearth_mkdirs(gt, err))) return st;
  hearth_rig rig;
  memset(&rig, 0, sizeof rig);
  rig.thermal_only = 1;
  hearth_synth_thermal_camera(o, &rig.thermal);
  const hearth_camera *cam = &rig.thermal;
  snprintf(path, sizeof path, "%s/ground_truth/rig.json", root);
  if ((st = hearth_rig_write(path, &rig, err))) return st;
  int threads = o->threads > 0 ? o->threads : hearth_default_threads();
  float *rays = synth_ray_table(cam, 4, threads);
  hearth_detections dets = {0, NULL};
  dets.frames = hearth_calloc_array((size_t)o->n_frames + 1, sizeof(hearth_detection));
  if (!rays || !dets.frames) {
    free(rays);
    free(dets.frames);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth: out of memory");
  }
  /* the paper's plate */
  synth_plate_geom *g = malloc(sizeof *g);
  if (!g) {
    free(rays);
    free(dets.frames);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth: out of memory");
  }
  synth_plate_geom_init(g, NULL);
  const int nh = (int)g->n;
  hearth_rng base;
  hearth_rng_seed(&base, o->seed);
  /* plate distance and offsets that keep the whole plate in view and
   * reach the corners, by field of view */
  double dmin = o->wide_angle ? 0.11 : 0.22, dmax = o->wide_angle ? 0.20 : 0.40;
  double oxm = o->wide_angle ? 0.72 : 0.26, oym = o->wide_angle ? 0.48 : 0.17;
  for (int i = 0; i < o->n_frames && !st; i++) {
    hearth_rng r;
    hearth_rng_fork(&base, 7000 + (uint64_t)i, &r);
    hearth_rigid T;
    double c[HEARTH_TARGET_MAX_HOLES][2];
    int n = 0;
    for (int tries = 0; tries < 400 && n != nh; tries++) {
      double d = hearth_rng_range(&r, dmin, dmax);
      double ox = hearth_rng_range(&r, -oxm, oxm), oy = hearth_rng_range(&r, -oym, oym);
      synth_plate_pose(g, &r, d, ox, oy, &T);
      n = synth_plate_truth(cam, g, &T, c);
    }
    hearth_image img = {0};
    double ambient = hearth_rng_range(&r, 21.0, 23.0);
    st = synth_plate_thermal_frame(cam, g, &T, rays, ambient, hearth_rng_range(&r, 0.5, 1.5),
                                   hearth_rng_range(&r, 15.0, 25.0), 0.5, o->netd_c,
                                   hearth_rng_u64(&r), threads, &img, err);
    fmt_kind f = (fmt_kind)fmts[(size_t)i % nfmt];
    char name[64];
    snprintf(name, sizeof name, "IR_%04d", 3 * i + 11);
    snprintf(path, sizeof path, "%s/%s.%s", dir, name, k_fmt[f].ext);
    if (!st) st = write_frame(path, &img, f, err);
    hearth_image_free(&img);
    hearth_detection *det = &dets.frames[dets.n++];
    snprintf(det->frame, sizeof det->frame, "%s", name);
    snprintf(det->camera, sizeof det->camera, "thermal");
    det->found = n == nh;
    if (det->found) memcpy(det->centres, c, sizeof(double) * 2 * (size_t)nh);
    else snprintf(det->reason, sizeof det->reason, "only %d holes visible", n);
  }
  if (!st) {
    snprintf(path, sizeof path, "%s/detections.json", gt);
    st = hearth_detections_write(path, &dets, err);
  }
  hearth_detections_free(&dets);
  free(rays);
  free(g);
  return st;
}

hearth_status hearth_synth_thermal_only(const hearth_synth_thermal_opts *o, hearth_err *err) {
  if (!o || !o->out_root) return hearth_err_set(err, HEARTH_E_ARG, "synth: no output root");
  if (o->n_frames < 1 || o->n_frames > 1000 || o->width < 32 || o->height < 32 || o->width > 4096 ||
      o->height > 4096)
    return hearth_err_set(err, HEARTH_E_ARG, "synth: %d frames of %dx%d (1..1000, 32..4096)",
                          o->n_frames, o->width, o->height);
  int fmts[64];
  size_t nfmt;
  hearth_status st = parse_formats(o->formats, fmts, &nfmt, err);
  if (st) return st;
  if (hearth_path_exists(o->out_root))
    return hearth_err_set(err, HEARTH_E_ARG, "%s: output exists; refusing to overwrite",
                          o->out_root);
  char tmp[4096];
  if ((st = hearth_sweep_temps_of(o->out_root, NULL, err)) ||
      (st = hearth_temp_dir(o->out_root, tmp, sizeof tmp, err)))
    return st;
  st = build(o, tmp, fmts, nfmt, err);
  if (!st && rename(tmp, o->out_root) != 0)
    st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename %s into place: %s", o->out_root, tmp,
                        strerror(errno));
  if (st) hearth_remove_tree(tmp, NULL);
  return st;
}
