/* policy evaluation on H1-H3 as in the paper: 10 episodes per instruction
 * on held-out layouts, success within a time limit; policies: the scripted
 * expert, a replayed HDF5 demo, or an openpi policy server (LIBERO client
 * protocol: 10 no-op steps, then action chunks replanned every 5 steps) */
#include <hdf5.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/eval.h"
#include "hearth/image.h"
#include "hearth/msgpack.h"
#include "hearth/ws.h"

int hearth_eval_time_limit(hearth_sim_task t) {
  (void)t;
  return 280;
}

void hearth_eval_opts_default(hearth_eval_opts *o) {
  memset(o, 0, sizeof *o);
  o->tasks = (1u << 1) | (1u << 2) | (1u << 3);
  o->policy = "oracle";
  o->episodes = 10;
  o->thermal = 1;
  o->seed = 1;
  o->layout_base = HEARTH_EVAL_LAYOUT_BASE;
  o->render_size = 256;
  o->image_size = 224;
  o->replan_steps = 5;
  o->wait_steps = 10;
  o->timeout_s = 120;
  o->video_every = 2;
}

/* ---- observations ------------------------------------------------------------ */
void hearth_eval_resize_with_pad(const uint8_t *in, int w, int h, uint8_t *out, int ow, int oh) {
  memset(out, 0, (size_t)ow * oh * 3);
  double ratio = fmax((double)w / ow, (double)h / oh);
  int rw = (int)(w / ratio), rh = (int)(h / ratio);
  if (rw < 1) rw = 1;
  if (rh < 1) rh = 1;
  int x0 = (ow - rw) / 2, y0 = (oh - rh) / 2;
  double sx = (double)w / rw, sy = (double)h / rh;
  for (int y = 0; y < rh; y++) {
    /* pixel centres: half-pixel convention */
    double fy = (y + 0.5) * sy - 0.5;
    if (fy < 0) fy = 0;
    if (fy > h - 1) fy = h - 1;
    int ya = (int)fy, yb = ya + 1 < h ? ya + 1 : ya;
    double ty = fy - ya;
    for (int x = 0; x < rw; x++) {
      double fx = (x + 0.5) * sx - 0.5;
      if (fx < 0) fx = 0;
      if (fx > w - 1) fx = w - 1;
      int xa = (int)fx, xb = xa + 1 < w ? xa + 1 : xa;
      double tx = fx - xa;
      for (int c = 0; c < 3; c++) {
        double v = (1 - ty) * ((1 - tx) * in[3 * ((size_t)ya * w + xa) + c] + tx * in[3 * ((size_t)ya * w + xb) + c]) +
                   ty * ((1 - tx) * in[3 * ((size_t)yb * w + xa) + c] + tx * in[3 * ((size_t)yb * w + xb) + c]);
        int q = (int)lround(v);
        out[3 * ((size_t)(y + y0) * ow + x + x0) + c] = (uint8_t)(q < 0 ? 0 : q > 255 ? 255 : q);
      }
    }
  }
}

/* rotate 180 degrees (OpenGL rows -> openpi's LIBERO convention), resize */
static hearth_status put_image(hearth_mp_writer *w, const char *key, const uint8_t *img, int iw, int ih,
                               int size, hearth_err *err) {
  size_t n = (size_t)iw * ih * 3;
  uint8_t *rot = malloc(n), *out = malloc((size_t)size * size * 3);
  if (!rot || !out) {
    free(rot), free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "eval: image buffers");
  }
  for (size_t k = 0; k < (size_t)iw * ih; k++) memcpy(rot + 3 * k, img + 3 * ((size_t)iw * ih - 1 - k), 3);
  hearth_eval_resize_with_pad(rot, iw, ih, out, size, size);
  size_t shape[3] = {(size_t)size, (size_t)size, 3};
  hearth_mp_put_cstr(w, key);
  hearth_mp_put_ndarray(w, out, (size_t)size * size * 3, "|u1", shape, 3);
  free(rot), free(out);
  return HEARTH_OK;
}

