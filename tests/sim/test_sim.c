/* the sim tasks end to end on one small virtual-rig release shared by all
 * checks: the expert succeeds on every task and instruction, success needs
 * the target released on the mat, candidates look identical in RGB but
 * differ in thermal, layouts keep both candidates visible, and the
 * collected HDF5 file has LIBERO's keys, shapes and attributes and is the
 * same bytes for the same seed, also when collected in shards and merged */
#include <hdf5.h>
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hearth/hearth.h"
#include "hearth/sim.h"
#include "sim/sim_env.h"
#include "test_util.h"
#include "test_sim_release.h"

static double g_t0;
static void stamp(const char *what) {
  fprintf(stderr, "test_sim: %-28s %6.1f s wall %6.1f s cpu\n", what, hearth_now() - g_t0,
          (double)clock() / CLOCKS_PER_SEC);
}

/* mean absolute difference per channel of two images over a box */
static double box_diff(const uint8_t *a, const uint8_t *b, int w, const int bx[4]) {
  double s = 0;
  long n = 0;
  for (int y = bx[1]; y <= bx[3]; y++)
    for (int x = bx[0]; x <= bx[2]; x++)
      for (int c = 0; c < 3; c++, n++)
        s += abs((int)a[3 * (y * w + x) + c] - (int)b[3 * (y * w + x) + c]);
  return n ? s / (double)n : 0.0;
}

static void box_union(const int a[4], const int b[4], int o[4]) {
  o[0] = a[0] < b[0] ? a[0] : b[0], o[1] = a[1] < b[1] ? a[1] : b[1];
  o[2] = a[2] > b[2] ? a[2] : b[2], o[3] = a[3] > b[3] ? a[3] : b[3];
}

/* H1, H2: the candidates differ only in temperature. Render the scene,
 * swap the two candidates' places, render again: each slot's crop shows a
 * different candidate at the same pose under the same light, so RGB must
 * agree (identical geometry and texture) and thermal must not */
static void check_crops(hearth_sim_env *e, const char *name) {
  hearth_err err = {0};
  size_t px = (size_t)e->width * (size_t)e->height * 3;
  uint8_t *rgb0 = malloc(px), *th0 = malloc(px);
  if (!rgb0 || !th0) {
    CHECK(0);
    free(rgb0), free(th0);
    return;
  }
  hearth_sim_obs ob;
  int boxes0[2][4], boxes1[2][4];
  CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
  memcpy(rgb0, ob.agentview_rgb, px);
  memcpy(th0, ob.agentview_thermal, px);
  CHECK_OK(hearth_sim_candidate_boxes(e, boxes0, &err), &err);
  double p0[3], p1[3];
  sim_object_pos(e, 0, p0);
  sim_object_pos(e, 1, p1);
  sim_place_object(e, 0, p1);
  sim_place_object(e, 1, p0);
  CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
  CHECK_OK(hearth_sim_candidate_boxes(e, boxes1, &err), &err);
  /* boxes come per candidate identity (slot A first before the swap), so
   * after the swap slot s holds what boxes1[1 - s] describes */
  for (int slot = 0; slot < 2; slot++) {
    int bx[4];
    box_union(boxes0[slot], boxes1[1 - slot], bx);
    CHECK(bx[2] - bx[0] >= 3 && bx[3] - bx[1] >= 3); /* a real crop, not a pixel */
    double drgb = box_diff(rgb0, ob.agentview_rgb, e->width, bx);
    double dth = box_diff(th0, ob.agentview_thermal, e->width, bx);
    fprintf(stderr, "test_sim: %s slot %c crop %dx%d: RGB differs by %.2f, thermal by %.1f\n", name,
            'A' + slot, bx[2] - bx[0] + 1, bx[3] - bx[1] + 1, drgb, dth);
    CHECK_MSG(drgb < 2.0, "%s slot %c: RGB crops of the two candidates differ by %.2f", name,
              'A' + slot, drgb);
    CHECK_MSG(dth > 20.0, "%s slot %c: thermal crops of the candidates differ by only %.1f", name,
              'A' + slot, dth);
  }
  free(rgb0), free(th0);
}

