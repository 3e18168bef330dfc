/* hearth sim eval: score a policy on H1-H3 the way the paper does */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"
#include "hearth/hearth.h"

static const char *k_usage =
    "usage: hearth sim eval --policy SPEC [options]\n"
    "\n"
    "Evaluate a policy on the paper's tasks: N episodes per instruction (default 10:\n"
    "20 per task, 60 for all three), on held-out layouts (layout 2^32 + k of the seed\n"
    "stream, never used by collection; both instructions share a layout). Success =\n"
    "the target resting on the mat, released, within the time limit (280 control steps\n"
    "per task, after the 10 no-op steps of a server policy). Prints the paper's table\n"
    "(Task, Thermal, Instr. 1, Instr. 2, Average) ending with a line `overall <pct>`.\n"
    "A policy that errs (server gone, garbage, timeout) fails that episode with the\n"
    "reason; the evaluation goes on (reconnecting for the next episode).\n"
    "\n"
    "policies:\n"
    "  oracle               the scripted expert (privileged state): an upper bound\n"
    "  replay:FILE[#K]      actions of the demos (or demo K) of a `hearth sim collect`\n"
    "                       file, at their own layouts: checks determinism\n"
    "  ws://HOST:PORT       an openpi policy server (openpi-client protocol): LIBERO\n"
    "                       observations observation/image, observation/wrist_image\n"
    "                       (224x224, rotated 180 deg, resized with padding),\n"
    "                       observation/thermal_image, observation/state (8), prompt;\n"
    "                       action chunks, replanning every 5 steps\n"
    "\n"
    "options:\n"
    "  --policy SPEC        (required)\n"
    "  --task H1|H2|H3|all  tasks (default all)\n"
    "  --episodes N         episodes per instruction (default 10)\n"
    "  --no-thermal         leave observation/thermal_image out (the RGB-only condition)\n"
    "  --seed N             layout seed (default 1, as collection)\n"
    "  --release ROOT       assets from a release (derived/); default: virtual rig\n"
    "  --size N             rendered view side (default 256)\n"
    "  --shadows            shadow-mapped light in the RGB views (as at collection)\n"
    "  --gl osmesa|egl      GL back end (default $HEARTH_GL, else osmesa)\n"
    "  --image-size N       policy image side (default 224)\n"
    "  --max-steps N        time limit in control steps (default 280)\n"
    "  --replan N           actions executed per chunk (default 5)\n"
    "  --wait N             no-op steps before querying (default 10)\n"
    "  --timeout S          seconds to wait for the server (default 120)\n"
    "  --out DIR            also write DIR/results.txt, results.json, results.md\n"
    "  --video DIR          an animated PNG per episode (front RGB | thermal | wrist)\n"
    "  --video-every K      keep every K-th step in videos (default 2)\n"
    "  --quiet              no per-episode lines on stderr\n"
    "  -h, --help           this text\n";

static int write_text(const char *dir, const char *name, const char *s) {
  char path[4200];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  hearth_err err = {0};
  if (!s || hearth_write_file_atomic(path, s, strlen(s), &err)) return cli_fail("sim eval", &err);
  return 0;
}

