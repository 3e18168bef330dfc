/* The release stages: `detect` (captures -> detections.json + overlays) and
 * `calibrate` (detections + factory.json -> rig.json, rig_opencv.yaml,
 * calibration_report.json). Every input is read and checked before any
 * output is written, and each output is written atomically. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"
#include "hearth/image.h"
#include "hearth/thermal.h"

#define MAX_FRAMES 4096

void hearth_detect_job_default(hearth_detect_job *r) {
  memset(r, 0, sizeof *r);
  hearth_detect_opts_default(&r->detect);
  r->overlays = 1;
}

void hearth_calib_report_free(hearth_calib_report *r) {
  if (!r) return;
  free(r->thermal);
  free(r->pairs);
  r->thermal = r->pairs = NULL;
  r->n_thermal = r->n_pairs = 0;
}

static int cmp_name(const void *a, const void *b) {
  return strcmp((const char *)a, (const char *)b);
}

/* names "<prefix>DDD<suffix>" in dir, sorted; the stem (prefix + digits) is stored */
static hearth_status list_frames(const char *dir, char prefix, const char *suffix,
                                 char (*names)[HEARTH_NAME_MAX], size_t *n, hearth_err *err) {
  DIR *d = opendir(dir);
  *n = 0;
  if (!d) return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: cannot open the capture folder", dir);
  struct dirent *e;
  size_t sl = strlen(suffix);
  while ((e = readdir(d))) {
    const char *s = e->d_name;
    size_t len = strlen(s);
    if (len < 4 + sl || s[0] != prefix || strcmp(s + len - sl, suffix)) continue;
    size_t k = 1;
    while (k < len - sl && s[k] >= '0' && s[k] <= '9') k++;
    if (k != len - sl || k < 2 || k >= HEARTH_NAME_MAX) continue;
    if (*n >= MAX_FRAMES) {
      closedir(d);
      return hearth_err_set(err, HEARTH_E_LIMIT, "%s: more than %d capture frames", dir,
                            MAX_FRAMES);
    }
    memcpy(names[*n], s, k);
    names[*n][k] = 0;
    (*n)++;
  }
  closedir(d);
  qsort(names, *n, HEARTH_NAME_MAX, cmp_name);
  return HEARTH_OK;
}

/* ---- detect ------------------------------------------------------------------- */
/* One frame: detected on a worker, which also draws and encodes its
 * overlay; the files are written after every frame has been read. */
typedef struct det_job {
  const hearth_target *target;
  char path[4096];
  int thermal;
  hearth_detection det;
  size_t width, height; /* of the capture */
  uint8_t *png;         /* the encoded overlay (with overlays) */
  size_t png_size;
  hearth_status st;
  hearth_err err;
} det_job;

typedef struct det_ctx {
  det_job *jobs;
  const hearth_detect_job *run;
  int want_rgb_w, want_rgb_h;
} det_ctx;

/* The overlays' pictures: thermal in Turbo enlarged 4 times by repeating
 * each pixel (the sensor's pixels stay visible as 4 x 4 blocks, as in the
 * pose overlays); colour at half size, as libjpeg decodes it halved. */

/* an RGB image enlarged 4 times, each pixel repeated 4 x 4 times: every
 * source row widened once, then copied into the next three rows */
static void rep4(const hearth_image *src, hearth_image *dst) {
  const uint8_t *p = src->data;
  size_t sw = src->width, rowv = 3 * dst->width;
  uint8_t *q = dst->data;
  for (size_t y = 0; y < src->height; y++) {
    uint8_t *o = q + 4 * y * rowv;
    for (size_t x = 0; x < sw; x++)
      for (size_t r = 0; r < 4; r++) memcpy(o + 3 * (4 * x + r), p + 3 * (y * sw + x), 3);
    for (size_t r = 1; r < 4; r++) memcpy(o + r * rowv, o, rowv);
  }
}

/* the image of a capture of native_w x native_h enlarged s times (4:
 * thermal, 0.5: colour; a colour image already of that size is copied), through hearth_image_resize where
 * the shortcuts above do not apply */
static hearth_status overlay_scale(const hearth_image *img, size_t native_w, size_t native_h,
                                   int thermal, double s, hearth_image *big, hearth_err *err) {
  size_t w = (size_t)lround((double)native_w * s), h = (size_t)lround((double)native_h * s);
  hearth_image rgb = {0};
  hearth_status st;
  if (thermal) {
    const float *T = img->data;
    size_t n = img->width * img->height;
    double lo = T[0], hi = T[0];
    for (size_t i = 0; i < n; i++) {
      lo = fmin(lo, T[i]);
      hi = fmax(hi, T[i]);
    }
    const uint8_t nan_rgb[3] = {0, 0, 0};
    if ((st = hearth_turbo_image(img, lo, hi > lo ? hi : lo + 1, nan_rgb, &rgb, err))) return st;
    if (w == 4 * rgb.width && h == 4 * rgb.height) {
      if (!(st = hearth_image_alloc(big, w, h, 3, HEARTH_PIX_U8, err))) rep4(&rgb, big);
    } else {
      st = hearth_image_resize(&rgb, w, h, big, err);
    }
    hearth_image_free(&rgb);
    return st;
  }
  if ((st = hearth_image_alloc(&rgb, img->width, img->height, 3, HEARTH_PIX_U8, err))) return st;
  const uint8_t *p = img->data;
  uint8_t *q = rgb.data;
  if (img->channels == 3) memcpy(q, p, hearth_image_bytes(&rgb));
  else
    for (size_t i = 0; i < img->width * img->height; i++)
      for (int k = 0; k < 3; k++)
        q[3 * i + (size_t)k] = p[i * (size_t)img->channels + (img->channels > 3 ? (size_t)k : 0)];
  if (rgb.width == w && rgb.height == h) {
    *big = rgb;
    return HEARTH_OK;
  }
  st = hearth_image_resize(&rgb, w, h, big, err);
  hearth_image_free(&rgb);
  return st;
}