/* success needs the target itself resting on the mat, released */
static void check_success_rule(hearth_sim_env *e) {
  hearth_err err = {0};
  const double *mat = e->m->geom_pos + 3 * e->mat_geom;
  const double zero[7] = {0, 0, 0, 0, 0, 0, -1};
  double on_mat[3] = {mat[0], mat[1], HEARTH_SIM_TABLE_Z + 0.003};
  CHECK_OK(hearth_sim_reset(e, 7, 0, 0, &err), &err);
  CHECK(!hearth_sim_success(e)); /* the target starts in its slot */
  /* the other candidate on the mat: not a success */
  sim_place_object(e, 1 - e->target, on_mat);
  for (int t = 0; t < 4; t++) CHECK_OK(hearth_sim_step(e, zero, &err), &err);
  CHECK(!hearth_sim_success(e));
  /* the target beside the mat (12 cm past its edge): not a success */
  double beside[3] = {mat[0], mat[1] + e->m->geom_size[3 * e->mat_geom + 1] + 0.12, on_mat[2]};
  sim_place_object(e, e->target, beside);
  for (int t = 0; t < 4; t++) CHECK_OK(hearth_sim_step(e, zero, &err), &err);
  CHECK(!hearth_sim_success(e));
  /* the target 10 cm above the mat, falling: not yet a success */
  double above[3] = {mat[0] + 0.04, mat[1] + 0.04, on_mat[2] + 0.10};
  sim_place_object(e, 1 - e->target, beside);
  sim_place_object(e, e->target, above);
  CHECK(!hearth_sim_success(e));
  /* the target resting on the mat, gripper away: a success */
  sim_place_object(e, e->target, on_mat);
  for (int t = 0; t < 6; t++) CHECK_OK(hearth_sim_step(e, zero, &err), &err);
  CHECK(hearth_sim_success(e));
}

static void check_task(const char *root, hearth_sim_task task) {
  hearth_err err = {0};
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.task = task;
  o.release_root = root;
  o.width = o.height = 96;
  hearth_sim_env *e = NULL;
  const char *name = hearth_sim_task_name(task);
  CHECK_OK(hearth_sim_env_new(&o, &e, &err), &err);
  if (!e) return;
  CHECK_OK(hearth_sim_reset(e, 7, 0, 0, &err), &err);
  /* the layout rule: both candidates visible, by ray casts and in pixels */
  CHECK(sim_visible_frac(e, 0) >= SIM_MIN_VISIBLE && sim_visible_frac(e, 1) >= SIM_MIN_VISIBLE);
  double tv = 0, ov = 0;
  CHECK_OK(hearth_sim_visibility(e, &tv, &ov, &err), &err);
  CHECK_MSG(tv > 0.5 && ov > 0.5, "%s: candidates visible %.2f / %.2f", name, tv, ov);
  if (task != HEARTH_SIM_H3) check_crops(e, name);
  if (task == HEARTH_SIM_H1) check_success_rule(e);
  for (int ins = 0; ins < 2; ins++) {
    CHECK_OK(hearth_sim_reset(e, 7, 0, ins, &err), &err);
    CHECK(strcmp(hearth_sim_instruction(e), hearth_sim_instruction_text(task, ins)) == 0);
    int ok = 0, t;
    for (t = 0; t < hearth_sim_max_steps(e) && !ok; t++) {
      double a[7];
      hearth_sim_expert_action(e, a);
      for (int i = 0; i < 7; i++) CHECK(a[i] >= -1 && a[i] <= 1);
      CHECK_OK(hearth_sim_step(e, a, &err), &err);
      ok = hearth_sim_success(e);
      /* never a success while the expert still holds the object */
      if (ok) CHECK_MSG(e->phase >= 6, "%s: success reported in expert phase %d", name, e->phase);
    }
    CHECK_MSG(ok, "%s instruction %d: expert failed", name, ins);
    fprintf(stderr, "test_sim: %s instruction %d: success after %d steps\n", name, ins, t);
  }
  /* bad input */
  double bad[7] = {0, 0, NAN, 0, 0, 0, 0};
  CHECK(hearth_sim_step(e, bad, &err) == HEARTH_E_RANGE);
  CHECK(strstr(err.msg, "action[2]") != NULL);
  CHECK(hearth_sim_reset(e, 1, 0, 2, &err) == HEARTH_E_ARG);
  hearth_sim_env_free(e);
}