int hearth_cmd_sim_eval(int argc, char **argv) {
  hearth_eval_opts o;
  hearth_eval_opts_default(&o);
  const char *out = NULL, *release = NULL;
  for (int i = 1; i < argc; i++) {
    const char *v = NULL;
    long n;
    int r;
    if (cli_is_help(argv[i])) {
      fputs(k_usage, stdout);
      return 0;
    }
#define OPT(name) ((r = cli_opt(argc, argv, &i, name, &v)) != 0)
#define NEEDV(name)                                                       \
  if (r < 0) {                                                            \
    fprintf(stderr, "hearth sim eval: %s needs a value\n%s", name, k_usage); \
    return 2;                                                             \
  }
#define INTV(name, lo, hi, dst)                                                          \
  NEEDV(name);                                                                           \
  if (!cli_parse_int(v, lo, hi, &n)) {                                                   \
    fprintf(stderr, "hearth sim eval: %s: expected an integer in %d..%d, got \"%s\"\n", name, lo, hi, v); \
    return 2;                                                                            \
  }                                                                                      \
  dst = (int)n;
    if (OPT("--policy")) {
      NEEDV("--policy");
      o.policy = v;
    } else if (OPT("--task")) {
      NEEDV("--task");
      if (strcasecmp(v, "all") == 0) o.tasks = 0xe;
      else {
        hearth_sim_task t = hearth_sim_task_parse(v);
        if (!t) {
          fprintf(stderr, "hearth sim eval: --task: expected H1, H2, H3 or all, got \"%s\"\n", v);
          return 2;
        }
        o.tasks = 1u << t;
      }
    } else if (OPT("--episodes")) {
      INTV("--episodes", 1, 100000, o.episodes);
    } else if (strcmp(argv[i], "--shadows") == 0) {
      o.shadows = 1;
    } else if (OPT("--gl")) {
      NEEDV("--gl");
      o.gl = v;
    } else if (strcmp(argv[i], "--no-thermal") == 0) {
      o.thermal = 0;
    } else if (OPT("--seed")) {
      NEEDV("--seed");
      if (!cli_parse_u64(v, &o.seed)) {
        fprintf(stderr, "hearth sim eval: --seed: expected a non-negative integer, got \"%s\"\n", v);
        return 2;
      }
    } else if (OPT("--release")) {
      NEEDV("--release");
      release = v;
    } else if (OPT("--size")) {
      INTV("--size", 16, 2048, o.render_size);
    } else if (OPT("--image-size")) {
      INTV("--image-size", 8, 1024, o.image_size);
    } else if (OPT("--max-steps")) {
      INTV("--max-steps", 1, 100000, o.max_steps);
    } else if (OPT("--replan")) {
      INTV("--replan", 1, 64, o.replan_steps);
    } else if (OPT("--wait")) {
      INTV("--wait", 0, 1000, o.wait_steps);
    } else if (OPT("--timeout")) {
      NEEDV("--timeout");
      if (!cli_parse_num(v, &o.timeout_s) || !(o.timeout_s > 0)) {
        fprintf(stderr, "hearth sim eval: --timeout: expected seconds > 0, got \"%s\"\n", v);
        return 2;
      }
    } else if (OPT("--out")) {
      NEEDV("--out");
      out = v;
    } else if (OPT("--video")) {
      NEEDV("--video");
      o.video_dir = v;
    } else if (OPT("--video-every")) {
      INTV("--video-every", 1, 1000, o.video_every);
    } else if (strcmp(argv[i], "--quiet") == 0) {
      o.quiet = 1;
    } else {
      fprintf(stderr, "hearth sim eval: unknown option \"%s\"\n%s", argv[i], k_usage);
      return 2;
    }
  }
  if (!o.policy || strcmp(o.policy, "oracle") == 0) {
    if (!o.policy) {
      fprintf(stderr, "hearth sim eval: --policy is required\n%s", k_usage);
      return 2;
    }
  }
  char root[4200], tmpdir[4200] = "";
  /* the same virtual-rig assets as `hearth sim collect` makes by default */
  if (sim_cli_assets(release, 0, root, sizeof root, tmpdir, sizeof tmpdir, &o.use_ground_truth, o.quiet))
    return 1;
  o.release_root = root;
  hearth_eval_results res;
  hearth_err err = {0};
  hearth_status st = hearth_eval_run(&o, &res, &err);
  sim_cli_drop_assets(tmpdir);
  if (st) return cli_fail("sim eval", &err);
  char *txt = hearth_eval_format_text(&res);
  int rc = 0;
  if (txt) fputs(txt, stdout);
  else rc = 1;
  if (out && !rc) {
    char *js = hearth_eval_format_json(&res), *md = hearth_eval_format_markdown(&res);
    if (hearth_mkdirs(out, &err)) rc = cli_fail("sim eval", &err);
    else rc = write_text(out, "results.txt", txt) || write_text(out, "results.json", js) ||
              write_text(out, "results.md", md);
    free(js), free(md);
  }
  free(txt);
  hearth_eval_results_free(&res);
  return rc;
}
