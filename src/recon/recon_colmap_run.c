/* hearth recon --poses colmap: an instance's colour views through Debian's
 * `colmap` program (feature_extractor, exhaustive_matcher, mapper) and the
 * import of its model. The workspace holds images/<state>/<view>.jpg
 * (links to raw/), masks/<state>/<view>.jpg.png (from the cut-outs: COLMAP
 * ignores features where the mask is 0), database.db, sparse/<k>/ and one
 * log per step in logs/. */
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hearth/image.h"
#include "recon/recon_internal.h"

#define RUN_MAX_MODELS 64

typedef struct run_ctx {
  const hearth_colmap_job *job;
  char inst[4096], work[4096], images[4096], masks[4096], db[4096], sparse[4096], logs[4096];
  const char *program;
  int threads;
  size_t n_views;
  hearth_err *err;
} run_ctx;

/* buf = a/b; buf may be a */
static hearth_status join(char *buf, const char *a, const char *b, hearth_err *err) {
  char tmp[4096];
  if (hearth_path_join(tmp, sizeof tmp, a, b))
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s/%s: path too long", a, b);
  memcpy(buf, tmp, strlen(tmp) + 1);
  return HEARTH_OK;
}

/* ---- the workspace ------------------------------------------------------------------- */
/* 8-bit mask (255 object, 0 background) of a cut-out: alpha of RGBA or
 * gray+alpha, else any non-zero sample */
static hearth_status write_mask(const char *cutout, const char *mask, size_t want_w, size_t want_h,
                                hearth_err *err) {
  hearth_image img, m;
  hearth_status s = hearth_png_read(cutout, &img, err);
  if (s) return s;
  if (img.width != want_w || img.height != want_h) {
    s = hearth_err_set(err, HEARTH_E_SIZE, "%s: %zux%zu, but its colour image is %zux%zu", cutout,
                       img.width, img.height, want_w, want_h);
    hearth_image_free(&img);
    return s;
  }
  s = hearth_image_alloc(&m, img.width, img.height, 1, HEARTH_PIX_U8, err);
  if (s) {
    hearth_image_free(&img);
    return s;
  }
  size_t np = img.width * img.height, bps = (size_t)img.type;
  int ch = img.channels, alpha = ch == 2 || ch == 4;
  const uint8_t *src = img.data;
  uint8_t *dst = m.data;
  for (size_t i = 0; i < np; i++) {
    int on = 0;
    for (int c = alpha ? ch - 1 : 0; c < ch && !on; c++)
      for (size_t b = 0; b < bps; b++) on |= src[(i * (size_t)ch + (size_t)c) * bps + b] != 0;
    dst[i] = on ? 255 : 0;
  }
  s = hearth_png_write(mask, &m, err);
  hearth_image_free(&img);
  hearth_image_free(&m);
  return s;
}

/* the size of a colour image without decoding it (JPEG SOF or PNG IHDR) */
static int image_size(const char *path, size_t *w, size_t *h) {
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  uint8_t b[32];
  size_t n = fread(b, 1, 24, f);
  int ok = -1;
  if (n >= 24 && !memcmp(b, "\x89PNG", 4)) {
    *w = (size_t)b[16] << 24 | (size_t)b[17] << 16 | (size_t)b[18] << 8 | b[19];
    *h = (size_t)b[20] << 24 | (size_t)b[21] << 16 | (size_t)b[22] << 8 | b[23];
    ok = 0;
  } else if (n >= 4 && b[0] == 0xFF && b[1] == 0xD8) {
    fseek(f, 2, SEEK_SET);
    for (;;) {
      int c = fgetc(f);
      while (c == 0xFF) c = fgetc(f);
      if (c == EOF) break;
      uint8_t l[2];
      if (fread(l, 1, 2, f) != 2) break;
      size_t len = (size_t)l[0] << 8 | l[1];
      if ((c >= 0xC0 && c <= 0xCF) && c != 0xC4 && c != 0xC8 && c != 0xCC) {
        uint8_t sof[5];
        if (fread(sof, 1, 5, f) == 5) {
          *h = (size_t)sof[1] << 8 | sof[2];
          *w = (size_t)sof[3] << 8 | sof[4];
          ok = 0;
        }
        break;
      }
      if (len < 2 || fseek(f, (long)len - 2, SEEK_CUR)) break;
    }
  }
  fclose(f);
  return ok;
}

