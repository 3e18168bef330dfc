/* The LeRobot v2.1 export (hearth/export.h; fields and sources in
 * docs/lerobot.md): demos are read one at a time, their images rotated and
 * PNG-encoded in parallel (results by index, so the bytes do not depend on
 * the thread count), written as one Parquet file per episode, and their
 * statistics and metadata lines collected; the meta/ files and
 * norm_stats.json follow the last episode. Everything goes into a
 * temporary directory beside the output, renamed into place at the end. */
#include <dirent.h>
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "export/export_internal.h"
#include "hearth/export.h"
#include "hearth/geom.h"
#include "hearth/image.h"
#include "hearth/parquet.h"

void hearth_lerobot_opts_default(hearth_lerobot_opts *o) {
  memset(o, 0, sizeof *o);
  o->robot_type = "panda";
  o->thermal = 1;
}

/* ---- per-frame conversions -------------------------------------------------- */
void hearth_lerobot_axis_angle(const double rotvec[3], double out[3]) {
  const double ref[4] = HEARTH_LEROBOT_QUAT_REF;
  hearth_rotvec_to_axis_angle_near(rotvec, ref, out);
}

void hearth_lerobot_state(const double ee_pos[3], const double ee_ori[3], const double gripper[2],
                          double state[8]) {
  memcpy(state, ee_pos, 3 * sizeof(double));
  hearth_lerobot_axis_angle(ee_ori, state + 3);
  memcpy(state + 6, gripper, 2 * sizeof(double));
}

void hearth_lerobot_rotate180(const uint8_t *in, int w, int h, uint8_t *out) {
  size_t n = (size_t)w * (size_t)h;
  for (size_t k = 0; k < n; k++) memcpy(out + 3 * k, in + 3 * (n - 1 - k), 3);
}

/* ---- the features ----------------------------------------------------------- */
enum { F_IMAGE, F_VECTOR, F_FLOAT, F_INT };
typedef struct feature {
  const char *name;
  int kind, len;
} feature;
/* LeRobot's order: the dataset's features, then DEFAULT_FEATURES */
static const feature k_features[] = {
    {"image", F_IMAGE, 0},     {"wrist_image", F_IMAGE, 0}, {"thermal_image", F_IMAGE, 0},
    {"state", F_VECTOR, 8},    {"actions", F_VECTOR, 7},    {"thermal_state", F_VECTOR, 0},
    {"timestamp", F_FLOAT, 1}, {"frame_index", F_INT, 1},   {"episode_index", F_INT, 1},
    {"index", F_INT, 1},       {"task_index", F_INT, 1},
};
#define N_FEATURES (sizeof k_features / sizeof k_features[0])

/* what the inputs carry: the thermal view (unless opts.thermal is 0) and a
 * dynamic collection's obs/thermal_state of th_dim named columns */
typedef struct schema {
  int thermal, th_dim;
  const char *th_names; /* `;`-separated */
} schema;

static int feature_on(const schema *sc, size_t f) {
  const char *nm = k_features[f].name;
  if (strcmp(nm, "thermal_image") == 0) return sc->thermal;
  if (strcmp(nm, "thermal_state") == 0) return sc->thermal && sc->th_dim > 0;
  return 1;
}

static int feature_len(const schema *sc, size_t f) {
  return k_features[f].len ? k_features[f].len : sc->th_dim;
}

/* datasets' Features.to_dict() as json.dumps writes it: the Parquet
 * files' "huggingface" metadata */