/* ---- the HDF5 file ------------------------------------------------------- */
static int read_str_attr(hid_t f, const char *obj, const char *name, char *out, size_t cap) {
  out[0] = 0;
  if (H5Aexists_by_name(f, obj, name, H5P_DEFAULT) <= 0) return 0;
  hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
  hid_t t = H5Aget_type(a);
  /* every string attribute is variable-length UTF-8 (h5py reads str) */
  int ok =
      H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) && H5Tget_cset(t) == H5T_CSET_UTF8;
  char *s = NULL;
  if (ok) ok = H5Aread(a, t, &s) >= 0 && s && strlen(s) < cap;
  if (ok) snprintf(out, cap, "%s", s);
  if (s) H5free_memory(s);
  H5Tclose(t), H5Aclose(a);
  return ok;
}
static long long read_int_attr(hid_t f, const char *obj, const char *name) {
  long long v = -1;
  if (H5Aexists_by_name(f, obj, name, H5P_DEFAULT) <= 0) return -1;
  hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
  if (H5Aread(a, H5T_NATIVE_LLONG, &v) < 0) v = -1;
  H5Aclose(a);
  return v;
}
/* rank and dims of a dataset; 0 if missing */
static int dims_of(hid_t f, const char *path, hsize_t d[4]) {
  if (H5Lexists(f, path, H5P_DEFAULT) <= 0) return 0;
  hid_t ds = H5Dopen2(f, path, H5P_DEFAULT);
  hid_t sp = H5Dget_space(ds);
  int r = H5Sget_simple_extent_ndims(sp);
  if (r > 4) r = 4;
  H5Sget_simple_extent_dims(sp, d, NULL);
  H5Sclose(sp), H5Dclose(ds);
  return r;
}

static void check_file(const char *path, int S) {
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  CHECK(f >= 0);
  if (f < 0) return;
  char s[2048];
  /* the spec's wording of H1's instructions (independent of the code) */
  const char *want[2] = {"pick up the hot cup and place it on the mat",
                         "pick up the normal cup and place it on the mat"};
  CHECK(read_str_attr(f, "data", "problem_info", s, sizeof s));
  json_error_t je;
  json_t *pi = json_loads(s, 0, &je);
  CHECK(pi && json_is_string(json_object_get(pi, "language_instruction")));
  if (pi)
    CHECK(strcmp(json_string_value(json_object_get(pi, "language_instruction")), want[0]) == 0);
  json_decref(pi);
  CHECK(read_str_attr(f, "data", "env_args", s, sizeof s));
  json_t *ea = json_loads(s, 0, &je);
  CHECK(json_is_object(ea));
  /* collected with the default renderer, the one sim eval uses by default */
  json_t *kw = json_object_get(ea, "env_kwargs");
  const char *rn = json_string_value(json_object_get(kw, "renderer"));
  CHECK_MSG(rn && strcmp(rn, "soft") == 0, "env_args renderer %s", rn ? rn : "(none)");
  json_decref(ea);
  CHECK(read_str_attr(f, "data", "instructions", s, sizeof s));
  json_t *il = json_loads(s, 0, &je);
  CHECK(json_is_array(il) && json_array_size(il) == 2);
  for (size_t i = 0; il && i < 2; i++)
    CHECK(strcmp(json_string_value(json_array_get(il, i)), want[i]) == 0);
  json_decref(il);
  CHECK(read_str_attr(f, "data", "image_row_order", s, sizeof s) && strstr(s, "bottom"));
  CHECK(read_str_attr(f, "data", "macros_image_convention", s, sizeof s) &&
        strcmp(s, "opengl") == 0);
  CHECK(read_str_attr(f, "data", "env_name", s, sizeof s) && strcmp(s, "hearth_H1") == 0);
  CHECK(read_str_attr(f, "data", "bddl_file_content", s, sizeof s) && strstr(s, "(:goal"));
  CHECK(read_int_attr(f, "data", "num_demos") == 2);
  long long total = 0;
  for (int k = 0; k < 2; k++) {
    char g[64], p[128];
    snprintf(g, sizeof g, "data/demo_%d", k);
    long long T = read_int_attr(f, g, "num_samples");
    CHECK(T > 10);
    total += T;
    CHECK(read_str_attr(f, g, "language_instruction", s, sizeof s) && strcmp(s, want[k]) == 0);
    struct {
      const char *key;
      int rank;
      hsize_t d1, d2, d3;
    } want_ds[] = {{"actions", 2, 7, 0, 0},
                   {"rewards", 1, 0, 0, 0},
                   {"robot_states", 2, 9, 0, 0},
                   {"dones", 1, 0, 0, 0},
                   {"obs/agentview_rgb", 4, (hsize_t)S, (hsize_t)S, 3},
                   {"obs/agentview_thermal", 4, (hsize_t)S, (hsize_t)S, 3},
                   {"obs/eye_in_hand_rgb", 4, (hsize_t)S, (hsize_t)S, 3},
                   {"obs/joint_states", 2, 7, 0, 0},
                   {"obs/gripper_states", 2, 2, 0, 0},
                   {"obs/ee_states", 2, 6, 0, 0},
                   {"obs/ee_pos", 2, 3, 0, 0},
                   {"obs/ee_ori", 2, 3, 0, 0}};
    for (size_t i = 0; i < sizeof want_ds / sizeof want_ds[0]; i++) {
      hsize_t d[4] = {0};
      snprintf(p, sizeof p, "%s/%s", g, want_ds[i].key);
      int r = dims_of(f, p, d);
      CHECK_MSG(r == want_ds[i].rank && (long long)d[0] == T && (r < 2 || d[1] == want_ds[i].d1) &&
                    (r < 3 || d[2] == want_ds[i].d2) && (r < 4 || d[3] == want_ds[i].d3),
                "%s: rank %d dims %llu %llu %llu %llu", p, r, (unsigned long long)d[0],
                (unsigned long long)d[1], (unsigned long long)d[2], (unsigned long long)d[3]);
    }
    hsize_t d[4] = {0};
    snprintf(p, sizeof p, "%s/states", g);
    CHECK(dims_of(f, p, d) == 2 && (long long)d[0] == T && d[1] > 7);
    /* the last step is done and rewarded, earlier ones not */
    if (T > 0 && T < 10000) {
      uint8_t *dn = malloc((size_t)T);
      snprintf(p, sizeof p, "%s/dones", g);
      hid_t ds = H5Dopen2(f, p, H5P_DEFAULT);
      if (dn && ds >= 0 && H5Dread(ds, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, dn) >= 0) {
        CHECK(dn[T - 1] == 1 && dn[0] == 0);
      } else {
        CHECK(0);
      }
      if (ds >= 0) H5Dclose(ds);
      free(dn);
    }
  }
  CHECK(read_int_attr(f, "data", "total") == total);
  H5Fclose(f);
}