static hearth_status prepare_state(run_ctx *r, const char *state) {
  hearth_err *err = r->err;
  char raw[4096], mpath[4096], dir_img[4096], dir_mask[4096];
  hearth_status s;
  if ((s = join(raw, r->inst, "raw", err)) || (s = join(raw, raw, state, err)) ||
      (s = join(mpath, raw, "manifest.json", err)))
    return s;
  hearth_manifest man;
  if ((s = hearth_manifest_read(mpath, &man, err))) return s;
  if ((s = join(dir_img, r->images, state, err)) || (s = join(dir_mask, r->masks, state, err)) ||
      (s = hearth_mkdirs(dir_img, err)) ||
      (!r->job->no_masks && (s = hearth_mkdirs(dir_mask, err)))) {
    hearth_manifest_free(&man);
    return s;
  }
  for (size_t i = 0; i < man.n_views && !s; i++) {
    const hearth_view_files *v = &man.views[i];
    char rgb[4096], abs[PATH_MAX], link[4096], name[256];
    if ((s = join(rgb, raw, v->rgb, err))) break;
    if (!realpath(rgb, abs)) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s (view %s of %s): %s", rgb, v->view, state,
                         strerror(errno));
      break;
    }
    const char *dot = strrchr(v->rgb, '.'), *slash = strrchr(v->rgb, '/');
    const char *ext = dot && (!slash || dot > slash) ? dot : "";
    snprintf(name, sizeof name, "%s%s", v->view, ext);
    if ((s = join(link, dir_img, name, err))) break;
    unlink(link);
    if (symlink(abs, link) != 0) {
      s = hearth_err_set(err, HEARTH_E_IO, "%s: cannot link to %s: %s", link, abs, strerror(errno));
      break;
    }
    if (!r->job->no_masks) {
      char cut[4096], mask[4096], mname[300];
      size_t w = 0, h = 0;
      if (image_size(abs, &w, &h)) {
        s = hearth_err_set(err, HEARTH_E_PARSE,
                           "%s: cannot read the image size (JPEG or PNG expected)", rgb);
        break;
      }
      snprintf(mname, sizeof mname, "%s.png", name);
      if ((s = join(cut, raw, v->cutout, err)) || (s = join(mask, dir_mask, mname, err)) ||
          (s = write_mask(cut, mask, w, h, err)))
        break;
    }
    r->n_views++;
  }
  hearth_manifest_free(&man);
  return s;
}

/* remove what an earlier run left in a kept workspace (only hearth's names) */
static hearth_status clear_workspace(run_ctx *r) {
  static const char *const k_names[] = {"database.db", "database.db-shm", "database.db-wal",
                                        "images",      "masks",           "sparse",
                                        "logs"};
  for (size_t i = 0; i < sizeof k_names / sizeof k_names[0]; i++) {
    char p[4096];
    hearth_status s = join(p, r->work, k_names[i], r->err);
    if (s) return s;
    if (hearth_path_exists(p) && (s = hearth_remove_tree(p, r->err))) return s;
  }
  return HEARTH_OK;
}

/* ---- the steps ---------------------------------------------------------------------------- */
typedef enum step_kind { STEP_EXTRACT, STEP_MATCH, STEP_MAP } step_kind;

typedef struct step_progress {
  step_kind kind;
  hearth_progress p;
  int no_pair; /* the mapper found no initial pair */
} step_progress;

static void on_line(void *ctx, const char *line) {
  step_progress *sp = ctx;
  unsigned a, b, c;
  if (sp->kind == STEP_EXTRACT && sscanf(line, "Processed file [%u/%u]", &a, &b) == 2) {
    if (a > sp->p.done) hearth_progress_step(&sp->p, a - sp->p.done);
  } else if (sp->kind == STEP_MATCH &&
             sscanf(line, "Matching block [%u/%u, %u/", &a, &b, &c) == 3) {
    sp->p.total = (size_t)b * b;
    hearth_progress_step(&sp->p, 1);
  } else if (sp->kind == STEP_MAP) {
    if (sscanf(line, "Registering image #%u (%u)", &a, &b) == 2 && b > sp->p.done)
      hearth_progress_step(&sp->p, b - sp->p.done);
    if (strstr(line, "No good initial image pair found")) sp->no_pair = 1;
  }
}