static void hf_metadata(const schema *sc, ex_text *t) {
  ex_puts(t, "{\"info\": {\"features\": {");
  int first = 1;
  for (size_t f = 0; f < N_FEATURES; f++) {
    if (!feature_on(sc, f)) continue;
    const feature *ft = &k_features[f];
    if (!first) ex_puts(t, ", ");
    first = 0;
    ex_put_jstr(t, ft->name);
    switch (ft->kind) {
      case F_IMAGE: ex_puts(t, ": {\"_type\": \"Image\"}"); break;
      case F_VECTOR:
        ex_printf(
            t,
            ": {\"feature\": {\"dtype\": \"float32\", \"_type\": \"Value\"}, \"length\": %d, \"_type\": \"Sequence\"}",
            feature_len(sc, f));
        break;
      case F_FLOAT: ex_puts(t, ": {\"dtype\": \"float32\", \"_type\": \"Value\"}"); break;
      case F_INT: ex_puts(t, ": {\"dtype\": \"int64\", \"_type\": \"Value\"}"); break;
    }
  }
  ex_puts(t, "}}}");
}

/* info.json's "features" */
/* the region names of thermal_state as a JSON array */
static json_t *name_list(const char *names) {
  json_t *a = json_array();
  const char *p = names;
  while (*p) {
    const char *e = strchr(p, ';');
    size_t n = e ? (size_t)(e - p) : strlen(p);
    json_array_append_new(a, json_stringn(p, n));
    p += n + (e ? 1 : 0);
  }
  return a;
}

static json_t *info_features(const schema *sc, int size) {
  json_t *fs = json_object();
  for (size_t f = 0; f < N_FEATURES; f++) {
    if (!feature_on(sc, f)) continue;
    const feature *ft = &k_features[f];
    json_t *j = json_object();
    if (ft->kind == F_IMAGE) {
      json_object_set_new(j, "dtype", json_string("image"));
      json_object_set_new(j, "shape", json_pack("[iii]", size, size, 3));
      json_object_set_new(j, "names", json_pack("[sss]", "height", "width", "channel"));
    } else {
      json_object_set_new(j, "dtype", json_string(ft->kind == F_INT ? "int64" : "float32"));
      json_object_set_new(j, "shape", json_pack("[i]", feature_len(sc, f)));
      json_object_set_new(j, "names",
                          ft->kind != F_VECTOR                     ? json_null()
                          : strcmp(ft->name, "thermal_state") == 0 ? name_list(sc->th_names)
                                                                   : json_pack("[s]", ft->name));
    }
    json_object_set_new(fs, ft->name, j);
  }
  return fs;
}

/* ---- one episode ------------------------------------------------------------ */
typedef struct png_job {
  uint8_t *views[3]; /* rotated frames, T x size x size x 3 */
  int nviews, size;
  uint8_t **png; /* [frame * nviews + view] */
  size_t *png_len;
  int *failed;
} png_job;

static void encode_pngs(void *ctx, size_t b, size_t e, int t) {
  (void)t;
  png_job *j = ctx;
  size_t fs = (size_t)j->size * (size_t)j->size * 3;
  for (size_t k = b; k < e; k++) {
    size_t frame = k / (size_t)j->nviews, v = k % (size_t)j->nviews;
    hearth_image img = {(size_t)j->size, (size_t)j->size, 3, HEARTH_PIX_U8,
                        j->views[v] + frame * fs};
    hearth_err err = {0};
    j->failed[k] = hearth_png_encode(&img, &j->png[k], &j->png_len[k], &err) != HEARTH_OK;
  }
}

/* everything the export accumulates */
typedef struct exporter {
  const hearth_lerobot_opts *o;
  schema sc;
  char tmp[4200];
  int size, fps;
  char **tasks;
  size_t ntasks;
  ex_text episodes, stats, hfmeta;
  float *norm_state, *norm_actions; /* every frame's values */
  size_t frames, frames_cap, episode;
} exporter;

static int task_index(exporter *x, const char *task) {
  for (size_t k = 0; k < x->ntasks; k++)
    if (strcmp(x->tasks[k], task) == 0) return (int)k;
  char **nt = realloc(x->tasks, (x->ntasks + 1) * sizeof *nt);
  if (!nt) return -1;
  x->tasks = nt;
  if (!(nt[x->ntasks] = strdup(task))) return -1;
  return (int)x->ntasks++;
}

