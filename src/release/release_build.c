/* hearth build: every stage of a release, incrementally and in parallel.
 *
 * Each finished stage leaves a stamp (derived/.stamps/<stage>[-<state>].json,
 * release-level ones under calibration/.stamps/) holding a hash of its
 * parameters and of its inputs' paths, sizes and modification times, and the
 * list of its outputs. A stage re-runs when its stamp is missing, the hash
 * differs, or an output is missing. Stamps are written atomically after the
 * stage's outputs, which are themselves written atomically, so a killed run
 * leaves no stamp for the unfinished stage and a re-run redoes exactly that.
 * Every run, up to date or not, first removes the temporaries killed writers
 * left (core.h's pattern, writer no longer running) anywhere in its
 * instances and calibration/, so a resumed build ends with the same files as
 * an uninterrupted one and validates.
 * The parameters that shape the outputs come from the caller, else from the
 * release's build.json (the last build's), else the defaults, and are
 * recorded there before any stage runs (release_params.c).
 * The work is scheduled by stage: each instance's stages in order, its
 * per-state stages (map, overlay) of different states side by side once the
 * stages before them are done, and the stages that do not read the
 * calibration (scale) already while detection and calibration run, so a
 * core the single-threaded calibration leaves idle does an instance's work.
 * jobs workers take the next ready stage; each stage gets threads / jobs
 * workers of its own (the release-level stages all threads). Stages are
 * deterministic for any thread count, so the bytes do not depend on -j. */
#include <dirent.h>
#include <errno.h>
#include <jansson.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/dataset.h"
#include "hearth/map.h"
#include "hearth/poses.h"
#include "hearth/recon.h"
#include "hearth/recon_geom.h"
#include "hearth/release.h"
#include "release/release_internal.h"

#define PATH_SZ 4096

/* ---- file lists --------------------------------------------------------------- */
void hearth_build_files_free(hearth_build_files *f) {
  if (!f) return;
  for (size_t i = 0; i < f->n; i++) free(f->paths[i]);
  free(f->paths);
  memset(f, 0, sizeof *f);
}

hearth_status hearth_build_files_add(hearth_build_files *f, const char *fmt, ...) {
  char buf[PATH_SZ];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (n < 0 || n >= (int)sizeof buf) return HEARTH_E_LIMIT;
  if (f->n == f->cap) {
    size_t cap = f->cap ? 2 * f->cap : 32;
    char **p = realloc(f->paths, cap * sizeof *p);
    if (!p) return HEARTH_E_NOMEM;
    f->paths = p;
    f->cap = cap;
  }
  if (!(f->paths[f->n] = strdup(buf))) return HEARTH_E_NOMEM;
  f->n++;
  return HEARTH_OK;
}

/* Remove what killed writers left (temporary files, whole temporary
 * directories, directories moved aside: hearth_sweep_temps) from the directories of a stage's
 * outputs (relative to root) and of its stamp (absolute) and, with parents,
 * from the directories holding those (a temperature map's state directory is
 * written whole next to the old one). An instance stage's directories belong
 * to the one instance this worker is building, so no live writer of another
 * worker or shard is in them. */
static hearth_status sweep_temps(const char *root, const hearth_build_files *out, const char *stamp,
                                 int parents, size_t *n_removed, hearth_err *err) {
  size_t nd = 0, cap = 2 * (out->n + 1);
  char(*dirs)[PATH_SZ] = malloc(cap * sizeof *dirs);
  if (!dirs) return hearth_err_set(err, HEARTH_E_NOMEM, "build: out of memory");
  hearth_status s = HEARTH_OK;
  for (size_t i = 0; i <= out->n && !s; i++) {
    char dir[PATH_SZ];
    if (i < out->n) {
      if (hearth_path_join(dir, sizeof dir, root, out->paths[i]))
        s = hearth_err_set(err, HEARTH_E_LIMIT, "%s/%s: path too long", root, out->paths[i]);
    } else {
      snprintf(dir, sizeof dir, "%s", stamp);
    }
    for (int up = 0; up <= parents && !s; up++) {
      char *slash = strrchr(dir, '/');
      if (!slash) break;
      *slash = 0;
      int seen = 0;
      for (size_t j = 0; j < nd && !seen; j++) seen = !strcmp(dirs[j], dir);
      if (!seen) memcpy(dirs[nd++], dir, strlen(dir) + 1);
    }
  }
  size_t total = 0;
  for (size_t j = 0; j < nd && !s; j++) {
    size_t n = 0;
    s = hearth_sweep_temps(dirs[j], NULL, 0, &n, err);
    total += n;
  }
  free(dirs);
  *n_removed = total;
  return s;
}

