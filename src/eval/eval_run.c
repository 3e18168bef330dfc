/* policy evaluation on H1-H3 as in the paper: 10 episodes per instruction
 * on held-out layouts, success within a time limit; policies: the scripted
 * expert, a replayed HDF5 demo, or an openpi policy server (LIBERO client
 * protocol: 10 no-op steps, then action chunks replanned every 5 steps) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eval/eval_replay.h"
#include "eval/eval_ws.h"
#include "hearth/eval.h"
#include "hearth/image.h"

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
      memcpy(f + ((size_t)y * W + (size_t)k * ob->width) * 3,
             views[k] + (size_t)(H - 1 - y) * ob->width * 3,
             (size_t)ob->width * 3); /* top row first */
  v->n++;
}

/* the episode's frames as an animated PNG, 1/10 s each; nothing when
 * there are none */
static hearth_status video_write(const video *v, const char *path, hearth_err *err) {
  if (v->n == 0) return HEARTH_OK;
  return hearth_apng_write(path, v->frames, (size_t)v->w, (size_t)v->h, (size_t)v->n, 1, 10, err);
}

/* ---- the evaluation loop ---------------------------------------------------- */
typedef struct ep_ctx {
  const hearth_eval_opts *o;
  hearth_sim_env *env;
  eval_ws_policy *ws;
  const eval_replay_demo *demo;
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
    if (eval_ws_ensure(x->ws, &perr)) perror_ = 1;
    else if (o->thermal && x->ws->thermal_decl == 0) {
      /* a reconnection's metadata disowns the thermal view */
      snprintf(perr.msg, sizeof perr.msg,
               "policy server %s: its metadata now declares %s: it ignores the thermal view",
               x->ws->url, x->ws->thermal_why);
      perror_ = 1;
    }
  }
  double state[4096], *nstate = NULL;
  size_t ns = 0;
  if (x->demo && x->demo->states) {
    ns = hearth_sim_state(e, state, 4096);
    if (ns != x->demo->S) {
      snprintf(ep->reason, sizeof ep->reason,
               "replay: state length %zu differs from the file's %zu", ns, x->demo->S);
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
      eval_ws_policy *p = x->ws;
      if (p->next >= p->nchunk) {
        if (!observed && (st = hearth_sim_observe(e, &ob, err))) return st;
        if (eval_ws_query(p, &ob, prompt, &perr)) {
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
    if (hearth_sim_failure(e)) {
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
    if (x->ws) eval_ws_drop(x->ws, perr.status == HEARTH_E_PARSE ? 1002 : 1001);
  } else if (!ep->success && hearth_sim_failure(e))
    snprintf(ep->reason, sizeof ep->reason, "%s", hearth_sim_failure(e));
  else if (!ep->success)
    snprintf(ep->reason, sizeof ep->reason,
             x->demo ? "replay ended without success" : "time limit (%d steps)", limit);
  return HEARTH_OK;
}

/* connect to the server before any episode and hold its metadata against
 * the thermal condition */
static hearth_status check_server(const hearth_eval_opts *o, eval_ws_policy *p,
                                  hearth_eval_results *r, hearth_err *err) {
  hearth_status st = eval_ws_ensure(p, err);
  if (st) {
    hearth_err_prefix(err, "eval: before the first episode");
    return st;
  }
  if (o->thermal && p->thermal_decl == 0)
    return hearth_err_set(
        err, HEARTH_E_ARG,
        "eval: policy server %s: its metadata declares %s, so it ignores the thermal view, but "
        "the thermal condition is on: evaluate it with --no-thermal (the RGB-only condition) "
        "or serve a policy that reads observation/thermal_image",
        p->url, p->thermal_why);
  r->thermal_used = !o->thermal ? 0 : p->thermal_decl == 1 ? 1 : -1;
  if (r->thermal_used < 0)
    snprintf(
        r->warning, sizeof r->warning,
        "policy server %s declares neither \"hearth_thermal\" nor \"image_keys\" in its metadata: whether "
        "it reads observation/thermal_image is unknown (thermal_used \"unknown\"; a policy trained without "
        "it ignores the key)",
        p->url);
  else if (!o->thermal && p->thermal_decl == 1)
    snprintf(
        r->warning, sizeof r->warning,
        "policy server %s declares %s in its metadata, but --no-thermal leaves observation/thermal_image out",
        p->url, p->thermal_why);
  if (!o->quiet)
    fprintf(stderr, "sim eval: policy server %s: metadata %s\n", p->url, p->metadata_json);
  if (r->warning[0] && !o->quiet) fprintf(stderr, "sim eval: warning: %s\n", r->warning);
  return HEARTH_OK;
}

static hearth_status push_ep(hearth_eval_results *r, const hearth_eval_episode *ep,
                             hearth_err *err) {
  hearth_eval_episode *n = realloc(r->eps, (r->n + 1) * sizeof *n);
  if (!n) return hearth_err_set(err, HEARTH_E_NOMEM, "eval: results");
  r->eps = n;
  r->eps[r->n++] = *ep;
  return HEARTH_OK;
}

static hearth_status episode_with_video(ep_ctx *x, hearth_eval_episode *ep, int limit,
                                        hearth_err *err) {
  video v = {0};
  x->vid = x->o->video_dir ? &v : NULL;
  hearth_status st = run_episode(x, ep, limit, err);
  if (!st && x->vid) {
    char path[4200];
    snprintf(path, sizeof path, "%s/%s_instr%d_ep%02d.png", x->o->video_dir,
             hearth_sim_task_name(ep->task), ep->instruction + 1, ep->episode);
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
    return hearth_err_set(err, HEARTH_E_RANGE, "eval: episodes must be 1..100000, got %d",
                          o->episodes);
  if (o->replan_steps < 1 || o->replan_steps > 64)
    return hearth_err_set(err, HEARTH_E_RANGE, "eval: replan steps must be 1..64, got %d",
                          o->replan_steps);
  if (o->image_size < 8 || o->image_size > 1024 || o->render_size < 16 || o->render_size > 2048)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "eval: image size must be 8..1024 and render size 16..2048");
  int is_ws = strncmp(o->policy, "ws://", 5) == 0;
  int is_replay = strncmp(o->policy, "replay:", 7) == 0;
  if (!is_ws && !is_replay && strcmp(o->policy, "oracle") != 0)
    return hearth_err_set(
        err, HEARTH_E_ARG,
        "eval: policy \"%s\": expected oracle, replay:FILE.hdf5[#K] or ws://HOST:PORT", o->policy);
  snprintf(r->policy, sizeof r->policy, "%s", o->policy);
  r->thermal = is_ws ? o->thermal : -1;
  if (o->video_dir) {
    hearth_status st = hearth_mkdirs(o->video_dir, err);
    if (st) return st;
  }
  double t0 = hearth_now();
  eval_replay_file rf = {0};
  hearth_status st = HEARTH_OK;
  if (is_replay && (st = eval_replay_load(o->policy + 7, &rf, err))) return st;
  eval_ws_policy wsp = {0};
  wsp.url = o->policy;
  wsp.timeout_s = o->timeout_s > 0 ? o->timeout_s : 120;
  wsp.image_size = o->image_size;
  wsp.thermal = o->thermal;
  wsp.replan = o->replan_steps;
  r->render_size = o->render_size, r->image_size = o->image_size, r->replan_steps = o->replan_steps;
  r->wait_steps = is_ws ? o->wait_steps : 0, r->shadows = o->shadows;
  if (is_ws) st = check_server(o, &wsp, r, err);
  for (int task = 1; task < HEARTH_SIM_TASK_END && !st; task++) {
    if (!hearth_sim_task_valid((hearth_sim_task)task)) continue;
    if (is_replay ? task != (int)rf.task : !(o->tasks & (1u << task))) continue;
    hearth_sim_opts so;
    hearth_sim_opts_default(&so);
    so.task = (hearth_sim_task)task;
    so.release_root = o->release_root;
    so.use_ground_truth = o->use_ground_truth;
    so.width = so.height = o->render_size;
    so.shadows = o->shadows;
    so.renderer = o->renderer;
    so.thermal = o->thermal_mode;
    so.gl = o->gl;
    int limit = o->max_steps > 0 ? o->max_steps : hearth_eval_time_limit(so.task);
    so.max_steps = limit + o->wait_steps;
    if (is_replay)
      for (int i = 0; i < rf.n; i++)
        if ((int)rf.demos[i].T + 1 > so.max_steps) so.max_steps = (int)rf.demos[i].T + 1;
    hearth_sim_env *env = NULL;
    if ((st = hearth_sim_env_new(&so, &env, err))) break;
    if (!r->renderer[0]) snprintf(r->renderer, sizeof r->renderer, "%s", hearth_sim_renderer(env));
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
            fprintf(stderr, "eval %s instr %d episode %d: %s%s%s\n", hearth_sim_task_name(so.task),
                    ins + 1, k, ep.success ? "success" : "failure", ep.success ? "" : ": ",
                    ep.success ? "" : ep.reason);
        }
    }
    hearth_sim_env_free(env);
  }
  if (wsp.metadata_json && !(r->metadata_json = strdup(wsp.metadata_json)) && !st)
    st = hearth_err_set(err, HEARTH_E_NOMEM, "eval: results");
  eval_ws_free(&wsp);
  eval_replay_free(&rf);
  r->seconds = hearth_now() - t0;
  if (st) hearth_eval_results_free(r);
  return st;
}

void hearth_eval_results_free(hearth_eval_results *r) {
  if (!r) return;
  free(r->eps);
  free(r->metadata_json);
  memset(r, 0, sizeof *r);
}

size_t hearth_eval_policy_errors(const hearth_eval_results *r) {
  size_t n = 0;
  for (size_t i = 0; i < r->n; i++) n += r->eps[i].error != 0;
  return n;
}