hearth_status hearth_eval_encode_obs(const hearth_sim_obs *obs, const char *prompt, int thermal, int size,
                                     hearth_mp_writer *w, hearth_err *err) {
  if (!obs->eye_in_hand_rgb) return hearth_err_set(err, HEARTH_E_ARG, "eval: the wrist view is off");
  hearth_mp_put_map(w, thermal ? 5 : 4);
  hearth_status st = put_image(w, "observation/image", obs->agentview_rgb, obs->width, obs->height, size, err);
  if (!st) st = put_image(w, "observation/wrist_image", obs->eye_in_hand_rgb, obs->width, obs->height, size, err);
  if (!st && thermal)
    st = put_image(w, "observation/thermal_image", obs->agentview_thermal, obs->width, obs->height, size, err);
  if (st) return st;
  double state[8];
  memcpy(state, obs->ee_pos, 3 * sizeof(double));
  memcpy(state + 3, obs->ee_ori, 3 * sizeof(double));
  memcpy(state + 6, obs->gripper_states, 2 * sizeof(double));
  uint8_t le[64];
  for (int k = 0; k < 8; k++) {
    uint64_t u;
    memcpy(&u, &state[k], 8);
    for (int b = 0; b < 8; b++) le[8 * k + b] = (uint8_t)(u >> (8 * b));
  }
  size_t shape[1] = {8};
  hearth_mp_put_cstr(w, "observation/state");
  hearth_mp_put_ndarray(w, le, sizeof le, "<f8", shape, 1);
  hearth_mp_put_cstr(w, "prompt");
  hearth_mp_put_cstr(w, prompt);
  if (w->failed) return hearth_err_set(err, HEARTH_E_NOMEM, "eval: encoding the observation");
  return HEARTH_OK;
}

/* ---- videos: the three views side by side, one frame per kept step ------------- */
typedef struct video {
  int w, h, n, cap;
  uint8_t *frames;
} video;

static void video_add(video *v, const hearth_sim_obs *ob) {
  int W = ob->width * (ob->eye_in_hand_rgb ? 3 : 2), H = ob->height;
  if (v->n == 0) v->w = W, v->h = H;
  if (W != v->w || H != v->h || v->n >= 4000) return;
  size_t fs = (size_t)W * H * 3;
  if (v->n == v->cap) {
    int cap = v->cap ? v->cap * 2 : 64;
    uint8_t *nf = realloc(v->frames, fs * cap);
    if (!nf) return;
    v->frames = nf, v->cap = cap;
  }
  uint8_t *f = v->frames + fs * v->n;
  const uint8_t *views[3] = {ob->agentview_rgb, ob->agentview_thermal, ob->eye_in_hand_rgb};
  for (int y = 0; y < H; y++)
    for (int k = 0; k < W / ob->width; k++)
      memcpy(f + ((size_t)y * W + (size_t)k * ob->width) * 3, views[k] + (size_t)(H - 1 - y) * ob->width * 3,
             (size_t)ob->width * 3); /* top row first */
  v->n++;
}

/* the episode's frames as an animated PNG, 1/10 s each; nothing when
 * there are none */
static hearth_status video_write(const video *v, const char *path, hearth_err *err) {
  if (v->n == 0) return HEARTH_OK;
  return hearth_apng_write(path, v->frames, (size_t)v->w, (size_t)v->h, (size_t)v->n, 1, 10, err);
}

/* ---- replay: actions of LIBERO HDF5 demos -------------------------------------- */
typedef struct replay_demo {
  int index, instruction;
  uint64_t layout;
  size_t T, S;
  double *actions, *states;
} replay_demo;

typedef struct replay_file {
  hearth_sim_task task;
  uint64_t seed;
  int n;
  replay_demo *demos;
} replay_file;

static void replay_free(replay_file *r) {
  for (int i = 0; i < r->n; i++) free(r->demos[i].actions), free(r->demos[i].states);
  free(r->demos);
  memset(r, 0, sizeof *r);
}

static int h5_read_str_attr(hid_t obj, const char *name, char *buf, size_t n) {
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  hid_t t = H5Aget_type(a);
  int ok = 0;
  if (H5Tget_class(t) == H5T_STRING && !H5Tis_variable_str(t)) {
    size_t sz = H5Tget_size(t);
    char *tmp = calloc(1, sz + 1);
    if (tmp && H5Aread(a, t, tmp) >= 0) snprintf(buf, n, "%s", tmp), ok = 1;
    free(tmp);
  } else if (H5Tget_class(t) == H5T_STRING) {
    char *s = NULL;
    hid_t mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, H5T_VARIABLE);
    if (H5Aread(a, mt, &s) >= 0 && s) snprintf(buf, n, "%s", s), ok = 1;
    free(s);
    H5Tclose(mt);
  }
  H5Tclose(t);
  H5Aclose(a);
  return ok;
}