/* ---- stamps ------------------------------------------------------------------- */
static uint64_t fnv(uint64_t h, const void *data, size_t n) {
  const uint8_t *p = data;
  for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

/* hash of the parameters and each input's path, size and mtime */
static uint64_t inputs_hash(const char *root, const char *params, const hearth_build_files *in) {
  uint64_t h = 0xcbf29ce484222325ull;
  h = fnv(h, params, strlen(params) + 1);
  for (size_t i = 0; i < in->n; i++) {
    char p[PATH_SZ], line[PATH_SZ + 64];
    snprintf(p, sizeof p, "%s/%s", root, in->paths[i]);
    struct stat st;
    if (stat(p, &st) == 0)
      snprintf(line, sizeof line, "%s %lld %lld.%09ld", in->paths[i], (long long)st.st_size,
               (long long)st.st_mtim.tv_sec, (long)st.st_mtim.tv_nsec);
    else snprintf(line, sizeof line, "%s missing", in->paths[i]);
    h = fnv(h, line, strlen(line) + 1);
  }
  return h;
}

static int stamp_fresh(const char *root, const char *stamp, const char *params,
                       const hearth_build_files *in, const hearth_build_files *out) {
  /* through hearth_read_file: a stamp that is not a regular file is stale,
   * never waited on */
  uint8_t *text = NULL;
  size_t len = 0;
  if (hearth_read_file(stamp, (size_t)16 << 20, &text, &len, NULL)) return 0;
  json_t *o = json_loadb((const char *)text, len, 0, NULL);
  free(text);
  if (!o) return 0;
  char want[32];
  snprintf(want, sizeof want, "%016llx", (unsigned long long)inputs_hash(root, params, in));
  const char *have = json_string_value(json_object_get(o, "inputs_hash"));
  int fresh = have && !strcmp(have, want);
  json_decref(o);
  for (size_t i = 0; fresh && i < out->n; i++) {
    char p[PATH_SZ];
    snprintf(p, sizeof p, "%s/%s", root, out->paths[i]);
    fresh = hearth_path_exists(p);
  }
  return fresh;
}

static hearth_status stamp_write(const char *root, const char *stamp, const char *stage,
                                 const char *target, const char *params,
                                 const hearth_build_files *in, const hearth_build_files *out,
                                 hearth_err *err) {
  char dir[PATH_SZ], hash[32];
  snprintf(dir, sizeof dir, "%s", stamp);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = 0;
  hearth_status s = hearth_mkdirs(dir, err);
  if (s) return s;
  snprintf(hash, sizeof hash, "%016llx", (unsigned long long)inputs_hash(root, params, in));
  json_t *o = json_object(), *ji = json_array(), *jo = json_array();
  json_object_set_new(o, "stage", json_string(stage));
  json_object_set_new(o, "target", json_string(target));
  json_object_set_new(o, "params", json_string(params));
  json_object_set_new(o, "inputs_hash", json_string(hash));
  for (size_t i = 0; i < in->n; i++) json_array_append_new(ji, json_string(in->paths[i]));
  for (size_t i = 0; i < out->n; i++) json_array_append_new(jo, json_string(out->paths[i]));
  json_object_set_new(o, "inputs", ji);
  json_object_set_new(o, "outputs", jo);
  char *text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER);
  json_decref(o);
  if (!text) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot encode", stamp);
  s = hearth_write_file_atomic(stamp, text, strlen(text), err);
  free(text);
  return s;
}

/* ---- options and report ---------------------------------------------------------- */
void hearth_build_opts_default(hearth_build_opts *o) {
  memset(o, 0, sizeof *o);
  o->shard_count = 1;
  o->fusion = HEARTH_BUILD_FUSION_UNSET;
  o->min_cos = -1.0;
  o->bake_rgb = -1;
  o->calibrate = -1;
  o->calib_overlays = -1;
}

/* Fill o's unset parameters from root/build.json (unless the caller said
 * to ignore it), else from the defaults, and record the result there
 * (rewritten only when it changes). */
static hearth_status resolve_params(const char *root, hearth_build_opts *o, hearth_err *err) {
  char path[PATH_SZ];
  snprintf(path, sizeof path, "%s/build.json", root);
  hb_params p, old;
  hb_params_default(&p);
  int have_old = 0;
  if (hearth_path_exists(path)) {
    hearth_status s = hb_params_read(path, &old, err);
    if (s && !o->ignore_recorded) {
      if (err) {
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err->msg);
        hearth_err_set(
            err, s,
            "build: %s (the recorded parameters: delete the file to build with the defaults)", msg);
      }
      return s;
    }
    have_old = !s;
    if (have_old && !o->ignore_recorded) p = old;
  }
  if (o->resolution) p.resolution = o->resolution;
  if (o->fusion != HEARTH_BUILD_FUSION_UNSET) p.fusion = o->fusion;
  if (o->min_cos >= 0.0) p.min_cos = o->min_cos;
  if (o->rgb_resolution) p.rgb_resolution = o->rgb_resolution;
  if (o->bake_rgb >= 0) p.bake_rgb = o->bake_rgb != 0;
  if (o->calibrate >= 0) p.calibrate = o->calibrate != 0;
  if (o->calib_overlays >= 0) p.calib_overlays = o->calib_overlays != 0;
  o->resolution = p.resolution;
  o->fusion = p.fusion;
  o->min_cos = p.min_cos;
  o->rgb_resolution = p.rgb_resolution;
  o->bake_rgb = p.bake_rgb;
  o->calibrate = p.calibrate;
  o->calib_overlays = p.calib_overlays;
  if (o->dry_run || (have_old && hb_params_same(&old, &p))) return HEARTH_OK;
  return hb_params_write(path, &p, err);
}

void hearth_build_report_free(hearth_build_report *r) {
  if (!r) return;
  free(r->instances);
  memset(r, 0, sizeof *r);
}

/* ---- per-instance stages --------------------------------------------------------- */
/* recon (hearth's own reconstruction, only for instances without a recon/ of
 * another tool) comes first: scale reads recon/. bake comes before refine and
 * map: it rewrites derived/mesh.glb (texture only), which they read, so a
 * finished build has every later stamp taken after it */
enum { ST_RECON, ST_SCALE, ST_BAKE, ST_TRANSFER, ST_REFINE, ST_MAP, ST_OVERLAY, ST_COUNT };
static const char *const k_stage_names[ST_COUNT] = {"recon",  "scale", "bake",   "transfer",
                                                    "refine", "map",   "overlay"};

/* every stage is part of every build (kept as a hook for optional stages) */
static int stage_available(int st) {
  (void)st;
  return 1;
}