/* overlay: the image (thermal in Turbo, enlarged 4x; colour halved) with
 * the centres joined row by row, one colour per row; encoded into j->png
 * as a picture (its repeated rows are cheap to store) */
static hearth_status draw_overlay(det_job *j, const hearth_image *img, hearth_err *err) {
  hearth_image big = {0};
  double s = j->thermal ? 4 : 0.5;
  hearth_status st = overlay_scale(img, j->width, j->height, j->thermal, s, &big, err);
  if (st) return st;
  if (j->det.found) {
    static const uint8_t row_rgb[8][3] = {{255, 0, 0},   {255, 128, 0}, {255, 255, 0},
                                          {0, 255, 0},   {0, 255, 255}, {0, 128, 255},
                                          {160, 0, 255}, {255, 0, 255}};
    const uint8_t white[3] = {255, 255, 255};
    /* pixel centre convention: native u -> (u + 0.5) s - 0.5 */
    const int holes = (int)hearth_target_holes(j->target);
    for (int i = 0, r = 0, next = hearth_target_row_holes(j->target, 0); i < holes; i++) {
      if (i == next) next += hearth_target_row_holes(j->target, ++r);
      double x = (j->det.centres[i][0] + 0.5) * s - 0.5, y = (j->det.centres[i][1] + 0.5) * s - 0.5;
      const uint8_t *rc = row_rgb[r & 7]; /* eight row colours, repeated */
      if (i + 1 < holes) {
        double x1 = (j->det.centres[i + 1][0] + 0.5) * s - 0.5;
        double y1 = (j->det.centres[i + 1][1] + 0.5) * s - 0.5;
        hearth_draw_line(&big, x, y, x1, y1, rc, 2);
      }
      hearth_draw_circle(&big, x, y, 4, i == 0 ? white : rc);
    }
    hearth_draw_text(&big, 8, 8, j->det.frame, white, 2);
  } else {
    const uint8_t red[3] = {255, 40, 40};
    char msg[300];
    snprintf(msg, sizeof msg, "%s: %s", j->det.frame, j->det.reason);
    hearth_draw_text(&big, 8, 8, msg, red, 2);
  }
  st = hearth_png_encode_picture(&big, &j->png, &j->png_size, err);
  hearth_image_free(&big);
  return st;
}

hearth_status calib_overlay_encode(const hearth_image *img, int thermal,
                                   const hearth_target *target, const hearth_detection *det,
                                   uint8_t **png, size_t *size, hearth_err *err) {
  det_job *j = calloc(1, sizeof *j);
  if (!j) return hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
  hearth_target tdef;
  j->target = hearth_target_or_default(target, &tdef);
  j->thermal = thermal;
  j->det = *det;
  j->width = img->width;
  j->height = img->height;
  hearth_status st = draw_overlay(j, img, err);
  *png = j->png;
  *size = j->png_size;
  free(j);
  return st;
}

static void det_range(void *vctx, size_t b, size_t e, int ti) {
  det_ctx *c = vctx;
  (void)ti;
  for (size_t i = b; i < e; i++) {
    det_job *j = &c->jobs[i];
    hearth_image img = {0};
    if (j->thermal) {
      /* any size: the captures tell the thermal camera's (all must agree) */
      const hearth_csv_opts any = {0, 0};
      j->st = hearth_thermal_read_csv(j->path, &any, &img, &j->err);
      if (!j->st) j->st = hearth_detect_plate_thermal(&img, &c->run->detect, &j->det, &j->err);
      j->width = img.width;
      j->height = img.height;
    } else {
      /* detection reads the luma plane only (no chroma work); the overlay,
       * if wanted, decodes the colour image at half size */
      /* the colour camera's size (factory.json), checked from the header
       * before the pixels are decoded */
      hearth_image_expect want = {(size_t)c->want_rgb_w,
                                  (size_t)c->want_rgb_h,
                                  0,
                                  0,
                                  0,
                                  "(the colour camera of factory.json)"};
      j->st =
          hearth_jpeg_read_gray_expect(j->path, c->want_rgb_w > 0 ? &want : NULL, &img, &j->err);
      if (!j->st) j->st = hearth_detect_plate_color(&img, &c->run->detect, &j->det, &j->err);
      j->width = img.width;
      j->height = img.height;
      if (!j->st && c->run->overlays) {
        hearth_image_free(&img);
        j->st = hearth_jpeg_read_half(j->path, &img, &j->err);
      }
    }
    if (!j->st && c->run->overlays) j->st = draw_overlay(j, &img, &j->err);
    hearth_image_free(&img);
    /* every error names its file */
    if (j->st && !strstr(j->err.msg, j->path)) hearth_err_prefix(&j->err, "%s", j->path);
  }
}

