/* recon/report.json (hearth recon's turntable route, docs/dataset.md)
 * checked by hearth validate: every member's presence and type, and its
 * agreement with what lies beside it (the manifests, recon/poses_rgb.json,
 * the meshes). Every problem is collected, each naming the member. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "release/release_internal.h"

typedef struct rc_ctx {
  const char *path;
  const hb_recon_expect *x;
  hearth_problems *p;
} rc_ctx;

#define BAD(c, ...) hearth_problems_add((c)->p, (c)->path, __VA_ARGS__)

/* an integer member >= 0 (at most hi when hi >= 0); -1 when bad or absent */
static long long get_count(const rc_ctx *c, const json_t *o, const char *where, const char *key,
                           long long hi) {
  const json_t *v = json_object_get(o, key);
  if (!v) {
    BAD(c, "%s%s: missing (an integer)", where, key);
    return -1;
  }
  if (!json_is_integer(v) || json_integer_value(v) < 0) {
    BAD(c, "%s%s: expected an integer >= 0", where, key);
    return -1;
  }
  long long n = (long long)json_integer_value(v);
  if (hi >= 0 && n > hi) {
    BAD(c, "%s%s: %lld, more than the %lld views", where, key, n, hi);
    return -1;
  }
  return n;
}

/* a finite number member (>= 0 when nonneg); NAN when bad or absent */
static double get_real(const rc_ctx *c, const json_t *o, const char *where, const char *key,
                       int nonneg) {
  const json_t *v = json_object_get(o, key);
  if (!v) {
    BAD(c, "%s%s: missing (a number)", where, key);
    return NAN;
  }
  double x = json_is_number(v) ? json_number_value(v) : NAN;
  if (!json_is_number(v) || !isfinite(x)) {
    BAD(c, "%s%s: expected a finite number", where, key);
    return NAN;
  }
  if (nonneg && x < 0) {
    BAD(c, "%s%s: %g, expected a number >= 0", where, key, x);
    return NAN;
  }
  return x;
}

/* an array of 3 finite numbers; 0 when bad or absent */
static int get_vec3(const rc_ctx *c, const json_t *o, const char *where, const char *key,
                    double out[3]) {
  const json_t *v = json_object_get(o, key);
  int ok = json_is_array(v) && json_array_size(v) == 3;
  for (size_t k = 0; ok && k < 3; k++) {
    const json_t *e = json_array_get(v, k);
    ok = json_is_number(e) && isfinite(out[k] = json_number_value(e));
  }
  if (!ok) BAD(c, "%s%s: expected an array of 3 finite numbers", where, key);
  return ok;
}

/* the index of a state of instance.json, -1 if none */
static int state_index(const hb_recon_expect *x, const char *s) {
  for (size_t k = 0; k < x->n_states; k++)
    if (!strcmp(x->states[k], s)) return (int)k;
  return -1;
}

/* a string member naming a state of the instance; its index or -1 */
static int get_state(const rc_ctx *c, const json_t *o, const char *where) {
  const json_t *v = json_object_get(o, "state");
  if (!json_is_string(v)) {
    BAD(c, "%sstate: expected a string", where);
    return -1;
  }
  int k = state_index(c->x, json_string_value(v));
  if (k < 0)
    BAD(c, "%sstate: '%s' is not a state of this instance (instance.json)", where,
        json_string_value(v));
  return k;
}