static int h5_read_int_attr(hid_t obj, const char *name, long long *v) {
  hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  if (a < 0) return 0;
  int ok = H5Aread(a, H5T_NATIVE_LLONG, v) >= 0;
  H5Aclose(a);
  return ok;
}

static double *h5_read_2d(hid_t g, const char *name, size_t *rows, size_t *cols) {
  hid_t d = H5Dopen2(g, name, H5P_DEFAULT);
  if (d < 0) return NULL;
  hid_t sp = H5Dget_space(d);
  hsize_t dims[2] = {0, 0};
  double *buf = NULL;
  if (H5Sget_simple_extent_ndims(sp) == 2) {
    H5Sget_simple_extent_dims(sp, dims, NULL);
    if (dims[0] < 100000 && dims[1] < 100000) {
      buf = hearth_alloc_array(dims[0] * dims[1] > 0 ? (size_t)(dims[0] * dims[1]) : 1, sizeof(double));
      if (buf && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) free(buf), buf = NULL;
    }
  }
  H5Sclose(sp);
  H5Dclose(d);
  *rows = (size_t)dims[0], *cols = (size_t)dims[1];
  return buf;
}

/* "FILE" or "FILE#K" */
static hearth_status replay_load(const char *spec, replay_file *r, hearth_err *err) {
  memset(r, 0, sizeof *r);
  char path[4096];
  snprintf(path, sizeof path, "%s", spec);
  int only = -1;
  char *hash = strrchr(path, '#');
  if (hash) {
    long k;
    char *end;
    k = strtol(hash + 1, &end, 10);
    if (*end || k < 0 || k > 1000000)
      return hearth_err_set(err, HEARTH_E_ARG, "replay: \"%s\": expected FILE.hdf5#K with K a demo index", spec);
    only = (int)k;
    *hash = 0;
  }
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open as HDF5", path);
  hearth_status st = HEARTH_OK;
  hid_t data = H5Gopen2(f, "data", H5P_DEFAULT);
  char ea[2048];
  long long ndemo = 0;
  if (data < 0 || !h5_read_str_attr(data, "env_args", ea, sizeof ea) || !h5_read_int_attr(data, "num_demos", &ndemo)) {
    st = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: expected group data with attributes env_args and num_demos", path);
    goto done;
  }
  json_error_t je;
  json_t *j = json_loads(ea, 0, &je);
  const char *env = j ? json_string_value(json_object_get(j, "env_name")) : NULL;
  json_t *seed = j ? json_object_get(json_object_get(j, "env_kwargs"), "seed") : NULL;
  if (env && strncmp(env, "hearth_", 7) == 0) r->task = hearth_sim_task_parse(env + 7);
  if (seed && json_is_integer(seed)) r->seed = (uint64_t)json_integer_value(seed);
  json_decref(j);
  if (!r->task || !seed) {
    st = hearth_err_set(err, HEARTH_E_PARSE, "%s: data.env_args: expected env_name \"hearth_H1..3\" and env_kwargs.seed", path);
    goto done;
  }
  if (ndemo < 0 || ndemo > 100000 || (only >= 0 && only >= ndemo)) {
    st = hearth_err_set(err, HEARTH_E_RANGE, "%s: demo %d requested, file has %lld", path, only, ndemo);
    goto done;
  }
  int first = only >= 0 ? only : 0, count = only >= 0 ? 1 : (int)ndemo;
  r->demos = calloc((size_t)(count ? count : 1), sizeof *r->demos);
  if (!r->demos) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "replay: demos");
    goto done;
  }
  for (int i = 0; i < count && !st; i++) {
    char name[64];
    snprintf(name, sizeof name, "demo_%d", first + i);
    hid_t g = H5Gopen2(data, name, H5P_DEFAULT);
    replay_demo *d = &r->demos[i];
    long long lay = 0, ins = 0;
    size_t ar = 0, ac = 0, sr = 0, sc = 0;
    if (g >= 0) {
      d->actions = h5_read_2d(g, "actions", &ar, &ac);
      d->states = h5_read_2d(g, "states", &sr, &sc);
    }
    if (g < 0 || !h5_read_int_attr(g, "layout", &lay) || !h5_read_int_attr(g, "instruction_index", &ins) ||
        !d->actions || ac != 7 || (d->states && sr != ar) || ins < 0 || ins > 1 || lay < 0)
      st = hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: data/%s: expected attributes layout, instruction_index and datasets actions (T,7), states (T,S)",
                          path, name);
    if (g >= 0) H5Gclose(g);
    d->index = first + i, d->instruction = (int)ins, d->layout = (uint64_t)lay, d->T = ar, d->S = d->states ? sc : 0;
    r->n = i + 1;
  }