hearth_status hearth_calib_detect_release(const char *root, const hearth_detect_job *run,
                                          hearth_detections *out, hearth_err *err) {
  hearth_detect_job def;
  if (!run) {
    hearth_detect_job_default(&def);
    run = &def;
  }
  if (!root) return hearth_err_set(err, HEARTH_E_ARG, "detect: no release root");
  char dth[4096], dst[4096], path[4096];
  snprintf(dth, sizeof dth, "%s/calibration/captures/thermal", root);
  snprintf(dst, sizeof dst, "%s/calibration/captures/stereo", root);
  /* no stereo folder: a thermal-only root (frames of any name and format) */
  if (!hearth_path_exists(dst)) return calib_detect_thermal_only(root, run, out, err);
  hearth_status st = HEARTH_OK;
  char(*fnames)[HEARTH_NAME_MAX] = malloc(sizeof(*fnames) * MAX_FRAMES);
  char(*pnames)[HEARTH_NAME_MAX] = malloc(sizeof(*pnames) * MAX_FRAMES);
  char(*tnames)[HEARTH_NAME_MAX] = malloc(sizeof(*tnames) * MAX_FRAMES);
  det_job *jobs = NULL;
  size_t nf = 0, np = 0, nt = 0, nj = 0;
  if (!fnames || !pnames || !tnames) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "detect: out of memory");
    goto done;
  }
  if ((st = list_frames(dth, 'f', ".csv", fnames, &nf, err)) ||
      (st = list_frames(dst, 'p', "_rgb.jpg", pnames, &np, err)) ||
      (st = list_frames(dst, 'p', "_thermal.csv", tnames, &nt, err)))
    goto done;
  /* every pair needs both halves */
  for (size_t i = 0, k = 0; i < np || k < nt;) {
    int c = i >= np ? 1 : k >= nt ? -1 : strcmp(pnames[i], tnames[k]);
    if (c) {
      st = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "%s/%s%s: missing (the other half of pair %s exists)", dst,
                          c < 0 ? pnames[i] : tnames[k], c < 0 ? "_thermal.csv" : "_rgb.jpg",
                          c < 0 ? pnames[i] : tnames[k]);
      goto done;
    }
    i++;
    k++;
  }
  if (nf == 0 && np == 0) {
    st =
        hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s/calibration/captures: no capture frames", root);
    goto done;
  }
  /* the target (calibration/target.json; absent: the paper's plate) */
  hearth_detect_job job = *run;
  snprintf(path, sizeof path, "%s/calibration/target.json", root);
  if ((st = hearth_target_read(path, &job.detect.target, err))) goto done;
  det_ctx ctx;
  memset(&ctx, 0, sizeof ctx);
  ctx.run = &job;
  snprintf(path, sizeof path, "%s/calibration/factory.json", root);
  if (hearth_path_exists(path)) {
    hearth_factory_calib fc;
    if ((st = hearth_factory_read(path, &fc, err))) goto done;
    ctx.want_rgb_w = fc.rgb.width;
    ctx.want_rgb_h = fc.rgb.height;
  }
  nj = nf + 2 * np;
  jobs = hearth_calloc_array(nj, sizeof(det_job));
  if (!jobs) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "detect: out of memory");
    goto done;
  }
  for (size_t i = 0; i < nj; i++) jobs[i].target = &job.detect.target;
  for (size_t i = 0; i < nf; i++) {
    det_job *j = &jobs[i];
    snprintf(j->path, sizeof j->path, "%s/%s.csv", dth, fnames[i]);
    j->thermal = 1;
    snprintf(j->det.frame, sizeof j->det.frame, "%s", fnames[i]);
    snprintf(j->det.camera, sizeof j->det.camera, "thermal");
  }
  for (size_t i = 0; i < np; i++) {
    det_job *a = &jobs[nf + 2 * i], *b = a + 1;
    snprintf(a->path, sizeof a->path, "%s/%s_thermal.csv", dst, pnames[i]);
    a->thermal = 1;
    snprintf(a->det.frame, sizeof a->det.frame, "%s", pnames[i]);
    snprintf(a->det.camera, sizeof a->det.camera, "thermal");
    snprintf(b->path, sizeof b->path, "%s/%s_rgb.jpg", dst, pnames[i]);
    snprintf(b->det.frame, sizeof b->det.frame, "%s", pnames[i]);
    snprintf(b->det.camera, sizeof b->det.camera, "rgb");
  }
  ctx.jobs = jobs;
  int threads = run->threads > 0 ? run->threads : hearth_default_threads();
  /* frames are independent; results land by index, so the output does not
   * depend on the thread count */
  if ((st = hearth_parallel_for(nj, threads, det_range, &ctx), st)) {
    hearth_err_set(err, st, "detect: cannot start worker threads");
    goto done;
  }
  for (size_t i = 0; i < nj; i++)
    if (jobs[i].st) {
      st = jobs[i].st;
      if (err) *err = jobs[i].err;
      goto done;
    }
  /* one thermal camera: every thermal capture of one size */
  for (size_t i = 0, first = nj; i < nj; i++) {
    if (!jobs[i].thermal) continue;
    if (first == nj) first = i;
    else if (jobs[i].width != jobs[first].width || jobs[i].height != jobs[first].height) {
      st = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "%s: a %zux%zu matrix, but %s is %zux%zu (one thermal camera)",
                          jobs[i].path, jobs[i].width, jobs[i].height, jobs[first].path,
                          jobs[first].width, jobs[first].height);
      goto done;
    }
  }
  /* outputs: overlays, then detections.json */
  if (run->overlays) {
    snprintf(path, sizeof path, "%s/calibration/overlays", root);
    if ((st = hearth_mkdirs(path, err))) goto done;
    for (size_t i = 0; i < nj; i++) {
      snprintf(path, sizeof path, "%s/calibration/overlays/%s_%s.png", root, jobs[i].det.frame,
               jobs[i].det.camera);
      if ((st = hearth_write_file_atomic(path, jobs[i].png, jobs[i].png_size, err))) goto done;
    }
  }
  hearth_detections dets;
  memset(&dets, 0, sizeof dets);
  dets.target = job.detect.target;
  dets.n = nj;
  dets.frames = hearth_calloc_array(nj, sizeof(hearth_detection));
  if (!dets.frames) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "detect: out of memory");
    goto done;
  }
  for (size_t i = 0; i < nj; i++) dets.frames[i] = jobs[i].det;
  snprintf(path, sizeof path, "%s/calibration/detections.json", root);
  st = hearth_detections_write(path, &dets, err);
  if (!st && out) *out = dets;
  else hearth_detections_free(&dets);