size_t hearth_build_instance_stages(const char **names, int *available, size_t max) {
  size_t n = 0;
  for (int s = 0; s < ST_COUNT && n < max; s++, n++) {
    if (names) names[n] = k_stage_names[s];
    if (available) available[n] = stage_available(s);
  }
  return n;
}

typedef struct inst_plan {
  char id[HEARTH_NAME_MAX];
  size_t n_states;
  char states[HEARTH_MAX_STATES][HEARTH_NAME_MAX];
  hearth_manifest man[HEARTH_MAX_STATES];
  int readable;
  int own_recon; /* recon/ is hearth's to make: missing, or made by an earlier build */
  char why[1024];
} inst_plan;

/* one stage run of one instance (and state, for map and overlay) */
enum { UNIT_PENDING, UNIT_RUNNING, UNIT_OK, UNIT_FAILED };
typedef struct build_unit {
  size_t inst; /* index into plans */
  int st;
  size_t k;  /* the state, for per-state stages */
  int state; /* UNIT_* */
} build_unit;

/* the release-level stages' outcome, which every stage that reads the
   calibration waits for */
enum { GATE_CLOSED, GATE_OPEN, GATE_FAILED };

typedef struct build_ctx {
  const char *root;
  const hearth_build_opts *o;
  int stage_threads;
  int use_stage[ST_COUNT];
  inst_plan *plans;
  hearth_build_instance *res;
  size_t n;
  build_unit *units; /* instance after instance, each in stage order */
  size_t n_units, units_left, running;
  int gate;
  int gate_all; /* caller-supplied release stages: every stage waits for them */
  pthread_cond_t cv;
  size_t units_total, units_done;
  size_t stages_run, stages_fresh, temps_removed;
  hearth_progress prog;
  int tty;
  FILE *log;
  pthread_mutex_t mu;
} build_ctx;

static void fusion_params(const hearth_build_opts *o, char *buf, size_t n) {
  const char *f = o->fusion == HEARTH_FUSE_MAX         ? "max"
                  : o->fusion == HEARTH_FUSE_ROBUST    ? "robust"
                  : o->fusion == HEARTH_FUSE_CORRECTED ? "corrected"
                                                       : "mean";
  char mc[32];
  hearth_format_fixed(mc, sizeof mc, o->min_cos, 6);
  /* normals=auto: hearth_map_run's smoothed normals for a fused mesh */
  snprintf(buf, n, "resolution=%zu fusion=%s min_cos=%s turbo=10..60 normals=auto", o->resolution,
           f, mc);
}

/* the recon stage bakes the colour texture into recon/ when the release has
   a calibrated rig (the bake's colour camera); without one recon/mesh.glb
   stays untextured */
static int recon_bakes(const char *root) {
  char path[PATH_SZ];
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  return hearth_path_exists(path);
}