done:
  if (data >= 0) H5Gclose(data);
  H5Fclose(f);
  if (st) replay_free(r);
  return st;
}

/* ---- openpi policy over WebSocket ------------------------------------------------- */
typedef struct ws_policy {
  const char *url;
  hearth_ws *c;
  double timeout_s;
  int image_size, thermal, replan;
  double chunk[64][7];
  int nchunk, next;
  char metadata[512];
} ws_policy;

static void ws_drop(ws_policy *p, int code) {
  hearth_ws_close(p->c, code);
  p->c = NULL;
}

/* connect and read the metadata the server sends first */
static hearth_status ws_ensure(ws_policy *p, hearth_err *err) {
  if (p->c) return HEARTH_OK;
  hearth_status st = hearth_ws_connect(p->url, p->timeout_s, &p->c, err);
  if (st) return st;
  uint8_t *m = NULL;
  size_t n = 0;
  int op = 0;
  st = hearth_ws_recv(p->c, &m, &n, &op, p->timeout_s, err);
  if (!st && op != HEARTH_WS_BINARY)
    st = hearth_err_set(err, HEARTH_E_PARSE, "policy server %s: expected the metadata as a binary message, got text \"%.200s\"",
                        p->url, (const char *)m);
  hearth_mp_doc doc;
  if (!st) {
    hearth_mp_limits lim = {16, 100000, 16u << 20};
    st = hearth_mp_decode(m, n, &lim, &doc, err);
    if (st) hearth_err_prefix(err, "policy server %s: metadata: ", p->url);
    else {
      if (doc.root->type != HEARTH_MP_MAP)
        st = hearth_err_set(err, HEARTH_E_PARSE, "policy server %s: metadata: expected a map", p->url);
      else
        snprintf(p->metadata, sizeof p->metadata, "%zu keys", doc.root->n);
      hearth_mp_doc_free(&doc);
    }
  }
  free(m);
  if (st) ws_drop(p, 1002);
  return st;
}

/* one request: the observation -> a chunk of actions */
static hearth_status ws_query(ws_policy *p, const hearth_sim_obs *ob, const char *prompt, hearth_err *err) {
  hearth_mp_writer w;
  hearth_mp_writer_init(&w);
  hearth_status st = hearth_eval_encode_obs(ob, prompt, p->thermal, p->image_size, &w, err);
  if (!st) st = hearth_ws_send(p->c, HEARTH_WS_BINARY, w.buf, w.len, 0, err);
  hearth_mp_writer_free(&w);
  if (st) return st;
  uint8_t *m = NULL;
  size_t n = 0;
  int op = 0;
  st = hearth_ws_recv(p->c, &m, &n, &op, p->timeout_s, err);
  if (st) return st;
  if (op == HEARTH_WS_TEXT) {
    /* openpi's error path: the traceback as text, then close 1011 */
    /* a traceback ends with the exception: keep the end */
    char text[400];
    while (n && (m[n - 1] == '\n' || m[n - 1] == ' ')) n--;
    size_t k = n < sizeof text - 1 ? n : sizeof text - 1;
    memcpy(text, m + (n - k), k);
    text[k] = 0;
    free(m);
    for (char *q = text; *q; q++)
      if (*q == '\n' || *q == '\r') *q = ' ';
    hearth_err tmp = {0};
    uint8_t *m2 = NULL;
    size_t n2;
    int op2;
    int code = 0;
    if (hearth_ws_recv(p->c, &m2, &n2, &op2, 2.0, &tmp) != HEARTH_OK || 1) code = hearth_ws_close_code(p->c, NULL);
    free(m2);
    return hearth_err_set(err, HEARTH_E_IO, "policy server %s: server error (close code %d): %s", p->url, code, text);
  }
  hearth_mp_doc doc;
  hearth_mp_limits lim = {16, 100000, 64u << 20};
  st = hearth_mp_decode(m, n, &lim, &doc, err);
  if (st) {
    hearth_err_prefix(err, "policy server %s: reply: ", p->url);
    free(m);
    return st;
  }
  const hearth_mp_value *act = hearth_mp_map_get(doc.root, "actions", HEARTH_MP_STR);
  hearth_mp_ndarray a;
  if (!act) st = hearth_err_set(err, HEARTH_E_NOT_FOUND, "policy server %s: reply: expected a map with \"actions\"", p->url);
  else st = hearth_mp_ndarray_get(act, "reply.actions", &a, err);
  if (!st && (a.kind != 'f' || a.ndim != 2 || a.shape[1] != 7 || a.shape[0] < (size_t)p->replan))
    st = hearth_err_set(err, HEARTH_E_SIZE,
                        "policy server %s: reply.actions: expected float (H, 7) with H >= %d, got dtype %s ndim %d shape[0] %zu",
                        p->url, p->replan, a.dtype, a.ndim, a.ndim ? a.shape[0] : 0);
  if (!st) {
    p->nchunk = p->replan;
    p->next = 0;
    for (int t = 0; t < p->replan && !st; t++)
      for (int k = 0; k < 7; k++) {
        double v = hearth_mp_ndarray_at(&a, (size_t)t * 7 + k);
        if (!isfinite(v)) st = hearth_err_set(err, HEARTH_E_RANGE, "policy server %s: reply.actions[%d][%d] is not finite", p->url, t, k);
        p->chunk[t][k] = v;
      }
  }
  hearth_mp_doc_free(&doc);
  free(m);
  return st;
}