done:
  if (jobs)
    for (size_t i = 0; i < nj; i++) free(jobs[i].png);
  free(jobs);
  free(fnames);
  free(pnames);
  free(tnames);
  return st;
}

/* ---- OpenCV YAML ------------------------------------------------------------------ */
/* 16 significant digits in scientific notation, built from integers so the
 * locale cannot change the decimal point */
static void yaml_num(FILE *fp, double x) {
  if (!isfinite(x) || x == 0) {
    fputs(x == 0 ? "0." : ".nan", fp);
    return;
  }
  int e = (int)floor(log10(fabs(x)));
  double m = fabs(x) / pow(10.0, e);
  uint64_t v = (uint64_t)llround(m * 1e15);
  if (v >= 10000000000000000ULL) {
    e++;
    v = (uint64_t)llround(fabs(x) / pow(10.0, e) * 1e15);
  } else if (v < 1000000000000000ULL) {
    e--;
    v = (uint64_t)llround(fabs(x) / pow(10.0, e) * 1e15);
  }
  char digits[24];
  snprintf(digits, sizeof digits, "%016llu", (unsigned long long)v);
  fprintf(fp, "%s%c.%se%+03d", x < 0 ? "-" : "", digits[0], digits + 1, e);
}

static void yaml_mat(FILE *fp, const char *name, int rows, int cols, const double *v) {
  fprintf(fp, "%s: !!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: d\n   data: [ ", name, rows,
          cols);
  for (int i = 0; i < rows * cols; i++) {
    if (i) fputs(", ", fp);
    yaml_num(fp, v[i]);
  }
  fputs(" ]\n", fp);
}

void calib_yaml_num(FILE *fp, double x) { yaml_num(fp, x); }

void calib_yaml_mat(FILE *fp, const char *name, int rows, int cols, const double *v) {
  yaml_mat(fp, name, rows, cols, v);
}

static void yaml_cam(FILE *fp, const char *name, const hearth_camera *c) {
  char key[64];
  double K[9];
  hearth_camera_K(c, K);
  fprintf(fp, "%s_width: %d\n%s_height: %d\n", name, c->width, name, c->height);
  snprintf(key, sizeof key, "%s_K", name);
  yaml_mat(fp, key, 3, 3, K);
  snprintf(key, sizeof key, "%s_dist", name);
  yaml_mat(fp, key, 1, 5, c->dist);
}

hearth_status hearth_calib_write_opencv_yaml(const char *path, const hearth_rig *rig,
                                             hearth_err *err) {
  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  FILE *fp = af.fp;
  fputs("%YAML:1.0\n---\n", fp);
  yaml_cam(fp, "rgb", &rig->rgb);
  yaml_cam(fp, "thermal", &rig->thermal);
  yaml_cam(fp, "depth", &rig->depth);
  yaml_mat(fp, "R_thermal_from_rgb", 3, 3, rig->T_thermal_from_rgb.R);
  yaml_mat(fp, "T_thermal_from_rgb", 3, 1, rig->T_thermal_from_rgb.t);
  yaml_mat(fp, "R_depth_from_rgb", 3, 3, rig->T_depth_from_rgb.R);
  yaml_mat(fp, "T_depth_from_rgb", 3, 1, rig->T_depth_from_rgb.t);
  fputs("thermal_rms_px: ", fp);
  yaml_num(fp, rig->thermal_rms_px);
  fputs("\nstereo_rms_px: ", fp);
  yaml_num(fp, rig->stereo_rms_px);
  fputs("\n", fp);
  if (ferror(fp)) return hearth_atomic_fail(&af, err);
  return hearth_atomic_commit(&af, err);
}