static hearth_status run_step(run_ctx *r, step_kind kind, const char *step, const char *const *argv,
                              double *seconds) {
  char label[96], log[4096], file[64];
  snprintf(label, sizeof label, "colmap %s", step);
  snprintf(file, sizeof file, "%s.log", step);
  hearth_status s = join(log, r->logs, file, r->err);
  if (s) return s;
  step_progress sp;
  memset(&sp, 0, sizeof sp);
  sp.kind = kind;
  hearth_progress_begin(&sp.p, label, kind == STEP_MATCH ? 1 : r->n_views, r->job->quiet);
  double t0 = hearth_now();
  s = hearth_exec(label, argv, log, on_line, &sp, r->err);
  *seconds = hearth_now() - t0;
  if (kind == STEP_MAP) {
    /* the progress counted the largest model while it grew; the model
     * imported says how many views it holds */
    if (!r->job->quiet)
      fprintf(stderr, "%s%s: done (%.1fs)\n", sp.p.is_tty ? "\n" : "", label, *seconds);
  } else if (!s && (sp.p.is_tty || sp.p.done < sp.p.total)) {
    hearth_progress_end(&sp.p); /* a plain line at 100 % is there already */
  } else if (s && sp.p.is_tty && !r->job->quiet) {
    fputc('\n', stderr);
  }
  if (s && kind == STEP_MAP && sp.no_pair)
    return hearth_err_set(
        r->err, HEARTH_E_NUMERIC,
        "colmap mapper made no model: no pair of views with enough matched "
        "features to start from (too little texture inside the cut-outs?); its log: %s",
        log);
  return s;
}

/* "a,b,c" of the FULL_OPENCV parameters of hearth camera c (COLMAP pixels) */
static char *full_opencv_params(const hearth_camera *c) {
  double p[12] = {c->fx,      c->fy,      c->cx + 0.5, c->cy + 0.5, c->dist[0], c->dist[1],
                  c->dist[2], c->dist[3], c->dist[4],  0,           0,          0};
  hearth_strbuf b = {0};
  for (int i = 0; i < 12; i++) {
    if (i) hearth_strbuf_printf(&b, ",");
    rc_json_real(&b, p[i]);
  }
  return hearth_strbuf_take(&b);
}

static hearth_status colour_camera(run_ctx *r, hearth_camera *cam) {
  char path[4096];
  hearth_status s;
  if ((s = join(path, r->job->root, "calibration/rig.json", r->err))) return s;
  if (hearth_path_exists(path)) {
    hearth_rig rig;
    if ((s = hearth_rig_read(path, &rig, r->err)) ||
        (s = hearth_rig_require_stereo(&rig, path, "the reconstruction (its colour camera)",
                                       r->err)))
      return s;
    *cam = rig.rgb;
    return HEARTH_OK;
  }
  if ((s = join(path, r->job->root, "calibration/factory.json", r->err))) return s;
  if (hearth_path_exists(path)) {
    hearth_factory_calib f;
    if ((s = hearth_factory_read(path, &f, r->err))) return s;
    *cam = f.rgb;
    return HEARTH_OK;
  }
  return hearth_err_set(r->err, HEARTH_E_NOT_FOUND,
                        "%s: neither calibration/rig.json nor calibration/factory.json holds the "
                        "colour camera; use the intrinsics COLMAP estimates instead (--intrinsics "
                        "estimate)",
                        r->job->root);
}