/* ---- the evaluation loop ---------------------------------------------------- */
typedef struct ep_ctx {
  const hearth_eval_opts *o;
  hearth_sim_env *env;
  ws_policy *ws;
  const replay_demo *demo;
  video *vid;
} ep_ctx;

static hearth_status run_episode(ep_ctx *x, hearth_eval_episode *ep, int limit, hearth_err *err) {
  const hearth_eval_opts *o = x->o;
  hearth_sim_env *e = x->env;
  hearth_status st = hearth_sim_reset(e, ep->seed, ep->layout, ep->instruction, err);
  if (st) return st; /* a sim failure stops the evaluation */
  const char *prompt = hearth_sim_instruction(e);
  int wait = x->ws ? o->wait_steps : 0;
  hearth_err perr = {0};
  int perror_ = 0;
  if (x->ws) {
    x->ws->nchunk = x->ws->next = 0;
    if (ws_ensure(x->ws, &perr)) perror_ = 1;
  }
  double state[4096], *nstate = NULL;
  size_t ns = 0;
  if (x->demo && x->demo->states) {
    ns = hearth_sim_state(e, state, 4096);
    if (ns != x->demo->S) {
      snprintf(ep->reason, sizeof ep->reason, "replay: state length %zu differs from the file's %zu", ns, x->demo->S);
      ep->error = 1;
      return HEARTH_OK;
    }
    nstate = state;
  }
  ep->state_diff = x->demo ? 0 : -1;
  int t;
  for (t = 0; t < wait + limit && !perror_; t++) {
    double a[7] = {0, 0, 0, 0, 0, 0, -1};
    int policy_t = t - wait;
    hearth_sim_obs ob;
    int observed = 0;
    if (x->vid && (t % (o->video_every > 0 ? o->video_every : 1)) == 0) {
      if ((st = hearth_sim_observe(e, &ob, err))) return st;
      observed = 1;
      video_add(x->vid, &ob);
    }
    if (policy_t < 0) {
      /* openpi's LIBERO client: let objects settle with no-ops */
    } else if (x->ws) {
      ws_policy *p = x->ws;
      if (p->next >= p->nchunk) {
        if (!observed && (st = hearth_sim_observe(e, &ob, err))) return st;
        if (ws_query(p, &ob, prompt, &perr)) {
          perror_ = 1;
          break;
        }
      }
      memcpy(a, p->chunk[p->next++], sizeof a);
    } else if (x->demo) {
      if ((size_t)policy_t >= x->demo->T) break;
      if (nstate) {
        hearth_sim_state(e, nstate, ns);
        const double *ref = x->demo->states + (size_t)policy_t * ns;
        for (size_t k = 0; k < ns; k++) {
          double d = fabs(nstate[k] - ref[k]);
          if (d > ep->state_diff || isnan(d)) ep->state_diff = d;
        }
      }
      memcpy(a, x->demo->actions + (size_t)policy_t * 7, sizeof a);
    } else {
      hearth_sim_expert_action(e, a);
    }
    if ((st = hearth_sim_step(e, a, err))) {
      /* a policy's non-finite action is the policy's failure */
      if (st == HEARTH_E_RANGE) {
        snprintf(perr.msg, sizeof perr.msg, "%s", err->msg);
        perror_ = 1;
        break;
      }
      return st;
    }
    if (hearth_sim_success(e)) {
      t++;
      break;
    }
  }
  ep->steps = t - wait > 0 ? t - wait : 0;
  ep->success = !perror_ && hearth_sim_success(e);
  if (x->vid) {
    hearth_sim_obs ob;
    if (hearth_sim_observe(e, &ob, err) == HEARTH_OK) video_add(x->vid, &ob);
  }
  if (perror_) {
    ep->error = 1;
    snprintf(ep->reason, sizeof ep->reason, "%s", perr.msg);
    if (x->ws) ws_drop(x->ws, perr.status == HEARTH_E_PARSE ? 1002 : 1001);
  } else if (!ep->success)
    snprintf(ep->reason, sizeof ep->reason, x->demo ? "replay ended without success" : "time limit (%d steps)", limit);
  return HEARTH_OK;
}