/* ---- calibrate ------------------------------------------------------------------- */
static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

static hearth_status write_report(const char *path, const hearth_calib_report *r, hearth_err *err) {
  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  FILE *fp = af.fp;
  char b[64];
  fputs("{\n  \"thermal_frames\": [", fp);
  for (int pass = 0; pass < 2; pass++) {
    size_t n = pass ? r->n_pairs : r->n_thermal;
    const hearth_calib_frame_report *f = pass ? r->pairs : r->thermal;
    if (pass) fputs("],\n  \"stereo_pairs\": [", fp);
    for (size_t i = 0; i < n; i++) {
      fprintf(fp, "%s\n    {\"frame\": \"%s\", \"used\": %s, \"rms_px\": ", i ? "," : "",
              f[i].frame, f[i].used ? "true" : "false");
      if (isfinite(f[i].rms_px) && hearth_format_fixed(b, sizeof b, f[i].rms_px, 5) > 0)
        fputs(b, fp);
      else fputs("null", fp);
      fprintf(fp, ", \"note\": \"%s\"}", f[i].note);
    }
  }
  fputs("],\n  \"thermal_rms_px\": ", fp);
  hearth_format_fixed(b, sizeof b, r->rig.thermal_rms_px, 5);
  fputs(b, fp);
  fputs(",\n  \"stereo_rms_px\": ", fp);
  hearth_format_fixed(b, sizeof b, r->rig.stereo_rms_px, 5);
  fputs(b, fp);
  if (isfinite(r->stereo_rms_nominal_px)) {
    /* against the nominal target: what a calibration that takes the
     * target as drawn reports (the same as stereo_rms_px without the
     * target model) */
    fputs(",\n  \"stereo_rms_nominal_px\": ", fp);
    hearth_format_fixed(b, sizeof b, r->stereo_rms_nominal_px, 5);
    fputs(b, fp);
  }
  fputs("\n}\n", fp);
  if (ferror(fp)) return hearth_atomic_fail(&af, err);
  return hearth_atomic_commit(&af, err);
}

/* The colour camera of factory.json must have the size of the colour
 * captures the detections were made on (their headers are read, not their
 * pixels); detections of a capture that is no longer there are taken as
 * they are. */
static hearth_status check_factory_size(const char *root, const char *pfac,
                                        const hearth_factory_calib *fc,
                                        const hearth_detections *dets, hearth_err *err) {
  const hearth_image_expect header = {.header_only = 1};
  for (size_t i = 0; i < dets->n; i++) {
    const hearth_detection *d = &dets->frames[i];
    if (strcmp(d->camera, "rgb")) continue;
    char path[4096];
    snprintf(path, sizeof path, "%s/calibration/captures/stereo/%s_rgb.jpg", root, d->frame);
    if (!hearth_path_exists(path)) continue;
    hearth_image img = {0};
    hearth_status st = hearth_jpeg_read_expect(path, &header, &img, err);
    if (st) return st;
    if (img.width != (size_t)fc->rgb.width || img.height != (size_t)fc->rgb.height)
      return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                            "%s: the colour camera is %dx%d, but capture %s is %zux%zu", pfac,
                            fc->rgb.width, fc->rgb.height, path, img.width, img.height);
  }
  return HEARTH_OK;
}

/* the default of hearth_calib_opts.hole_radius_m: left at it, the target's
 * hole is used */
static double def_hole_radius(void) {
  hearth_calib_opts d;
  hearth_calib_opts_default(&d);
  return d.hole_radius_m;
}

/* The thermal camera's size, from the first thermal capture present
 * (thermal frames, then the thermal halves of the pairs) of a frame in the
 * detections. */
static hearth_status thermal_capture_size(const char *root, const hearth_detections *dets, int *w,
                                          int *h, hearth_err *err) {
  for (int pass = 0; pass < 2; pass++)
    for (size_t i = 0; i < dets->n; i++) {
      const hearth_detection *d = &dets->frames[i];
      if (strcmp(d->camera, "thermal") || (d->frame[0] == 'p') != pass) continue;
      char path[4096];
      snprintf(path, sizeof path, "%s/calibration/captures/%s/%s%s.csv", root,
               pass ? "stereo" : "thermal", d->frame, pass ? "_thermal" : "");
      if (!hearth_path_exists(path)) continue;
      hearth_csv_opts any = {0, 0};
      hearth_image img = {0};
      hearth_status st = hearth_thermal_read_csv(path, &any, &img, err);
      if (st) return st;
      *w = (int)img.width;
      *h = (int)img.height;
      hearth_image_free(&img);
      return HEARTH_OK;
    }
  return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                        "%s/calibration/captures: no thermal capture of the detected frames (the "
                        "thermal camera's size comes from them)",
                        root);
}