static hearth_status grow_norm(exporter *x, size_t T, hearth_err *err) {
  if (x->frames + T <= x->frames_cap) return HEARTH_OK;
  size_t cap = x->frames_cap ? x->frames_cap : 4096;
  while (cap < x->frames + T) cap *= 2;
  float *s = realloc(x->norm_state, cap * 8 * sizeof *s);
  if (s) x->norm_state = s;
  float *a = s ? realloc(x->norm_actions, cap * 7 * sizeof *a) : NULL;
  if (!s || !a)
    return hearth_err_set(err, HEARTH_E_NOMEM, "export: norm statistics of %zu frames", cap);
  x->norm_actions = a;
  x->frames_cap = cap;
  return HEARTH_OK;
}

/* the Parquet file of one episode */
static hearth_status write_parquet(exporter *x, const png_job *pj, const float *state,
                                   const float *actions, const float *th, size_t T, int task,
                                   hearth_err *err) {
  char dir[4400], path[4500];
  size_t chunk = x->episode / HEARTH_LEROBOT_CHUNK_SIZE;
  snprintf(dir, sizeof dir, "%s/data/chunk-%03zu", x->tmp, chunk);
  snprintf(path, sizeof path, "%s/episode_%06zu.parquet", dir, x->episode);
  hearth_status st = hearth_mkdirs(dir, err);
  if (st) return st;
  hearth_pq_column cols[N_FEATURES];
  size_t nc = 0;
  for (size_t f = 0; f < N_FEATURES; f++) {
    if (!feature_on(&x->sc, f)) continue;
    static const hearth_pq_kind kinds[] = {HEARTH_PQ_BLOB, HEARTH_PQ_FLOAT_LIST, HEARTH_PQ_FLOAT,
                                           HEARTH_PQ_INT64};
    cols[nc++] = (hearth_pq_column){k_features[f].name, kinds[k_features[f].kind]};
  }
  hearth_pq_writer *w;
  st = hearth_pq_open(path, cols, nc, HEARTH_LEROBOT_ROWS_PER_GROUP, &w, err);
  if (st) return st;
  st = hearth_pq_add_metadata(w, "huggingface", x->hfmeta.p, err);
  for (size_t i = 0; i < T && !st; i++) {
    hearth_pq_cell cells[N_FEATURES];
    char name[32];
    snprintf(name, sizeof name, "frame_%06zu.png", i);
    size_t c = 0;
    int view = 0;
    for (size_t f = 0; f < N_FEATURES; f++) {
      if (!feature_on(&x->sc, f)) continue;
      hearth_pq_cell *cl = &cells[c++];
      memset(cl, 0, sizeof *cl);
      const char *nm = k_features[f].name;
      if (k_features[f].kind == F_IMAGE) {
        size_t k = i * (size_t)pj->nviews + (size_t)view++;
        cl->bytes = pj->png[k], cl->bytes_len = pj->png_len[k], cl->path = name;
      } else if (strcmp(nm, "state") == 0) {
        cl->list = state + 8 * i, cl->list_len = 8;
      } else if (strcmp(nm, "actions") == 0) {
        cl->list = actions + 7 * i, cl->list_len = 7;
      } else if (strcmp(nm, "thermal_state") == 0) {
        size_t R = (size_t)x->sc.th_dim;
        cl->list = th + R * i, cl->list_len = R;
      } else if (strcmp(nm, "timestamp") == 0) {
        cl->f = (float)((double)i / (double)x->fps);
      } else if (strcmp(nm, "frame_index") == 0) {
        cl->i = (int64_t)i;
      } else if (strcmp(nm, "episode_index") == 0) {
        cl->i = (int64_t)x->episode;
      } else if (strcmp(nm, "index") == 0) {
        cl->i = (int64_t)(x->frames + i);
      } else {
        cl->i = task;
      }
    }
    st = hearth_pq_write_row(w, cells, err);
  }
  if (st) {
    hearth_pq_abort(w);
    return st;
  }
  return hearth_pq_close(w, err);
}