static long file_bytes(const char *path, uint8_t **out) {
  FILE *fp = fopen(path, "rb");
  *out = NULL;
  if (!fp) return -1;
  fseek(fp, 0, SEEK_END);
  long n = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  *out = malloc(n > 0 ? (size_t)n : 1);
  if (!*out || fread(*out, 1, (size_t)n, fp) != (size_t)n) n = -1;
  fclose(fp);
  return n;
}

static const char *g_renderer; /* NULL: the default */

static hearth_status collect(const char *root, const char *path, int S, int max_steps,
                             hearth_sim_collect_stats *s, hearth_err *err) {
  hearth_sim_collect_opts o;
  hearth_sim_collect_opts_default(&o);
  o.renderer = g_renderer;
  o.task = HEARTH_SIM_H1;
  o.release_root = root;
  o.layouts = 1;
  o.image_size = S;
  o.seed = 3;
  o.quiet = 1;
  o.max_steps = max_steps;
  o.keep_failures = max_steps < 100; /* short runs: store what there is */
  o.out_path = path;
  return hearth_sim_collect(&o, s, err);
}

static int same_file(const char *a, const char *b) {
  uint8_t *x, *y;
  long nx = file_bytes(a, &x), ny = file_bytes(b, &y);
  int same = nx > 0 && nx == ny && x && y && memcmp(x, y, (size_t)nx) == 0;
  free(x), free(y);
  return same;
}

static hearth_status collect_shard(const char *root, const char *path, int layouts, int shard,
                                   int shards, int split, hearth_err *err) {
  hearth_sim_collect_opts o;
  hearth_sim_collect_opts_default(&o);
  o.task = HEARTH_SIM_H1;
  o.release_root = root;
  o.layouts = layouts;
  o.image_size = 24;
  o.seed = 5;
  o.quiet = 1;
  o.max_steps = 12;
  o.keep_failures = 1;
  o.shard_index = shard, o.shard_count = shards;
  o.split_instructions = split;
  o.out_path = path;
  hearth_sim_collect_stats s;
  return hearth_sim_collect(&o, &s, err);
}

/* scale-out: the shards of a collection merged give the bytes of one run,
 * also for split files; merging refuses what is not one collection */
