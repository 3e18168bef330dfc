/* policy evaluation end to end on a tiny virtual-rig release: the oracle
 * solves every instruction, a replayed demo reproduces its success and its
 * states exactly, an openpi-protocol server (tests/eval/policy_server.py)
 * serving a demo's actions succeeds, a misbehaving server fails episodes
 * with reasons while the evaluation goes on, and the RGB-only probe: a
 * selector seeing only RGB cannot beat chance at choosing the H1/H2 target,
 * one seeing the thermal view can; the server's metadata decides whether
 * the thermal condition may run, and a run failed wholly by the server
 * exits non-zero */
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "hearth/hearth.h"
#include "sim/sim_env.h"
#include "test_probe.h"
#include "test_util.h"

static char g_root[1200], g_dir[1100];

static void make_release(void) {
  snprintf(g_root, sizeof g_root, "%s/release", g_dir);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.ideal = 1; /* closed-form: the clean rig */
  so.out_root = g_root;
  const char *cats[] = {"cup",    "canned_drink", "electric_kettle", "eraser",
                        "orange", "smartphone",   "sponge"};
  so.n_categories = 7;
  for (int i = 0; i < 7; i++) so.categories[i] = cats[i];
  so.n_states = 3;
  so.states[0] = "neutral", so.states[1] = "hot", so.states[2] = "iced";
  so.n_views = 6;
  so.triangles = 2000;
  so.texture_size = 128;
  so.map_resolution = 64;
  so.calibration = 0;
  so.quiet = 1;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&so, &err), &err);
}

static void base_opts(hearth_eval_opts *o) {
  hearth_eval_opts_default(o);
  o->release_root = g_root;
  o->use_ground_truth = 1;
  o->render_size = 48;
  o->image_size = 32;
  o->quiet = 1;
}

static void test_oracle(void) {
  hearth_eval_opts o;
  base_opts(&o);
  o.episodes = 2;
  hearth_eval_results r;
  hearth_err err = {0};
  CHECK_OK(hearth_eval_run(&o, &r, &err), &err);
  CHECK(r.n == 12);
  double pi[HEARTH_SIM_TASK_END][2], pt[HEARTH_SIM_TASK_END];
  hearth_eval_rates(&r, pi, pt);
  for (int t = 1; t <= 3; t++)
    for (int i = 0; i < 2; i++)
      CHECK_MSG(pi[t][i] >= 0.95, "oracle H%d instruction %d: %.2f", t, i + 1, pi[t][i]);
  /* held-out layouts, both instructions on the same layout */
  for (size_t k = 0; k < r.n; k++)
    CHECK(r.eps[k].layout == HEARTH_EVAL_LAYOUT_BASE + (uint64_t)r.eps[k].episode);
  char *txt = hearth_eval_format_text(&r);
  CHECK(txt != NULL);
  if (txt) {
    /* the last line starts with overall and carries k/n */
    char *last = strstr(txt, "\noverall ");
    CHECK(last != NULL && strchr(last + 1, '\n') == txt + strlen(txt) - 1);
    int ok = 0, n = 0;
    CHECK(last && sscanf(last, "\noverall %*s (%d/%d)", &ok, &n) == 2 && n == 12);
  }
  char *md = hearth_eval_format_markdown(&r), *js = hearth_eval_format_json(&r);
  CHECK(md && strstr(md, "| Task | Thermal | Instr. 1 | Instr. 2 | Average |"));
  CHECK(js && strstr(js, "\"overall_success\"") && strstr(js, "\"episodes\""));
  free(txt), free(md), free(js);
  hearth_eval_results_free(&r);
}

static void collect_demo(const char *path) {
  hearth_sim_collect_opts c;
  hearth_sim_collect_opts_default(&c);
  c.task = HEARTH_SIM_H1;
  c.release_root = g_root;
  c.use_ground_truth = 1;
  c.layouts = 1;
  c.image_size = 32;
  c.quiet = 1;
  c.out_path = path;
  hearth_err err = {0};
  hearth_sim_collect_stats s;
  CHECK_OK(hearth_sim_collect(&c, &s, &err), &err);
  CHECK(s.demos == 2);
}