/* the episode's line of meta/episodes_stats.jsonl */
static hearth_status episode_stats(exporter *x, const png_job *pj, const float *state,
                                   const float *actions, const float *th, size_t T, int task,
                                   hearth_err *err) {
  double *ts = hearth_alloc_array(T, sizeof *ts);
  int64_t *iv = hearth_alloc_array(T, sizeof *iv);
  if (!ts || !iv) {
    free(ts), free(iv);
    return hearth_err_set(err, HEARTH_E_NOMEM, "export: episode statistics");
  }
  hearth_status st = HEARTH_OK;
  ex_text *t = &x->stats;
  ex_printf(t, "{\"episode_index\": %zu, \"stats\": {", x->episode);
  int view = 0, first = 1;
  for (size_t f = 0; f < N_FEATURES && !st; f++) {
    if (!feature_on(&x->sc, f)) continue;
    const char *nm = k_features[f].name;
    ex_stats s;
    if (k_features[f].kind == F_IMAGE) {
      st = ex_stats_images(pj->views[view++], T, pj->size, pj->size, &s, err);
    } else if (k_features[f].kind == F_VECTOR) {
      const float *v = strcmp(nm, "state") == 0 ? state : strcmp(nm, "actions") == 0 ? actions : th;
      ex_stats_f32(v, T, feature_len(&x->sc, f), &s);
    } else if (k_features[f].kind == F_FLOAT) {
      for (size_t i = 0; i < T; i++) ts[i] = (double)i / (double)x->fps;
      st = ex_stats_f64(ts, T, &s, err);
    } else {
      for (size_t i = 0; i < T; i++)
        iv[i] = strcmp(nm, "frame_index") == 0     ? (int64_t)i
                : strcmp(nm, "episode_index") == 0 ? (int64_t)x->episode
                : strcmp(nm, "index") == 0         ? (int64_t)(x->frames + i)
                                                   : task;
      st = ex_stats_i64(iv, T, &s, err);
    }
    if (st) break;
    if (!first) ex_puts(t, ", ");
    first = 0;
    ex_put_stats(t, nm, &s);
  }
  ex_puts(t, "}}\n");
  free(ts), free(iv);
  return st;
}