/* the inputs and outputs of stage st for (instance, state) */
static hearth_status stage_files(const build_ctx *c, const inst_plan *p, int st, size_t k,
                                 hearth_build_files *in, hearth_build_files *out, char *params,
                                 size_t psz) {
  const char *id = p->id;
  hearth_status s = HEARTH_OK;
#define IN(...) \
  if (!s) s = hearth_build_files_add(in, __VA_ARGS__)
#define OUT(...) \
  if (!s) s = hearth_build_files_add(out, __VA_ARGS__)
  params[0] = 0;
  switch (st) {
    case ST_RECON:
      /* the turntable route with its defaults, the colour texture baked at
         the build's colour resolution */
      snprintf(params, psz, "turntable defaults bake=%zu stride=2", c->o->rgb_resolution);
      IN("instances/%s/instance.json", id);
      IN("calibration/factory.json");
      IN("calibration/rig.json");
      for (size_t j = 0; j < p->n_states; j++) {
        IN("instances/%s/raw/%s/manifest.json", id, p->states[j]);
        for (size_t v = 0; v < p->man[j].n_views; v++) {
          const hearth_view_files *vf = &p->man[j].views[v];
          IN("instances/%s/raw/%s/%s", id, p->states[j], vf->rgb);
          IN("instances/%s/raw/%s/%s", id, p->states[j], vf->cutout);
          IN("instances/%s/raw/%s/%s", id, p->states[j], vf->depth);
          IN("instances/%s/raw/%s/%s", id, p->states[j], vf->depth_intrinsics);
        }
      }
      OUT("instances/%s/recon/poses_rgb.json", id);
      OUT("instances/%s/recon/poses_rgb_cameras.json", id);
      OUT("instances/%s/recon/mesh_geometry.glb", id);
      OUT("instances/%s/recon/mesh.glb", id);
      if (recon_bakes(c->root)) OUT("instances/%s/recon/rgb_texture.png", id);
      OUT("instances/%s/recon/report.json", id);
      break;
    case ST_SCALE:
      snprintf(params, psz, "scale defaults");
      IN("instances/%s/instance.json", id);
      IN("instances/%s/recon/mesh.glb", id);
      IN("instances/%s/recon/poses_rgb.json", id);
      IN("instances/%s/recon/rgb_texture.png", id);
      for (size_t j = 0; j < p->n_states; j++) {
        IN("instances/%s/raw/%s/manifest.json", id, p->states[j]);
        for (size_t v = 0; v < p->man[j].n_views; v++) {
          IN("instances/%s/raw/%s/%s", id, p->states[j], p->man[j].views[v].depth);
          IN("instances/%s/raw/%s/%s", id, p->states[j], p->man[j].views[v].depth_intrinsics);
        }
      }
      OUT("instances/%s/derived/scale.json", id);
      OUT("instances/%s/derived/mesh.glb", id);
      OUT("instances/%s/derived/poses_rgb.json", id);
      break;
    case ST_TRANSFER:
      snprintf(params, psz, "keep_refined=%d", c->use_stage[ST_REFINE]);
      IN("calibration/rig.json");
      IN("instances/%s/derived/poses_rgb.json", id);
      OUT("instances/%s/derived/poses_thermal_transferred.json", id);
      OUT("instances/%s/derived/poses_thermal.json", id);
      break;
    case ST_REFINE:
      snprintf(params, psz, "refine defaults");
      IN("calibration/rig.json");
      IN("instances/%s/derived/mesh.glb", id);
      IN("instances/%s/derived/poses_thermal_transferred.json", id);
      for (size_t j = 0; j < p->n_states; j++) {
        IN("instances/%s/raw/%s/manifest.json", id, p->states[j]);
        for (size_t v = 0; v < p->man[j].n_views; v++)
          IN("instances/%s/raw/%s/%s", id, p->states[j], p->man[j].views[v].thermal);
      }
      OUT("instances/%s/derived/poses_thermal.json", id);
      break;
    case ST_BAKE:
      snprintf(params, psz, "resolution=%zu stride=2", c->o->rgb_resolution);
      IN("calibration/rig.json");
      IN("instances/%s/derived/poses_rgb.json", id);
      IN("instances/%s/derived/scale.json", id); /* a new metric mesh means a new bake */
      if (p->n_states) {
        IN("instances/%s/raw/%s/manifest.json", id, p->states[0]);
        for (size_t v = 0; v < p->man[0].n_views; v++)
          IN("instances/%s/raw/%s/%s", id, p->states[0], p->man[0].views[v].rgb);
      }
      OUT("instances/%s/derived/rgb_texture.png", id);
      OUT("instances/%s/derived/mesh.glb", id);
      break;
    case ST_MAP:
    case ST_OVERLAY: {
      const char *state = p->states[k];
      if (st == ST_MAP) fusion_params(c->o, params, psz);
      else snprintf(params, psz, "zoom=2");
      IN("calibration/rig.json");
      IN("instances/%s/derived/mesh.glb", id);
      IN("instances/%s/derived/poses_thermal.json", id);
      if (st == ST_OVERLAY) IN("instances/%s/derived/poses_thermal_transferred.json", id);
      IN("instances/%s/raw/%s/manifest.json", id, state);
      for (size_t v = 0; v < p->man[k].n_views; v++)
        IN("instances/%s/raw/%s/%s", id, state, p->man[k].views[v].thermal);
      if (st == ST_MAP) {
        static const char *f[] = {"temperature_observed.npy", "temperature_filled.npy", "mask.npy",
                                  "thermal_turbo.png", "provenance.json"};
        for (int j = 0; j < 5; j++) OUT("instances/%s/derived/%s/%s", id, state, f[j]);
      } else {
        OUT("instances/%s/derived/overlay/%s/contact_sheet.png", id, state);
      }
      break;
    }
  }
#undef IN
#undef OUT
  return s;
}

/* hearth recon ROOT --instance ID (turntable poses, mesh from depth, its
 * atlas), then the colour texture baked from the first state's views into
 * recon/rgb_texture.png and recon/mesh.glb: the hand-over an outside tool
 * gives. A pending stamp is written first, so recon/ files of a killed run
 * are known as the build's own (and replaced) on the next one. Errors name
 * the instance and the step. */
static hearth_status run_recon(const build_ctx *c, const inst_plan *p, hearth_err *err) {
  char stamp[PATH_SZ], dir[PATH_SZ], mesh[PATH_SZ], poses[PATH_SZ], tex[PATH_SZ];
  snprintf(stamp, sizeof stamp, "%s/instances/%s/derived/.stamps/recon.json", c->root, p->id);
  snprintf(dir, sizeof dir, "%s", stamp);
  *strrchr(dir, '/') = 0;
  hearth_status s = hearth_mkdirs(dir, err);
  static const char k_pending[] = "{\"stage\": \"recon\", \"inputs_hash\": \"pending\"}\n";
  if (!s) s = hearth_write_file_atomic(stamp, k_pending, sizeof k_pending - 1, err);
  if (s) return s;
  hearth_recon_job job;
  hearth_recon_job_default(&job);
  job.root = c->root;
  job.instance = p->id;
  job.force = 1;
  job.quiet = 1;
  job.poses.threads = c->stage_threads;
  hearth_recon_summary sum;
  if ((s = hearth_recon_run(&job, &sum, err))) {
    hearth_err_prefix(err, "%s: recon (turntable poses, mesh, atlas)", p->id);
    return s;
  }
  hearth_recon_summary_free(&sum);
  if (!recon_bakes(c->root)) return HEARTH_OK;
  snprintf(mesh, sizeof mesh, "%s/instances/%s/recon/mesh.glb", c->root, p->id);
  snprintf(poses, sizeof poses, "%s/instances/%s/recon/poses_rgb.json", c->root, p->id);
  snprintf(tex, sizeof tex, "%s/instances/%s/recon/rgb_texture.png", c->root, p->id);
  hearth_bake_job b;
  hearth_bake_job_default(&b);
  b.root = c->root;
  b.instance = p->id;
  b.resolution = c->o->rgb_resolution;
  b.mesh_path = mesh;
  b.poses_path = poses;
  b.out_mesh = mesh;
  b.out_texture = tex;
  b.threads = c->stage_threads;
  if ((s = hearth_bake_rgb_run(&b, err)))
    hearth_err_prefix(err, "%s: recon (colour bake into recon/)", p->id);
  return s;
}

