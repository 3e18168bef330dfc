/* Release-level stages: temperature mapping of one state and colour-texture
 * baking (see include/hearth/map.h). */
#include <errno.h>
#include <stdarg.h>
#include <jansson.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "hearth/npy.h"
#include "hearth/map.h"
#include "hearth/dataset.h"
#include "hearth/thermal.h"

#define PATH_SZ 4096

static hearth_status joinf(char *buf, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static hearth_status joinf(char *buf, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(buf, PATH_SZ, fmt, ap);
  va_end(ap);
  return (n < 0 || n >= PATH_SZ) ? HEARTH_E_LIMIT : HEARTH_OK;
}

void hearth_map_job_default(hearth_map_job *job) {
  memset(job, 0, sizeof *job);
  hearth_map_opts_default(&job->map);
  job->map.normal_passes = HEARTH_MAP_NORMALS_AUTO;
  job->map.crease_deg = HEARTH_MAP_CREASE_AUTO;
  job->turbo_lo = 10.0;
  job->turbo_hi = 60.0;
}

/* the views to use: all manifest views, or the named subset (each must exist) */
static hearth_status select_views(const hearth_manifest *man, const char *list, const char *mpath,
                                  size_t *idx, size_t *n, hearth_err *err) {
  *n = 0;
  if (!list || !*list) {
    for (size_t i = 0; i < man->n_views; i++) idx[(*n)++] = i;
    return HEARTH_OK;
  }
  const char *p = list;
  while (*p) {
    const char *e = strchr(p, ',');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    size_t found = SIZE_MAX;
    for (size_t i = 0; i < man->n_views; i++)
      if (strlen(man->views[i].view) == len && !strncmp(man->views[i].view, p, len)) found = i;
    if (found == SIZE_MAX)
      return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no view '%.*s' in this state", mpath,
                            (int)len, p);
    for (size_t k = 0; k < *n; k++)
      if (idx[k] == found)
        return hearth_err_set(err, HEARTH_E_ARG, "view '%.*s' named twice", (int)len, p);
    idx[(*n)++] = found;
    p = e ? e + 1 : p + len;
  }
  if (!*n) return hearth_err_set(err, HEARTH_E_ARG, "no views selected");
  return HEARTH_OK;
}

static json_t *mat3_json(const double *M) {
  json_t *a = json_array();
  for (int r = 0; r < 3; r++) {
    json_t *row = json_array();
    for (int c = 0; c < 3; c++) json_array_append_new(row, json_real(M[3 * r + c]));
    json_array_append_new(a, row);
  }
  return a;
}

static json_t *vec_json(const double *v, int n) {
  json_t *a = json_array();
  for (int i = 0; i < n; i++) json_array_append_new(a, json_real(v[i]));
  return a;
}

static const char *fusion_name(hearth_fusion f) {
  return f == HEARTH_FUSE_MAX         ? "max"
         : f == HEARTH_FUSE_ROBUST    ? "robust"
         : f == HEARTH_FUSE_CORRECTED ? "corrected"
                                      : "mean";
}

static json_t *camera_json(const hearth_camera *c) {
  json_t *o = json_object();
  double K[9];
  hearth_camera_K(c, K);
  json_object_set_new(o, "width", json_integer(c->width));
  json_object_set_new(o, "height", json_integer(c->height));
  json_object_set_new(o, "K", mat3_json(K));
  json_object_set_new(o, "dist", vec_json(c->dist, 5));
  return o;
}