static hearth_status export_demo(exporter *x, const ex_source *src, size_t src_index, int64_t k,
                                 hearth_err *err) {
  ex_demo d;
  hearth_status st = ex_demo_read(src, k, x->o->thermal, &d, err);
  size_t T = d.T, S = (size_t)x->size, fs = S * S * 3;
  png_job pj = {{NULL}, x->o->thermal ? 3 : 2, x->size, NULL, NULL, NULL};
  float *state = NULL, *actions = NULL;
  if (!st) {
    const uint8_t *in[3] = {d.rgb, d.wrist, d.thermal};
    for (int v = 0; v < pj.nviews && !st; v++) {
      pj.views[v] = hearth_alloc_array(T, fs);
      if (!pj.views[v])
        st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: data/demo_%lld: %zu frames of %zux%zu",
                            src->path, (long long)k, T, S, S);
      for (size_t i = 0; i < T && !st; i++)
        hearth_lerobot_rotate180(in[v] + i * fs, x->size, x->size, pj.views[v] + i * fs);
    }
  }
  size_t n_png = T * (size_t)pj.nviews;
  if (!st) {
    pj.png = calloc(n_png, sizeof *pj.png);
    pj.png_len = calloc(n_png, sizeof *pj.png_len);
    pj.failed = calloc(n_png, sizeof *pj.failed);
    state = hearth_alloc_array(T, 8 * sizeof *state);
    actions = hearth_alloc_array(T, 7 * sizeof *actions);
    if (!pj.png || !pj.png_len || !pj.failed || !state || !actions)
      st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: data/demo_%lld: %zu frames", src->path,
                          (long long)k, T);
  }
  if (!st) {
    hearth_parallel_for(n_png, x->o->threads, encode_pngs, &pj);
    for (size_t i = 0; i < n_png && !st; i++)
      if (pj.failed[i])
        st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: data/demo_%lld: PNG of frame %zu", src->path,
                            (long long)k, i / (size_t)pj.nviews);
  }
  int task = -1;
  if (!st) {
    for (size_t i = 0; i < T; i++) {
      double s8[8];
      hearth_lerobot_state(d.ee_pos + 3 * i, d.ee_ori + 3 * i, d.gripper + 2 * i, s8);
      for (int j = 0; j < 8; j++) state[8 * i + (size_t)j] = (float)s8[j];
      for (int j = 0; j < 7; j++) actions[7 * i + (size_t)j] = (float)d.actions[7 * i + (size_t)j];
    }
    task = task_index(x, d.instruction);
    if (task < 0) st = hearth_err_set(err, HEARTH_E_NOMEM, "export: tasks");
  }
  if (!st) st = write_parquet(x, &pj, state, actions, d.thermal_state, T, task, err);
  if (!st) st = episode_stats(x, &pj, state, actions, d.thermal_state, T, task, err);
  if (!st) st = grow_norm(x, T, err);
  if (!st) {
    memcpy(x->norm_state + 8 * x->frames, state, T * 8 * sizeof *state);
    memcpy(x->norm_actions + 7 * x->frames, actions, T * 7 * sizeof *actions);
    ex_text *e = &x->episodes;
    ex_printf(e, "{\"episode_index\": %zu, \"tasks\": [", x->episode);
    ex_put_jstr(e, d.instruction);
    ex_printf(e, "], \"length\": %zu, \"hearth\": {\"source\": %zu, \"demo\": %lld, \"task\": ", T,
              src_index, (long long)k);
    ex_put_jstr(e, src->task);
    ex_printf(e, ", \"seed\": %lld, \"layout\": %lld, \"instruction_index\": %lld}}\n",
              (long long)src->seed, (long long)d.layout, (long long)d.instruction_index);
    x->frames += T;
    x->episode++;
  }
  if (pj.png)
    for (size_t i = 0; i < n_png; i++) free(pj.png[i]);
  free(pj.png), free(pj.png_len), free(pj.failed);
  for (int v = 0; v < 3; v++) free(pj.views[v]);
  free(state), free(actions);
  ex_demo_free(&d);
  return st;
}

/* ---- meta files ------------------------------------------------------------- */
static hearth_status write_text(const exporter *x, const char *rel, const ex_text *t,
                                hearth_err *err) {
  char path[4400];
  snprintf(path, sizeof path, "%s/%s", x->tmp, rel);
  if (t->failed) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  return hearth_write_file_atomic(path, t->p ? t->p : "", t->n, err);
}

static const char *base_name(const char *p) {
  const char *s = strrchr(p, '/');
  return s ? s + 1 : p;
}

