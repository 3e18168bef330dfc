/* hearth stats: the paper's "Object dataset overview" table for a release
 * tree, counted from the files that are actually there. */
#include <dirent.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "hearth/image.h"
#include "hearth/npy.h"
#include "hearth/dataset.h"
#include "hearth/release.h"
#include "hearth/thermal.h"

#define PATH_SZ 4096

static const char *const k_kinds[HEARTH_N_STATE_KINDS] = {"neutral", "hot", "warm", "iced", "used"};

static int is_file(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* bytes of the regular files below a directory (0 if absent) */
static uint64_t tree_bytes(const char *dir) {
  uint64_t total = 0;
  char **stack = NULL;
  size_t n = 0, cap = 0;
  /* iterative walk with stat: nftw's callback cannot carry a context */
  stack = malloc(sizeof *stack * (cap = 16));
  if (!stack) return 0;
  stack[n++] = strdup(dir);
  while (n) {
    char *d = stack[--n];
    if (!d) continue;
    struct dirent **ents = NULL;
    int m = scandir(d, &ents, NULL, NULL);
    for (int i = 0; i < m; i++) {
      const char *nm = ents[i]->d_name;
      if (strcmp(nm, ".") && strcmp(nm, "..")) {
        char p[PATH_SZ];
        snprintf(p, sizeof p, "%s/%s", d, nm);
        struct stat st;
        if (lstat(p, &st) == 0) {
          if (S_ISREG(st.st_mode)) total += (uint64_t)st.st_size;
          else if (S_ISDIR(st.st_mode)) {
            if (n == cap) {
              char **ns = realloc(stack, sizeof *stack * (cap *= 2));
              if (!ns) {
                free(ents[i]);
                continue;
              }
              stack = ns;
            }
            stack[n++] = strdup(p);
          }
        }
      }
      free(ents[i]);
    }
    free(ents);
    free(d);
  }
  free(stack);
  return total;
}

hearth_status hearth_release_stats_compute(const char *root, hearth_release_stats *st,
                                           hearth_err *err) {
  memset(st, 0, sizeof *st);
  char path[PATH_SZ];
  snprintf(path, sizeof path, "%s/release.json", root);
  hearth_release_doc rel = {0};
  hearth_status s = hearth_release_read(path, &rel, err);
  if (s) return s;
  int cat_nonneutral[18] = {0};
  uint64_t elev_seen = 0, azi_seen = 0;
  int first_view = 1;
  for (size_t i = 0; i < rel.n_instances; i++) {
    const char *id = rel.instances[i];
    hearth_instance_doc doc;
    snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, id);
    if ((s = hearth_instance_load(root, id, &doc, err))) goto done;
    st->n_instances++;
    int cat = -1;
    for (int c = 0; c < 18; c++)
      if (!strcmp(hearth_categories[c], doc.category)) cat = c;
    if (cat >= 0) st->instances_per_category[cat]++;
    int nonneutral = 0;
    for (size_t k = 0; k < doc.n_states; k++) {
      const char *state = doc.states[k];
      st->n_states++;
      for (int j = 0; j < HEARTH_N_STATE_KINDS; j++)
        if (!strcmp(state, k_kinds[j])) st->states_by_kind[j]++;
      if (strcmp(state, "neutral")) nonneutral = 1;
      char sdir[PATH_SZ];
      snprintf(sdir, sizeof sdir, "%s/instances/%s/raw/%s", root, id, state);
      snprintf(path, sizeof path, "%s/manifest.json", sdir);
      hearth_manifest man = {0};
      if ((s = hearth_manifest_read(path, &man, err))) goto done;
      if (st->n_states == 1 || man.n_views < st->views_min) st->views_min = man.n_views;
      if (man.n_views > st->views_max) st->views_max = man.n_views;
      for (size_t v = 0; v < man.n_views; v++) {
        const hearth_view_files *vf = &man.views[v];
        char a[PATH_SZ], b[PATH_SZ];
        snprintf(a, sizeof a, "%s/%s", sdir, vf->rgb);
        snprintf(b, sizeof b, "%s/%s", sdir, vf->thermal);
        int has_rgb = is_file(a), has_th = is_file(b);
        if (has_rgb && has_th) st->n_pairs++;
        if (vf->elevation_index >= 0 && vf->elevation_index < 64)
          elev_seen |= 1ull << vf->elevation_index;
        if (vf->azimuth_index >= 0 && vf->azimuth_index < 64) azi_seen |= 1ull << vf->azimuth_index;
        char dp[PATH_SZ];
        snprintf(dp, sizeof dp, "%s/%s", sdir, vf->depth);
        if (is_file(dp)) st->n_depth++;
        /* sizes of the raw data, from the first complete view */
        if (first_view && has_rgb && has_th && is_file(dp)) {
          /* the images' sizes from their headers (no pixels decoded) */
          hearth_image img = {0};
          hearth_csv_opts any = {0, 0};
          const hearth_image_expect header = {.header_only = 1};
          if (!hearth_jpeg_read_expect(a, &header, &img, NULL))
            st->rgb_w = img.width, st->rgb_h = img.height;
          if (!hearth_thermal_read_csv(b, &any, &img, NULL))
            st->thermal_w = img.width, st->thermal_h = img.height;
          hearth_image_free(&img);
          if (!hearth_png_read_expect(dp, &header, &img, NULL))
            st->depth_w = img.width, st->depth_h = img.height;
          first_view = 0;
        }
      }
      hearth_manifest_free(&man);
      /* derived per state */
      char ddir[PATH_SZ], a[PATH_SZ], b[PATH_SZ];
      snprintf(ddir, sizeof ddir, "%s/instances/%s/derived/%s", root, id, state);
      snprintf(a, sizeof a, "%s/temperature_filled.npy", ddir);
      snprintf(b, sizeof b, "%s/mask.npy", ddir);
      if (is_file(a) && is_file(b)) {
        st->n_maps++;
        if (!st->map_resolution) {
          hearth_npy m = {0};
          if (!hearth_npy_read(b, &m, NULL) && m.ndim == 2) st->map_resolution = m.shape[0];
          hearth_npy_free(&m);
        }
      }
      snprintf(a, sizeof a, "%s/thermal_turbo.png", ddir);
      if (is_file(a)) st->n_turbo++;
      snprintf(a, sizeof a, "%s/provenance.json", ddir);
      if (is_file(a)) st->n_provenance++;
    }
    if (nonneutral) {
      st->n_instances_nonneutral++;
      if (cat >= 0) cat_nonneutral[cat] = 1;
    }
    char dd[PATH_SZ];
    snprintf(dd, sizeof dd, "%s/instances/%s/derived", root, id);
    const struct {
      const char *name;
      size_t *count;
    } assets[] = {{"mesh.glb", &st->n_meshes},
                  {"rgb_texture.png", &st->n_rgb_textures},
                  {"scale.json", &st->n_scales},
                  {"poses_rgb.json", &st->n_poses_rgb},
                  {"poses_thermal.json", &st->n_poses_thermal}};
    for (size_t j = 0; j < sizeof assets / sizeof assets[0]; j++) {
      snprintf(path, sizeof path, "%s/%s", dd, assets[j].name);
      if (is_file(path)) (*assets[j].count)++;
    }
    st->derived_bytes += tree_bytes(dd);
    snprintf(path, sizeof path, "%s/instances/%s/raw", root, id);
    st->raw_bytes += tree_bytes(path);
  }
  for (int c = 0; c < 18; c++) {
    if (st->instances_per_category[c]) st->n_categories++;
    if (cat_nonneutral[c]) st->n_categories_nonneutral++;
  }
  st->n_elevations = (size_t)__builtin_popcountll(elev_seen);
  st->n_azimuths = (size_t)__builtin_popcountll(azi_seen);
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  st->has_calibration = is_file(path);
  snprintf(path, sizeof path, "%s/ground_truth", root);
  st->has_ground_truth = hearth_path_exists(path);
done:
  hearth_release_free(&rel);
  return s;
}