static hearth_status stage_run(const build_ctx *c, const inst_plan *p, int st, size_t k,
                               size_t *mapped, hearth_err *err) {
  const hearth_build_opts *o = c->o;
  switch (st) {
    case ST_RECON: return run_recon(c, p, err);
    case ST_SCALE: {
      hearth_scale_job j = {c->root, p->id, NULL, {0}};
      hearth_scale_opts_default(&j.opts);
      j.opts.threads = c->stage_threads;
      return hearth_scale_run(&j, NULL, err);
    }
    case ST_TRANSFER: {
      hearth_transfer_job j = {c->root, p->id, NULL, NULL, 0};
      /* with refinement, transfer must not overwrite refined poses; without
         it, transferred poses are what mapping uses */
      if (c->use_stage[ST_REFINE]) {
        j.keep_refined = 1;
      }
      return hearth_transfer_run(&j, err);
    }
    case ST_REFINE: {
      hearth_refine_job j;
      hearth_refine_job_default(&j);
      j.root = c->root;
      j.instance = p->id;
      j.opts.threads = c->stage_threads;
      return hearth_refine_run(&j, NULL, err);
    }
    case ST_BAKE: {
      hearth_bake_job j = {c->root, p->id, NULL, o->rgb_resolution, 2,
                           NULL,    NULL,  NULL, c->stage_threads};
      return hearth_bake_rgb_run(&j, err);
    }
    case ST_MAP: {
      hearth_map_job j;
      hearth_map_job_default(&j);
      j.root = c->root;
      j.instance = p->id;
      j.state = p->states[k];
      j.map.resolution = o->resolution;
      j.map.fusion = o->fusion;
      j.map.min_cos = o->min_cos;
      j.map.threads = c->stage_threads;
      hearth_status s = hearth_map_run(&j, NULL, err);
      if (!s && mapped) (*mapped)++;
      return s;
    }
    case ST_OVERLAY: {
      hearth_overlay_job j = {0};
      j.root = c->root;
      j.instance = p->id;
      j.state = p->states[k];
      j.zoom = 2;
      j.threads = c->stage_threads;
      size_t nw = 0;
      return hearth_overlay_run(&j, &nw, err);
    }
  }
  return hearth_err_set(err, HEARTH_E_ARG, "unknown stage");
}

/* the stage is part of this instance's build */
static int stage_used(const build_ctx *c, const inst_plan *p, int st) {
  return c->use_stage[st] && (st != ST_RECON || p->own_recon);
}

static size_t units_of(const build_ctx *c, const inst_plan *p) {
  size_t u = 0;
  for (int st = 0; st < ST_COUNT; st++)
    if (stage_used(c, p, st)) u += (st == ST_MAP || st == ST_OVERLAY) ? p->n_states : 1;
  return u;
}

/* one unit of work finished: progress bar on a terminal, a line otherwise
   (none for a unit skipped after a failure: outcome NULL); c->mu held */
static void unit_done_locked(build_ctx *c, const char *what, const char *outcome, double secs) {
  c->units_done++;
  if (!c->o->quiet) {
    if (c->tty) {
      hearth_progress_step(&c->prog, 1);
    } else if (outcome) {
      fprintf(c->log, "build [%zu/%zu] %s: %s", c->units_done, c->units_total, what, outcome);
      if (secs >= 0) fprintf(c->log, " (%.1f s)", secs);
      fputc('\n', c->log);
      fflush(c->log);
    }
  }
}

static void unit_done(build_ctx *c, const char *what, const char *outcome, double secs) {
  pthread_mutex_lock(&c->mu);
  unit_done_locked(c, what, outcome, secs);
  pthread_mutex_unlock(&c->mu);
}

/* run (or skip) one stage of one instance; returns 0 on failure */
static int do_stage(build_ctx *c, size_t idx, int st, size_t k) {
  inst_plan *p = &c->plans[idx];
  hearth_build_instance *r = &c->res[idx];
  char stamp[PATH_SZ], params[512], what[256];
  int per_state = st == ST_MAP || st == ST_OVERLAY;
  if (per_state) {
    snprintf(stamp, sizeof stamp, "%s/instances/%s/derived/.stamps/%s-%s.json", c->root, p->id,
             k_stage_names[st], p->states[k]);
    snprintf(what, sizeof what, "%s %s %s", p->id, k_stage_names[st], p->states[k]);
  } else {
    snprintf(stamp, sizeof stamp, "%s/instances/%s/derived/.stamps/%s.json", c->root, p->id,
             k_stage_names[st]);
    snprintf(what, sizeof what, "%s %s", p->id, k_stage_names[st]);
  }
  hearth_build_files in = {0}, out = {0};
  hearth_err err = {0};
  int ok = 1;
  hearth_status s = stage_files(c, p, st, k, &in, &out, params, sizeof params);
  if (s) {
    hearth_err_set(&err, s, "%s: cannot list the stage's files", what);
    goto fail;
  }
  if (!c->o->force && stamp_fresh(c->root, stamp, params, &in, &out)) {
    pthread_mutex_lock(&c->mu);
    c->stages_fresh++;
    r->stages_skipped++;
    if (st == ST_MAP) r->states_mapped++;
    pthread_mutex_unlock(&c->mu);
    unit_done(c, what, "up to date", -1);
    goto done;
  }
  if (c->o->dry_run) {
    unit_done(c, what, "would run", -1);
    goto done;
  }
  double t0 = hearth_now();
  size_t mapped = 0, swept = 0;
  if ((s = sweep_temps(c->root, &out, stamp, 1, &swept, &err))) goto fail;
  if (swept) {
    pthread_mutex_lock(&c->mu);
    c->temps_removed += swept;
    pthread_mutex_unlock(&c->mu);
  }
  if ((s = stage_run(c, p, st, k, &mapped, &err))) goto fail;
  if ((s = stamp_write(c->root, stamp, k_stage_names[st], what, params, &in, &out, &err)))
    goto fail;
  pthread_mutex_lock(&c->mu);
  r->states_mapped += mapped;
  r->stages_run++;
  c->stages_run++;
  pthread_mutex_unlock(&c->mu);
  unit_done(c, what, "done", hearth_now() - t0);
  goto done;
fail:
  ok = 0;
  pthread_mutex_lock(&c->mu);
  if (!r->failed) {
    r->failed = 1;
    snprintf(r->failed_stage, sizeof r->failed_stage, "%s", k_stage_names[st]);
    snprintf(r->reason, sizeof r->reason, "%s", err.msg[0] ? err.msg : hearth_strerror(s));
  }
  pthread_mutex_unlock(&c->mu);
  unit_done(c, what, "FAILED", -1);
  if (!c->o->quiet && c->tty) {
    pthread_mutex_lock(&c->mu);
    fprintf(stderr, "\nbuild: %s failed: %s\n", what, err.msg);
    pthread_mutex_unlock(&c->mu);
  }
done:
  hearth_build_files_free(&in);
  hearth_build_files_free(&out);
  return ok;
}

