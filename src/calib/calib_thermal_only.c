/* Thermal-only calibration: `detect` and `calibrate --thermal-only` on a
 * root that holds only calibration/captures/thermal (frames of any name
 * and format) and, optionally, the target. Detection tries each frame as
 * it is and negated (holes bright or dark); calibration fits the
 * 5-parameter and the rational lens model, compares them on held-out
 * frames, and writes a thermal-only rig.json, the OpenCV YAML and the
 * report. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "calib/calib_internal.h"
#include "hearth/thermal.h"

#define TO_MAX_FRAMES 4096

/* ---- the frames of captures/thermal ---------------------------------------------- */
/* One frame file: its name in the folder and its frame name in
 * detections.json (the name without its extension, characters other than
 * letters, digits, '_' and '-' as '_', at most HEARTH_NAME_MAX - 1). */
typedef struct to_file {
  char file[256];
  char frame[HEARTH_NAME_MAX];
} to_file;

static int cmp_file(const void *a, const void *b) {
  return strcmp(((const to_file *)a)->file, ((const to_file *)b)->file);
}
static int cmp_frame(const void *a, const void *b) {
  return strcmp(((const to_file *)a)->frame, ((const to_file *)b)->frame);
}

static void frame_name(const char *file, char out[HEARTH_NAME_MAX]) {
  size_t n = strlen(file);
  const char *dot = strrchr(file, '.');
  if (dot && dot != file) n = (size_t)(dot - file);
  if (n > HEARTH_NAME_MAX - 1) n = HEARTH_NAME_MAX - 1;
  for (size_t i = 0; i < n; i++) {
    char c = file[i];
    int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
             c == '_' || c == '-';
    out[i] = ok ? c : '_';
  }
  out[n] = 0;
}

/* every regular file of dir not starting with '.', sorted by name (bytes) */
static hearth_status list_files(const char *dir, to_file **files, size_t *n, hearth_err *err) {
  *files = NULL;
  *n = 0;
  DIR *d = opendir(dir);
  if (!d)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "%s: cannot open the thermal capture folder (a thermal-only root holds "
                          "calibration/captures/thermal)",
                          dir);
  to_file *f = hearth_calloc_array(TO_MAX_FRAMES, sizeof *f);
  if (!f) {
    closedir(d);
    return hearth_err_set(err, HEARTH_E_NOMEM, "detect: out of memory");
  }
  hearth_status st = HEARTH_OK;
  struct dirent *e;
  size_t k = 0;
  while ((e = readdir(d))) {
    if (e->d_name[0] == '.') continue;
    char path[4096];
    struct stat sb;
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    if (stat(path, &sb) || !S_ISREG(sb.st_mode)) continue;
    if (strlen(e->d_name) >= sizeof f[0].file) {
      st = hearth_err_set(err, HEARTH_E_LIMIT, "%s: a file name longer than %zu bytes", path,
                          sizeof f[0].file - 1);
      break;
    }
    if (k >= TO_MAX_FRAMES) {
      st = hearth_err_set(err, HEARTH_E_LIMIT, "%s: more than %d frames", dir, TO_MAX_FRAMES);
      break;
    }
    snprintf(f[k].file, sizeof f[k].file, "%s", e->d_name);
    frame_name(e->d_name, f[k].frame);
    k++;
  }
  closedir(d);
  if (!st && k == 0)
    st = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                        "%s: no thermal frames (expected CSV matrices or PNG/TIFF images)", dir);
  if (st) {
    free(f);
    return st;
  }
  /* two files must not share a frame name (f001.csv and f001.png) */
  qsort(f, k, sizeof *f, cmp_frame);
  for (size_t i = 1; i < k; i++)
    if (!strcmp(f[i].frame, f[i - 1].frame)) {
      st = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "%s: %s and %s would both be frame \"%s\"; rename one", dir,
                          f[i - 1].file, f[i].file, f[i].frame);
      free(f);
      return st;
    }
  qsort(f, k, sizeof *f, cmp_file);
  *files = f;
  *n = k;
  return HEARTH_OK;
}

