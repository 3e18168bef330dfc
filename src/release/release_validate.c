/* hearth validate: a release checked against docs/dataset.md. Every problem
 * is collected (never just the first) as "path: what"; instances are checked
 * in parallel and their findings merged in release order. */
#include <dirent.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "hearth/image.h"
#include "hearth/mesh.h"
#include "hearth/recon_geom.h"
#include "hearth/npy.h"
#include "hearth/recon.h"
#include "hearth/dataset.h"
#include "hearth/release.h"
#include "hearth/thermal.h"
#include "release/release_internal.h"

#define PATH_SZ 4096

void hearth_problems_free(hearth_problems *p) {
  if (!p) return;
  free(p->items);
  memset(p, 0, sizeof *p);
}

hearth_status hearth_problems_add(hearth_problems *p, const char *path, const char *fmt, ...) {
  if (p->n == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 16;
    hearth_problem *it = realloc(p->items, cap * sizeof *it);
    if (!it) return HEARTH_E_NOMEM;
    p->items = it;
    p->cap = cap;
  }
  hearth_problem *q = &p->items[p->n++];
  snprintf(q->path, sizeof q->path, "%s", path);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(q->what, sizeof q->what, fmt, ap);
  va_end(ap);
  return HEARTH_OK;
}

/* a reader's error as a problem: its message already names the file, so
 * strip a leading "path: " to avoid saying it twice */
static void add_err(hearth_problems *p, const char *path, const hearth_err *e) {
  const char *m = e->msg;
  size_t n = strlen(path);
  if (!strncmp(m, path, n) && m[n] == ':') m += n + 1;
  while (*m == ' ') m++;
  hearth_problems_add(p, path, "%s", *m ? m : hearth_strerror(e->status));
}

void hearth_validate_opts_default(hearth_validate_opts *o) { memset(o, 0, sizeof *o); }

/* ---- image headers ------------------------------------------------------- */
typedef struct img_info {
  size_t w, h;
  int channels, bits;
} img_info;

static uint32_t be32(const uint8_t *b) {
  return ((uint32_t)b[0] << 24) | ((uint32_t)b[1] << 16) | ((uint32_t)b[2] << 8) | b[3];
}

/* PNG: IHDR must be the first chunk; the file must end with IEND */
static int png_info(const uint8_t *d, size_t n, img_info *ii, char *why, size_t wsz) {
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n < 33 + 12 || memcmp(d, sig, 8) || memcmp(d + 12, "IHDR", 4)) {
    snprintf(why, wsz, "not a PNG file");
    return 0;
  }
  ii->w = be32(d + 16);
  ii->h = be32(d + 20);
  ii->bits = d[24];
  switch (d[25]) {
    case 0: ii->channels = 1; break;
    case 2: ii->channels = 3; break;
    case 3: ii->channels = 3; break;
    case 4: ii->channels = 2; break;
    case 6: ii->channels = 4; break;
    default: snprintf(why, wsz, "PNG colour type %d is invalid", d[25]); return 0;
  }
  if (memcmp(d + n - 8, "IEND", 4)) {
    snprintf(why, wsz, "PNG is truncated (no IEND chunk at the end)");
    return 0;
  }
  return 1;
}

/* JPEG: SOI, then markers up to the first start-of-frame; ends with EOI */
static int jpeg_info(const uint8_t *d, size_t n, img_info *ii, char *why, size_t wsz) {
  if (n < 4 || d[0] != 0xFF || d[1] != 0xD8) {
    snprintf(why, wsz, "not a JPEG file");
    return 0;
  }
  size_t i = 2;
  while (i + 4 <= n) {
    if (d[i] != 0xFF) {
      snprintf(why, wsz, "JPEG marker expected at byte %zu", i);
      return 0;
    }
    uint8_t m = d[i + 1];
    if (m == 0xFF) {
      i++;
      continue;
    }
    size_t len = ((size_t)d[i + 2] << 8) | d[i + 3];
    if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC) {
      if (i + 10 > n) break;
      ii->bits = d[i + 4];
      ii->h = ((size_t)d[i + 5] << 8) | d[i + 6];
      ii->w = ((size_t)d[i + 7] << 8) | d[i + 8];
      ii->channels = d[i + 9];
      int k = 0;
      while (n - k > 2 && d[n - 1 - k] != 0xD9 && k < 64) k++; /* tolerate trailing padding */
      if (n < 2 + (size_t)k || d[n - 2 - k] != 0xFF || d[n - 1 - k] != 0xD9) {
        snprintf(why, wsz, "JPEG is truncated (no end-of-image marker)");
        return 0;
      }
      return 1;
    }
    i += 2 + len;
  }
  snprintf(why, wsz, "JPEG has no frame header");
  return 0;
}

typedef enum { IMG_PNG, IMG_JPEG } img_kind;