static hearth_status run_colmap(run_ctx *r, hearth_colmap_result *res) {
  const hearth_colmap_job *job = r->job;
  char threads[16];
  snprintf(threads, sizeof threads, "%d", r->threads);
  char *params = NULL;
  hearth_status s = HEARTH_OK;
  if (job->intrinsics == HEARTH_COLMAP_INTR_CALIBRATION) {
    hearth_camera cam = {0};
    if ((s = colour_camera(r, &cam))) return s;
    if (!(params = full_opencv_params(&cam)))
      return hearth_err_set(r->err, HEARTH_E_NOMEM, "out of memory");
  }
  int calibrated = params != NULL;
  const char *extract[32] = {r->program,
                             "feature_extractor",
                             "--database_path",
                             r->db,
                             "--image_path",
                             r->images,
                             "--ImageReader.single_camera",
                             "1",
                             "--SiftExtraction.use_gpu",
                             "0",
                             "--SiftExtraction.num_threads",
                             threads,
                             "--ImageReader.camera_model",
                             calibrated ? "FULL_OPENCV" : "SIMPLE_RADIAL"};
  int n = 14;
  if (calibrated) {
    extract[n++] = "--ImageReader.camera_params";
    extract[n++] = params;
  }
  if (!job->no_masks) {
    extract[n++] = "--ImageReader.mask_path";
    extract[n++] = r->masks;
  }
  extract[n] = NULL;
  s = run_step(r, STEP_EXTRACT, "feature_extractor", extract, &res->seconds[0]);
  free(params);
  if (s) return s;
  const char *match[] =
      {r->program, "exhaustive_matcher",         "--database_path", r->db, "--SiftMatching.use_gpu",
       "0",        "--SiftMatching.num_threads", threads,           NULL};
  if ((s = run_step(r, STEP_MATCH, "exhaustive_matcher", match, &res->seconds[1]))) return s;
  if ((s = hearth_mkdirs(r->sparse, r->err))) return s;
  const char *map[32] = {r->program,      "mapper",       "--database_path",
                         r->db,           "--image_path", r->images,
                         "--output_path", r->sparse,      "--Mapper.num_threads",
                         threads};
  n = 10;
  if (calibrated) {
    static const char *const k_fixed[] = {"--Mapper.ba_refine_focal_length",    "0",
                                          "--Mapper.ba_refine_principal_point", "0",
                                          "--Mapper.ba_refine_extra_params",    "0"};
    for (size_t i = 0; i < sizeof k_fixed / sizeof k_fixed[0]; i++) map[n++] = k_fixed[i];
  }
  map[n] = NULL;
  return run_step(r, STEP_MAP, "mapper", map, &res->seconds[2]);
}

/* the model of sparse/ with the most registered images */
static hearth_status best_model(run_ctx *r, hearth_colmap_model *best, size_t *n_models) {
  DIR *d = opendir(r->sparse);
  if (!d) return hearth_err_set(r->err, HEARTH_E_IO, "%s: %s", r->sparse, strerror(errno));
  char names[RUN_MAX_MODELS][32];
  size_t n = 0;
  struct dirent *e;
  while ((e = readdir(d)) && n < RUN_MAX_MODELS) {
    size_t k = strspn(e->d_name, "0123456789");
    if (k && !e->d_name[k] && k < sizeof names[0])
      snprintf(names[n++], sizeof names[0], "%s", e->d_name);
  }
  closedir(d);
  *n_models = n;
  memset(best, 0, sizeof *best);
  long best_index = -1;
  for (size_t i = 0; i < n; i++) {
    char dir[4096];
    hearth_colmap_model m;
    hearth_status s = join(dir, r->sparse, names[i], r->err);
    if (!s) s = hearth_colmap_read(dir, &m, r->err);
    if (s) {
      hearth_colmap_model_free(best);
      return s;
    }
    long idx = strtol(names[i], NULL, 10);
    if (m.n_images > best->n_images ||
        (m.n_images == best->n_images && best_index >= 0 && idx < best_index) || best_index < 0) {
      hearth_colmap_model_free(best);
      *best = m;
      best_index = idx;
    } else {
      hearth_colmap_model_free(&m);
    }
  }
  if (best_index < 0 || !best->n_images)
    return hearth_err_set(r->err, HEARTH_E_NUMERIC,
                          "colmap mapper registered no view (%s is empty)", r->sparse);
  return HEARTH_OK;
}