static void check_aim(const rc_ctx *c, const json_t *aim, long long n_views) {
  if (json_is_null(aim)) return;
  if (!json_is_object(aim)) {
    BAD(c, "aim: expected null (the term off) or an object");
    return;
  }
  double w = get_real(c, aim, "aim.", "weight", 1);
  if (w == 0) BAD(c, "aim.weight: 0, but a term that is off is null");
  double ax[3];
  if (get_vec3(c, aim, "aim.", "axis_direction", ax) && (ax[0] != 0 || ax[1] != 0 || ax[2] != 1))
    BAD(c, "aim.axis_direction: (%g, %g, %g), expected [0, 0, 1] (the frame's +z)", ax[0], ax[1],
        ax[2]);
  const json_t *states = json_object_get(aim, "states");
  long long sum_states = 0, sum_places = 0;
  int sums_ok = 1;
  if (!json_is_array(states) || !json_array_size(states)) {
    BAD(c, "aim.states: expected a non-empty array");
    sums_ok = 0;
  } else {
    size_t i;
    const json_t *st;
    json_array_foreach(states, i, st) {
      char where[64];
      snprintf(where, sizeof where, "aim.states[%zu].", i);
      if (!json_is_object(st)) {
        BAD(c, "aim.states[%zu]: expected an object", i);
        sums_ok = 0;
        continue;
      }
      int k = get_state(c, st, where);
      for (size_t j = 0; k >= 0 && j < i; j++) {
        const json_t *sj = json_object_get(json_array_get(states, j), "state");
        if (json_is_string(sj) && !strcmp(json_string_value(sj), c->x->states[k]))
          BAD(c, "%sstate: '%s' listed twice (also aim.states[%zu])", where, c->x->states[k], j);
      }
      long long hi = k >= 0 && c->x->manifests && c->x->manifests[k].n_views
                         ? (long long)c->x->manifests[k].n_views
                         : n_views;
      long long nv = get_count(c, st, where, "views", hi);
      if (nv < 0) sums_ok = 0;
      else sum_states += nv;
      static const char *const sig[] = {"sigma_along_mm", "sigma_across_mm"};
      for (size_t j = 0; j < 2; j++) {
        const json_t *js = json_object_get(st, sig[j]);
        if (!js) BAD(c, "%s%s: missing (a number, or null)", where, sig[j]);
        else if (!json_is_null(js)) get_real(c, st, where, sig[j], 1);
      }
      double C[3], A[3];
      int hc = get_vec3(c, st, where, "point_m", C), ha = get_vec3(c, st, where, "axis_m", A);
      if (hc && ha && (A[0] != C[0] || A[1] != C[1] || A[2] != 0))
        BAD(c, "%saxis_m: (%g, %g, %g), expected point_m's x and y at z = 0", where, A[0], A[1],
            A[2]);
    }
  }
  const json_t *places = json_object_get(aim, "places");
  if (!json_is_array(places) || !json_array_size(places)) {
    BAD(c, "aim.places: expected a non-empty array");
    return;
  }
  size_t i;
  const json_t *pl;
  json_array_foreach(places, i, pl) {
    char where[64];
    snprintf(where, sizeof where, "aim.places[%zu].", i);
    if (!json_is_object(pl)) {
      BAD(c, "aim.places[%zu]: expected an object", i);
      sums_ok = 0;
      continue;
    }
    const json_t *ring = json_object_get(pl, "ring");
    if (!ring) BAD(c, "%sring: missing (null, or an elevation index)", where);
    else if (!json_is_null(ring) && !(json_is_integer(ring) && json_integer_value(ring) >= 0))
      BAD(c, "%sring: expected null (every ring) or an elevation index >= 0", where);
    else if (json_is_null(ring) && json_array_size(places) != 1)
      BAD(c, "%sring: null (one place for every ring), but there are %zu places", where,
          json_array_size(places));
    long long nv = get_count(c, pl, where, "views", n_views);
    if (nv < 0) sums_ok = 0;
    else sum_places += nv;
    double P[3];
    int hp = get_vec3(c, pl, where, "camera_m", P);
    double d = get_real(c, pl, where, "distance_m", 1);
    double len = hp ? sqrt(P[0] * P[0] + P[1] * P[1] + P[2] * P[2]) : 0;
    if (hp && isfinite(d) && fabs(d - len) > 1e-9 * (1 + d))
      BAD(c, "%sdistance_m: %g, but |camera_m| is %g", where, d, len);
    get_real(c, pl, where, "side_rms_mm", 1);
    double dr = get_real(c, pl, where, "depth_rms_mm", 1);
    double rel = get_real(c, pl, where, "depth_rms_rel", 1);
    if (isfinite(dr) && isfinite(rel) && len > 0 &&
        fabs(rel - dr / 1000.0 / len) > 1e-9 * (1 + rel))
      BAD(c, "%sdepth_rms_rel: %g, but depth_rms_mm / |camera_m| is %g", where, rel,
          dr / 1000.0 / len);
  }
  if (sums_ok && sum_states != sum_places)
    BAD(c, "aim: the states hold %lld views, the places %lld", sum_states, sum_places);
}