static hearth_status write_provenance(const char *path, const hearth_map_job *job,
                                      const hearth_manifest *man, const size_t *idx, size_t n,
                                      const hearth_map_result *r, const hearth_rig *rig,
                                      const char *rig_path, const char *poses_path,
                                      const char *mesh_path, hearth_err *err) {
  const char *root = job->root;
  json_t *o = json_object();
  json_object_set_new(o, "instance", json_string(job->instance));
  json_object_set_new(o, "state", json_string(job->state));
  /* views that contributed at least one texel, in manifest order */
  json_t *sv = json_array(), *hits = json_object();
  for (size_t k = 0; k < n; k++) {
    const char *name = man->views[idx[k]].view;
    if (r->view_hits[k] > 0) json_array_append_new(sv, json_string(name));
    json_object_set_new(hits, name, json_integer(r->view_hits[k]));
  }
  json_object_set_new(o, "source_views", sv);
  json_object_set_new(o, "surface_pixels_per_view", hits);
  json_t *rj = json_object();
  json_object_set_new(rj, "path", json_string(hearth_path_under(root, rig_path)));
  json_object_set_new(rj, "thermal", camera_json(&rig->thermal));
  json_t *tj = json_object();
  json_object_set_new(tj, "R", mat3_json(rig->T_thermal_from_rgb.R));
  json_object_set_new(tj, "t", vec_json(rig->T_thermal_from_rgb.t, 3));
  json_object_set_new(rj, "T_thermal_from_rgb", tj);
  json_object_set_new(o, "rig", rj);
  json_object_set_new(o, "poses", json_string(hearth_path_under(root, poses_path)));
  json_object_set_new(o, "mesh", json_string(hearth_path_under(root, mesh_path)));
  json_t *pj = json_object();
  json_object_set_new(pj, "resolution", json_integer((json_int_t)r->R));
  json_object_set_new(pj, "fusion", json_string(fusion_name(job->map.fusion)));
  json_object_set_new(pj, "min_cos", json_real(job->map.min_cos));
  json_object_set_new(pj, "views", json_string(job->views && *job->views ? job->views : "all"));
  json_object_set_new(pj, "keep_edges", json_boolean(job->map.keep_edges));
  json_object_set_new(pj, "normal_passes", json_integer(job->map.normal_passes));
  json_object_set_new(pj, "crease_deg", json_real(job->map.crease_deg));
  json_object_set_new(pj, "visibility",
                      json_string(job->map.trace_rays ? "traced rays"
                                                      : "rasterised where the mesh is in front"));
  json_object_set_new(pj, "turbo_range_c", vec_json((double[]){job->turbo_lo, job->turbo_hi}, 2));
  json_object_set_new(pj, "splat", json_string("bilinear"));
  json_object_set_new(pj, "fill", json_string("nearest observed texel within the UV island"));
  json_object_set_new(o, "parameters", pj);
  json_t *cj = json_object();
  json_object_set_new(cj, "surface_texels", json_integer((json_int_t)r->n_surface));
  json_object_set_new(cj, "observed_texels", json_integer((json_int_t)r->n_observed));
  json_object_set_new(cj, "filled_texels", json_integer((json_int_t)r->n_filled));
  json_object_set_new(cj, "unobserved_texels", json_integer((json_int_t)r->n_unobserved));
  json_object_set_new(cj, "observed_fraction",
                      json_real(r->n_surface ? (double)r->n_observed / (double)r->n_surface : 0.0));
  json_object_set_new(o, "coverage", cj);
  json_object_set_new(o, "software_version", json_string(HEARTH_VERSION));
  char *text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
  json_decref(o);
  if (!text) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot encode", path);
  hearth_status s = hearth_write_file_atomic(path, text, strlen(text), err);
  free(text);
  return s;
}

/* the first failing job, in job order, as the run's error (parallel jobs
 * each keep their own status and message) */
static hearth_status first_failure(const hearth_status *st, const hearth_err *errs, size_t n,
                                   hearth_err *err) {
  for (size_t k = 0; k < n; k++)
    if (st[k]) {
      *err = errs[k];
      return st[k];
    }
  return HEARTH_OK;
}

typedef struct csv_jobs {
  const char *root, *inst, *state;
  const hearth_manifest *man;
  const size_t *idx;
  hearth_image *imgs;
  hearth_csv_opts opts;
  hearth_status *st;
  hearth_err *errs;
  const char *rig_path; /* where opts' size comes from */
} csv_jobs;