static hearth_status push_ep(hearth_eval_results *r, const hearth_eval_episode *ep, hearth_err *err) {
  hearth_eval_episode *n = realloc(r->eps, (r->n + 1) * sizeof *n);
  if (!n) return hearth_err_set(err, HEARTH_E_NOMEM, "eval: results");
  r->eps = n;
  r->eps[r->n++] = *ep;
  return HEARTH_OK;
}

static hearth_status episode_with_video(ep_ctx *x, hearth_eval_episode *ep, int limit, hearth_err *err) {
  video v = {0};
  x->vid = x->o->video_dir ? &v : NULL;
  hearth_status st = run_episode(x, ep, limit, err);
  if (!st && x->vid) {
    char path[4200];
    snprintf(path, sizeof path, "%s/%s_instr%d_ep%02d.png", x->o->video_dir, hearth_sim_task_name(ep->task),
             ep->instruction + 1, ep->episode);
    st = video_write(&v, path, err);
  }
  free(v.frames);
  x->vid = NULL;
  return st;
}

hearth_status hearth_eval_run(const hearth_eval_opts *o, hearth_eval_results *r, hearth_err *err) {
  memset(r, 0, sizeof *r);
  if (!o->policy) return hearth_err_set(err, HEARTH_E_ARG, "eval: no policy");
  if (o->episodes < 1 || o->episodes > 100000)
    return hearth_err_set(err, HEARTH_E_RANGE, "eval: episodes must be 1..100000, got %d", o->episodes);
  if (o->replan_steps < 1 || o->replan_steps > 64)
    return hearth_err_set(err, HEARTH_E_RANGE, "eval: replan steps must be 1..64, got %d", o->replan_steps);
  if (o->image_size < 8 || o->image_size > 1024 || o->render_size < 16 || o->render_size > 2048)
    return hearth_err_set(err, HEARTH_E_RANGE, "eval: image size must be 8..1024 and render size 16..2048");
  int is_ws = strncmp(o->policy, "ws://", 5) == 0;
  int is_replay = strncmp(o->policy, "replay:", 7) == 0;
  if (!is_ws && !is_replay && strcmp(o->policy, "oracle") != 0)
    return hearth_err_set(err, HEARTH_E_ARG, "eval: policy \"%s\": expected oracle, replay:FILE.hdf5[#K] or ws://HOST:PORT",
                          o->policy);
  snprintf(r->policy, sizeof r->policy, "%s", o->policy);
  r->thermal = is_ws ? o->thermal : -1;
  if (o->video_dir) {
    hearth_status st = hearth_mkdirs(o->video_dir, err);
    if (st) return st;
  }
  double t0 = hearth_now();
  replay_file rf = {0};
  hearth_status st = HEARTH_OK;
  if (is_replay && (st = replay_load(o->policy + 7, &rf, err))) return st;
  ws_policy wsp = {0};
  wsp.url = o->policy;
  wsp.timeout_s = o->timeout_s > 0 ? o->timeout_s : 120;
  wsp.image_size = o->image_size;
  wsp.thermal = o->thermal;
  wsp.replan = o->replan_steps;
  for (int task = 1; task <= 3 && !st; task++) {
    if (is_replay ? task != (int)rf.task : !(o->tasks & (1u << task))) continue;
    hearth_sim_opts so;
    hearth_sim_opts_default(&so);
    so.task = (hearth_sim_task)task;
    so.release_root = o->release_root;
    so.use_ground_truth = o->use_ground_truth;
    so.width = so.height = o->render_size;
    so.shadows = o->shadows;
    so.gl = o->gl;
    int limit = o->max_steps > 0 ? o->max_steps : hearth_eval_time_limit(so.task);
    so.max_steps = limit + o->wait_steps;
    if (is_replay)
      for (int i = 0; i < rf.n; i++)
        if ((int)rf.demos[i].T + 1 > so.max_steps) so.max_steps = (int)rf.demos[i].T + 1;
    hearth_sim_env *env = NULL;
    if ((st = hearth_sim_env_new(&so, &env, err))) break;
    ep_ctx x = {o, env, is_ws ? &wsp : NULL, NULL, NULL};
    if (is_replay) {
      for (int i = 0; i < rf.n && !st; i++) {
        hearth_eval_episode ep = {0};
        ep.task = so.task, ep.instruction = rf.demos[i].instruction, ep.episode = rf.demos[i].index;
        ep.seed = rf.seed, ep.layout = rf.demos[i].layout, ep.expected_success = 1;
        x.demo = &rf.demos[i];
        st = episode_with_video(&x, &ep, (int)rf.demos[i].T, err);
        if (!st) st = push_ep(r, &ep, err);
      }
    } else {
      for (int ins = 0; ins < 2 && !st; ins++)
        for (int k = 0; k < o->episodes && !st; k++) {
          hearth_eval_episode ep = {0};
          ep.task = so.task, ep.instruction = ins, ep.episode = k;
          ep.seed = o->seed, ep.layout = o->layout_base + (uint64_t)k;
          ep.expected_success = -1;
          st = episode_with_video(&x, &ep, limit, err);
          if (!st) st = push_ep(r, &ep, err);
          if (!st && !o->quiet)
            fprintf(stderr, "eval %s instr %d episode %d: %s%s%s\n", hearth_sim_task_name(so.task), ins + 1, k,
                    ep.success ? "success" : "failure", ep.success ? "" : ": ", ep.success ? "" : ep.reason);
        }
    }
    hearth_sim_env_free(env);
  }
  snprintf(r->metadata, sizeof r->metadata, "%s", wsp.metadata);
  if (wsp.c) ws_drop(&wsp, 1000);
  replay_free(&rf);
  r->seconds = hearth_now() - t0;
  if (st) hearth_eval_results_free(r);
  return st;
}