static void check_per_view(const rc_ctx *c, const json_t *pv, long long n_views) {
  if (!json_is_array(pv)) {
    BAD(c, "per_view: expected an array");
    return;
  }
  if (n_views >= 0 && (long long)json_array_size(pv) != n_views)
    BAD(c, "per_view: %zu entries, but views is %lld", json_array_size(pv), n_views);
  size_t i;
  const json_t *v;
  json_array_foreach(pv, i, v) {
    char where[64];
    snprintf(where, sizeof where, "per_view[%zu].", i);
    if (!json_is_object(v)) {
      BAD(c, "per_view[%zu]: expected an object", i);
      continue;
    }
    int k = get_state(c, v, where);
    const json_t *jn = json_object_get(v, "view");
    if (!json_is_string(jn)) {
      BAD(c, "%sview: expected a string", where);
    } else if (k >= 0) {
      const char *name = json_string_value(jn);
      const hearth_manifest *m = c->x->manifests ? &c->x->manifests[k] : NULL;
      int found = !m || !m->n_views;
      for (size_t j = 0; m && !found && j < m->n_views; j++)
        found = !strcmp(m->views[j].view, name);
      if (!found)
        BAD(c, "%sview: '%s' does not exist in %s's manifest", where, name, c->x->states[k]);
      else if (c->x->poses && !hearth_poses_find(c->x->poses, c->x->states[k], name))
        BAD(c, "%sview: %s/%s has no pose in poses_rgb.json", where, c->x->states[k], name);
      for (size_t j = 0; j < i; j++) {
        const json_t *o = json_array_get(pv, j), *s2 = json_object_get(o, "state"),
                     *v2 = json_object_get(o, "view");
        if (json_is_string(s2) && json_is_string(v2) && !strcmp(json_string_value(v2), name) &&
            !strcmp(json_string_value(s2), c->x->states[k])) {
          BAD(c, "%sview: %s/%s listed twice (also per_view[%zu])", where, c->x->states[k], name,
              j);
          break;
        }
      }
    }
    static const char *const counts[] = {"points", "plane_inliers", "pairs", "matches"};
    for (size_t j = 0; j < sizeof counts / sizeof counts[0]; j++)
      get_count(c, v, where, counts[j], -1);
    static const struct {
      const char *k;
      int nonneg;
    } reals[] = {{"plane_rms_mm", 1},
                 {"height_m", 0},
                 {"elevation_deg", 0},
                 {"icp_rms_mm", 1},
                 {"d_azimuth_deg", 0}};
    for (size_t j = 0; j < sizeof reals / sizeof reals[0]; j++)
      get_real(c, v, where, reals[j].k, reals[j].nonneg);
  }
}