static void check_shards(const char *root, const char *dir) {
  hearth_err err = {0};
  char one[1200], part[3][1200], merged[1200];
  snprintf(one, sizeof one, "%s/one.hdf5", dir);
  snprintf(merged, sizeof merged, "%s/merged.hdf5", dir);
  CHECK_OK(collect_shard(root, one, 3, 0, 1, 0, &err), &err);
  for (int i = 0; i < 3; i++) {
    snprintf(part[i], sizeof part[i], "%s/part%d.hdf5", dir, i);
    CHECK_OK(collect_shard(root, part[i], 3, i, 3, 0, &err), &err);
  }
  const char *order[3] = {part[2], part[0], part[1]}; /* any order */
  int n = 0;
  CHECK_OK(hearth_sim_merge(merged, order, 3, &n, &err), &err);
  CHECK(n == 6);
  CHECK_MSG(same_file(one, merged), "3 shards merged differ from one run");
  /* split files: two shards per instruction file */
  char sone[1200], sp[2][1200], f1[1200], f2[1200];
  snprintf(sone, sizeof sone, "%s/sone.hdf5", dir);
  CHECK_OK(collect_shard(root, sone, 3, 0, 1, 1, &err), &err);
  for (int i = 0; i < 2; i++) {
    snprintf(sp[i], sizeof sp[i], "%s/sp%d.hdf5", dir, i);
    CHECK_OK(collect_shard(root, sp[i], 3, i, 2, 1, &err), &err);
  }
  for (int ins = 0; ins < 2; ins++) {
    char a[1200], b[1200], ref[1200], out[1200];
    hearth_sim_split_path(sp[0], ins, a, sizeof a);
    hearth_sim_split_path(sp[1], ins, b, sizeof b);
    hearth_sim_split_path(sone, ins, ref, sizeof ref);
    snprintf(out, sizeof out, "%s/smerged_%d.hdf5", dir, ins);
    const char *two[2] = {a, b};
    CHECK_OK(hearth_sim_merge(out, two, 2, &n, &err), &err);
    CHECK(n == 3);
    CHECK_MSG(same_file(ref, out), "split instruction %d: merged shards differ from one run",
              ins + 1);
  }
  hearth_sim_split_path(sp[0], 0, f1, sizeof f1);
  hearth_sim_split_path(sp[1], 1, f2, sizeof f2);
  /* refusals, each naming what is wrong */
  const char *missing[2] = {part[0], part[1]};
  CHECK(hearth_sim_merge(merged, missing, 2, NULL, &err) == HEARTH_E_ARG &&
        strstr(err.msg, "give all 3"));
  const char *twice[3] = {part[0], part[1], part[1]};
  CHECK(hearth_sim_merge(merged, twice, 3, NULL, &err) == HEARTH_E_ARG &&
        strstr(err.msg, "both shard 1/3"));
  const char *mixed[2] = {f1, f2};
  CHECK_MSG(hearth_sim_merge(merged, mixed, 2, NULL, &err) == HEARTH_E_ARG &&
                strstr(err.msg, "differ in data@"),
            "%s", err.msg);
  const char *whole[1] = {one};
  CHECK(hearth_sim_merge(merged, whole, 1, NULL, &err) == HEARTH_E_ARG &&
        strstr(err.msg, "hearth_shard"));
  CHECK(same_file(one, merged)); /* a refused merge leaves the output as it was */
  CHECK(collect_shard(root, one, 3, 3, 3, 0, &err) == HEARTH_E_ARG);
  CHECK(collect_shard(root, one, 2, 2, 3, 0, &err) == HEARTH_E_ARG && strstr(err.msg, "no slot"));
}