static void test_replay(const char *demo) {
  hearth_eval_opts o;
  base_opts(&o);
  char spec[1300];
  snprintf(spec, sizeof spec, "replay:%s", demo);
  o.policy = spec;
  hearth_eval_results r;
  hearth_err err = {0};
  CHECK_OK(hearth_eval_run(&o, &r, &err), &err);
  CHECK(r.n == 2);
  for (size_t k = 0; k < r.n; k++) {
    CHECK_MSG(r.eps[k].success, "replay of demo %d: %s", r.eps[k].episode, r.eps[k].reason);
    CHECK_MSG(r.eps[k].state_diff == 0.0, "replay of demo %d: states differ by %g",
              r.eps[k].episode, r.eps[k].state_diff);
    CHECK(r.eps[k].layout == 0 && r.eps[k].instruction == r.eps[k].episode);
  }
  hearth_eval_results_free(&r);
  /* a demo index past the end names the file */
  snprintf(spec, sizeof spec, "replay:%s#7", demo);
  CHECK(hearth_eval_run(&o, &r, &err) == HEARTH_E_RANGE);
  CHECK(strstr(err.msg, demo) != NULL);
}

/* ---- the python policy server ---------------------------------------------- */
typedef struct server {
  pid_t pid;
  char url[64], log[1200];
} server;

static int start_server(server *s, const char *name, const char *const *extra) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  char script[1200], portf[1200];
  snprintf(script, sizeof script, "%s/tests/eval/policy_server.py", src ? src : ".");
  snprintf(portf, sizeof portf, "%s/%s.port", g_dir, name);
  snprintf(s->log, sizeof s->log, "%s/%s.log", g_dir, name);
  unlink(portf), unlink(s->log);
  const char *argv[32] = {"/usr/bin/python3", script, "--port-file", portf, "--log", s->log};
  int n = 6;
  for (int k = 0; extra && extra[k] && n < 30; k++) argv[n++] = extra[k];
  argv[n] = NULL;
  s->pid = fork();
  if (s->pid == 0) {
    execv(argv[0], (char *const *)argv);
    _exit(127);
  }
  for (int k = 0; k < 300; k++) { /* up to 30 s for python to start */
    FILE *f = fopen(portf, "r");
    int port = 0;
    if (f) {
      if (fscanf(f, "%d", &port) != 1) port = 0;
      fclose(f);
    }
    if (port > 0) {
      snprintf(s->url, sizeof s->url, "ws://127.0.0.1:%d", port);
      return 1;
    }
    int status;
    if (waitpid(s->pid, &status, WNOHANG) == s->pid) break;
    struct timespec ts = {0, 100000000};
    nanosleep(&ts, NULL);
  }
  fprintf(stderr, "policy server %s did not start\n", name);
  g_test_failures++;
  return 0;
}

static void stop_server(server *s) {
  if (s->pid > 0) {
    kill(s->pid, SIGTERM);
    waitpid(s->pid, NULL, 0);
  }
  s->pid = 0;
}

static int count_lines(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  int n = 0, c;
  while ((c = fgetc(f)) != EOF) n += c == '\n';
  fclose(f);
  return n;
}

/* a server replaying the demo's actions (no wait, replan 5): success, one
 * request per 5 steps */
static void test_ws_demo(const char *demo) {
  server s = {0};
  const char *extra[] = {"--size", "32", "--actions", demo, NULL};
  if (!start_server(&s, "demo", extra)) return;
  hearth_eval_opts o;
  base_opts(&o);
  o.policy = s.url;
  o.tasks = 1u << HEARTH_SIM_H1;
  o.episodes = 1;
  o.layout_base = 0; /* the demo's layout */
  o.wait_steps = 0;
  o.timeout_s = 20;
  hearth_eval_results r;
  hearth_err err = {0};
  CHECK_OK(hearth_eval_run(&o, &r, &err), &err);
  int want_req = 0;
  CHECK(r.n == 2);
  for (size_t k = 0; k < r.n; k++) {
    CHECK_MSG(r.eps[k].success, "ws demo instr %d: %s", r.eps[k].instruction + 1, r.eps[k].reason);
    want_req += (r.eps[k].steps + 4) / 5;
  }
  CHECK_MSG(count_lines(s.log) == want_req, "server saw %d requests, expected %d",
            count_lines(s.log), want_req);
  hearth_eval_results_free(&r);
  stop_server(&s);
}