void hb_recon_report_check(const char *text, size_t len, const char *path, const hb_recon_expect *x,
                           hearth_problems *p) {
  rc_ctx c = {path, x, p};
  json_error_t je;
  json_t *o = json_loadb(text, len, JSON_REJECT_DUPLICATES, &je);
  if (!o) {
    BAD(&c, "line %d, column %d: %s", je.line, je.column, je.text);
    return;
  }
  if (!json_is_object(o)) {
    BAD(&c, "expected an object at the top level");
    json_decref(o);
    return;
  }
  const json_t *ji = json_object_get(o, "instance"), *jr = json_object_get(o, "route");
  if (!json_is_string(ji)) BAD(&c, "instance: expected a string");
  else if (x->instance && strcmp(json_string_value(ji), x->instance))
    BAD(&c, "instance: names '%s', expected '%s'", json_string_value(ji), x->instance);
  if (!json_is_string(jr)) BAD(&c, "route: expected a string");
  else if (strcmp(json_string_value(jr), "turntable"))
    BAD(&c, "route: '%s', expected 'turntable' (the only route that writes a report)",
        json_string_value(jr));
  long long nv = get_count(&c, o, "", "views", -1);
  if (nv == 0) BAD(&c, "views: 0, a reconstruction has at least one view");
  if (nv > 0 && x->manifest_views >= 0 && nv != x->manifest_views)
    BAD(&c, "views: %lld, but the manifests list %lld", nv, x->manifest_views);
  if (nv > 0 && x->poses && (size_t)nv != x->poses->n)
    BAD(&c, "views: %lld, but poses_rgb.json has %zu", nv, x->poses->n);
  get_count(&c, o, "", "pairs", -1);
  get_count(&c, o, "", "iterations", -1);
  static const char *const of_views[] = {"encoder_views", "colour_views", "ring_plane_views"};
  /* bounded by the views there are (the manifests'), else by the report's */
  long long hi = x->manifest_views >= 0 ? x->manifest_views : nv > 0 ? nv : -1;
  for (size_t j = 0; j < 3; j++) get_count(&c, o, "", of_views[j], hi);
  /* written since the rings without a table were started from the others */
  if (json_object_get(o, "free_ring_views")) get_count(&c, o, "", "free_ring_views", hi);
  /* the backdrop's check (written since 2026-12-06) */
  if (json_object_get(o, "wall_views")) {
    get_count(&c, o, "", "wall_views", hi);
    get_count(&c, o, "", "wall_check_views", hi);
    const json_t *wt = json_object_get(o, "wall_tilt_deg");
    if (!wt) BAD(&c, "wall_tilt_deg: missing (a number, or null when no view checked the wall)");
    else if (!json_is_null(wt)) get_real(&c, o, "", "wall_tilt_deg", 1);
  }
  static const char *const icp[] = {"icp_rms_start_mm", "icp_rms_mm", "icp_median_mm"};
  for (size_t j = 0; j < 3; j++) get_real(&c, o, "", icp[j], 1);
  const json_t *aim = json_object_get(o, "aim");
  if (!aim) BAD(&c, "aim: missing (null when the term was off)");
  else check_aim(&c, aim, hi);
  const json_t *mesh = json_object_get(o, "mesh");
  if (mesh && !json_is_object(mesh)) {
    BAD(&c, "mesh: expected an object");
  } else if (mesh) {
    long long v = get_count(&c, mesh, "mesh.", "vertices", -1),
              t = get_count(&c, mesh, "mesh.", "triangles", -1);
    double vox = get_real(&c, mesh, "mesh.", "voxel_m", 1);
    if (vox == 0) BAD(&c, "mesh.voxel_m: 0, expected a voxel size > 0");
    if (v >= 0 && x->mesh_vertices >= 0 && v != x->mesh_vertices)
      BAD(&c, "mesh.vertices: %lld, but mesh_geometry.glb has %lld", v, x->mesh_vertices);
    if (t >= 0 && x->mesh_triangles >= 0 && t != x->mesh_triangles)
      BAD(&c, "mesh.triangles: %lld, but mesh_geometry.glb has %lld", t, x->mesh_triangles);
    /* the openings: written since hearth recon left unseen ones open */
    if (json_object_get(mesh, "open_loops") || json_object_get(mesh, "open_edges")) {
      long long ol = get_count(&c, mesh, "mesh.", "open_loops", -1),
                oe = get_count(&c, mesh, "mesh.", "open_edges", -1);
      if (ol >= 0 && oe >= 0 && oe < 3 * ol)
        BAD(&c, "mesh.open_edges: %lld, fewer than 3 for each of the %lld open loops", oe, ol);
      if (ol >= 0 && x->mesh_open_loops >= 0 && ol != x->mesh_open_loops)
        BAD(&c, "mesh.open_loops: %lld, but mesh_geometry.glb has %lld", ol, x->mesh_open_loops);
    }
  } else if (x->mesh_triangles >= 0) {
    BAD(&c, "mesh: missing, but mesh_geometry.glb is beside it");
  }
  const json_t *atlas = json_object_get(o, "atlas");
  if (atlas && !json_is_object(atlas)) {
    BAD(&c, "atlas: expected an object");
  } else if (atlas) {
    long long ch = get_count(&c, atlas, "atlas.", "charts", -1);
    get_count(&c, atlas, "atlas.", "merged", -1);
    if (ch == 0) BAD(&c, "atlas.charts: 0, an atlas has at least one chart");
    if (ch > 0 && x->atlas_charts >= 0 && ch != x->atlas_charts)
      BAD(&c, "atlas.charts: %lld, but mesh.glb has %lld UV islands", ch, x->atlas_charts);
    static const char *const st[] = {"stretch_l2", "stretch_l2_max", "stretch_l2_chart_max",
                                     "area_distortion", "angle_distortion"};
    for (size_t j = 0; j < sizeof st / sizeof st[0]; j++) get_real(&c, atlas, "atlas.", st[j], 1);
    double pe = get_real(&c, atlas, "atlas.", "packing_efficiency", 1);
    if (pe > 1) BAD(&c, "atlas.packing_efficiency: %g, more than the whole square", pe);
  }
  check_per_view(&c, json_object_get(o, "per_view"), nv);
  json_decref(o);
}

/* UV islands of a mesh: its triangles' components over shared vertices */
static size_t find_root(size_t *up, size_t i) {
  while (up[i] != i) i = up[i] = up[up[i]];
  return i;
}

long long hb_mesh_islands(const hearth_mesh *m) {
  size_t *up = malloc((m->n_vertices ? m->n_vertices : 1) * sizeof *up);
  if (!up) return -1;
  for (size_t i = 0; i < m->n_vertices; i++) up[i] = i;
  for (size_t t = 0; t < m->n_triangles; t++) {
    size_t a = find_root(up, m->indices[3 * t]);
    for (int k = 1; k < 3; k++) {
      size_t b = find_root(up, m->indices[3 * t + k]);
      if (a != b) up[b] = a;
    }
  }
  /* count roots of used vertices */
  unsigned char *used = calloc(m->n_vertices ? m->n_vertices : 1, 1);
  long long n = 0;
  if (!used) {
    free(up);
    return -1;
  }
  for (size_t t = 0; t < 3 * m->n_triangles; t++) used[m->indices[t]] = 1;
  for (size_t i = 0; i < m->n_vertices; i++) n += used[i] && find_root(up, i) == i;
  free(used);
  free(up);
  return n;
}