static void read_csv_range(void *ctx, size_t b, size_t e, int t) {
  csv_jobs *c = ctx;
  (void)t;
  for (size_t k = b; k < e; k++) {
    char path[PATH_SZ];
    if (joinf(path, "%s/instances/%s/raw/%s/%s", c->root, c->inst, c->state,
              c->man->views[c->idx[k]].thermal)) {
      c->st[k] =
          hearth_err_set(&c->errs[k], HEARTH_E_LIMIT, "%s/instances/%s/raw/%s: path too long",
                         c->root, c->inst, c->state);
      continue;
    }
    c->st[k] = hearth_thermal_read_csv_camera(path, c->opts.width, c->opts.height, c->rig_path,
                                              &c->imgs[k], &c->errs[k]);
  }
}

typedef struct out_jobs {
  const char *dir;
  const hearth_map_result *r;
  double lo, hi;
  hearth_status st[2];
  hearth_err errs[2];
} out_jobs;

/* job 0: the three .npy maps; job 1: the Turbo texture PNG */
static void write_outputs(void *ctx, size_t b, size_t e, int t) {
  out_jobs *o = ctx;
  (void)t;
  for (size_t k = b; k < e; k++) {
    char path[PATH_SZ];
    hearth_err *err = &o->errs[k];
    hearth_status s = HEARTH_OK;
    size_t shape[2] = {o->r->R, o->r->R};
    if (k == 0) {
      if (!(s = joinf(path, "%s/temperature_observed.npy", o->dir)))
        s = hearth_npy_write(path, HEARTH_NPY_F32, 2, shape, o->r->observed, err);
      if (!s && !(s = joinf(path, "%s/temperature_filled.npy", o->dir)))
        s = hearth_npy_write(path, HEARTH_NPY_F32, 2, shape, o->r->filled, err);
      if (!s && !(s = joinf(path, "%s/mask.npy", o->dir)))
        s = hearth_npy_write(path, HEARTH_NPY_U8, 2, shape, o->r->mask, err);
    } else {
      hearth_image tex = {0};
      const uint8_t black[3] = {0, 0, 0};
      s = hearth_map_texture(o->r, o->lo, o->hi, 4, black, &tex, err);
      if (!s && !(s = joinf(path, "%s/thermal_turbo.png", o->dir)))
        s = hearth_png_write(path, &tex, err);
      hearth_image_free(&tex);
    }
    if (s && !err->msg[0]) hearth_err_set(err, s, "%s: path too long", o->dir);
    o->st[k] = s;
  }
}

/* the mesh, read, and the mapping layout, made on a thread of their own */
typedef struct layout_build {
  const char *mesh_path;
  hearth_mesh *mesh;
  const hearth_camera *cam;
  const hearth_map_opts *opts;
  hearth_map_layout *layout;
  hearth_status s;
  int mesh_failed; /* s is the mesh file's error */
  hearth_err err;
  double seconds;
} layout_build;

static void *layout_build_run(void *arg) {
  layout_build *b = arg;
  hearth_glb_read_opts gopts = {.require_uvs = 1};
  if ((b->s = hearth_glb_read(b->mesh_path, &gopts, b->mesh, &b->err))) {
    b->mesh_failed = 1;
    return NULL;
  }
  double t0 = hearth_now();
  b->s = hearth_map_layout_new(b->mesh, b->cam, b->opts, &b->layout, &b->err);
  b->seconds = hearth_now() - t0;
  return NULL;
}

/* The normal passes of an automatic job: 2 for a mesh hearth fused from depth
   (recon/report.json's "mesh" member; docs/dataset.md), 0 otherwise. */
static int auto_normal_passes(const char *root, const char *inst) {
  char path[PATH_SZ];
  joinf(path, "%s/instances/%s/recon/report.json", root, inst);
  json_t *j = json_load_file(path, 0, NULL);
  const json_t *mj = j ? json_object_get(j, "mesh") : NULL;
  int fused = json_is_object(mj) && json_number_value(json_object_get(mj, "voxel_m")) > 0;
  json_decref(j);
  return fused ? 2 : 0;
}