/* misbehaving servers: the first connection's 2nd request goes wrong */
static void test_ws_failure(const char *mode, const char *want, int thermal_client,
                            int thermal_server) {
  server s = {0};
  char th[8];
  snprintf(th, sizeof th, "%d", thermal_server);
  const char *extra[] = {"--size", "32", "--mode", mode, "--sleep", "3", "--thermal", th, NULL};
  if (!start_server(&s, mode, extra)) return;
  hearth_eval_opts o;
  base_opts(&o);
  o.policy = s.url;
  o.tasks = 1u << HEARTH_SIM_H1;
  o.episodes = 1;
  o.max_steps = 15;
  o.wait_steps = 3;
  o.timeout_s = 1.0;
  o.thermal = thermal_client;
  hearth_eval_results r;
  hearth_err err = {0};
  CHECK_OK(hearth_eval_run(&o, &r, &err), &err);
  CHECK(r.n == 2);
  if (r.n == 2) {
    if (want) {
      CHECK_MSG(r.eps[0].error && !r.eps[0].success && strstr(r.eps[0].reason, want),
                "mode %s: episode 1 reason \"%s\", expected \"%s\"", mode, r.eps[0].reason, want);
      /* the evaluation went on with a fresh connection (a key mismatch fails every request) */
      if (strcmp(mode, "ok") == 0)
        CHECK_MSG(r.eps[1].error && strstr(r.eps[1].reason, want), "mode %s: episode 2: %s", mode,
                  r.eps[1].reason);
      else
        CHECK_MSG(!r.eps[1].error && strstr(r.eps[1].reason, "time limit"),
                  "mode %s: episode 2: %s", mode, r.eps[1].reason);
    } else {
      for (int k = 0; k < 2; k++)
        CHECK_MSG(!r.eps[k].error && strstr(r.eps[k].reason, "time limit"),
                  "mode %s: episode %d: %s", mode, k, r.eps[k].reason);
      /* 12 policy steps with replan 5: 3 requests per episode */
      CHECK(count_lines(s.log) == 6);
    }
  }
  hearth_eval_results_free(&r);
  stop_server(&s);
}

/* H6 with a server that only holds still: the iced can warms past its
 * limit on the table, which ends the episode early as a task failure (not
 * a policy error) with the simulator's reason; the room-temperature can of
 * instruction 2 has no limit and runs into the time limit */
static void test_ws_h6_deadline(void) {
  server s = {0};
  const char *extra[] = {"--size", "32", "--mode", "ok", "--thermal", "1", NULL};
  if (!start_server(&s, "h6", extra)) return;
  hearth_eval_opts o;
  base_opts(&o);
  o.policy = s.url;
  o.tasks = 1u << HEARTH_SIM_H6;
  o.episodes = 1;
  o.wait_steps = 3;
  hearth_eval_results r;
  hearth_err err = {0};
  CHECK_OK(hearth_eval_run(&o, &r, &err), &err);
  CHECK(r.n == 2);
  if (r.n == 2) {
    CHECK_MSG(!r.eps[0].error && !r.eps[0].success && strstr(r.eps[0].reason, "warmed past") &&
                  r.eps[0].steps < hearth_eval_time_limit(HEARTH_SIM_H6),
              "H6 instruction 1: %s after %d steps", r.eps[0].reason, r.eps[0].steps);
    CHECK_MSG(!r.eps[1].error && strstr(r.eps[1].reason, "time limit"), "H6 instruction 2: %s",
              r.eps[1].reason);
    printf("H6 with a still policy: %s (%d steps)\n", r.eps[0].reason, r.eps[0].steps);
  }
  hearth_eval_results_free(&r);
  stop_server(&s);
}

/* the server's metadata held against the thermal condition: a server that
 * declares it ignores the thermal view is refused before any episode, one
 * that declares nothing is "unknown", never silently "w/" */