static const to_file *find_file(const to_file *files, size_t nf, const char *frame) {
  for (size_t k = 0; k < nf; k++)
    if (!strcmp(files[k].frame, frame)) return &files[k];
  return NULL;
}

/* ---- detect -------------------------------------------------------------------------- */
typedef struct to_job {
  char path[4096];
  hearth_detection det;
  size_t width, height;
  hearth_frame_kind kind;
  uint8_t *png;
  size_t png_size;
  hearth_status st;
  hearth_err err;
} to_job;

typedef struct to_ctx {
  to_job *jobs;
  const hearth_detect_job *run;
} to_ctx;

static void to_range(void *vctx, size_t b, size_t e, int ti) {
  to_ctx *c = vctx;
  (void)ti;
  for (size_t i = b; i < e; i++) {
    to_job *j = &c->jobs[i];
    hearth_image img = {0}, neg = {0};
    j->st = hearth_frame_read(j->path, &img, &j->kind, &j->err);
    if (!j->st) {
      j->width = img.width;
      j->height = img.height;
      j->st = hearth_detect_plate_thermal(&img, &c->run->detect, &j->det, &j->err);
    }
    /* holes darker than the plate: the same detection on the negated frame */
    if (!j->st && !j->det.found &&
        !(j->st = hearth_image_alloc(&neg, img.width, img.height, 1, HEARTH_PIX_F32, &j->err))) {
      const float *p = img.data;
      float *q = neg.data;
      for (size_t k = 0; k < img.width * img.height; k++) q[k] = -p[k];
      hearth_detection d2 = j->det;
      j->st = hearth_detect_plate_thermal(&neg, &c->run->detect, &d2, &j->err);
      if (!j->st && d2.found) j->det = d2;
    }
    if (!j->st && c->run->overlays)
      j->st = calib_overlay_encode(&img, 1, &c->run->detect.target, &j->det, &j->png, &j->png_size,
                                   &j->err);
    hearth_image_free(&img);
    hearth_image_free(&neg);
    if (j->st && !strstr(j->err.msg, j->path)) hearth_err_prefix(&j->err, "%s", j->path);
  }
}

hearth_status calib_detect_thermal_only(const char *root, const hearth_detect_job *run,
                                        hearth_detections *out, hearth_err *err) {
  char dir[4096], path[4096];
  /* the target of calibration/target.json (absent: the paper's plate) */
  hearth_detect_job job = *run;
  snprintf(path, sizeof path, "%s/calibration/target.json", root);
  hearth_status st = hearth_target_read(path, &job.detect.target, err);
  if (st) return st;
  run = &job;
  snprintf(dir, sizeof dir, "%s/calibration/captures/thermal", root);
  to_file *files = NULL;
  size_t n = 0;
  if ((st = list_files(dir, &files, &n, err))) return st;
  to_job *jobs = hearth_calloc_array(n, sizeof *jobs);
  hearth_detections dets = {0, NULL};
  if (!jobs) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "detect: out of memory");
    goto done;
  }
  for (size_t i = 0; i < n; i++) {
    snprintf(jobs[i].path, sizeof jobs[i].path, "%s/%s", dir, files[i].file);
    snprintf(jobs[i].det.frame, sizeof jobs[i].det.frame, "%s", files[i].frame);
    snprintf(jobs[i].det.camera, sizeof jobs[i].det.camera, "thermal");
  }
  to_ctx ctx = {jobs, run};
  int threads = run->threads > 0 ? run->threads : hearth_default_threads();
  if ((st = hearth_parallel_for(n, threads, to_range, &ctx))) {
    hearth_err_set(err, st, "detect: cannot start worker threads");
    goto done;
  }
  for (size_t i = 0; i < n; i++)
    if (jobs[i].st) {
      st = jobs[i].st;
      if (err) *err = jobs[i].err;
      goto done;
    }
  /* one camera: every frame has the first frame's size */
  for (size_t i = 1; i < n; i++)
    if (jobs[i].width != jobs[0].width || jobs[i].height != jobs[0].height) {
      st = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "%s: %zux%zu, but %s (the first frame) is %zux%zu: one camera's frames "
                          "have one size",
                          jobs[i].path, jobs[i].width, jobs[i].height, jobs[0].path, jobs[0].width,
                          jobs[0].height);
      goto done;
    }
  if (run->overlays) {
    snprintf(path, sizeof path, "%s/calibration/overlays", root);
    if ((st = hearth_mkdirs(path, err))) goto done;
    for (size_t i = 0; i < n; i++) {
      snprintf(path, sizeof path, "%s/calibration/overlays/%s_thermal.png", root,
               jobs[i].det.frame);
      if ((st = hearth_write_file_atomic(path, jobs[i].png, jobs[i].png_size, err))) goto done;
    }
  }
  dets.n = n;
  dets.frames = hearth_calloc_array(n, sizeof(hearth_detection));
  if (!dets.frames) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "detect: out of memory");
    goto done;
  }
  for (size_t i = 0; i < n; i++) dets.frames[i] = jobs[i].det;
  dets.target = job.detect.target;
  snprintf(path, sizeof path, "%s/calibration/detections.json", root);
  if ((st = hearth_detections_write(path, &dets, err))) goto done;
  if (out) {
    *out = dets;
    dets.frames = NULL;
  }