hearth_status hearth_map_run(const hearth_map_job *job_in, hearth_map_result *stats,
                             hearth_err *err) {
  if (!job_in)
    return hearth_err_set(err, HEARTH_E_ARG, "map: root, instance and state are required");
  hearth_map_job jc = *job_in;
  const hearth_map_job *job = &jc;
  if (!job->root || !job->instance || !job->state)
    return hearth_err_set(err, HEARTH_E_ARG, "map: root, instance and state are required");
  char rig_path[PATH_SZ], poses_path[PATH_SZ], mesh_path[PATH_SZ], man_path[PATH_SZ],
      out_dir[PATH_SZ], tmp_dir[PATH_SZ], path[PATH_SZ];
  const char *inst = job->instance, *root = job->root;
  if (job->rig_path) snprintf(rig_path, PATH_SZ, "%s", job->rig_path);
  else joinf(rig_path, "%s/calibration/rig.json", root);
  if (job->poses_path) snprintf(poses_path, PATH_SZ, "%s", job->poses_path);
  else joinf(poses_path, "%s/instances/%s/derived/poses_thermal.json", root, inst);
  if (job->mesh_path) snprintf(mesh_path, PATH_SZ, "%s", job->mesh_path);
  else joinf(mesh_path, "%s/instances/%s/derived/mesh.glb", root, inst);
  const int fused = !job->mesh_path && auto_normal_passes(root, inst) > 0;
  if (jc.map.normal_passes < 0) jc.map.normal_passes = fused ? 2 : 0;
  if (jc.map.crease_deg < 0) jc.map.crease_deg = fused ? 60.0 : 0.0;
  joinf(man_path, "%s/instances/%s/raw/%s/manifest.json", root, inst, job->state);
  if (job->out_dir) snprintf(out_dir, PATH_SZ, "%s", job->out_dir);
  else joinf(out_dir, "%s/instances/%s/derived/%s", root, inst, job->state);

  double t_start = hearth_now(), t_read = 0.0;
  hearth_rig rig;
  hearth_manifest man = {0};
  hearth_poses poses = {0};
  hearth_mesh mesh = {0};
  hearth_image *imgs = NULL;
  hearth_map_view *views = NULL;
  size_t *idx = NULL, n = 0;
  hearth_map_result r = {0};
  tmp_dir[0] = 0;
  layout_build lb = {0};
  pthread_t lb_tid;
  int lb_started = 0;
  hearth_status s;
  if ((s = hearth_rig_read(rig_path, &rig, err)) ||
      (s = hearth_rig_require_stereo(&rig, rig_path, "mapping", err)))
    goto done;
  if ((s = hearth_manifest_read(man_path, &man, err))) goto done;
  if (strcmp(man.instance, inst) || strcmp(man.state, job->state)) {
    s = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                       "%s: names instance '%s' state '%s', expected '%s' '%s'", man_path,
                       man.instance, man.state, inst, job->state);
    goto done;
  }
  if ((s = hearth_poses_read(poses_path, &poses, err))) goto done;
  idx = calloc(man.n_views ? man.n_views : 1, sizeof *idx);
  imgs = calloc(man.n_views ? man.n_views : 1, sizeof *imgs);
  views = calloc(man.n_views ? man.n_views : 1, sizeof *views);
  if (!idx || !imgs || !views) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
    goto done;
  }
  if ((s = select_views(&man, job->views, man_path, idx, &n, err))) goto done;
  for (size_t k = 0; k < n; k++) {
    const hearth_view_files *vf = &man.views[idx[k]];
    const hearth_view_pose *vp = hearth_poses_find(&poses, job->state, vf->view);
    if (!vp) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no pose for state '%s' view '%s'",
                         poses_path, job->state, vf->view);
      goto done;
    }
    views[k].image = &imgs[k];
    views[k].T_world_from_cam = vp->T_world_from_cam;
    views[k].time_s = vf->has_time ? vf->time_s : 0.0;
    views[k].pass = vf->elevation_index;
  }
  /* the mesh is read and the layout (UV raster, islands, pixel grid and
     fan: mesh and camera only) made on a thread of their own while the CSVs
     are read; a bad mesh is reported before a bad CSV, a failed layout
     after */
  lb = (layout_build){mesh_path, &mesh, &rig.thermal, &job->map, NULL, HEARTH_OK, 0, {0}, 0.0};
  lb_started = pthread_create(&lb_tid, NULL, layout_build_run, &lb) == 0;
  if (!lb_started) layout_build_run(&lb);
  /* the CSVs in parallel; the first failing view (in order) is reported */
  {
    csv_jobs cj = {root,
                   inst,
                   job->state,
                   &man,
                   idx,
                   imgs,
                   {(size_t)rig.thermal.width, (size_t)rig.thermal.height},
                   NULL,
                   NULL,
                   rig_path};
    cj.st = calloc(n ? n : 1, sizeof *cj.st);
    cj.errs = calloc(n ? n : 1, sizeof *cj.errs);
    if (!cj.st || !cj.errs) {
      free(cj.st);
      free(cj.errs);
      s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
      goto done;
    }
    int nt = job->map.threads > 0 ? job->map.threads : hearth_default_threads();
    hearth_parallel_chunks(n, 1, nt, read_csv_range, &cj);
    hearth_status cs = first_failure(cj.st, cj.errs, n, err);
    free(cj.st);
    free(cj.errs);
    t_read = hearth_now() - t_start;
    if (lb_started) pthread_join(lb_tid, NULL);
    lb_started = 0;
    if (lb.s && (lb.mesh_failed || !cs)) {
      if (err) *err = lb.err;
      s = lb.s;
      if (!lb.mesh_failed) hearth_err_prefix(err, "%s/%s", inst, job->state);
      goto done;
    }
    if ((s = cs)) goto done;
  }
  if (job->timing) memset(job->timing, 0, sizeof *job->timing);
  /* the viewing cosines are not written: not kept */
  hearth_map_opts mo = job->map;
  mo.skip_best_cos = 1;
  if ((s = hearth_map_views_with_layout(lb.layout, NULL, views, n, &mo, &r, job->timing, err))) {
    hearth_err_prefix(err, "%s/%s", inst, job->state);
    goto done;
  }
  /* a map without surface is nothing mapped: the UVs cover no texel */
  if (!r.n_surface) {
    s = hearth_err_set(err, HEARTH_E_RANGE,
                       "%s/%s: %s: the mesh's UV layout covers no texel of the %zux%zu map "
                       "(surface 0 texels): its UVs lie outside [0,1] or its UV triangles "
                       "are too small to hold a texel centre",
                       inst, job->state, mesh_path, r.R, r.R);
    goto done;
  }
  if (job->timing) job->timing->raster = lb.seconds;
  /* write everything into a temporary sibling directory, then swap it in */
  double t_write0 = hearth_now();
  char parent[PATH_SZ];
  joinf(parent, "%s/instances/%s/derived", root, inst);
  if (!job->out_dir && (s = hearth_mkdirs(parent, err))) goto done;
  /* what a killed earlier run left beside out_dir goes first */
  if ((s = hearth_sweep_temps_of(out_dir, NULL, err))) goto done;
  if ((s = hearth_temp_dir(out_dir, tmp_dir, PATH_SZ, err))) {
    tmp_dir[0] = 0;
    goto done;
  }
  {
    /* the maps and the Turbo texture (colouring, padding, PNG compression)
     * are written side by side */
    out_jobs oj = {tmp_dir, &r, job->turbo_lo, job->turbo_hi, {HEARTH_OK, HEARTH_OK}, {{0}, {0}}};
    int nt = job->map.threads > 0 ? job->map.threads : hearth_default_threads();
    hearth_parallel_for(2, nt, write_outputs, &oj);
    if ((s = first_failure(oj.st, oj.errs, 2, err))) goto done;
  }
  joinf(path, "%s/provenance.json", tmp_dir);
  if ((s = write_provenance(path, job, &man, idx, n, &r, &rig, rig_path, poses_path, mesh_path,
                            err)))
    goto done;
  if ((s = hearth_replace_dir(tmp_dir, out_dir, err))) goto done;
  tmp_dir[0] = 0;
  if (job->timing) {
    job->timing->read = t_read;
    job->timing->write = hearth_now() - t_write0;
    job->timing->total = hearth_now() - t_start;
  }
  if (stats) {
    *stats = r;
    stats->observed = stats->filled = NULL;
    stats->mask = NULL;
    stats->best_cos = NULL;
    stats->view_hits = NULL;
  }