/* "1 per category" or "1-3 per category" */
static void per_category(const hearth_release_stats *st, char *buf, size_t n) {
  size_t lo = 0, hi = 0;
  for (int c = 0; c < 18; c++) {
    size_t k = st->instances_per_category[c];
    if (!k) continue;
    if (!lo || k < lo) lo = k;
    if (k > hi) hi = k;
  }
  if (lo == hi) snprintf(buf, n, "%zu per category", lo);
  else snprintf(buf, n, "%zu-%zu per category", lo, hi);
}

static void human_bytes(uint64_t b, char *buf, size_t n) {
  char num[32];
  if (b >= (1ull << 30))
    hearth_format_fixed(num, sizeof num, (double)b / (1ull << 30), 1),
        snprintf(buf, n, "%s GiB", num);
  else if (b >= (1ull << 20))
    hearth_format_fixed(num, sizeof num, (double)b / (1ull << 20), 1),
        snprintf(buf, n, "%s MiB", num);
  else hearth_format_fixed(num, sizeof num, (double)b / 1024.0, 1), snprintf(buf, n, "%s KiB", num);
}

void hearth_release_stats_print(const hearth_release_stats *st, FILE *out) {
  char buf[1024], pc[64];
  const int w = 28;
  fprintf(out, "Object dataset overview\n");
  fprintf(out, "%.*s\n", 100,
          "------------------------------------------------------------"
          "----------------------------------------");
  size_t off = 0;
  for (int c = 0; c < 18 && off < sizeof buf; c++)
    if (st->instances_per_category[c])
      off += (size_t)snprintf(buf + off, sizeof buf - off, "%s%s", off ? ", " : "",
                              hearth_categories[c]);
  fprintf(out, "%-*s %zu (%s)\n", w, "Object categories", st->n_categories, off ? buf : "none");
  per_category(st, pc, sizeof pc);
  fprintf(out, "%-*s %zu (%s)\n", w, "Physical instances", st->n_instances, pc);
  off = 0;
  for (int j = 1; j < HEARTH_N_STATE_KINDS && off < sizeof buf; j++)
    if (st->states_by_kind[j])
      off += (size_t)snprintf(buf + off, sizeof buf - off, "%s%zu %s", off ? ", " : "",
                              st->states_by_kind[j], k_kinds[j]);
  fprintf(out, "%-*s room temperature (neutral) for %zu instances", w, "Thermal states",
          st->states_by_kind[0]);
  if (off)
    fprintf(out, ", plus %s for %zu instances in %zu categories", buf, st->n_instances_nonneutral,
            st->n_categories_nonneutral);
  fprintf(out, " (%zu object states)\n", st->n_states);
  if (st->views_min == st->views_max)
    fprintf(out, "%-*s %zu", w, "Views per object state", st->views_max);
  else fprintf(out, "%-*s %zu-%zu", w, "Views per object state", st->views_min, st->views_max);
  /* a subset of the turntable grid says so, rather than implying the full grid */
  fprintf(out, " (%s%zu elevations x %zu azimuths)\n",
          st->views_max == st->n_elevations * st->n_azimuths ? "" : "drawn from ", st->n_elevations,
          st->n_azimuths);
  fprintf(out, "%-*s %zu (%zu object states", w, "RGB-thermal pairs", st->n_pairs, st->n_states);
  if (st->views_min == st->views_max) fprintf(out, " x %zu views", st->views_max);
  fprintf(out, ")\n");
  fprintf(out,
          "%-*s RGB image (%zux%zu), apparent-temperature matrix (%zux%zu, CSV), depth map "
          "(%zux%zu); %zu depth maps\n",
          w, "Raw data per view", st->rgb_w, st->rgb_h, st->thermal_w, st->thermal_h, st->depth_w,
          st->depth_h, st->n_depth);
  fprintf(out,
          "%-*s mesh (GLB with UV) %zu/%zu, RGB texture %zu/%zu, metric scale %zu/%zu, "
          "per-view camera poses %zu/%zu;\n%-*s temperature UV map with validity mask %zu/%zu "
          "(%zux%zu), thermal texture (PNG) %zu/%zu, provenance %zu/%zu; calibration %s\n",
          w, "Derived assets", st->n_meshes, st->n_instances, st->n_rgb_textures, st->n_instances,
          st->n_scales, st->n_instances, st->n_poses_thermal, st->n_instances, w, "", st->n_maps,
          st->n_states, st->map_resolution, st->map_resolution, st->n_turbo, st->n_states,
          st->n_provenance, st->n_states, st->has_calibration ? "yes" : "no");
  char rb[32], db[32];
  human_bytes(st->raw_bytes, rb, sizeof rb);
  human_bytes(st->derived_bytes, db, sizeof db);
  fprintf(out, "%-*s raw %s, derived %s%s\n", w, "Size on disk", rb, db,
          st->has_ground_truth ? " (ground truth present: virtual rig)" : "");
}