done:
  hearth_detections_free(&dets);
  if (jobs)
    for (size_t i = 0; i < n; i++) free(jobs[i].png);
  free(jobs);
  free(files);
  return st;
}

/* ---- fitting ------------------------------------------------------------------------- */
static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* The problem: nt frames of np centres (img), the target, the image size. */
typedef struct to_problem {
  const double (*obj)[3];
  size_t np; /* holes of the target */
  const double *img;
  size_t nt;
  int width, height;
  const hearth_calib_opts *o;
} to_problem;

/* One model's robust fit: used frames, their perspective-corrected
 * centres (pts, packed in frame order of the used ones), the camera and
 * per-frame RMS (all frames, the rejected ones at the final camera). */
typedef struct to_fit {
  hearth_camera cam;
  double rms;
  double *frms; /* nt */
  int *used;    /* nt */
  double *pts;  /* nt * np * 2: the used frames' corrected centres, packed */
  size_t m;     /* used frames */
} to_fit;

static void pack_used(const to_problem *p, const int *used, double *pts, size_t *m) {
  *m = 0;
  for (size_t i = 0; i < p->nt; i++)
    if (used[i])
      memcpy(pts + 2 * p->np * (*m)++, p->img + 2 * p->np * i, sizeof(double) * 2 * p->np);
}

static hearth_status solve(const to_problem *p, hearth_lens_model model, const double *pts,
                           size_t m, hearth_camera *cam, double *rms, double *frms,
                           hearth_rigid *poses, hearth_err *err) {
  hearth_calib_opts o = *p->o;
  o.lens_model = model;
  return hearth_calib_intrinsics(p->obj, p->np, pts, m, p->width, p->height, &o, cam, rms, frms,
                                 poses, err);
}

/* outlier rounds (frames far above the median residual dropped, the solve
 * repeated), then perspective correction of the centroids (moved to the
 * projected hole centres with the current poses, re-solved, three times) */