/* check an image file's kind, size, channels and bit depth; decode fully if asked */
static void check_image(hearth_problems *p, const char *path, img_kind kind, size_t w, size_t h,
                        const int *channels_ok, int bits, int decode, size_t *nfiles) {
  uint8_t *d = NULL;
  size_t n = 0;
  hearth_err e = {0};
  (*nfiles)++;
  if (hearth_read_file(path, (size_t)256 << 20, &d, &n, &e)) {
    add_err(p, path, &e);
    return;
  }
  img_info ii = {0};
  char why[256];
  int ok = kind == IMG_PNG ? png_info(d, n, &ii, why, sizeof why)
                           : jpeg_info(d, n, &ii, why, sizeof why);
  if (!ok) {
    hearth_problems_add(p, path, "%s", why);
  } else {
    int fine = 1;
    if ((w && ii.w != w) || (h && ii.h != h)) {
      hearth_problems_add(p, path, "image is %zux%zu, expected %zux%zu", ii.w, ii.h, w ? w : ii.w,
                          h ? h : ii.h);
      fine = 0;
    }
    int cok = 0;
    for (const int *c = channels_ok; *c; c++) cok |= *c == ii.channels;
    if (!cok)
      hearth_problems_add(p, path, "image has %d channel(s), which this file may not have",
                          ii.channels);
    if (bits && ii.bits != bits)
      hearth_problems_add(p, path, "image is %d-bit, expected %d-bit", ii.bits, bits);
    /* a header that disagrees is reported without decoding what it declares */
    if (decode && fine && cok) {
      hearth_image img = {0};
      hearth_status s = kind == IMG_PNG ? hearth_png_read_mem(d, n, path, &img, &e)
                                        : hearth_jpeg_read_mem(d, n, path, &img, &e);
      if (s) add_err(p, path, &e);
      hearth_image_free(&img);
    }
  }
  free(d);
}

/* 1 if anything is at path; a FIFO, device or directory in place of a file
 * is then reported by the reader that follows ("not a regular file (a
 * FIFO)"), never called missing and never waited on */