char *hearth_release_stats_json(const hearth_release_stats *st) {
  json_t *o = json_object();
  json_t *cats = json_object();
  for (int c = 0; c < 18; c++)
    if (st->instances_per_category[c])
      json_object_set_new(cats, hearth_categories[c],
                          json_integer((json_int_t)st->instances_per_category[c]));
  json_object_set_new(o, "categories", json_integer((json_int_t)st->n_categories));
  json_object_set_new(o, "instances_per_category", cats);
  json_object_set_new(o, "instances", json_integer((json_int_t)st->n_instances));
  json_object_set_new(o, "object_states", json_integer((json_int_t)st->n_states));
  json_t *kinds = json_object();
  for (int j = 0; j < HEARTH_N_STATE_KINDS; j++)
    json_object_set_new(kinds, k_kinds[j], json_integer((json_int_t)st->states_by_kind[j]));
  json_object_set_new(o, "states_by_kind", kinds);
  json_object_set_new(o, "instances_with_non_neutral_state",
                      json_integer((json_int_t)st->n_instances_nonneutral));
  json_object_set_new(o, "categories_with_non_neutral_state",
                      json_integer((json_int_t)st->n_categories_nonneutral));
  json_t *v = json_object();
  json_object_set_new(v, "min", json_integer((json_int_t)st->views_min));
  json_object_set_new(v, "max", json_integer((json_int_t)st->views_max));
  json_object_set_new(v, "elevations", json_integer((json_int_t)st->n_elevations));
  json_object_set_new(v, "azimuths", json_integer((json_int_t)st->n_azimuths));
  json_object_set_new(o, "views_per_state", v);
  json_object_set_new(o, "rgb_thermal_pairs", json_integer((json_int_t)st->n_pairs));
  json_object_set_new(o, "depth_maps", json_integer((json_int_t)st->n_depth));
  json_t *raw = json_object();
  json_object_set_new(raw, "rgb", json_pack("[I,I]", (json_int_t)st->rgb_w, (json_int_t)st->rgb_h));
  json_object_set_new(raw, "thermal",
                      json_pack("[I,I]", (json_int_t)st->thermal_w, (json_int_t)st->thermal_h));
  json_object_set_new(raw, "depth",
                      json_pack("[I,I]", (json_int_t)st->depth_w, (json_int_t)st->depth_h));
  json_object_set_new(o, "raw_per_view", raw);
  json_t *d = json_object();
  json_object_set_new(d, "meshes", json_integer((json_int_t)st->n_meshes));
  json_object_set_new(d, "rgb_textures", json_integer((json_int_t)st->n_rgb_textures));
  json_object_set_new(d, "scales", json_integer((json_int_t)st->n_scales));
  json_object_set_new(d, "poses_rgb", json_integer((json_int_t)st->n_poses_rgb));
  json_object_set_new(d, "poses_thermal", json_integer((json_int_t)st->n_poses_thermal));
  json_object_set_new(d, "temperature_maps", json_integer((json_int_t)st->n_maps));
  json_object_set_new(d, "thermal_textures", json_integer((json_int_t)st->n_turbo));
  json_object_set_new(d, "provenance", json_integer((json_int_t)st->n_provenance));
  json_object_set_new(d, "map_resolution", json_integer((json_int_t)st->map_resolution));
  json_object_set_new(d, "calibration", json_boolean(st->has_calibration));
  json_object_set_new(o, "derived_assets", d);
  json_object_set_new(o, "raw_bytes", json_integer((json_int_t)st->raw_bytes));
  json_object_set_new(o, "derived_bytes", json_integer((json_int_t)st->derived_bytes));
  json_object_set_new(o, "ground_truth", json_boolean(st->has_ground_truth));
  char *text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER);
  json_decref(o);
  if (!text) return NULL;
  size_t n = strlen(text);
  char *t2 = realloc(text, n + 2);
  if (!t2) {
    free(text);
    return NULL;
  }
  t2[n] = '\n';
  t2[n + 1] = 0;
  return t2;
}