static hearth_status import_model(run_ctx *r, hearth_colmap_result *res) {
  hearth_colmap_model m;
  hearth_status s = best_model(r, &m, &res->n_models);
  if (s) return s;
  hearth_poses poses;
  hearth_recon_cameras cams;
  s = hearth_colmap_to_poses(&m, "neutral", &poses, &cams, r->err);
  res->n_registered = m.n_images;
  res->n_points = m.n_points;
  hearth_colmap_model_free(&m);
  if (s) return s;
  char cam_path[4096], dir[4096];
  snprintf(dir, sizeof dir, "%s", res->out);
  char *slash = strrchr(dir, '/');
  if (slash) {
    *slash = 0;
    if (*dir) s = hearth_mkdirs(dir, r->err);
  }
  if (!s && hearth_recon_cameras_path(res->out, cam_path, sizeof cam_path))
    s = hearth_err_set(r->err, HEARTH_E_LIMIT, "%s: path too long", res->out);
  if (!s) s = hearth_poses_write(res->out, &poses, r->err);
  if (!s) s = hearth_recon_cameras_write(cam_path, &cams, r->err);
  hearth_poses_free(&poses);
  hearth_recon_cameras_free(&cams);
  return s;
}

hearth_status hearth_colmap_run(const hearth_colmap_job *job, hearth_colmap_result *res,
                                hearth_err *err) {
  memset(res, 0, sizeof *res);
  if (!job || !job->root || !job->instance)
    return hearth_err_set(err, HEARTH_E_ARG, "hearth_colmap_run: root and instance are required");
  if (!hearth_instance_id_valid(job->instance))
    return hearth_err_set(err, HEARTH_E_ARG, "'%s' is not an instance id (<category>_<NN>)",
                          job->instance);
  run_ctx r;
  memset(&r, 0, sizeof r);
  r.job = job;
  r.err = err;
  r.program = job->colmap ? job->colmap : "colmap";
  r.threads = job->threads > 0 ? job->threads : hearth_default_threads();
  if (!hearth_program_found(r.program))
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "colmap: '%s' not found%s; install COLMAP (on Debian: apt-get install "
                          "colmap) or name the program with --colmap",
                          r.program, strchr(r.program, '/') ? "" : " on PATH");
  hearth_status s;
  char instances[4096], ijson[4096];
  if ((s = join(instances, job->root, "instances", err)) ||
      (s = join(r.inst, instances, job->instance, err)) ||
      (s = join(ijson, r.inst, "instance.json", err)))
    return s;
  if (job->out) snprintf(res->out, sizeof res->out, "%s", job->out);
  else if ((s = join(res->out, r.inst, "recon/poses_rgb.json", err))) return s;
  if (hearth_path_exists(res->out) && !job->force)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "%s exists (poses in the frame of the reconstruction beside it); "
                          "--force replaces it",
                          res->out);
  hearth_instance_doc inst;
  if ((s = hearth_instance_read(ijson, &inst, err))) return s;
  int temp = !job->work;
  if (temp) {
    const char *tmp = getenv("TMPDIR");
    snprintf(r.work, sizeof r.work, "%s/hearth-colmap-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(r.work))
      return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create a workspace: %s", r.work,
                            strerror(errno));
  } else {
    snprintf(r.work, sizeof r.work, "%s", job->work);
    if ((s = hearth_mkdirs(r.work, err)) || (s = clear_workspace(&r))) return s;
  }
  snprintf(res->work, sizeof res->work, "%s", r.work);
  if ((s = join(r.images, r.work, "images", err)) || (s = join(r.masks, r.work, "masks", err)) ||
      (s = join(r.db, r.work, "database.db", err)) || (s = join(r.sparse, r.work, "sparse", err)) ||
      (s = join(r.logs, r.work, "logs", err)) || (s = hearth_mkdirs(r.logs, err)))
    return s;
  if (!job->quiet)
    fprintf(stderr, "recon %s: preparing %zu state(s) in %s\n", job->instance, inst.n_states,
            r.work);
  for (size_t i = 0; i < inst.n_states && !s; i++) s = prepare_state(&r, inst.states[i]);
  res->n_views = r.n_views;
  if (!s && !r.n_views) s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no colour views", r.inst);
  if (!s) s = run_colmap(&r, res);
  if (!s) s = import_model(&r, res);
  if (s) {
    hearth_err_prefix(err, "%s", job->instance);
    if (!job->quiet)
      fprintf(stderr, "recon %s: workspace kept for inspection: %s\n", job->instance, r.work);
    return s;
  }
  if (temp) {
    hearth_err tmp_err;
    if (hearth_remove_tree(r.work, &tmp_err) == HEARTH_OK) res->work[0] = 0;
  }
  return HEARTH_OK;
}