done:
  if (lb_started) pthread_join(lb_tid, NULL);
  hearth_map_layout_free(lb.layout);
  if (tmp_dir[0]) hearth_remove_tree(tmp_dir, NULL);
  hearth_map_result_free(&r);
  if (imgs)
    for (size_t k = 0; k < man.n_views; k++) hearth_image_free(&imgs[k]);
  free(imgs);
  free(views);
  free(idx);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&poses);
  hearth_manifest_free(&man);
  return s;
}

/* The colour bake's memory: the mapping decodes each view's frame when its
 * cast reaches it and frees it after the view's splat (hearth_map_opts'
 * load), so a worker holds one frame at a time; the frames' headers are
 * checked, view by view, before the mapping starts. */
typedef struct bake_frames {
  const char *root, *inst, *state, *rig_path;
  const hearth_manifest *man;
  const hearth_camera *cam; /* the colour camera, whole */
  size_t stride;            /* the mapping's pixel grid: every stride-th pixel is decoded */
  size_t win[4];            /* the part of that grid decoded: {x0, y0, w, h} (bake_window) */
} bake_frames;

/* The colour views see the object in a part of the image. The mapping's
 * pixel grid is cut to the window that holds every view's possible hits
 * (hearth_ray_fan_extent) grown by the 2 pixels the silhouette filter reads
 * beyond them, so its per-pixel arrays, the fan and the decoded frames are
 * the window's. The crop is the camera with its principal point moved by
 * the window's corner (a multiple of the stride): every grid pixel keeps
 * its ray, every view its hits and their frame, and the texture is the
 * same. win = {x0, y0, w, h} (grid pixels); the whole grid when a view
 * cannot bound its hits (a vertex behind it) or none has any. */