static hearth_status robust_fit(const to_problem *p, hearth_lens_model model, to_fit *f,
                                hearth_err *err) {
  size_t nt = p->nt;
  double *tmp = hearth_alloc_array(nt, sizeof(double));
  hearth_rigid *poses = hearth_alloc_array(nt, sizeof(hearth_rigid));
  hearth_status st = HEARTH_OK;
  if (!tmp || !poses) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "calibrate: out of memory");
    goto done;
  }
  for (size_t i = 0; i < nt; i++) f->used[i] = 1;
  for (int round = 0; round < 4; round++) {
    pack_used(p, f->used, f->pts, &f->m);
    if ((st = solve(p, model, f->pts, f->m, &f->cam, &f->rms, NULL, NULL, err))) goto done;
    for (size_t i = 0; i < nt; i++) {
      hearth_rigid T;
      hearth_err e2;
      if (hearth_calib_pose(&f->cam, p->obj, p->np, p->img + 2 * p->np * i, &T, &f->frms[i], &e2))
        f->frms[i] = INFINITY;
    }
    size_t k = 0;
    for (size_t i = 0; i < nt; i++)
      if (f->used[i]) tmp[k++] = f->frms[i];
    qsort(tmp, k, sizeof(double), cmp_double);
    double lim = fmax(p->o->outlier_factor * tmp[k / 2], p->o->outlier_min_px);
    int changed = 0;
    size_t nu = 0;
    for (size_t i = 0; i < nt; i++) {
      int u = f->frms[i] <= lim;
      changed |= u != f->used[i];
      f->used[i] = u;
      nu += (size_t)u;
    }
    if (nu < 3) {
      st = hearth_err_set(err, HEARTH_E_NUMERIC, "fewer than 3 consistent thermal frames");
      goto done;
    }
    if (!changed) break;
  }
  pack_used(p, f->used, f->pts, &f->m);
  if ((st = solve(p, model, f->pts, f->m, &f->cam, &f->rms, tmp, poses, err))) goto done;
  for (int pass = 0; p->o->perspective_correction && pass < 3; pass++) {
    pack_used(p, f->used, f->pts, &f->m);
    for (size_t k = 0; k < f->m; k++) {
      double bias[2 * HEARTH_TARGET_MAX_HOLES];
      calib_circle_bias(&f->cam, &poses[k], p->obj, p->np, p->o->hole_radius_m, 0.0, bias);
      for (size_t q = 0; q < 2 * p->np; q++) f->pts[2 * p->np * k + q] -= bias[q];
    }
    if ((st = solve(p, model, f->pts, f->m, &f->cam, &f->rms, tmp, poses, err))) goto done;
  }
  for (size_t i = 0, k = 0; i < nt; i++)
    if (f->used[i]) f->frms[i] = tmp[k++];
done:
  free(tmp);
  free(poses);
  return st;
}

/* k-fold held-out RMS of a model on the fit's corrected centres: fold j
 * holds the used frames at positions j, j + k, ...; each is predicted by
 * the calibration on the others (its own pose fitted) */
static hearth_status heldout(const to_problem *p, hearth_lens_model model, const to_fit *f,
                             int folds, double *rms, hearth_err *err) {
  size_t m = f->m;
  double *train = hearth_alloc_array(m * 2 * p->np, sizeof(double));
  if (!train) return hearth_err_set(err, HEARTH_E_NOMEM, "calibrate: out of memory");
  double sum = 0;
  size_t count = 0;
  hearth_status st = HEARTH_OK;
  for (int j = 0; j < folds && !st; j++) {
    size_t mt = 0;
    for (size_t i = 0; i < m; i++)
      if ((int)(i % (size_t)folds) != j)
        memcpy(train + 2 * p->np * mt++, f->pts + 2 * p->np * i, sizeof(double) * 2 * p->np);
    hearth_camera cam;
    if ((st = solve(p, model, train, mt, &cam, NULL, NULL, NULL, err))) {
      hearth_err_prefix(err, "held-out fold %d of %d", j + 1, folds);
      break;
    }
    for (size_t i = (size_t)j; i < m; i += (size_t)folds) {
      hearth_rigid T;
      double r;
      hearth_err e2;
      /* a frame the model cannot even place is predicted infinitely badly */
      if (hearth_calib_pose(&cam, p->obj, p->np, f->pts + 2 * p->np * i, &T, &r, &e2)) r = INFINITY;
      sum += r * r * (double)p->np;
      count += p->np;
    }
  }
  free(train);
  if (!st) *rms = sqrt(sum / (double)count);
  return st;
}