/* the temporaries killed writers left anywhere in a tree, removed on every
 * run (up to date or not); those of running writers stay */
static size_t sweep_tree(const char *dir, int depth, int dry_run) {
  size_t n = 0;
  if (!dry_run) hearth_sweep_temps(dir, NULL, depth, &n, NULL);
  return n;
}

/* the temporaries of killed writers in an instance, removed before any of
   its stages runs; an unreadable instance fails whole */
static void prepare_instance(build_ctx *c, size_t idx) {
  inst_plan *p = &c->plans[idx];
  hearth_build_instance *r = &c->res[idx];
  char dir[PATH_SZ];
  snprintf(dir, sizeof dir, "%s/instances/%s", c->root, p->id);
  c->temps_removed += sweep_tree(dir, 8, c->o->dry_run);
  if (p->readable) return;
  r->failed = 1;
  snprintf(r->failed_stage, sizeof r->failed_stage, "read");
  snprintf(r->reason, sizeof r->reason, "%s", p->why);
  size_t u = units_of(c, p);
  for (size_t i = 0; i < u; i++) unit_done(c, p->id, "FAILED", -1);
}

static int per_state_stage(int st) { return st == ST_MAP || st == ST_OVERLAY; }

/* scale reads only the instance's own files; every other stage reads
   calibration/rig.json */
static int needs_gate(const build_ctx *c, int st) { return c->gate_all || st != ST_SCALE; }

/* The first unit ready to run, marked running; NULL when none is. A unit is
 * ready when every earlier stage of its instance that is not per-state has
 * succeeded (and the gate is open, if it reads the calibration); one after a
 * failed such stage is skipped (counted, no line), as in a serial build.
 * Called with c->mu held. */
static build_unit *next_unit(build_ctx *c) {
  for (size_t i = 0; i < c->n_units; i++) {
    build_unit *u = &c->units[i];
    if (u->state != UNIT_PENDING) continue;
    int blocked = 0, dead = 0;
    for (size_t j = i; j-- > 0 && c->units[j].inst == u->inst;) {
      const build_unit *v = &c->units[j];
      if (per_state_stage(v->st) || v->st >= u->st) continue;
      if (v->state == UNIT_FAILED) dead = 1;
      else if (v->state != UNIT_OK) blocked = 1;
    }
    if (dead) {
      u->state = UNIT_FAILED;
      c->units_left--;
      unit_done_locked(c, NULL, NULL, -1);
      continue;
    }
    if (blocked || (needs_gate(c, u->st) && c->gate != GATE_OPEN)) continue;
    u->state = UNIT_RUNNING;
    c->running++;
    return u;
  }
  return NULL;
}

/* a job: ready units until none is left or none can become ready (every
   one left waits for a gate that failed) */
static void *worker(void *arg) {
  build_ctx *c = arg;
  pthread_mutex_lock(&c->mu);
  while (c->units_left) {
    build_unit *u = next_unit(c);
    if (u) {
      pthread_mutex_unlock(&c->mu);
      int ok = do_stage(c, u->inst, u->st, u->k);
      pthread_mutex_lock(&c->mu);
      u->state = ok ? UNIT_OK : UNIT_FAILED;
      c->units_left--;
      c->running--;
      pthread_cond_broadcast(&c->cv);
      continue;
    }
    if (c->gate != GATE_CLOSED && !c->running) break;
    pthread_cond_wait(&c->cv, &c->mu);
  }
  pthread_cond_broadcast(&c->cv);
  pthread_mutex_unlock(&c->mu);
  return NULL;
}

static void open_gate(build_ctx *c, int gate) {
  pthread_mutex_lock(&c->mu);
  c->gate = gate;
  pthread_cond_broadcast(&c->cv);
  pthread_mutex_unlock(&c->mu);
}

static void free_plans(build_ctx *c) {
  for (size_t i = 0; i < c->n; i++)
    for (size_t k = 0; k < c->plans[i].n_states; k++) hearth_manifest_free(&c->plans[i].man[k]);
  free(c->plans);
}