static int present(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

/* tw x th: the thermal camera's size (0 x 0: any consistent rectangle) */
static void check_csv(hearth_problems *p, const char *path, size_t tw, size_t th, size_t *nfiles) {
  hearth_csv_opts co = {tw, th};
  hearth_image img = {0};
  hearth_err e = {0};
  (*nfiles)++;
  if (hearth_thermal_read_csv(path, &co, &img, &e)) add_err(p, path, &e);
  hearth_image_free(&img);
}

/* ---- one instance --------------------------------------------------------- */
typedef struct state_views {
  char state[HEARTH_NAME_MAX];
  hearth_manifest man; /* n_views == 0 if unreadable */
  int ok;
} state_views;

static int has_view(const state_views *sv, size_t ns, const char *state, const char *view) {
  for (size_t i = 0; i < ns; i++) {
    if (strcmp(sv[i].state, state)) continue;
    for (size_t k = 0; k < sv[i].man.n_views; k++)
      if (!strcmp(sv[i].man.views[k].view, view)) return 1;
  }
  return 0;
}

/* a poses file: readable (rotations are checked by the reader), every entry
 * names a view of a state of this instance, and (every_view) every view has
 * a pose, else at least one view has; keep (optional) takes the poses when
 * they read, else stays zeroed. 1 if they read. */
static int check_poses(hearth_problems *p, const char *path, const state_views *sv, size_t ns,
                       int every_view, hearth_poses *keep, size_t *nfiles) {
  hearth_poses poses = {0};
  hearth_err e = {0};
  (*nfiles)++;
  if (!present(path)) {
    hearth_problems_add(p, path, "missing");
    return 0;
  }
  if (hearth_poses_read(path, &poses, &e)) {
    add_err(p, path, &e);
    return 0;
  }
  for (size_t i = 0; i < poses.n; i++) {
    int state_known = 0;
    for (size_t k = 0; k < ns; k++) state_known |= !strcmp(sv[k].state, poses.views[i].state);
    if (!state_known)
      hearth_problems_add(p, path, "views[%zu]: state '%s' is not a state of this instance", i,
                          poses.views[i].state);
    else if (!has_view(sv, ns, poses.views[i].state, poses.views[i].view))
      hearth_problems_add(p, path, "views[%zu]: view '%s' does not exist in state '%s'", i,
                          poses.views[i].view, poses.views[i].state);
  }
  for (size_t k = 0; every_view && k < ns; k++)
    for (size_t v = 0; v < sv[k].man.n_views; v++)
      if (!hearth_poses_find(&poses, sv[k].state, sv[k].man.views[v].view))
        hearth_problems_add(p, path, "no pose for state '%s' view '%s'", sv[k].state,
                            sv[k].man.views[v].view);
  if (!every_view && !poses.n) hearth_problems_add(p, path, "no view has a pose");
  if (keep) *keep = poses;
  else hearth_poses_free(&poses);
  return 1;
}

static void check_provenance(hearth_problems *p, const char *path, const char *inst,
                             const state_views *sv, size_t R, size_t *nfiles) {
  (*nfiles)++;
  json_error_t je;
  hearth_err e = {0};
  uint8_t *text = NULL;
  size_t len = 0;
  if (!present(path)) {
    hearth_problems_add(p, path, "missing");
    return;
  }
  if (hearth_read_file(path, (size_t)16 << 20, &text, &len, &e)) {
    add_err(p, path, &e);
    return;
  }
  json_t *o = json_loadb((const char *)text, len, JSON_REJECT_DUPLICATES, &je);
  free(text);
  if (!o) {
    hearth_problems_add(p, path, "line %d, column %d: %s", je.line, je.column, je.text);
    return;
  }
  if (!json_is_object(o)) {
    hearth_problems_add(p, path, "expected an object at the top level");
    json_decref(o);
    return;
  }
  json_t *ji = json_object_get(o, "instance"), *js = json_object_get(o, "state");
  if (!json_is_string(ji)) hearth_problems_add(p, path, "instance: expected a string");
  else if (strcmp(json_string_value(ji), inst))
    hearth_problems_add(p, path, "instance: names '%s', expected '%s'", json_string_value(ji),
                        inst);
  if (!json_is_string(js)) hearth_problems_add(p, path, "state: expected a string");
  else if (strcmp(json_string_value(js), sv->state))
    hearth_problems_add(p, path, "state: names '%s', expected '%s'", json_string_value(js),
                        sv->state);
  json_t *jv = json_object_get(o, "source_views");
  if (!json_is_array(jv)) {
    hearth_problems_add(p, path, "source_views: expected an array of view names");
  } else {
    size_t i;
    json_t *x;
    json_array_foreach(jv, i, x) {
      if (!json_is_string(x)) {
        hearth_problems_add(p, path, "source_views[%zu]: expected a string", i);
        continue;
      }
      if (!has_view(sv, 1, sv->state, json_string_value(x)))
        hearth_problems_add(p, path, "source_views[%zu]: view '%s' does not exist in %s's manifest",
                            i, json_string_value(x), sv->state);
      for (size_t k = 0; k < i; k++)
        if (json_is_string(json_array_get(jv, k)) &&
            !strcmp(json_string_value(json_array_get(jv, k)), json_string_value(x)))
          hearth_problems_add(p, path, "source_views[%zu]: view '%s' listed twice", i,
                              json_string_value(x));
    }
  }
  json_t *jr = json_object_get(o, "rig");
  if (!json_is_object(jr) || !json_is_string(json_object_get(jr, "path")))
    hearth_problems_add(p, path, "rig.path: expected a string");
  json_t *jp = json_object_get(o, "parameters");
  if (!json_is_object(jp)) {
    hearth_problems_add(p, path, "parameters: expected an object");
  } else {
    json_t *res = json_object_get(jp, "resolution");
    if (!json_is_integer(res))
      hearth_problems_add(p, path, "parameters.resolution: expected an integer");
    else if (R && (size_t)json_integer_value(res) != R)
      hearth_problems_add(p, path, "parameters.resolution: %lld, but the maps are %zux%zu",
                          (long long)json_integer_value(res), R, R);
    if (!json_is_string(json_object_get(jp, "fusion")))
      hearth_problems_add(p, path, "parameters.fusion: expected a string");
  }
  if (!json_is_string(json_object_get(o, "software_version")))
    hearth_problems_add(p, path, "software_version: expected a string");
  json_decref(o);
}

/* a 2-D npy of the given dtype; returns 1 and fills a when readable */
static int read_map(hearth_problems *p, const char *path, hearth_npy_dtype dt, hearth_npy *a,
                    size_t *nfiles) {
  hearth_err e = {0};
  (*nfiles)++;
  if (!present(path)) {
    hearth_problems_add(p, path, "missing");
    return 0;
  }
  if (hearth_npy_read(path, a, &e)) {
    add_err(p, path, &e);
    return 0;
  }
  if (a->dtype != dt || a->ndim != 2 || a->shape[0] != a->shape[1] || !a->shape[0]) {
    hearth_problems_add(p, path, "expected a square 2-D %s array, found %s with %d dimension(s)",
                        dt == HEARTH_NPY_F32 ? "float32" : "uint8",
                        a->dtype == HEARTH_NPY_F32 ? "float32" : "uint8", a->ndim);
    hearth_npy_free(a);
    return 0;
  }
  return 1;
}

static void check_state_maps(hearth_problems *p, const char *dir, const char *inst,
                             const state_views *sv, size_t *nfiles) {
  char path[PATH_SZ];
  hearth_npy mask = {0}, obs = {0}, fil = {0};
  snprintf(path, sizeof path, "%s/mask.npy", dir);
  int have_mask = read_map(p, path, HEARTH_NPY_U8, &mask, nfiles);
  size_t R = have_mask ? mask.shape[0] : 0;
  char opath[PATH_SZ], fpath[PATH_SZ];
  snprintf(opath, sizeof opath, "%s/temperature_observed.npy", dir);
  snprintf(fpath, sizeof fpath, "%s/temperature_filled.npy", dir);
  int have_obs = read_map(p, opath, HEARTH_NPY_F32, &obs, nfiles);
  int have_fil = read_map(p, fpath, HEARTH_NPY_F32, &fil, nfiles);
  if (have_obs && R && obs.shape[0] != R) {
    hearth_problems_add(p, opath, "map is %zux%zu but mask.npy is %zux%zu", obs.shape[0],
                        obs.shape[1], R, R);
    have_obs = 0;
  }
  if (have_fil && R && fil.shape[0] != R) {
    hearth_problems_add(p, fpath, "map is %zux%zu but mask.npy is %zux%zu", fil.shape[0],
                        fil.shape[1], R, R);
    have_fil = 0;
  }
  if (have_mask) {
    const uint8_t *m = mask.data;
    const float *o = have_obs ? obs.data : NULL, *f = have_fil ? fil.data : NULL;
    size_t bad_mask = 0, bad_obs = 0, bad_fil = 0, first_mask = 0, first_obs = 0, first_fil = 0;
    size_t n = R * R;
    for (size_t i = 0; i < n; i++) {
      if (m[i] > 3) {
        if (!bad_mask++) first_mask = i;
        continue;
      }
      if (o && m[i] == 1 &&
          !(isfinite(o[i]) && o[i] >= HEARTH_THERMAL_MIN_C && o[i] <= HEARTH_THERMAL_MAX_C))
        if (!bad_obs++) first_obs = i;
      if (f && (m[i] == 1 || m[i] == 2) &&
          !(isfinite(f[i]) && f[i] >= HEARTH_THERMAL_MIN_C && f[i] <= HEARTH_THERMAL_MAX_C))
        if (!bad_fil++) first_fil = i;
    }
    if (bad_mask)
      hearth_problems_add(p, path,
                          "%zu texel(s) with a value outside {0,1,2,3}, first [%zu][%zu] = %u",
                          bad_mask, first_mask / R, first_mask % R, m[first_mask]);
    if (bad_obs)
      hearth_problems_add(p, opath,
                          "%zu observed texel(s) (mask 1) not a temperature in -50..650 degC, "
                          "first [%zu][%zu]",
                          bad_obs, first_obs / R, first_obs % R);
    if (bad_fil)
      hearth_problems_add(p, fpath,
                          "%zu texel(s) with mask 1 or 2 not a temperature in -50..650 "
                          "degC, first [%zu][%zu]",
                          bad_fil, first_fil / R, first_fil % R);
  }
  static const int rgb_only[] = {3, 0};
  snprintf(path, sizeof path, "%s/thermal_turbo.png", dir);
  if (!present(path)) {
    (*nfiles)++;
    hearth_problems_add(p, path, "missing");
  } else {
    check_image(p, path, IMG_PNG, R, R, rgb_only, 8, 0, nfiles);
  }
  snprintf(path, sizeof path, "%s/provenance.json", dir);
  check_provenance(p, path, inst, sv, R, nfiles);
  hearth_npy_free(&mask);
  hearth_npy_free(&obs);
  hearth_npy_free(&fil);
}

/* leftovers of interrupted atomic writes anywhere under dir (a killed build
 * or capture tool); they are not part of the release. Sorted per directory
 * for a deterministic problem order. */
static int cmp_str(const void *a, const void *b) {
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static void check_leftovers(hearth_problems *p, const char *dir, int depth) {
  DIR *d = opendir(dir);
  if (!d) return;
  char **names = NULL;
  size_t n = 0, cap = 0;
  struct dirent *e;
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    if (n == cap) {
      char **q = realloc(names, (cap = cap ? 2 * cap : 16) * sizeof *q);
      if (!q) break;
      names = q;
    }
    if (!(names[n] = strdup(e->d_name))) break;
    n++;
  }
  closedir(d);
  if (n) qsort(names, n, sizeof *names, cmp_str);
  for (size_t i = 0; i < n; i++) {
    char path[PATH_SZ];
    struct stat st;
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    long pid;
    if (hearth_temp_parse(names[i], NULL, &pid)) {
      if (hearth_temp_writer_alive(pid))
        hearth_problems_add(p, path, "a temporary of process %ld, which is still writing", pid);
      else hearth_problems_add(p, path, "left by an interrupted write (hearth build removes it)");
    } else if (depth < 8 && lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
      check_leftovers(p, path, depth + 1);
    free(names[i]);
  }
  free(names);
}

/* what check_recon_files read of recon/ for check_recon_report: the poses
 * (zeroed unless they read), the geometry mesh's sizes and the mesh's UV
 * islands (-1 unless they read) */
typedef struct recon_read {
  hearth_poses poses;
  int poses_read;
  long long mesh_vertices, mesh_triangles, mesh_open_loops, atlas_charts;
} recon_read;

/* recon/report.json (hearth recon's turntable route), when present: its
 * members against the manifests and what check_recon_files read of
 * recon/poses_rgb.json and the meshes beside it */
static void check_recon_report(hearth_problems *p, const char *dir, const char *id,
                               const hearth_instance_doc *doc, const state_views *sv,
                               const recon_read *rr, size_t *nfiles) {
  char path[PATH_SZ];
  snprintf(path, sizeof path, "%s/recon/report.json", dir);
  if (!present(path)) return;
  (*nfiles)++;
  hearth_err e = {0};
  uint8_t *text = NULL;
  size_t len = 0;
  if (hearth_read_file(path, (size_t)64 << 20, &text, &len, &e)) {
    add_err(p, path, &e);
    return;
  }
  hearth_manifest man[HEARTH_MAX_STATES];
  const char *states[HEARTH_MAX_STATES];
  size_t ns = doc->n_states < HEARTH_MAX_STATES ? doc->n_states : HEARTH_MAX_STATES;
  long long all = 0;
  for (size_t k = 0; k < ns; k++) {
    states[k] = doc->states[k];
    man[k] = sv[k].man;
    if (!sv[k].ok) all = -1;
    else if (all >= 0) all += (long long)sv[k].man.n_views;
  }
  hb_recon_expect x = {id,
                       ns,
                       states,
                       man,
                       all,
                       rr->poses_read ? &rr->poses : NULL,
                       rr->mesh_vertices,
                       rr->mesh_triangles,
                       rr->mesh_open_loops,
                       rr->atlas_charts};
  hb_recon_report_check((const char *)text, len, path, &x, p);
  free(text);
}

/* recon/, the reconstruction's hand-over (an outside tool's, the virtual
 * rig's stand-in or hearth's own): every file a rebuild reads from it must
 * read with the strict readers. Its poses may leave views out (a COLMAP
 * model that did not register them), but each names a view of this
 * instance; the mesh (with UVs), the geometry-only mesh, the texture and
 * the cameras document are checked where present (hearth recon --no-mesh
 * leaves poses only). */
static void check_recon_files(hearth_problems *p, const char *dir, const state_views *sv, size_t ns,
                              int decode, recon_read *rr, size_t *nfiles) {
  char f[PATH_SZ];
  hearth_err e = {0};
  snprintf(f, sizeof f, "%s/recon", dir);
  if (!hearth_path_exists(f)) return;
  snprintf(f, sizeof f, "%s/recon/poses_rgb.json", dir);
  rr->poses_read = check_poses(p, f, sv, ns, 0, &rr->poses, nfiles);
  static const char *glbs[2] = {"mesh.glb", "mesh_geometry.glb"};
  for (int j = 0; j < 2; j++) {
    snprintf(f, sizeof f, "%s/recon/%s", dir, glbs[j]);
    if (!present(f)) continue; /* hearth recon --no-mesh writes poses only */
    (*nfiles)++;
    hearth_mesh mesh = {0};
    hearth_glb_read_opts go = {.require_uvs = j == 0};
    if (hearth_glb_read(f, &go, &mesh, &e)) {
      add_err(p, f, &e);
    } else if (j == 0) {
      rr->atlas_charts = hb_mesh_islands(&mesh);
    } else {
      rr->mesh_vertices = (long long)mesh.n_vertices;
      rr->mesh_triangles = (long long)mesh.n_triangles;
      size_t loops = 0;
      if (hearth_mesh_open_loops(&mesh, &loops, NULL, &e)) add_err(p, f, &e);
      else rr->mesh_open_loops = (long long)loops;
    }
    hearth_mesh_free(&mesh);
  }
  static const int rgb34[] = {3, 4, 0};
  snprintf(f, sizeof f, "%s/recon/rgb_texture.png", dir);
  if (present(f)) check_image(p, f, IMG_PNG, 0, 0, rgb34, 8, decode, nfiles);
  snprintf(f, sizeof f, "%s/recon/poses_rgb_cameras.json", dir);
  if (present(f)) {
    (*nfiles)++;
    hearth_recon_cameras cams = {0};
    if (hearth_recon_cameras_read(f, &cams, &e)) add_err(p, f, &e);
    hearth_recon_cameras_free(&cams);
  }
}

static void check_instance(const char *root, const char *id, const hearth_validate_opts *o,
                           const size_t tsize[2], hearth_problems *p, size_t *nfiles) {
  char path[PATH_SZ], dir[PATH_SZ];
  hearth_err e = {0};
  snprintf(dir, sizeof dir, "%s/instances/%s", root, id);
  check_leftovers(p, dir, 0);
  snprintf(path, sizeof path, "%s/instance.json", dir);
  hearth_instance_doc doc;
  (*nfiles)++;
  if (!present(path)) {
    hearth_problems_add(p, dir, "instance listed in release.json has no instance.json");
    return;
  }
  if (hearth_instance_read(path, &doc, &e)) {
    add_err(p, path, &e);
    return;
  }
  if (strcmp(doc.id, id))
    hearth_problems_add(p, path, "id: '%s', but the directory is instances/%s", doc.id, id);
  state_views *sv = calloc(doc.n_states ? doc.n_states : 1, sizeof *sv);
  if (!sv) {
    hearth_problems_add(p, dir, "out of memory");
    return;
  }
  static const int rgb3[] = {3, 0}, cut[] = {1, 2, 4, 0}, gray[] = {1, 0};
  for (size_t k = 0; k < doc.n_states; k++) {
    snprintf(sv[k].state, sizeof sv[k].state, "%s", doc.states[k]);
    char sdir[PATH_SZ];
    snprintf(sdir, sizeof sdir, "%s/raw/%s", dir, doc.states[k]);
    snprintf(path, sizeof path, "%s/manifest.json", sdir);
    (*nfiles)++;
    if (!present(path)) {
      hearth_problems_add(p, path, "missing (state '%s' is listed in instance.json)",
                          doc.states[k]);
      continue;
    }
    if (hearth_manifest_read(path, &sv[k].man, &e)) {
      add_err(p, path, &e);
      continue;
    }
    sv[k].ok = 1;
    if (strcmp(sv[k].man.instance, id) || strcmp(sv[k].man.state, doc.states[k]))
      hearth_problems_add(p, path, "names instance '%s' state '%s', expected '%s' '%s'",
                          sv[k].man.instance, sv[k].man.state, id, doc.states[k]);
    for (size_t v = 0; v < sv[k].man.n_views; v++) {
      const hearth_view_files *vf = &sv[k].man.views[v];
      char f[PATH_SZ];
      const struct {
        const char *rel, *what;
      } files[5] = {{vf->rgb, "rgb"},
                    {vf->cutout, "cutout"},
                    {vf->depth, "depth"},
                    {vf->depth_intrinsics, "depth_intrinsics"},
                    {vf->thermal, "thermal"}};
      int have[5];
      for (int j = 0; j < 5; j++) {
        snprintf(f, sizeof f, "%s/%s", sdir, files[j].rel);
        have[j] = present(f);
        if (!have[j]) {
          (*nfiles)++;
          hearth_problems_add(p, f, "missing (view %s's %s in %s/manifest.json)", vf->view,
                              files[j].what, doc.states[k]);
        }
      }
      if (have[0]) {
        snprintf(f, sizeof f, "%s/%s", sdir, vf->rgb);
        check_image(p, f, IMG_JPEG, 1920, 1080, rgb3, 8, o->decode_images, nfiles);
      }
      if (have[1]) {
        snprintf(f, sizeof f, "%s/%s", sdir, vf->cutout);
        check_image(p, f, IMG_PNG, 1920, 1080, cut, 8, o->decode_images, nfiles);
      }
      if (have[2]) {
        snprintf(f, sizeof f, "%s/%s", sdir, vf->depth);
        check_image(p, f, IMG_PNG, 640, 576, gray, 16, o->decode_images, nfiles);
      }
      if (have[3]) {
        hearth_depth_intrinsics di;
        snprintf(f, sizeof f, "%s/%s", sdir, vf->depth_intrinsics);
        (*nfiles)++;
        if (hearth_depth_intrinsics_read(f, &di, &e)) add_err(p, f, &e);
        else if (di.depth.width != 640 || di.depth.height != 576)
          hearth_problems_add(p, f, "width x height %dx%d, but depth/%s.png is 640x576",
                              (int)di.depth.width, (int)di.depth.height, vf->view);
      }
      if (have[4]) {
        snprintf(f, sizeof f, "%s/%s", sdir, vf->thermal);
        check_csv(p, f, tsize[0], tsize[1], nfiles);
      }
    }
  }
  recon_read rr = {{0}, 0, -1, -1, -1, -1};
  check_recon_files(p, dir, sv, doc.n_states, o->decode_images, &rr, nfiles);
  check_recon_report(p, dir, id, &doc, sv, &rr, nfiles);
  hearth_poses_free(&rr.poses);
  if (o->raw_only) goto done;

  /* derived/: scale, mesh, poses, per-state maps (one line if never built) */
  snprintf(path, sizeof path, "%s/derived", dir);
  if (!hearth_path_exists(path)) {
    hearth_problems_add(p, path,
                        "missing: the instance was never built (run `hearth build`, "
                        "or validate a capture with --raw-only)");
    goto done;
  }
  snprintf(path, sizeof path, "%s/derived/scale.json", dir);
  (*nfiles)++;
  hearth_scale_doc sd;
  if (!present(path)) hearth_problems_add(p, path, "missing");
  else if (hearth_scale_doc_read(path, &sd, &e)) add_err(p, path, &e);
  snprintf(path, sizeof path, "%s/derived/mesh.glb", dir);
  (*nfiles)++;
  if (!present(path)) {
    hearth_problems_add(p, path, "missing");
  } else {
    hearth_mesh mesh = {0};
    hearth_glb_read_opts go = {.require_uvs = 1};
    if (hearth_glb_read(path, &go, &mesh, &e)) add_err(p, path, &e);
    hearth_mesh_free(&mesh);
  }
  static const char *pose_files[] = {"poses_rgb.json", "poses_thermal_transferred.json",
                                     "poses_thermal.json"};
  for (int j = 0; j < 3; j++) {
    snprintf(path, sizeof path, "%s/derived/%s", dir, pose_files[j]);
    check_poses(p, path, sv, doc.n_states, 1, NULL, nfiles);
  }
  for (size_t k = 0; k < doc.n_states; k++) {
    if (!sv[k].ok) continue;
    char sdir[PATH_SZ];
    snprintf(sdir, sizeof sdir, "%s/derived/%s", dir, doc.states[k]);
    check_state_maps(p, sdir, id, &sv[k], nfiles);
  }
done:
  for (size_t k = 0; k < doc.n_states; k++) hearth_manifest_free(&sv[k].man);
  free(sv);
}

/* ---- release level --------------------------------------------------------- */
/* The thermal camera's size into tsize: rig.json's when it reads, else the
 * first thermal capture's, else 0 x 0 (any). */
static void check_calibration(const char *root, const hearth_validate_opts *o, hearth_problems *p,
                              size_t tsize[2], size_t *nfiles) {
  char path[PATH_SZ];
  hearth_err e = {0};
  hearth_rig rig;
  snprintf(path, sizeof path, "%s/calibration", root);
  check_leftovers(p, path, 0);
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  (*nfiles)++;
  if (!present(path)) {
    if (!o->raw_only) hearth_problems_add(p, path, "missing");
  } else if (hearth_rig_read(path, &rig, &e)) {
    add_err(p, path, &e);
  } else if (rig.thermal_only) {
    hearth_problems_add(p, path,
                        "a thermal-only rig (hearth calibrate --thermal-only): a release needs "
                        "the stereo calibration (the colour camera and T_thermal_from_rgb)");
  } else if (rig.rgb.width != 1920 || rig.rgb.height != 1080 || rig.depth.width != 640 ||
             rig.depth.height != 576) {
    hearth_problems_add(p, path, "camera sizes rgb %dx%d, depth %dx%d; expected 1920x1080, 640x576",
                        (int)rig.rgb.width, (int)rig.rgb.height, (int)rig.depth.width,
                        (int)rig.depth.height);
  } else {
    tsize[0] = (size_t)rig.thermal.width;
    tsize[1] = (size_t)rig.thermal.height;
  }
  if (!tsize[0]) {
    /* no usable rig.json: the size of the first thermal capture */
    const char *first[2] = {"thermal", "stereo"};
    for (int j = 0; j < 2 && !tsize[0]; j++) {
      char dir[PATH_SZ];
      snprintf(dir, sizeof dir, "%s/calibration/captures/%s", root, first[j]);
      struct dirent **ents = NULL;
      int n = scandir(dir, &ents, NULL, alphasort);
      for (int i = 0; i < n; i++) {
        size_t L = strlen(ents[i]->d_name);
        if (!tsize[0] && L > 4 && !strcmp(ents[i]->d_name + L - 4, ".csv")) {
          char f[PATH_SZ];
          hearth_csv_opts any = {0, 0};
          hearth_image img = {0};
          snprintf(f, sizeof f, "%s/%s", dir, ents[i]->d_name);
          if (!hearth_thermal_read_csv(f, &any, &img, NULL)) {
            tsize[0] = img.width;
            tsize[1] = img.height;
          }
          hearth_image_free(&img);
        }
        free(ents[i]);
      }
      free(ents);
    }
  }
  snprintf(path, sizeof path, "%s/calibration/factory.json", root);
  if (present(path)) {
    hearth_factory_calib f;
    (*nfiles)++;
    if (hearth_factory_read(path, &f, &e)) add_err(p, path, &e);
  }
  /* the target (optional) and the detections made for it */
  hearth_target target = hearth_target_default();
  int target_ok = 1;
  snprintf(path, sizeof path, "%s/calibration/target.json", root);
  if (present(path)) {
    (*nfiles)++;
    if (hearth_target_read(path, &target, &e)) {
      add_err(p, path, &e);
      target_ok = 0;
    }
  }
  snprintf(path, sizeof path, "%s/calibration/detections.json", root);
  if (present(path)) {
    hearth_detections d = {0};
    (*nfiles)++;
    if (hearth_detections_read(path, &d, &e)) {
      add_err(p, path, &e);
    } else {
      hearth_target td;
      const hearth_target *dt = hearth_target_or_default(&d.target, &td);
      if (target_ok &&
          (dt->lattice != target.lattice || dt->rows != target.rows || dt->cols != target.cols))
        hearth_problems_add(p, path,
                            "made for a %s %d x %d target, calibration/target.json says %s %d x %d",
                            hearth_lattice_name(dt->lattice), dt->rows, dt->cols,
                            hearth_lattice_name(target.lattice), target.rows, target.cols);
    }
    hearth_detections_free(&d);
  }
  /* capture frames: thermal CSVs and stereo JPEGs */
  static const int rgb3[] = {3, 0};
  const char *sub[2] = {"thermal", "stereo"};
  for (int j = 0; j < 2; j++) {
    char dir[PATH_SZ];
    snprintf(dir, sizeof dir, "%s/calibration/captures/%s", root, sub[j]);
    struct dirent **ents = NULL;
    int n = scandir(dir, &ents, NULL, alphasort);
    for (int i = 0; i < n; i++) {
      const char *nm = ents[i]->d_name;
      size_t L = strlen(nm);
      snprintf(path, sizeof path, "%s/%s", dir, nm);
      if (L > 4 && !strcmp(nm + L - 4, ".csv")) check_csv(p, path, tsize[0], tsize[1], nfiles);
      else if (L > 4 && !strcmp(nm + L - 4, ".jpg"))
        check_image(p, path, IMG_JPEG, 1920, 1080, rgb3, 8, o->decode_images, nfiles);
      free(ents[i]);
    }
    free(ents);
  }
}

static void check_ground_truth(const char *root, const hearth_release_doc *rel, hearth_problems *p,
                               size_t *nfiles) {
  char path[PATH_SZ];
  hearth_err e = {0};
  snprintf(path, sizeof path, "%s/ground_truth", root);
  if (!hearth_path_exists(path)) return;
  hearth_rig rig;
  snprintf(path, sizeof path, "%s/ground_truth/rig.json", root);
  (*nfiles)++;
  if (hearth_rig_read(path, &rig, &e)) add_err(p, path, &e);
  for (size_t i = 0; i < rel->n_instances; i++) {
    hearth_scale_doc sd;
    snprintf(path, sizeof path, "%s/ground_truth/instances/%s/scale.json", root, rel->instances[i]);
    (*nfiles)++;
    if (hearth_scale_doc_read(path, &sd, &e)) add_err(p, path, &e);
  }
}

typedef struct vctx {
  size_t tsize[2]; /* the thermal camera's size */
  const char *root;
  const hearth_release_doc *rel;
  const hearth_validate_opts *o;
  hearth_problems *per; /* one list per instance */
  size_t *nfiles;
} vctx;

static void validate_range(void *ctx, size_t b, size_t e, int t) {
  vctx *c = ctx;
  for (size_t i = b; i < e; i++)
    check_instance(c->root, c->rel->instances[i], c->o, c->tsize, &c->per[i], &c->nfiles[i]);
}

hearth_status hearth_validate_release(const char *root, const hearth_validate_opts *o,
                                      hearth_problems *out, size_t *files_checked,
                                      hearth_err *err) {
  if (!root || !out)
    return hearth_err_set(err, HEARTH_E_ARG, "validate: root and out are required");
  hearth_validate_opts def;
  if (!o) {
    hearth_validate_opts_default(&def);
    o = &def;
  }
  size_t nfiles = 0;
  char path[PATH_SZ];
  hearth_err e = {0};
  snprintf(path, sizeof path, "%s/release.json", root);
  hearth_release_doc rel = {0};
  nfiles++;
  if (!present(path)) {
    hearth_problems_add(out, path, "missing (is %s a release root?)", root);
    if (files_checked) *files_checked = nfiles;
    return HEARTH_OK;
  }
  if (hearth_release_read(path, &rel, &e)) add_err(out, path, &e);
  /* the parameters of the last build (optional) */
  snprintf(path, sizeof path, "%s/build.json", root);
  if (present(path)) {
    hb_params bp;
    nfiles++;
    if (hb_params_read(path, &bp, &e)) add_err(out, path, &e);
  }
  size_t tsize[2] = {0, 0};
  check_calibration(root, o, out, tsize, &nfiles);

  /* directories under instances/ that release.json does not list */
  snprintf(path, sizeof path, "%s/instances", root);
  struct dirent **ents = NULL;
  int nd = scandir(path, &ents, NULL, alphasort);
  for (int i = 0; i < nd; i++) {
    const char *nm = ents[i]->d_name;
    if (nm[0] != '.') {
      int listed = 0;
      for (size_t k = 0; k < rel.n_instances; k++) listed |= !strcmp(rel.instances[k], nm);
      char d[PATH_SZ];
      snprintf(d, sizeof d, "%s/instances/%s", root, nm);
      if (!listed) hearth_problems_add(out, d, "instance directory not listed in release.json");
    }
    free(ents[i]);
  }
  free(ents);

  hearth_problems *per = calloc(rel.n_instances ? rel.n_instances : 1, sizeof *per);
  size_t *nf = calloc(rel.n_instances ? rel.n_instances : 1, sizeof *nf);
  if (!per || !nf) {
    free(per);
    free(nf);
    hearth_release_free(&rel);
    return hearth_err_set(err, HEARTH_E_NOMEM, "validate: out of memory");
  }
  vctx c = {{tsize[0], tsize[1]}, root, &rel, o, per, nf};
  int nt = o->threads > 0 ? o->threads : hearth_default_threads();
  if ((size_t)nt > rel.n_instances) nt = rel.n_instances ? (int)rel.n_instances : 1;
  hearth_status s = hearth_parallel_for(rel.n_instances, nt, validate_range, &c);
  for (size_t i = 0; i < rel.n_instances; i++) {
    for (size_t k = 0; k < per[i].n && s == HEARTH_OK; k++)
      if (hearth_problems_add(out, per[i].items[k].path, "%s", per[i].items[k].what))
        s = hearth_err_set(err, HEARTH_E_NOMEM, "validate: out of memory");
    nfiles += nf[i];
    hearth_problems_free(&per[i]);
  }
  if (s == HEARTH_OK) check_ground_truth(root, &rel, out, &nfiles);
  free(per);
  free(nf);
  hearth_release_free(&rel);
  if (files_checked) *files_checked = nfiles;
  return s;
}