static hearth_status write_info(const exporter *x, const ex_source *src,
                                const size_t *first_episode, hearth_err *err) {
  const hearth_lerobot_opts *o = x->o;
  json_t *j = json_object();
  char split[64];
  snprintf(split, sizeof split, "0:%zu", x->episode);
  json_object_set_new(j, "codebase_version", json_string(HEARTH_LEROBOT_VERSION));
  json_object_set_new(j, "robot_type", json_string(o->robot_type));
  json_object_set_new(j, "total_episodes", json_integer((json_int_t)x->episode));
  json_object_set_new(j, "total_frames", json_integer((json_int_t)x->frames));
  json_object_set_new(j, "total_tasks", json_integer((json_int_t)x->ntasks));
  json_object_set_new(j, "total_videos", json_integer(0));
  json_object_set_new(j, "total_chunks",
                      json_integer((json_int_t)((x->episode + HEARTH_LEROBOT_CHUNK_SIZE - 1) /
                                                HEARTH_LEROBOT_CHUNK_SIZE)));
  json_object_set_new(j, "chunks_size", json_integer(HEARTH_LEROBOT_CHUNK_SIZE));
  json_object_set_new(j, "fps", json_integer(x->fps));
  json_object_set_new(j, "splits", json_pack("{ss}", "train", split));
  json_object_set_new(j, "data_path",
                      json_string(
                          "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet"));
  json_object_set_new(
      j, "video_path",
      json_string("videos/chunk-{episode_chunk:03d}/{video_key}/episode_{episode_index:06d}.mp4"));
  json_object_set_new(j, "features", info_features(&x->sc, x->size));
  json_t *h = json_object();
  json_object_set_new(h, "software_version", json_string(HEARTH_VERSION));
  json_object_set_new(h, "images",
                      json_string("the collection's views rotated by 180 degrees (OpenGL rows -> "
                                  "img[::-1, ::-1]), as hearth sim eval sends them"));
  json_object_set_new(h, "state",
                      json_string(
                          "ee_pos (3), continuous axis-angle of ee_ori (3), gripper_states (2)"));
  json_object_set_new(h, "actions",
                      json_string("[dx dy dz dax day daz grip] in [-1, 1], as stored"));
  if (x->sc.thermal && x->sc.th_dim > 0)
    json_object_set_new(h, "thermal_state",
                        json_string(
                            "obs/thermal_state as stored: the lumped thermal model's region "
                            "temperatures (degC) of objects 0..3, columns as named"));
  json_t *srcs = json_array();
  for (size_t k = 0; k < o->n_inputs; k++) {
    char eps[64];
    snprintf(eps, sizeof eps, "%zu:%zu", first_episode[k], first_episode[k + 1]);
    json_t *s = json_object();
    json_object_set_new(s, "file", json_string(base_name(src[k].path)));
    json_object_set_new(s, "task", json_string(src[k].task));
    json_object_set_new(s, "seed", json_integer((json_int_t)src[k].seed));
    json_object_set_new(s, "asset_source", json_string(src[k].asset_source));
    json_object_set_new(s, "renderer", json_string(src[k].renderer));
    json_object_set_new(s, "episodes", json_string(eps));
    json_array_append_new(srcs, s);
  }
  json_object_set_new(h, "sources", srcs);
  json_object_set_new(j, "hearth", h);
  char *text = json_dumps(j, JSON_INDENT(4) | JSON_PRESERVE_ORDER);
  json_decref(j);
  if (!text) return hearth_err_set(err, HEARTH_E_NOMEM, "export: info.json");
  ex_text t = {text, strlen(text), strlen(text) + 1, 0};
  hearth_status st = write_text(x, "meta/info.json", &t, err);
  free(text);
  return st;
}

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return x < y ? -1 : x > y;
}

/* openpi's norm_stats.json: per dimension mean, std and the 1st / 99th
 * percentile (the smallest value with at least that fraction of the
 * values at or below it) over every frame */