static void test_ws_thermal(const char *decl, const char *keys, int thermal, hearth_status want_st,
                            int want_used) {
  server s = {0};
  char th[8];
  snprintf(th, sizeof th, "%d", thermal);
  const char *extra[12] = {"--size", "32", "--thermal", th, "--declare-thermal", decl};
  int n = 6;
  if (keys) extra[n++] = "--image-keys", extra[n++] = keys;
  extra[n] = NULL;
  if (!start_server(&s, "meta", extra)) return;
  hearth_eval_opts o;
  base_opts(&o);
  o.policy = s.url;
  o.tasks = 1u << HEARTH_SIM_H1;
  o.episodes = 1;
  o.max_steps = 5;
  o.wait_steps = 1;
  o.timeout_s = 5;
  o.thermal = thermal;
  hearth_eval_results r;
  hearth_err err = {0};
  hearth_status st = hearth_eval_run(&o, &r, &err);
  if (want_st) {
    CHECK_MSG(st == want_st && strstr(err.msg, "ignores the thermal view") &&
                  strstr(err.msg, "--no-thermal"),
              "decl %s keys %s: %s", decl, keys ? keys : "-", err.msg);
    CHECK_MSG(count_lines(s.log) == 0, "the server got requests before the refusal");
  } else {
    CHECK_OK(st, &err);
    CHECK_MSG(r.thermal_used == want_used,
              "decl %s keys %s thermal %d: thermal_used %d, expected %d", decl, keys ? keys : "-",
              thermal, r.thermal_used, want_used);
    char *js = hearth_eval_format_json(&r), *txt = hearth_eval_format_text(&r);
    const char *used = want_used < 0 ? "\"thermal_used\": \"unknown\""
                       : want_used   ? "\"thermal_used\": true"
                                     : "\"thermal_used\": false";
    CHECK_MSG(js && strstr(js, used) && strstr(js, "\"server\": \"hearth-test\"") &&
                  strstr(js, "\"render_size\": 48") && strstr(js, "\"image_size\": 32") &&
                  strstr(js, "\"replan_steps\": 5") &&
                  strstr(js, "\"renderer\": \"soft: hearth rasteriser"),
              "results.json: %s", js ? js : "(null)");
    const char *label = want_used < 0 ? "H1     w/?" : thermal ? "H1     w/ " : "H1     w/o";
    CHECK_MSG(txt && strstr(txt, label) &&
                  strstr(txt, "server metadata: {\"server\":\"hearth-test\""),
              "text: %s", txt ? txt : "(null)");
    CHECK(want_used >= 0 || (strstr(r.warning, "unknown") && txt && strstr(txt, "warning: ")));
    free(js), free(txt);
    hearth_eval_results_free(&r);
  }
  stop_server(&s);
}

/* the command exits non-zero when every episode failed because of the
 * server, and says so; results are written all the same */
static void test_cli_all_policy_errors(void) {
  server s = {0};
  const char *extra[] = {"--size", "32",         "--mode", "error", "--bad-at",
                         "0",      "--bad-conn", "0",      NULL};
  if (!start_server(&s, "allbad", extra)) return;
  char cmd[4000], out[1300];
  snprintf(out, sizeof out, "%s/cli_eval", g_dir);
  snprintf(
      cmd, sizeof cmd,
      "'%s' sim eval --policy %s --release '%s' --ground-truth --task H1 --episodes 1 --size 48 --image-size 32 "
      "--max-steps 6 --wait 1 --timeout 5 --quiet --out '%s' > '%s.log' 2>&1",
      HEARTH_EXE, s.url, g_root, out, out);
  int rc = system(cmd);
  CHECK_MSG(WIFEXITED(rc) && WEXITSTATUS(rc) == 1, "hearth sim eval exited %d",
            WIFEXITED(rc) ? WEXITSTATUS(rc) : -1);
  char path[1400], buf[8192] = "";
  snprintf(path, sizeof path, "%s.log", out);
  FILE *f = fopen(path, "r");
  if (f) {
    buf[fread(buf, 1, sizeof buf - 1, f)] = 0;
    fclose(f);
  }
  CHECK_MSG(strstr(buf, "every episode (2 of 2) failed because the policy erred") &&
                strstr(buf, "policy errors: 2 of 2"),
            "output: %s", buf);
  /* a run that measured nothing writes no results */
  snprintf(path, sizeof path, "%s/results.json", out);
  CHECK_MSG(access(path, F_OK) != 0, "%s written by a run that measured nothing", path);
  stop_server(&s);
}

/* ---- the RGB-only probe ------------------------------------------------------ */
/* choose a slot from one view: the candidate reading hotter / colder /
 * nearer room temperature as the instruction asks; a difference under 3 degC
 * is no evidence, so slot A */
static int select_slot(const uint8_t *view, int w, int boxes[2][4], const char *instr,
                       const uint8_t lut[256][3]) {
  double t0 = probe_crop_temp(view, w, boxes[0], lut), t1 = probe_crop_temp(view, w, boxes[1], lut);
  if (fabs(t0 - t1) < 3) return 0;
  if (strstr(instr, "hot")) return t1 > t0;
  if (strstr(instr, "iced")) return t1 < t0;
  return fabs(t1 - 22) < fabs(t0 - 22);
}