/* read instance.json and manifests (the stage file lists need them) */
static void plan_instance(const char *root, inst_plan *p) {
  char path[PATH_SZ];
  hearth_err e = {0};
  /* recon/ is the build's own when it is missing or an earlier build made it
     (its stamp, pending or done); another tool's recon/ is never touched */
  snprintf(path, sizeof path, "%s/instances/%s/recon", root, p->id);
  p->own_recon = !hearth_path_exists(path);
  snprintf(path, sizeof path, "%s/instances/%s/derived/.stamps/recon.json", root, p->id);
  if (hearth_path_exists(path)) p->own_recon = 1;
  hearth_instance_doc doc;
  if (hearth_instance_load(root, p->id, &doc, &e)) {
    snprintf(p->why, sizeof p->why, "%s", e.msg);
    return;
  }
  p->n_states = doc.n_states;
  for (size_t k = 0; k < doc.n_states; k++) {
    snprintf(p->states[k], sizeof p->states[k], "%s", doc.states[k]);
    snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, p->id, doc.states[k]);
    if (hearth_manifest_read(path, &p->man[k], &e)) {
      snprintf(p->why, sizeof p->why, "%s", e.msg);
      return;
    }
  }
  p->readable = 1;
}

static hearth_status run_release_stage(const char *root, const hearth_build_stage *bs,
                                       const hearth_build_opts *o, int threads, FILE *log, int *ran,
                                       size_t *swept, hearth_err *err) {
  hearth_build_files in = {0}, out = {0};
  char stamp[PATH_SZ];
  snprintf(stamp, sizeof stamp, "%s/calibration/.stamps/%s.json", root, bs->name);
  const char *params = bs->params ? bs->params : "";
  hearth_status s = bs->files(bs->ctx, root, &in, &out, err);
  *ran = 0;
  if (s) goto done;
  if (!o->force && stamp_fresh(root, stamp, params, &in, &out)) {
    if (!o->quiet) fprintf(log, "build: %s: up to date\n", bs->name);
    goto done;
  }
  if (o->dry_run) {
    if (!o->quiet) fprintf(log, "build: %s: would run\n", bs->name);
    *ran = -1; /* neither run nor up to date */
    goto done;
  }
  double t0 = hearth_now();
  if ((s = sweep_temps(root, &out, stamp, 0, swept, err))) goto done;
  if ((s = bs->run(bs->ctx, root, threads, err))) {
    hearth_err_prefix(err, "%s", bs->name);
    goto done;
  }
  if ((s = stamp_write(root, stamp, bs->name, "release", params, &in, &out, err))) goto done;
  *ran = 1;
  if (!o->quiet) fprintf(log, "build: %s: done (%.1f s)\n", bs->name, hearth_now() - t0);
done:
  hearth_build_files_free(&in);
  hearth_build_files_free(&out);
  return s;
}