static hearth_status norm_stats(const exporter *x, hearth_err *err) {
  ex_text t = {0};
  size_t N = x->frames;
  float *col = hearth_alloc_array(N ? N : 1, sizeof *col);
  if (!col) return hearth_err_set(err, HEARTH_E_NOMEM, "export: norm statistics");
  ex_puts(&t, "{\n  \"norm_stats\": {");
  for (int key = 0; key < 2; key++) {
    const float *v = key == 0 ? x->norm_state : x->norm_actions;
    int dim = key == 0 ? 8 : 7;
    double st[4][8];
    for (int j = 0; j < dim; j++) {
      double sum = 0, ss = 0;
      for (size_t i = 0; i < N; i++) sum += v[i * (size_t)dim + (size_t)j];
      double m = N ? sum / (double)N : 0;
      for (size_t i = 0; i < N; i++) {
        double dv = v[i * (size_t)dim + (size_t)j] - m;
        ss += dv * dv;
        col[i] = v[i * (size_t)dim + (size_t)j];
      }
      qsort(col, N, sizeof *col, cmp_float);
      st[0][j] = m;
      st[1][j] = N ? sqrt(ss / (double)N) : 0;
      for (int q = 0; q < 2; q++) {
        double c = ceil((q == 0 ? 0.01 : 0.99) * (double)N);
        size_t r = c < 1 ? 0 : (size_t)c - 1;
        st[2 + q][j] = N ? col[r < N ? r : N - 1] : 0;
      }
    }
    ex_puts(&t, key == 0 ? "\n    \"state\": {" : ",\n    \"actions\": {");
    static const char *names[4] = {"mean", "std", "q01", "q99"};
    for (int s = 0; s < 4; s++) {
      ex_printf(&t, "%s\n      \"%s\": [", s ? "," : "", names[s]);
      for (int j = 0; j < dim; j++) {
        ex_puts(&t, j ? ",\n        " : "\n        ");
        ex_put_float(&t, st[s][j]);
      }
      ex_puts(&t, "\n      ]");
    }
    ex_puts(&t, "\n    }");
  }
  ex_puts(&t, "\n  }\n}");
  free(col);
  hearth_status s = write_text(x, "norm_stats.json", &t, err);
  ex_text_free(&t);
  return s;
}