static void bake_window(const hearth_camera *cam, size_t stride, const hearth_mesh *mesh,
                        const hearth_map_view *views, size_t n_views, hearth_camera *crop,
                        size_t win[4]) {
  const size_t pw = ((size_t)cam->width + stride - 1) / stride,
               ph = ((size_t)cam->height + stride - 1) / stride;
  *crop = *cam;
  win[0] = win[1] = 0;
  win[2] = pw;
  win[3] = ph;
  size_t u[4] = {SIZE_MAX, 0, SIZE_MAX, 0}; /* x0, x1, y0, y1 */
  for (size_t v = 0; v < n_views; v++) {
    size_t b[4];
    if (hearth_ray_fan_extent(cam, stride, mesh, &views[v].T_world_from_cam, 1.0, b, NULL)) return;
    if (b[0] > b[1]) continue;
    u[0] = b[0] < u[0] ? b[0] : u[0];
    u[1] = b[1] > u[1] ? b[1] : u[1];
    u[2] = b[2] < u[2] ? b[2] : u[2];
    u[3] = b[3] > u[3] ? b[3] : u[3];
  }
  if (u[0] > u[1]) return;
  const size_t x0 = u[0] > 2 ? u[0] - 2 : 0, x1 = u[1] + 2 < pw ? u[1] + 2 : pw - 1,
               y0 = u[2] > 2 ? u[2] - 2 : 0, y1 = u[3] + 2 < ph ? u[3] + 2 : ph - 1;
  win[0] = x0;
  win[1] = y0;
  win[2] = x1 - x0 + 1;
  win[3] = y1 - y0 + 1;
  crop->cx = cam->cx - (double)(x0 * stride);
  crop->cy = cam->cy - (double)(y0 * stride);
  /* a grid of exactly w x h pixels, the last one within the image */
  crop->width = (int)((win[2] - 1) * stride + 1);
  crop->height = (int)((win[3] - 1) * stride + 1);
}