/* ---- outputs ------------------------------------------------------------------------- */
static void json_num(FILE *fp, double x, int decimals) {
  char b[64];
  if (isfinite(x) && hearth_format_fixed(b, sizeof b, x, decimals) > 0) fputs(b, fp);
  else fputs("null", fp);
}

static void json_cam(FILE *fp, const hearth_camera *c) {
  fprintf(fp, "{\"width\": %d, \"height\": %d, \"fx\": ", c->width, c->height);
  json_num(fp, c->fx, 6);
  fputs(", \"fy\": ", fp);
  json_num(fp, c->fy, 6);
  fputs(", \"cx\": ", fp);
  json_num(fp, c->cx, 6);
  fputs(", \"cy\": ", fp);
  json_num(fp, c->cy, 6);
  fputs(", \"dist\": [", fp);
  for (int k = 0; k < hearth_lens_n_coeffs(c->model); k++) {
    if (k) fputs(", ", fp);
    json_num(fp, c->dist[k], 9);
  }
  fputs("]}", fp);
}

static hearth_status write_report(const char *path, const hearth_calib_report *r,
                                  const to_file *files, size_t n_files, hearth_err *err) {
  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  FILE *fp = af.fp;
  const hearth_lens_choice *lc = &r->lens;
  fputs("{\n  \"thermal_only\": true,\n  \"thermal_frames\": [", fp);
  for (size_t i = 0; i < r->n_thermal; i++) {
    const hearth_calib_frame_report *f = &r->thermal[i];
    const to_file *tf = find_file(files, n_files, f->frame);
    const char *file = tf ? tf->file : "";
    fprintf(fp, "%s\n    {\"frame\": \"%s\", \"file\": \"", i ? "," : "", f->frame);
    for (const char *c = file; *c; c++) {
      if (*c == '"' || *c == '\\') fputc('\\', fp);
      if ((unsigned char)*c < 0x20) fprintf(fp, "\\u%04x", (unsigned char)*c);
      else fputc(*c, fp);
    }
    fprintf(fp, "\", \"used\": %s, \"rms_px\": ", f->used ? "true" : "false");
    json_num(fp, f->rms_px, 5);
    fprintf(fp, ", \"note\": \"%s\"}", f->note);
  }
  fputs("],\n  \"lens_models\": [", fp);
  for (int m = 0; m < 2; m++) {
    const hearth_lens_fit *lf = &lc->fit[m];
    fprintf(fp, "%s\n    {\"model\": \"%s\", \"camera\": ", m ? "," : "",
            hearth_lens_name((hearth_lens_model)m));
    json_cam(fp, &lf->cam);
    fputs(", \"train_rms_px\": ", fp);
    json_num(fp, lf->train_rms_px, 5);
    fputs(", \"heldout_rms_px\": ", fp);
    json_num(fp, lf->heldout_rms_px, 5);
    fputs("}", fp);
  }
  fprintf(fp, "],\n  \"lens_model\": \"%s\",\n  \"lens_choice\": {\"folds\": %d, \"forced\": %s, ",
          hearth_lens_name(lc->chosen), lc->folds, lc->forced ? "true" : "false");
  fputs("\"margin_rel\": ", fp);
  json_num(fp, HEARTH_LENS_MARGIN_REL, 3);
  fputs(", \"margin_px\": ", fp);
  json_num(fp, HEARTH_LENS_MARGIN_PX, 3);
  fprintf(fp, ", \"reason\": \"%s\"},\n  \"thermal_rms_px\": ", lc->reason);
  json_num(fp, r->rig.thermal_rms_px, 5);
  fputs("\n}\n", fp);
  if (ferror(fp)) return hearth_atomic_fail(&af, err);
  return hearth_atomic_commit(&af, err);
}