/* ---- the output directory --------------------------------------------------- */
static int dir_is_empty(const char *p) {
  DIR *d = opendir(p);
  if (!d) return 0;
  struct dirent *e;
  int empty = 1;
  while ((e = readdir(d)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) empty = 0;
  closedir(d);
  return empty;
}

static hearth_status make_tmp_dir(const char *out, char *tmp, size_t n, int *existed,
                                  hearth_err *err) {
  struct stat sb;
  *existed = 0;
  if (stat(out, &sb) == 0) {
    if (!S_ISDIR(sb.st_mode) || !dir_is_empty(out))
      return hearth_err_set(err, HEARTH_E_ARG,
                            "%s: exists and is not an empty directory; refusing to overwrite", out);
    *existed = 1;
  }
  char parent[4096];
  snprintf(parent, sizeof parent, "%s", out);
  char *slash = strrchr(parent, '/');
  if (slash && slash != parent) {
    *slash = 0;
    hearth_status st = hearth_mkdirs(parent, err);
    if (st) return st;
  }
  if ((size_t)snprintf(tmp, n, "%s.tmp-XXXXXX", out) >= n)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", out);
  if (!mkdtemp(tmp))
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create: %s", tmp, strerror(errno));
  char meta[4400];
  snprintf(meta, sizeof meta, "%s/meta", tmp);
  if (mkdir(meta, 0755) != 0) {
    hearth_remove_tree(tmp, NULL);
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot create: %s", meta, strerror(errno));
  }
  return HEARTH_OK;
}

hearth_status hearth_lerobot_export(const hearth_lerobot_opts *o, hearth_lerobot_stats *stats,
                                    hearth_err *err) {
  double t0 = hearth_now();
  if (stats) memset(stats, 0, sizeof *stats);
  if (!o || !o->out_dir || !*o->out_dir || !o->inputs || o->n_inputs < 1 ||
      o->n_inputs > HEARTH_LEROBOT_MAX_INPUTS || !o->robot_type)
    return hearth_err_set(
        err, HEARTH_E_ARG,
        "export: an output directory, a robot type and 1..%d input files are needed",
        HEARTH_LEROBOT_MAX_INPUTS);
  char out[4096];
  if ((size_t)snprintf(out, sizeof out, "%s", o->out_dir) >= sizeof out)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", o->out_dir);
  for (size_t n = strlen(out); n > 1 && out[n - 1] == '/';) out[--n] = 0;
  ex_source *src = calloc(o->n_inputs, sizeof *src);
  size_t *first = calloc(o->n_inputs + 1, sizeof *first);
  if (!src || !first) {
    free(src), free(first);
    return hearth_err_set(err, HEARTH_E_NOMEM, "export: sources");
  }
  hearth_status st = HEARTH_OK;
  size_t opened = 0, total = 0;
  for (; opened < o->n_inputs && !st; opened++) {
    st = ex_source_open(o->inputs[opened], &src[opened], err);
    if (st) break;
    total += (size_t)src[opened].num_demos;
    if (opened && (src[opened].size != src[0].size || src[opened].fps != src[0].fps))
      st = hearth_err_set(
          err, HEARTH_E_INCONSISTENT,
          "%s: %d-pixel images at %d Hz, but %s has %d-pixel images at %d Hz (one LeRobot dataset "
          "has one image shape and one fps)",
          src[opened].path, src[opened].size, src[opened].fps, src[0].path, src[0].size,
          src[0].fps);
    else if (opened && o->thermal &&
             (src[opened].th_dim != src[0].th_dim ||
              strcmp(src[opened].th_names, src[0].th_names) != 0))
      st = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                          "%s: obs/thermal_state has %d columns, %s has %d (or other region names; "
                          "one LeRobot dataset has one set of features)",
                          src[opened].path, src[opened].th_dim, src[0].path, src[0].th_dim);
  }
  if (!st && total == 0) st = hearth_err_set(err, HEARTH_E_SIZE, "export: the inputs hold no demo");
  exporter x = {.o = o};
  int existed = 0;
  if (!st) {
    x.size = src[0].size, x.fps = src[0].fps;
    st = make_tmp_dir(out, x.tmp, sizeof x.tmp, &existed, err);
  }
  if (st) {
    for (size_t k = 0; k < opened; k++) ex_source_close(&src[k]);
    free(src), free(first);
    return st;
  }
  x.sc = (schema){o->thermal, src[0].th_dim, src[0].th_names};
  hf_metadata(&x.sc, &x.hfmeta);
  hearth_progress prog;
  hearth_progress_begin(&prog, "export", total, o->quiet);
  for (size_t f = 0; f < o->n_inputs && !st; f++) {
    first[f] = x.episode;
    for (int64_t k = 0; k < src[f].num_demos && !st; k++) {
      st = export_demo(&x, &src[f], f, k, err);
      hearth_progress_step(&prog, 1);
    }
    first[f + 1] = x.episode;
  }
  hearth_progress_end(&prog);
  if (!st) st = write_info(&x, src, first, err);
  if (!st) {
    ex_text tasks = {0};
    for (size_t k = 0; k < x.ntasks; k++) {
      ex_printf(&tasks, "{\"task_index\": %zu, \"task\": ", k);
      ex_put_jstr(&tasks, x.tasks[k]);
      ex_puts(&tasks, "}\n");
    }
    st = write_text(&x, "meta/tasks.jsonl", &tasks, err);
    ex_text_free(&tasks);
  }
  if (!st) st = write_text(&x, "meta/episodes.jsonl", &x.episodes, err);
  if (!st) st = write_text(&x, "meta/episodes_stats.jsonl", &x.stats, err);
  if (!st) st = norm_stats(&x, err);
  if (!st && existed && rmdir(out) != 0)
    st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot replace the empty directory: %s", out,
                        strerror(errno));
  if (!st && rename(x.tmp, out) != 0)
    st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename %s into place: %s", out, x.tmp,
                        strerror(errno));
  if (st) hearth_remove_tree(x.tmp, NULL);
  if (!st && stats) {
    stats->episodes = x.episode, stats->frames = x.frames, stats->tasks = x.ntasks;
    stats->seconds = hearth_now() - t0;
  }
  for (size_t k = 0; k < o->n_inputs; k++) ex_source_close(&src[k]);
  for (size_t k = 0; k < x.ntasks; k++) free(x.tasks[k]);
  free(x.tasks);
  ex_text_free(&x.episodes), ex_text_free(&x.stats), ex_text_free(&x.hfmeta);
  free(x.norm_state), free(x.norm_actions);
  free(src), free(first);
  return st;
}