/* view k's colour frame: of the colour camera's size (checked before its
   pixels are decoded), RGB, its pixel grid only (the mapping's load_grid);
   header_only: its header alone */
static hearth_status bake_frame(const bake_frames *f, size_t k, int header_only, hearth_image *img,
                                hearth_err *err) {
  char path[PATH_SZ], why[PATH_SZ + 32];
  joinf(path, "%s/instances/%s/raw/%s/%s", f->root, f->inst, f->state, f->man->views[k].rgb);
  snprintf(why, sizeof why, "(the colour camera of %s)", f->rig_path);
  hearth_image_expect want =
      {(size_t)f->cam->width, (size_t)f->cam->height, 0, 0, header_only, why};
  hearth_status s = header_only
                        ? hearth_jpeg_read_grid(path, &want, f->stride, img, err)
                        : hearth_jpeg_read_grid_window(path, &want, f->stride, f->win, img, err);
  if (s) return s;
  if (img->channels != 3) {
    hearth_image_free(img);
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s: expected an RGB image", path);
  }
  return HEARTH_OK;
}

static hearth_status bake_load(void *ctx, size_t k, hearth_image *img, hearth_err *err) {
  return bake_frame(ctx, k, 0, img, err);
}

hearth_status hearth_bake_rgb_run(const hearth_bake_job *job, hearth_err *err) {
  if (!job || !job->root || !job->instance)
    return hearth_err_set(err, HEARTH_E_ARG, "bake: root and instance are required");
  const char *root = job->root, *inst = job->instance;
  char rig_path[PATH_SZ], poses_path[PATH_SZ], mesh_path[PATH_SZ], man_path[PATH_SZ], path[PATH_SZ],
      state[HEARTH_NAME_MAX];
  if (job->rig_path) snprintf(rig_path, PATH_SZ, "%s", job->rig_path);
  else joinf(rig_path, "%s/calibration/rig.json", root);
  if (job->poses_path) snprintf(poses_path, PATH_SZ, "%s", job->poses_path);
  else joinf(poses_path, "%s/instances/%s/derived/poses_rgb.json", root, inst);
  if (job->mesh_path) snprintf(mesh_path, PATH_SZ, "%s", job->mesh_path);
  else joinf(mesh_path, "%s/instances/%s/derived/mesh.glb", root, inst);
  hearth_status s;
  if (job->state) {
    snprintf(state, sizeof state, "%s", job->state);
  } else {
    hearth_instance_doc idoc;
    joinf(path, "%s/instances/%s/instance.json", root, inst);
    if ((s = hearth_instance_load(root, inst, &idoc, err))) return s;
    if (!idoc.n_states) return hearth_err_set(err, HEARTH_E_INCONSISTENT, "%s: no states", path);
    snprintf(state, sizeof state, "%s", idoc.states[0]);
  }
  joinf(man_path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
  hearth_rig rig;
  hearth_manifest man = {0};
  hearth_poses poses = {0};
  hearth_mesh mesh = {0};
  hearth_map_view *views = NULL;
  hearth_map_result r = {0};
  uint8_t *tex_png = NULL; /* the colour texture, PNG-encoded */
  size_t tex_size = 0;
  if ((s = hearth_rig_read(rig_path, &rig, err)) ||
      (s = hearth_rig_require_stereo(&rig, rig_path, "mapping", err)))
    goto done;
  if ((s = hearth_manifest_read(man_path, &man, err))) goto done;
  if ((s = hearth_poses_read(poses_path, &poses, err))) goto done;
  hearth_glb_read_opts gopts = {.require_uvs = 1};
  if ((s = hearth_glb_read(mesh_path, &gopts, &mesh, err))) goto done;
  views = calloc(man.n_views ? man.n_views : 1, sizeof *views);
  if (!views) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "bake: out of memory");
    goto done;
  }
  const int stride = job->pixel_stride > 0 ? job->pixel_stride : 2;
  bake_frames frames = {root, inst, state, rig_path, &man, &rig.rgb, (size_t)stride, {0}};
  for (size_t k = 0; k < man.n_views; k++) {
    const hearth_view_files *vf = &man.views[k];
    const hearth_view_pose *vp = hearth_poses_find(&poses, state, vf->view);
    if (!vp) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no pose for state '%s' view '%s'",
                         poses_path, state, vf->view);
      goto done;
    }
    hearth_image head;
    if ((s = bake_frame(&frames, k, 1, &head, err))) goto done;
    views[k].image = NULL; /* decoded by the mapping (bake_load) */
    views[k].T_world_from_cam = vp->T_world_from_cam;
  }
  hearth_camera crop;
  bake_window(&rig.rgb, (size_t)stride, &mesh, views, man.n_views, &crop, frames.win);
  hearth_map_opts mo;
  hearth_map_opts_default(&mo);
  mo.fusion = HEARTH_FUSE_MEAN;
  mo.resolution = job->resolution ? job->resolution : 1024;
  mo.pixel_stride = stride;
  mo.min_cos = 0.2; /* grazing colour samples smear texture detail */
  mo.threads = job->threads;
  mo.skip_best_cos = 1;
  mo.skip_observed = 1; /* the texture is made from the filled map */
  mo.load = bake_load;
  mo.load_ctx = &frames;
  mo.load_channels = 3;
  mo.load_grid = 1;
  if ((s = hearth_map_views(&mesh, NULL, &crop, views, man.n_views, &mo, &r, err))) goto done;
  if (!r.n_surface) {
    s = hearth_err_set(err, HEARTH_E_RANGE,
                       "%s/%s: %s: the mesh's UV layout covers no texel of the %zux%zu colour "
                       "map (surface 0 texels): its UVs lie outside [0,1] or its UV triangles "
                       "are too small to hold a texel centre",
                       inst, state, mesh_path, r.R, r.R);
    goto done;
  }
  hearth_image_free(&mesh.texture);
  const uint8_t grey[3] = {128, 128, 128};
  if ((s = hearth_map_texture(&r, 0, 255, 8, grey, &mesh.texture, err))) goto done;
  if (job->out_texture) snprintf(path, PATH_SZ, "%s", job->out_texture);
  else joinf(path, "%s/instances/%s/derived/rgb_texture.png", root, inst);
  /* one PNG encoding: the texture file and the GLB's embedded image */
  if ((s = hearth_png_encode(&mesh.texture, &tex_png, &tex_size, err))) {
    hearth_err_prefix(err, "%s", path);
    goto done;
  }
  if ((s = hearth_write_file_atomic(path, tex_png, tex_size, err))) goto done;
  if (job->out_mesh) snprintf(path, PATH_SZ, "%s", job->out_mesh);
  else joinf(path, "%s/instances/%s/derived/mesh.glb", root, inst);
  s = hearth_glb_write_png(path, &mesh, tex_png, tex_size, err);
done:
  free(tex_png);
  hearth_map_result_free(&r);
  free(views);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&poses);
  hearth_manifest_free(&man);
  return s;
}

void hearth_bake_job_default(hearth_bake_job *job) {
  memset(job, 0, sizeof *job);
  job->resolution = 1024;
  job->pixel_stride = 2;
}