/* OpenCV's own names (its calibration sample's): camera_matrix and
 * distortion_coefficients (1x5 or 1x8) */
static hearth_status write_yaml(const char *path, const hearth_camera *c, double rms,
                                hearth_err *err) {
  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  FILE *fp = af.fp;
  double K[9];
  hearth_camera_K(c, K);
  fprintf(fp, "%%YAML:1.0\n---\nimage_width: %d\nimage_height: %d\n", c->width, c->height);
  calib_yaml_mat(fp, "camera_matrix", 3, 3, K);
  calib_yaml_mat(fp, "distortion_coefficients", 1, hearth_lens_n_coeffs(c->model), c->dist);
  fprintf(fp, "lens_model: \"%s\"\nthermal_rms_px: ", hearth_lens_name(c->model));
  calib_yaml_num(fp, rms);
  fputs("\n", fp);
  if (ferror(fp)) return hearth_atomic_fail(&af, err);
  return hearth_atomic_commit(&af, err);
}

/* ---- calibrate --------------------------------------------------------------------- */
/* the frames' size, from every found frame (all must agree); with stereo
 * captures beside (a full root), thermal detections without a file in
 * captures/thermal are the stereo pairs' halves and not used */
static hearth_status frames_size(const char *dir, const hearth_detections *dets,
                                 const to_file *files, size_t nf, int stereo, int *w, int *h,
                                 hearth_err *err) {
  char path[4096], first[4096] = "";
  *w = *h = 0;
  for (size_t i = 0; i < dets->n; i++) {
    const hearth_detection *d = &dets->frames[i];
    if (!d->found || strcmp(d->camera, "thermal")) continue;
    const to_file *f = find_file(files, nf, d->frame);
    if (!f && stereo) continue;
    if (!f)
      return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                            "%s: no file for frame \"%s\" of detections.json (run `hearth "
                            "detect` again)",
                            dir, d->frame);
    snprintf(path, sizeof path, "%s/%s", dir, f->file);
    hearth_image img = {0};
    hearth_status st = hearth_frame_read(path, &img, NULL, err);
    if (st) return st;
    int iw = (int)img.width, ih = (int)img.height;
    hearth_image_free(&img);
    if (!*w) {
      *w = iw;
      *h = ih;
      snprintf(first, sizeof first, "%s", path);
    } else if (iw != *w || ih != *h) {
      return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                            "%s: %dx%d, but %s (the first frame) is %dx%d: one camera's frames "
                            "have one size",
                            path, iw, ih, first, *w, *h);
    }
  }
  return HEARTH_OK;
}

static void fit_free(to_fit *f) {
  free(f->frms);
  free(f->used);
  free(f->pts);
}