hearth_status hearth_calib_calibrate_release(const char *root, const hearth_calib_opts *o,
                                             hearth_calib_report *rep, hearth_err *err) {
  hearth_calib_opts def;
  if (!o) {
    hearth_calib_opts_default(&def);
    o = &def;
  }
  if (!root || !rep) return hearth_err_set(err, HEARTH_E_ARG, "calibrate: missing argument");
  memset(rep, 0, sizeof *rep);
  rep->stereo_rms_nominal_px = NAN;
  char pdet[4096], pfac[4096], path[4096];
  snprintf(pdet, sizeof pdet, "%s/calibration/detections.json", root);
  snprintf(pfac, sizeof pfac, "%s/calibration/factory.json", root);
  double t0 = hearth_now();
  hearth_detections dets = {0, NULL};
  hearth_factory_calib fc;
  hearth_status st;
  if (!hearth_path_exists(pdet))
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: missing (run `hearth detect` first)", pdet);
  snprintf(path, sizeof path, "%s/calibration/captures/stereo", root);
  if (!hearth_path_exists(pfac) && !hearth_path_exists(path))
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "%s: missing, and no stereo captures: for thermal intrinsics alone "
                          "use `hearth calibrate ROOT --thermal-only`",
                          pfac);
  if ((st = hearth_detections_read(pdet, &dets, err))) return st;
  if ((st = hearth_factory_read(pfac, &fc, err)) ||
      (st = check_factory_size(root, pfac, &fc, &dets, err))) {
    hearth_detections_free(&dets);
    return st;
  }
  /* the target of target.json must be the one detection ordered by */
  hearth_target target;
  snprintf(path, sizeof path, "%s/calibration/target.json", root);
  if ((st = hearth_target_read(path, &target, err))) {
    hearth_detections_free(&dets);
    return st;
  }
  {
    hearth_target tdef;
    const hearth_target *dt = hearth_target_or_default(&dets.target, &tdef);
    if (dt->lattice != target.lattice || dt->rows != target.rows || dt->cols != target.cols ||
        fabs(dt->pitch_m - target.pitch_m) > 1e-9) {
      hearth_detections_free(&dets);
      return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                            "%s: made for a %s %d x %d target of pitch %.6g m, but %s describes "
                            "a %s %d x %d target of pitch %.6g m (run `hearth detect` again)",
                            pdet, hearth_lattice_name(dt->lattice), dt->rows, dt->cols, dt->pitch_m,
                            path, hearth_lattice_name(target.lattice), target.rows, target.cols,
                            target.pitch_m);
    }
  }
  /* the thermal camera's size: that of its captures */
  int tw = 0, th_h = 0;
  if ((st = thermal_capture_size(root, &dets, &tw, &th_h, err))) {
    hearth_detections_free(&dets);
    return st;
  }
  const size_t NH = hearth_target_holes(&target);
  const double hole_r =
      o->hole_radius_m != def_hole_radius() ? o->hole_radius_m : 0.5 * target.hole_diameter_m;
  /* the plate's depth hides part of each hole at a tilt (target.json
   * "thickness_m"); without the wall correction holes are taken as thin */
  const double wall_t = o->wall_correction ? target.thickness_m : 0.0;
  size_t n = dets.n;
  double(*obj)[3] = hearth_alloc_array(NH, sizeof *obj);
  double(*solved)[3] = hearth_alloc_array(NH, sizeof *solved);
  double *bias = hearth_alloc_array(2 * NH, sizeof(double));
  double *raw = hearth_alloc_array(2 * NH, sizeof(double));
  double *img_t = hearth_alloc_array(n * NH * 2, sizeof(double));
  double *img_a = hearth_alloc_array(n * NH * 2, sizeof(double));
  double *img_b = hearth_alloc_array(n * NH * 2, sizeof(double));
  double *img_c = hearth_alloc_array(n * NH * 2, sizeof(double));
  double *frms = hearth_alloc_array(n + 1, sizeof(double));
  double *tmp = hearth_alloc_array(n + 1, sizeof(double));
  int *used = hearth_calloc_array(n + 1, sizeof(int));
  size_t *tidx = hearth_alloc_array(n + 1, sizeof(size_t));
  size_t *pidx = hearth_alloc_array(n + 1, sizeof(size_t));
  hearth_rigid *poses = hearth_alloc_array(n + 1, sizeof(hearth_rigid));
  rep->thermal = hearth_calloc_array(n + 1, sizeof(hearth_calib_frame_report));
  rep->pairs = hearth_calloc_array(n + 1, sizeof(hearth_calib_frame_report));
  if (!obj || !solved || !bias || !raw || !img_t || !img_a || !img_b || !img_c || !frms || !tmp ||
      !used || !tidx || !pidx || !poses || !rep->thermal || !rep->pairs) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "calibrate: out of memory");
    goto done;
  }
  hearth_target_points(&target, obj);
  /* With the target model the calibration runs twice: the frames are
   * chosen (outlier rules), the centroids corrected and the offsets solved
   * first against the nominal target, whose drilling errors inflate every
   * residual alike and so let frames with their own errors through; then
   * all again from the target as solved. The RMS against the nominal
   * target is the first run's. */
  hearth_camera th;
  hearth_rigid Tth;
  double trms = 0, srms = NAN, snom = NAN, crms = NAN;
  for (int run = 0; run < (o->target_points && o->stereo_intrinsics ? 2 : 1); run++) {
    rep->n_thermal = rep->n_pairs = 0;
    /* thermal-only frames (fNNN) */
    size_t nt = 0;
    for (size_t i = 0; i < n; i++) {
      const hearth_detection *d = &dets.frames[i];
      if (d->frame[0] != 'f' || strcmp(d->camera, "thermal")) continue;
      hearth_calib_frame_report *fr = &rep->thermal[rep->n_thermal++];
      snprintf(fr->frame, sizeof fr->frame, "%s", d->frame);
      fr->rms_px = NAN;
      if (!d->found) {
        snprintf(fr->note, sizeof fr->note, "not detected: %.80s", d->reason);
        continue;
      }
      fr->used = 1;
      tidx[nt] = rep->n_thermal - 1;
      memcpy(img_t + nt * NH * 2, d->centres, sizeof(double) * 2 * NH);
      nt++;
    }
    if (nt < 3) {
      st = hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: %zu thermal-only frames with the plate found, at least 3 needed",
                          pdet, nt);
      goto done;
    }
    /* intrinsics; frames far above the median residual are dropped and the
     * solve repeated */
    for (size_t i = 0; i < nt; i++) used[i] = 1;
    for (int round = 0; round < 4; round++) {
      size_t m = 0;
      double *pts = img_b; /* scratch: the used frames packed */
      for (size_t i = 0; i < nt; i++)
        if (used[i]) memcpy(pts + 2 * NH * m++, img_t + 2 * NH * i, sizeof(double) * 2 * NH);
      if ((st = hearth_calib_intrinsics((const double(*)[3])obj, NH, pts, m, tw, th_h, o, &th,
                                        &trms, tmp, NULL, err))) {
        hearth_err_prefix(err, "%s", pdet);
        goto done;
      }
      /* residual of every frame (dropped ones too) at the new intrinsics */
      for (size_t i = 0; i < nt; i++) {
        hearth_rigid T;
        hearth_err e2;
        if (hearth_calib_pose(&th, (const double(*)[3])obj, NH, img_t + 2 * NH * i, &T, &frms[i],
                              &e2))
          frms[i] = INFINITY;
      }
      size_t k = 0;
      for (size_t i = 0; i < nt; i++)
        if (used[i]) tmp[k++] = frms[i];
      qsort(tmp, k, sizeof(double), cmp_double);
      double lim = fmax(o->outlier_factor * tmp[k / 2], o->outlier_min_px);
      int changed = 0;
      for (size_t i = 0; i < nt; i++) {
        int u = frms[i] <= lim;
        if (u != used[i]) changed = 1;
        used[i] = u;
      }
      size_t nu = 0;
      for (size_t i = 0; i < nt; i++) nu += (size_t)used[i];
      if (nu < 3) {
        st = hearth_err_set(err, HEARTH_E_NUMERIC, "%s: fewer than 3 consistent thermal frames",
                            pdet);
        goto done;
      }
      if (!changed) break;
    }
    /* perspective bias: move each used frame's centroids to projected centres
     * with the current intrinsics and poses, re-solve, twice */
    if (o->perspective_correction) {
      for (int pass = 0; pass < 2; pass++) {
        double *pts = img_b;
        size_t m = 0;
        for (size_t i = 0; i < nt; i++)
          if (used[i]) memcpy(pts + 2 * NH * m++, img_t + 2 * NH * i, sizeof(double) * 2 * NH);
        for (size_t k = 0; pass > 0 && k < m; k++) {
          calib_circle_bias(&th, &poses[k], (const double(*)[3])obj, NH, hole_r, wall_t, bias);
          for (size_t q = 0; q < 2 * NH; q++) pts[2 * NH * k + q] -= bias[q];
        }
        if ((st = hearth_calib_intrinsics((const double(*)[3])obj, NH, pts, m, tw, th_h, o, &th,
                                          &trms, tmp, poses, err))) {
          hearth_err_prefix(err, "%s", pdet);
          goto done;
        }
        if (pass == 0) continue;
        for (size_t i = 0, k = 0; i < nt; i++)
          if (used[i]) frms[i] = tmp[k++];
      }
      /* the loop above starts from uncorrected points: one more corrected solve */
      double *pts = img_b;
      size_t m = 0;
      for (size_t i = 0; i < nt; i++)
        if (used[i]) memcpy(pts + 2 * NH * m++, img_t + 2 * NH * i, sizeof(double) * 2 * NH);
      for (size_t k = 0; k < m; k++) {
        calib_circle_bias(&th, &poses[k], (const double(*)[3])obj, NH, hole_r, wall_t, bias);
        for (size_t q = 0; q < 2 * NH; q++) pts[2 * NH * k + q] -= bias[q];
      }
      if ((st = hearth_calib_intrinsics((const double(*)[3])obj, NH, pts, m, tw, th_h, o, &th,
                                        &trms, tmp, poses, err))) {
        hearth_err_prefix(err, "%s", pdet);
        goto done;
      }
      for (size_t i = 0, k = 0; i < nt; i++)
        if (used[i]) frms[i] = tmp[k++];
    }
    /* the used thermal frames as the intrinsics were solved from them */
    size_t nc = 0;
    for (size_t i = 0; i < nt; i++) {
      if (!used[i]) continue;
      /* with the perspective correction img_b holds them packed and corrected */
      const double *src = o->perspective_correction ? img_b + 2 * NH * nc : img_t + 2 * NH * i;
      memcpy(img_c + 2 * NH * nc++, src, sizeof(double) * 2 * NH);
    }
    for (size_t i = 0; i < nt; i++) {
      hearth_calib_frame_report *fr = &rep->thermal[tidx[i]];
      fr->rms_px = frms[i];
      fr->used = used[i];
      if (!used[i]) snprintf(fr->note, sizeof fr->note, "rejected: residual outlier");
    }
    /* stereo pairs: both halves found */
    size_t npair = 0;
    for (size_t i = 0; i < n; i++) {
      const hearth_detection *d = &dets.frames[i];
      if (d->frame[0] != 'p' || strcmp(d->camera, "rgb")) continue;
      const hearth_detection *t = NULL;
      for (size_t k = 0; k < n; k++)
        if (!strcmp(dets.frames[k].frame, d->frame) && !strcmp(dets.frames[k].camera, "thermal"))
          t = &dets.frames[k];
      hearth_calib_frame_report *fr = &rep->pairs[rep->n_pairs++];
      snprintf(fr->frame, sizeof fr->frame, "%s", d->frame);
      fr->rms_px = NAN;
      if (!t) {
        snprintf(fr->note, sizeof fr->note, "no thermal half");
        continue;
      }
      if (!d->found || !t->found) {
        snprintf(fr->note, sizeof fr->note, "not detected (%s): %.60s",
                 !d->found ? "rgb" : "thermal", !d->found ? d->reason : t->reason);
        continue;
      }
      pidx[npair] = rep->n_pairs - 1;
      memcpy(img_a + npair * NH * 2, d->centres, sizeof(double) * 2 * NH);
      memcpy(img_b + npair * NH * 2, t->centres, sizeof(double) * 2 * NH);
      npair++;
    }
    if (npair < 1) {
      st = hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: no stereo pair with the plate found in both cameras", pdet);
      goto done;
    }
    /* perspective bias in both cameras from each camera's own plate pose */
    if (o->perspective_correction) {
      for (size_t i = 0; i < npair; i++) {
        for (int c = 0; c < 2; c++) {
          const hearth_camera *cc = c ? &th : &fc.rgb;
          double *p = (c ? img_b : img_a) + 2 * NH * i;
          memcpy(raw, p, sizeof(double) * 2 * NH);
          for (int pass = 0; pass < 2; pass++) {
            hearth_rigid T;
            hearth_err e2;
            if (hearth_calib_pose(cc, (const double(*)[3])obj, NH, p, &T, NULL, &e2)) break;
            calib_circle_bias(cc, &T, (const double(*)[3])obj, NH, hole_r, wall_t, bias);
            for (size_t q = 0; q < 2 * NH; q++) p[q] = raw[q] - bias[q];
          }
        }
      }
    }
    double nom_rms = NAN;
    crms = NAN;
    if ((st = calib_stereo_joint_times(&fc.rgb, &th, (const double(*)[3])obj, NH, img_a, img_b,
                                       npair, img_c, nc, o, &Tth, &srms, &crms, frms, used, NULL,
                                       &nom_rms, solved, err))) {
      hearth_err_prefix(err, "%s", pdet);
      goto done;
    }
    memcpy(obj, solved, sizeof(double) * 3 * NH);
    for (size_t i = 0; i < npair; i++) {
      hearth_calib_frame_report *fr = &rep->pairs[pidx[i]];
      fr->rms_px = frms[i];
      fr->used = used[i];
      if (!used[i]) snprintf(fr->note, sizeof fr->note, "rejected: residual outlier");
    }
    if (run == 0) snom = nom_rms;
  }
  hearth_rig *rig = &rep->rig;
  rig->rgb = fc.rgb;
  rig->depth = fc.depth;
  rig->T_depth_from_rgb = fc.T_depth_from_rgb;
  rig->thermal = th;
  rig->T_thermal_from_rgb = Tth;
  rig->thermal_rms_px = isfinite(crms) ? crms : trms;
  rig->stereo_rms_px = srms;
  rep->stereo_rms_nominal_px = snom;
  rep->t_calib_s = hearth_now() - t0;
  /* outputs: the extras first, rig.json (what later stages read) last */
  snprintf(path, sizeof path, "%s/calibration/rig_opencv.yaml", root);
  if ((st = hearth_calib_write_opencv_yaml(path, rig, err))) goto done;
  snprintf(path, sizeof path, "%s/calibration/calibration_report.json", root);
  if ((st = write_report(path, rep, err))) goto done;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  st = hearth_rig_write(path, rig, err);
done:
  hearth_detections_free(&dets);
  free(obj);
  free(solved);
  free(bias);
  free(raw);
  free(img_t);
  free(img_a);
  free(img_b);
  free(img_c);
  free(frms);
  free(tmp);
  free(used);
  free(tidx);
  free(pidx);
  free(poses);
  if (st) hearth_calib_report_free(rep);
  return st;
}