void hearth_eval_results_free(hearth_eval_results *r) {
  if (!r) return;
  free(r->eps);
  memset(r, 0, sizeof *r);
}

double hearth_eval_rates(const hearth_eval_results *r, double per_instr[4][2], double per_task[4]) {
  int n[4][2] = {{0}}, k[4][2] = {{0}}, tot = 0, ok = 0;
  for (size_t i = 0; i < r->n; i++) {
    const hearth_eval_episode *e = &r->eps[i];
    n[e->task][e->instruction]++;
    k[e->task][e->instruction] += e->success;
    tot++, ok += e->success;
  }
  for (int t = 0; t < 4; t++) {
    int nt = n[t][0] + n[t][1];
    if (per_task) per_task[t] = nt ? (double)(k[t][0] + k[t][1]) / nt : NAN;
    for (int i = 0; i < 2; i++)
      if (per_instr) per_instr[t][i] = n[t][i] ? (double)k[t][i] / n[t][i] : NAN;
  }
  return tot ? (double)ok / tot : NAN;
}

static const char *pct(double f, char *buf) {
  if (isnan(f)) return "-";
  hearth_format_fixed(buf, 32, 100.0 * f, 1);
  return buf;
}

static const char *thermal_label(const hearth_eval_results *r) {
  return r->thermal < 0 ? "-" : r->thermal ? "w/" : "w/o";
}

static void counts(const hearth_eval_results *r, int *ok, int *tot) {
  *ok = *tot = 0;
  for (size_t i = 0; i < r->n; i++) *ok += r->eps[i].success, (*tot)++;
}

char *hearth_eval_format_text(const hearth_eval_results *r) {
  double pi[4][2], pt[4];
  double all = hearth_eval_rates(r, pi, pt);
  hearth_strbuf b = {0};
  for (size_t i = 0; i < r->n; i++)
    if (!r->eps[i].success)
      hearth_strbuf_printf(&b, "failed: %s instr %d episode %d (layout %llu): %s\n",
                           hearth_sim_task_name(r->eps[i].task), r->eps[i].instruction + 1, r->eps[i].episode,
                           (unsigned long long)r->eps[i].layout, r->eps[i].reason);
  hearth_strbuf_printf(&b, "policy %s\n", r->policy);
  hearth_strbuf_printf(&b, "%-6s %-8s %9s %9s %9s\n", "Task", "Thermal", "Instr. 1", "Instr. 2", "Average");
  for (int t = 1; t <= 3; t++) {
    if (isnan(pt[t])) continue;
    char a[32], c[32], d[32];
    hearth_strbuf_printf(&b, "%-6s %-8s %9s %9s %9s\n", hearth_sim_task_name((hearth_sim_task)t), thermal_label(r),
                         pct(pi[t][0], a), pct(pi[t][1], c), pct(pt[t], d));
  }
  int ok, tot;
  counts(r, &ok, &tot);
  char a[32];
  hearth_strbuf_printf(&b, "overall %s (%d/%d)\n", pct(all, a), ok, tot);
  return hearth_strbuf_take(&b);
}