static void check_collect(const char *root, const char *dir) {
  char path[3][1200];
  const int S = 32;
  hearth_err err = {0};
  hearth_sim_collect_stats s;
  for (int run = 0; run < 3; run++)
    snprintf(path[run], sizeof path[run], "%s/h1_%d.hdf5", dir, run);
  /* a full collect: both instructions of one layout succeed */
  CHECK_OK(collect(root, path[0], S, 400, &s, &err), &err);
  CHECK(s.demos == 2 && s.successes[0] == 1 && s.successes[1] == 1 && s.rejected_layouts == 0);
  check_file(path[0], S);
  /* same seed, same bytes (short episodes keep this cheap; they cover the
   * physics, the three renderers and the writer) */
  for (int run = 1; run < 3; run++) {
    CHECK_OK(collect(root, path[run], S, 30, &s, &err), &err);
    CHECK(s.demos == 2);
  }
  stamp("collects");
  uint8_t *a, *b;
  long na = file_bytes(path[1], &a), nb = file_bytes(path[2], &b);
  CHECK(na > 0 && na == nb && a && b && memcmp(a, b, (size_t)na) == 0);
  free(a), free(b);
  /* renderer none: the same episodes (the expert reads the state), no
   * image datasets */
  char none[1200];
  snprintf(none, sizeof none, "%s/h1_none.hdf5", dir);
  g_renderer = "none";
  CHECK_OK(collect(root, none, S, 30, &s, &err), &err);
  g_renderer = NULL;
  hid_t fa = H5Fopen(path[1], H5F_ACC_RDONLY, H5P_DEFAULT),
        fn = H5Fopen(none, H5F_ACC_RDONLY, H5P_DEFAULT);
  CHECK(fa >= 0 && fn >= 0);
  if (fa >= 0 && fn >= 0) {
    for (int dm = 0; dm < 2; dm++) {
      char ds[64];
      snprintf(ds, sizeof ds, "data/demo_%d/actions", dm);
      hsize_t da[4] = {0}, dn[4] = {0};
      CHECK(dims_of(fa, ds, da) == 2 && dims_of(fn, ds, dn) == 2 && da[0] == dn[0]);
      if (da[0] == dn[0] && da[0] > 0) {
        double *xa = malloc(sizeof(double) * da[0] * 7), *xn = malloc(sizeof(double) * da[0] * 7);
        hid_t a1 = H5Dopen2(fa, ds, H5P_DEFAULT), a2 = H5Dopen2(fn, ds, H5P_DEFAULT);
        CHECK(H5Dread(a1, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, xa) >= 0 &&
              H5Dread(a2, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, xn) >= 0);
        CHECK_MSG(memcmp(xa, xn, sizeof(double) * da[0] * 7) == 0,
                  "renderer none: demo %d took other actions", dm);
        H5Dclose(a1), H5Dclose(a2);
        free(xa), free(xn);
      }
      snprintf(ds, sizeof ds, "data/demo_%d/obs/agentview_rgb", dm);
      CHECK_MSG(H5Lexists(fa, ds, H5P_DEFAULT) > 0 && H5Lexists(fn, ds, H5P_DEFAULT) == 0,
                "renderer none: %s should exist only in the rendered file", ds);
    }
  }
  if (fa >= 0) H5Fclose(fa);
  if (fn >= 0) H5Fclose(fn);
  /* h5py (Debian python3-h5py), when present, reads it with LIBERO's keys */
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (src && access("/usr/bin/python3", X_OK) == 0 &&
      system("/usr/bin/python3 -c 'import h5py' 2>/dev/null") == 0) {
    char cmd[4000];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s/bench/sim_check_hdf5.py' '%s' >&2", src,
             path[0]);
    CHECK_MSG(system(cmd) == 0, "h5py check of %s failed", path[0]);
    /* every LIBERO / robomimic key with its type, strings as str */
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 '%s/tests/sim/check_libero_keys.py' '%s' --size %d >&2", src,
             path[0], S);
    CHECK_MSG(system(cmd) == 0, "LIBERO key check of %s failed", path[0]);
    char split1[1200];
    snprintf(cmd, sizeof cmd, "%s/sone.hdf5", dir);
    hearth_sim_split_path(cmd, 1, split1, sizeof split1);
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 '%s/tests/sim/check_libero_keys.py' '%s' --instructions 1 >&2", src,
             split1);
    CHECK_MSG(system(cmd) == 0, "LIBERO key check of %s failed", split1);
  } else {
    fprintf(stderr, "test_sim: no /usr/bin/python3 with h5py: skipping the h5py check\n");
  }
}

int main(void) {
  g_t0 = hearth_now();
  const char *dir = test_tmpdir("sim_tasks");
  char dirbuf[1100];
  snprintf(dirbuf, sizeof dirbuf, "%s", dir);
  const char *root = test_sim_release(dirbuf);
  stamp("virtual-rig release");
  check_task(root, HEARTH_SIM_H1);
  stamp("H1");
  check_task(root, HEARTH_SIM_H2);
  stamp("H2");
  check_task(root, HEARTH_SIM_H3);
  stamp("H3");
  check_shards(root, dirbuf);
  stamp("shards and merge");
  check_collect(root, dirbuf);
  stamp("collect checks");
  return g_test_failures ? 1 : 0;
}