static void test_probe(void) {
  uint8_t lut[256][3];
  for (int k = 0; k < 256; k++) hearth_turbo(k / 255.0, lut[k]);
  const int layouts = 16;
  for (int task = 1; task <= 2; task++) {
    hearth_sim_opts so;
    hearth_sim_opts_default(&so);
    so.task = (hearth_sim_task)task;
    so.release_root = g_root;
    so.use_ground_truth = 1;
    so.width = so.height = 64;
    so.render_wrist = 0;
    hearth_sim_env *e = NULL;
    hearth_err err = {0};
    CHECK_OK(hearth_sim_env_new(&so, &e, &err), &err);
    if (!e) return;
    int right[2] = {0, 0}, n = 0;
    for (int l = 0; l < layouts; l++)
      for (int ins = 0; ins < 2; ins++) {
        CHECK_OK(hearth_sim_reset(e, 99, HEARTH_EVAL_LAYOUT_BASE + (uint64_t)l, ins, &err), &err);
        hearth_sim_obs ob;
        int boxes[2][4];
        CHECK_OK(hearth_sim_observe(e, &ob, &err), &err);
        CHECK_OK(hearth_sim_candidate_boxes(e, boxes, &err), &err);
        /* privileged: only to score the choice */
        int target_slot = e->target ^ e->swap;
        const char *instr = hearth_sim_instruction(e);
        right[0] += select_slot(ob.agentview_rgb, ob.width, boxes, instr, lut) == target_slot;
        right[1] += select_slot(ob.agentview_thermal, ob.width, boxes, instr, lut) == target_slot;
        n++;
      }
    double acc_rgb = (double)right[0] / n, acc_th = (double)right[1] / n;
    printf("probe H%d: RGB-only %.3f, thermal %.3f over %d choices\n", task, acc_rgb, acc_th, n);
    CHECK_MSG(acc_rgb >= 0.3 && acc_rgb <= 0.7, "H%d: RGB-only selector at %.2f, expected chance",
              task, acc_rgb);
    CHECK_MSG(acc_th >= 0.95, "H%d: thermal selector at %.2f", task, acc_th);
    hearth_sim_env_free(e);
  }
}

static double t_start;
static void stamp(const char *what) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  double t = ts.tv_sec + ts.tv_nsec * 1e-9;
  if (t_start == 0) t_start = t;
  printf("[%6.1f s] %s\n", t - t_start, what);
  fflush(stdout);
}

int main(void) {
  stamp("start");
  snprintf(g_dir, sizeof g_dir, "%s", test_tmpdir("sim_eval"));
  make_release();
  stamp("make_release();");
  char demo[1300];
  snprintf(demo, sizeof demo, "%s/h1_demo.hdf5", g_dir);
  collect_demo(demo);
  stamp("collect_demo(demo);");
  test_probe();
  stamp("test_probe();");
  test_replay(demo);
  stamp("test_replay(demo);");
  test_ws_demo(demo);
  stamp("test_ws_demo(demo);");
  test_ws_failure("ok", NULL, 1, 1);
  test_ws_failure("ok", NULL, 0, 0);               /* the RGB-only condition */
  test_ws_failure("ok", "observation keys", 0, 1); /* the server checks the keys */
  test_ws_failure("error", "1011", 1, 1);
  test_ws_failure("disconnect", "closed the connection", 1, 1);
  test_ws_failure("garbage", "msgpack", 1, 1);
  test_ws_failure("rawgarbage", "websocket", 1, 1);
  test_ws_failure("slow", "no reply", 1, 1);
  test_ws_failure("short", "H >= 5", 1, 1);
  test_ws_failure("nan", "reply.actions[0][0] is NaN: action 0 of the chunk, element 0 (dx)", 1, 1);
  test_ws_failure("wide", "shape (10, 6): width 6, expected 7", 1, 1);
  stamp("ws failures");
  test_ws_h6_deadline();
  stamp("ws H6 deadline");
  test_ws_thermal("false", NULL, 1, HEARTH_E_ARG, 0);
  test_ws_thermal("none", "observation/image,observation/wrist_image", 1, HEARTH_E_ARG, 0);
  test_ws_thermal("none", NULL, 1, HEARTH_OK, -1); /* a stock server */
  test_ws_thermal("true", NULL, 1, HEARTH_OK, 1);
  test_ws_thermal("none", "observation/image,observation/wrist_image,observation/thermal_image", 1,
                  HEARTH_OK, 1);
  test_ws_thermal("false", NULL, 0, HEARTH_OK, 0); /* the RGB-only condition */
  stamp("ws metadata");
  test_cli_all_policy_errors();
  stamp("cli: all policy errors");
  test_oracle();
  stamp("test_oracle();");
  return g_test_failures ? 1 : 0;
}