char *hearth_eval_format_markdown(const hearth_eval_results *r) {
  double pi[4][2], pt[4];
  double all = hearth_eval_rates(r, pi, pt);
  hearth_strbuf b = {0};
  hearth_strbuf_printf(&b, "Task success rates (%%), policy `%s`\n\n", r->policy);
  hearth_strbuf_printf(&b, "| Task | Thermal | Instr. 1 | Instr. 2 | Average |\n|---|---|---:|---:|---:|\n");
  for (int t = 1; t <= 3; t++) {
    if (isnan(pt[t])) continue;
    char a[32], c[32], d[32];
    hearth_strbuf_printf(&b, "| %s | %s | %s | %s | %s |\n", hearth_sim_task_name((hearth_sim_task)t), thermal_label(r),
                         pct(pi[t][0], a), pct(pi[t][1], c), pct(pt[t], d));
  }
  int ok, tot;
  counts(r, &ok, &tot);
  char a[32];
  hearth_strbuf_printf(&b, "| **Overall** | %s | | | **%s** (%d/%d) |\n", thermal_label(r), pct(all, a), ok, tot);
  return hearth_strbuf_take(&b);
}

static json_t *jnum(double v) {
  if (isnan(v)) return json_null();
  return json_real(round(v * 1e4) / 1e4);
}

char *hearth_eval_format_json(const hearth_eval_results *r) {
  double pi[4][2], pt[4];
  double all = hearth_eval_rates(r, pi, pt);
  json_t *root = json_object();
  json_object_set_new(root, "policy", json_string(r->policy));
  json_object_set_new(root, "thermal", r->thermal < 0 ? json_null() : json_boolean(r->thermal));
  json_object_set_new(root, "overall_success", jnum(all));
  int ok, tot;
  counts(r, &ok, &tot);
  json_object_set_new(root, "successes", json_integer(ok));
  json_object_set_new(root, "episodes_total", json_integer(tot));
  json_t *tasks = json_object();
  for (int t = 1; t <= 3; t++) {
    if (isnan(pt[t])) continue;
    json_t *jt = json_object();
    json_object_set_new(jt, "instruction_1", jnum(pi[t][0]));
    json_object_set_new(jt, "instruction_2", jnum(pi[t][1]));
    json_object_set_new(jt, "average", jnum(pt[t]));
    json_object_set_new(jt, "time_limit", json_integer(hearth_eval_time_limit((hearth_sim_task)t)));
    json_object_set_new(tasks, hearth_sim_task_name((hearth_sim_task)t), jt);
  }
  json_object_set_new(root, "tasks", tasks);
  json_t *eps = json_array();
  for (size_t i = 0; i < r->n; i++) {
    const hearth_eval_episode *e = &r->eps[i];
    json_t *je = json_object();
    json_object_set_new(je, "task", json_string(hearth_sim_task_name(e->task)));
    json_object_set_new(je, "instruction", json_integer(e->instruction + 1));
    json_object_set_new(je, "episode", json_integer(e->episode));
    json_object_set_new(je, "seed", json_integer((json_int_t)e->seed));
    json_object_set_new(je, "layout", json_integer((json_int_t)e->layout));
    json_object_set_new(je, "success", json_boolean(e->success));
    json_object_set_new(je, "steps", json_integer(e->steps));
    json_object_set_new(je, "policy_error", json_boolean(e->error));
    json_object_set_new(je, "reason", json_string(e->reason));
    if (e->state_diff >= 0) json_object_set_new(je, "replay_max_state_diff", json_real(e->state_diff));
    json_array_append_new(eps, je);
  }
  json_object_set_new(root, "episodes", eps);
  json_object_set_new(root, "seconds", json_real(round(r->seconds * 100) / 100));
  char *s = json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
  json_decref(root);
  return s;
}