hearth_status hearth_build_release(const char *root, const hearth_build_opts *o_in,
                                   hearth_build_report *rep, hearth_err *err) {
  if (!root || !rep)
    return hearth_err_set(err, HEARTH_E_ARG, "build: root and report are required");
  memset(rep, 0, sizeof *rep);
  hearth_build_opts o;
  if (o_in) o = *o_in;
  else hearth_build_opts_default(&o);
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    return hearth_err_set(err, HEARTH_E_ARG, "build: shard %d/%d: expected 0 <= index < count",
                          o.shard_index, o.shard_count);
  FILE *log = o.log ? o.log : stdout;
  double t_start = hearth_now();
  int threads = o.threads > 0 ? o.threads : hearth_default_threads();

  char path[PATH_SZ];
  snprintf(path, sizeof path, "%s/release.json", root);
  hearth_release_doc rel = {0};
  hearth_status s = hearth_release_read(path, &rel, err);
  if (s) return s;
  if ((s = resolve_params(root, &o, err))) {
    hearth_release_free(&rel);
    return s;
  }

  /* release-level stages once, with every thread: detection and calibration
   * (when the release has calibration captures), then the caller's own */
  hearth_build_stage stages[2 + HEARTH_BUILD_MAX_STAGES];
  size_t n_stages = o.calibrate ? hb_calib_stages(root, o.calib_overlays, stages, 2) : 0;
  if (o.n_release_stages > HEARTH_BUILD_MAX_STAGES) {
    hearth_release_free(&rel);
    return hearth_err_set(err, HEARTH_E_ARG, "build: %zu release stages (at most %d)",
                          o.n_release_stages, HEARTH_BUILD_MAX_STAGES);
  }
  for (size_t i = 0; i < o.n_release_stages; i++) stages[n_stages++] = o.release_stages[i];

  /* this shard's instances, in release order */
  size_t n = 0;
  for (size_t i = 0; i < rel.n_instances; i++)
    if ((int)(i % (size_t)o.shard_count) == o.shard_index &&
        (!o.only_instance || !strcmp(o.only_instance, rel.instances[i])))
      n++;
  if (o.only_instance && !n) {
    hearth_release_free(&rel);
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "%s: no instance '%s' in this release (or shard)", path, o.only_instance);
  }
  build_ctx c;
  memset(&c, 0, sizeof c);
  c.root = root;
  c.o = &o;
  c.log = log;
  c.gate_all = o.n_release_stages > 0;
  c.plans = calloc(n ? n : 1, sizeof *c.plans);
  c.res = calloc(n ? n : 1, sizeof *c.res);
  if (!c.plans || !c.res) {
    free(c.plans);
    free(c.res);
    hearth_release_free(&rel);
    return hearth_err_set(err, HEARTH_E_NOMEM, "build: out of memory");
  }
  size_t j = 0;
  for (size_t i = 0; i < rel.n_instances; i++)
    if ((int)(i % (size_t)o.shard_count) == o.shard_index &&
        (!o.only_instance || !strcmp(o.only_instance, rel.instances[i]))) {
      snprintf(c.plans[j].id, sizeof c.plans[j].id, "%s", rel.instances[i]);
      snprintf(c.res[j].id, sizeof c.res[j].id, "%s", rel.instances[i]);
      j++;
    }
  hearth_release_free(&rel);
  c.n = n;
  for (int st = 0; st < ST_COUNT; st++) c.use_stage[st] = stage_available(st);
  if (!o.bake_rgb) c.use_stage[ST_BAKE] = 0;
  size_t n_units = 0;
  for (size_t i = 0; i < n; i++) {
    plan_instance(root, &c.plans[i]);
    c.res[i].n_states = c.plans[i].n_states;
    c.units_total += units_of(&c, &c.plans[i]);
    if (c.plans[i].readable) n_units += units_of(&c, &c.plans[i]);
  }
  c.units = calloc(n_units ? n_units : 1, sizeof *c.units);
  if (!c.units) {
    free_plans(&c);
    free(c.res);
    return hearth_err_set(err, HEARTH_E_NOMEM, "build: out of memory");
  }
  for (size_t i = 0; i < n; i++)
    for (int st = 0; c.plans[i].readable && st < ST_COUNT; st++) {
      if (!stage_used(&c, &c.plans[i], st)) continue;
      size_t nk = per_state_stage(st) ? c.plans[i].n_states : 1;
      for (size_t k = 0; k < nk; k++) c.units[c.n_units++] = (build_unit){i, st, k, UNIT_PENDING};
    }
  c.units_left = c.n_units;
  c.gate = n_stages ? GATE_CLOSED : GATE_OPEN;
  int jobs = o.jobs > 0 ? o.jobs : threads;
  if ((size_t)jobs > n) jobs = n ? (int)n : 1;
  c.stage_threads = threads / jobs > 0 ? threads / jobs : 1;
  pthread_mutex_init(&c.mu, NULL);
  pthread_cond_init(&c.cv, NULL);
  c.tty = isatty(fileno(stderr));

  rep->temps_removed += sweep_tree(root, 0, o.dry_run);
  char cdir[PATH_SZ];
  snprintf(cdir, sizeof cdir, "%s/calibration", root);
  rep->temps_removed += sweep_tree(cdir, 8, o.dry_run);
  for (size_t i = 0; i < n; i++) prepare_instance(&c, i);
  if (!o.quiet) {
    fprintf(log, "build: %zu instance(s)%s, %zu stage run(s) to check, %d job(s) x %d thread(s)\n",
            n, o.shard_count > 1 ? " in this shard" : "", c.units_total, jobs, c.stage_threads);
    fflush(log);
    if (c.tty) hearth_progress_begin(&c.prog, "build", c.units_total, 0);
  }
  /* the other jobs start at once: stages that do not read the calibration
     run beside the release-level stages, which this thread runs */
  pthread_t *tids = calloc((size_t)jobs, sizeof *tids);
  int started = 0;
  if (tids)
    for (int t = 1; t < jobs; t++) {
      if (pthread_create(&tids[t], NULL, worker, &c) != 0) break;
      started = t;
    }
  hearth_status s_rel = HEARTH_OK;
  for (size_t i = 0; i < n_stages && !s_rel; i++) {
    int ran = 0;
    size_t swept = 0;
    s_rel = run_release_stage(root, &stages[i], &o, threads, log, &ran, &swept, err);
    pthread_mutex_lock(&c.mu);
    rep->temps_removed += swept;
    if (s_rel) {
      rep->release_failed = 1;
      snprintf(rep->release_reason, sizeof rep->release_reason, "%s", err->msg);
    } else if (ran > 0) {
      rep->stages_run++;
    } else if (ran == 0) {
      rep->stages_up_to_date++;
    }
    pthread_mutex_unlock(&c.mu);
  }
  open_gate(&c, s_rel ? GATE_FAILED : GATE_OPEN);
  worker(&c);
  for (int t = 1; t <= started; t++) pthread_join(tids[t], NULL);
  free(tids);
  if (!o.quiet && c.tty) hearth_progress_end(&c.prog);
  pthread_cond_destroy(&c.cv);
  pthread_mutex_destroy(&c.mu);
  free_plans(&c);
  free(c.units);
  rep->stages_run += c.stages_run;
  rep->stages_up_to_date += c.stages_fresh;
  rep->temps_removed += c.temps_removed;
  rep->seconds = hearth_now() - t_start;
  if (s_rel) { /* no instance report: its stages that read the calibration never ran */
    free(c.res);
    return s_rel;
  }
  rep->n_instances = n;
  rep->instances = c.res;
  return HEARTH_OK;
}

void hearth_build_report_print(const hearth_build_report *r, FILE *out) {
  size_t ok = 0, failed = 0, states = 0, mapped = 0;
  for (size_t i = 0; i < r->n_instances; i++) {
    if (r->instances[i].failed) failed++;
    else ok++;
    states += r->instances[i].n_states;
    mapped += r->instances[i].states_mapped;
  }
  fprintf(out,
          "build summary: %zu instance(s): %zu complete, %zu failed; %zu/%zu state(s) mapped; "
          "%zu stage(s) run, %zu up to date; %.1f s\n",
          r->n_instances, ok, failed, mapped, states, r->stages_run, r->stages_up_to_date,
          r->seconds);
  if (r->temps_removed)
    fprintf(out, "  removed %zu temporary file(s)/folder(s) left by an interrupted run\n",
            r->temps_removed);
  if (r->release_failed) fprintf(out, "  release: FAILED: %s\n", r->release_reason);
  for (size_t i = 0; i < r->n_instances; i++)
    if (r->instances[i].failed)
      fprintf(out, "  %s: FAILED in %s: %s\n", r->instances[i].id, r->instances[i].failed_stage,
              r->instances[i].reason);
}