hearth_status hearth_calib_thermal_only_release(const char *root, const hearth_calib_opts *o,
                                                int force_model, hearth_calib_report *rep,
                                                hearth_err *err) {
  hearth_calib_opts def;
  if (!o) {
    hearth_calib_opts_default(&def);
    o = &def;
  }
  if (!root || !rep) return hearth_err_set(err, HEARTH_E_ARG, "calibrate: missing argument");
  if (force_model > HEARTH_LENS_RATIONAL8)
    return hearth_err_set(err, HEARTH_E_ARG, "calibrate: unknown lens model %d", force_model);
  memset(rep, 0, sizeof *rep);
  rep->stereo_rms_nominal_px = NAN;
  char pdet[4096], dir[4096], path[4096];
  snprintf(pdet, sizeof pdet, "%s/calibration/detections.json", root);
  snprintf(dir, sizeof dir, "%s/calibration/captures/thermal", root);
  double t0 = hearth_now();
  hearth_detections dets = {0, NULL};
  to_file *files = NULL;
  size_t nf = 0;
  hearth_status st;
  to_fit fits[2];
  memset(fits, 0, sizeof fits);
  static const size_t MAXH = HEARTH_TARGET_MAX_HOLES;
  double(*obj)[3] = hearth_alloc_array(MAXH, sizeof(*obj));
  hearth_target target;
  size_t nh = 0;
  double *img = NULL;
  size_t *tidx = NULL;
  if (!hearth_path_exists(pdet))
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: missing (run `hearth detect` first)", pdet);
  if (!obj) return hearth_err_set(err, HEARTH_E_NOMEM, "calibrate: out of memory");
  if ((st = hearth_detections_read(pdet, &dets, err))) {
    free(obj);
    return st;
  }
  /* the target of target.json (absent: the paper's plate), the one detection ordered by */
  snprintf(path, sizeof path, "%s/calibration/target.json", root);
  if ((st = hearth_target_read(path, &target, err))) goto done;
  {
    hearth_target tdef;
    const hearth_target *dt = hearth_target_or_default(&dets.target, &tdef);
    if (dt->lattice != target.lattice || dt->rows != target.rows || dt->cols != target.cols ||
        fabs(dt->pitch_m - target.pitch_m) > 1e-9) {
      st = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "%s: made for a %s %d x %d target, but %s describes a %s %d x %d "
                          "target (run `hearth detect` again)",
                          pdet, hearth_lattice_name(dt->lattice), dt->rows, dt->cols, path,
                          hearth_lattice_name(target.lattice), target.rows, target.cols);
      goto done;
    }
  }
  nh = hearth_target_holes(&target);
  hearth_target_points(&target, obj);
  hearth_calib_opts ot = *o, odef;
  hearth_calib_opts_default(&odef);
  /* left at its default, the hole radius is the target's */
  if (ot.hole_radius_m == odef.hole_radius_m) ot.hole_radius_m = 0.5 * target.hole_diameter_m;
  o = &ot;
  int width, height;
  snprintf(path, sizeof path, "%s/calibration/captures/stereo", root);
  int stereo = hearth_path_exists(path);
  if ((st = list_files(dir, &files, &nf, err)) ||
      (st = frames_size(dir, &dets, files, nf, stereo, &width, &height, err)))
    goto done;
  size_t n = dets.n;
  img = hearth_alloc_array(n * nh * 2 + 1, sizeof(double));
  tidx = hearth_alloc_array(n + 1, sizeof(size_t));
  rep->thermal = hearth_calloc_array(n + 1, sizeof(hearth_calib_frame_report));
  if (!img || !tidx || !rep->thermal) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "calibrate: out of memory");
    goto done;
  }
  size_t nt = 0;
  for (size_t i = 0; i < n; i++) {
    const hearth_detection *d = &dets.frames[i];
    if (strcmp(d->camera, "thermal") || (stereo && !find_file(files, nf, d->frame))) continue;
    hearth_calib_frame_report *fr = &rep->thermal[rep->n_thermal++];
    snprintf(fr->frame, sizeof fr->frame, "%s", d->frame);
    fr->rms_px = NAN;
    if (!d->found) {
      snprintf(fr->note, sizeof fr->note, "not detected: %.80s", d->reason);
      continue;
    }
    fr->used = 1;
    tidx[nt] = rep->n_thermal - 1;
    memcpy(img + nt * nh * 2, d->centres, sizeof(double) * 2 * nh);
    nt++;
  }
  if (nt < 3) {
    st = hearth_err_set(err, HEARTH_E_SIZE,
                        "%s: the plate was found in %zu of %zu thermal frames; at least 3 needed "
                        "(%d or more to compare the lens models)",
                        pdet, nt, rep->n_thermal, HEARTH_LENS_MIN_FRAMES);
    goto done;
  }
  to_problem prob = {(const double(*)[3])obj, nh, img, nt, width, height, o};
  hearth_lens_choice *lc = &rep->lens;
  for (int m = 0; m < 2; m++) {
    fits[m].frms = hearth_alloc_array(nt, sizeof(double));
    fits[m].used = hearth_calloc_array(nt, sizeof(int));
    fits[m].pts = hearth_alloc_array(nt * nh * 2, sizeof(double));
    if (!fits[m].frms || !fits[m].used || !fits[m].pts) {
      st = hearth_err_set(err, HEARTH_E_NOMEM, "calibrate: out of memory");
      goto done;
    }
    if ((st = robust_fit(&prob, (hearth_lens_model)m, &fits[m], err))) {
      hearth_err_prefix(err, "%s: %s model", pdet, hearth_lens_name((hearth_lens_model)m));
      goto done;
    }
    lc->fit[m].cam = fits[m].cam;
    lc->fit[m].train_rms_px = fits[m].rms;
    lc->fit[m].heldout_rms_px = NAN;
  }
  /* the comparison on the frames both fits kept */
  size_t m_used = fits[0].m < fits[1].m ? fits[0].m : fits[1].m;
  lc->chosen = HEARTH_LENS_BROWN5;
  if (m_used >= HEARTH_LENS_MIN_FRAMES) {
    lc->folds = m_used >= 10 ? 5 : (int)(m_used / 2);
    for (int m = 0; m < 2; m++)
      if ((st = heldout(&prob, (hearth_lens_model)m, &fits[m], lc->folds,
                        &lc->fit[m].heldout_rms_px, err))) {
        hearth_err_prefix(err, "%s: %s model", pdet, hearth_lens_name((hearth_lens_model)m));
        goto done;
      }
    double h5 = lc->fit[0].heldout_rms_px, h8 = lc->fit[1].heldout_rms_px;
    int better = h8 <= (1.0 - HEARTH_LENS_MARGIN_REL) * h5 && h5 - h8 >= HEARTH_LENS_MARGIN_PX;
    lc->chosen = better ? HEARTH_LENS_RATIONAL8 : HEARTH_LENS_BROWN5;
    snprintf(lc->reason, sizeof lc->reason,
             "held-out RMS %.4f px (rational8) vs %.4f px (brown5) over %d folds: %s", h8, h5,
             lc->folds,
             better ? "the rational model predicts better by the margin"
                    : "the rational model does not predict better by the margin");
  } else {
    snprintf(lc->reason, sizeof lc->reason,
             "%zu used frames: the held-out comparison needs %d; the 5-parameter model is used",
             m_used, HEARTH_LENS_MIN_FRAMES);
  }
  if (force_model >= 0) {
    lc->forced = 1;
    lc->chosen = (hearth_lens_model)force_model;
    size_t k = strlen(lc->reason);
    snprintf(lc->reason + k, sizeof lc->reason - k, "; %s forced by the caller",
             hearth_lens_name(lc->chosen));
  }
  const to_fit *f = &fits[lc->chosen];
  for (size_t i = 0; i < nt; i++) {
    hearth_calib_frame_report *fr = &rep->thermal[tidx[i]];
    fr->rms_px = f->frms[i];
    fr->used = f->used[i];
    if (!f->used[i]) snprintf(fr->note, sizeof fr->note, "rejected: residual outlier");
  }
  hearth_rig *rig = &rep->rig;
  rig->thermal_only = 1;
  rig->thermal = f->cam;
  rig->thermal_rms_px = f->rms;
  rep->t_calib_s = hearth_now() - t0;
  /* outputs: the extras first, rig.json (what later stages read) last */
  snprintf(path, sizeof path, "%s/calibration/rig_opencv.yaml", root);
  if ((st = write_yaml(path, &rig->thermal, rig->thermal_rms_px, err))) goto done;
  snprintf(path, sizeof path, "%s/calibration/calibration_report.json", root);
  if ((st = write_report(path, rep, files, nf, err))) goto done;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  st = hearth_rig_write(path, rig, err);
done:
  hearth_detections_free(&dets);
  free(files);
  free(img);
  free(tidx);
  fit_free(&fits[0]);
  fit_free(&fits[1]);
  free(obj);
  if (st) hearth_calib_report_free(rep);
  return st;
}
