/* hearth sim eval: score a policy on H1-H3 (and H4-H6) the way the paper does */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"
#include "hearth/hearth.h"

static const char *k_about =
    "Evaluate a policy on the paper's tasks (H1-H3; H4-H6 with --task): N episodes\n"
    "per instruction (default 10: 20 per task, 60 for H1-H3), on held-out layouts\n"
    "(layout 2^32 + k of the seed stream, never used by collection; both instructions\n"
    "share a layout). Success = the target resting on the mat, released, within the\n"
    "time limit (280 control steps per task, after the 10 no-op steps of a server\n"
    "policy) and, for H4, with no finger touching the pot above 45 degC, for H6,\n"
    "before the iced can warms past its limit. Prints the table\n"
    "(Task, Thermal, Instr. 1, Instr. 2, Average) ending with a line `overall <pct>`.\n"
    "A policy that errs (server gone, garbage, timeout) fails that episode with the\n"
    "reason; the evaluation goes on (reconnecting for the next episode). Such policy\n"
    "errors are counted apart from task failures; when every episode is one, the\n"
    "command exits with status 1 after writing the results.\n"
    "\n"
    "A server is connected before the first episode; its metadata map is printed and\n"
    "stored in results.json. The thermal condition with a server whose metadata says\n"
    "it ignores the thermal view (\"hearth_thermal\": false, or \"image_keys\" without\n"
    "\"observation/thermal_image\") is refused; a server that says neither gets a\n"
    "warning, Thermal \"w/?\" and \"thermal_used\": \"unknown\".\n"
    "\n"
    "policies (--policy):\n"
    "  oracle               the scripted expert (privileged state): an upper bound\n"
    "  replay:FILE[#K]      actions of the demos (or demo K) of a `hearth sim collect`\n"
    "                       file, at their own layouts: checks determinism\n"
    "  ws://HOST:PORT       an openpi policy server (openpi-client protocol): LIBERO\n"
    "                       observations observation/image, observation/wrist_image\n"
    "                       (224x224, rotated 180 deg, resized with padding),\n"
    "                       observation/thermal_image, observation/state (8), prompt;\n"
    "                       action chunks, replanning every 5 steps\n"
    "\n"
    "Views render at 256 px (--size), the side `hearth sim collect` stores, and are\n"
    "resized to 224 px (--image-size) for the policy, as openpi's LIBERO client does.\n";

static int write_text(const char *dir, const char *name, const char *s) {
  char path[4200];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  hearth_err err = {0};
  if (!s || hearth_write_file_atomic(path, s, strlen(s), &err)) return cli_fail("sim eval", &err);
  return 0;
}

/* 1 (after saying why) when the run measured nothing about the policy: no
 * episode ran, or every episode ended in the policy's error (a server that
 * is gone or misbehaves), so a 0 % would be a wrong answer, not a score */
static int measured_nothing(const hearth_eval_results *r) {
  if (r->n == 0) {
    fprintf(stderr, "hearth sim eval: no episode ran: nothing was measured\n");
    return 1;
  }
  size_t errs = 0, first = 0;
  for (size_t i = r->n; i-- > 0;)
    if (r->eps[i].error) errs++, first = i;
  if (errs < r->n) return 0;
  const hearth_eval_episode *e = &r->eps[first];
  fprintf(stderr,
          "hearth sim eval: every episode (%zu of %zu) failed because the policy erred, so "
          "nothing was measured; the first (%s instruction %d episode %d): %s\n",
          errs, r->n, hearth_sim_task_name(e->task), e->instruction + 1, e->episode, e->reason);
  return 1;
}

/* --thermal: hearth_sim_thermal values */
static const char *const k_thermal_names[] = {"static", "dynamic", NULL};
static const int k_thermal_values[] = {HEARTH_SIM_THERMAL_STATIC, HEARTH_SIM_THERMAL_DYNAMIC};

int hearth_cmd_sim_eval(int argc, char **argv) {
  hearth_eval_opts o;
  hearth_eval_opts_default(&o);
  const char *out = NULL, *release = NULL;
  unsigned tasks = o.tasks;
  int gt = 0;
  const cli_opt opts[] = {
      CLI_STR("--policy", "SPEC", &o.policy, "the policy, as listed above"),
      CLI_CALL("--task", "LIST", &tasks, sim_cli_parse_tasks, SIM_CLI_TASK_HELP, "tasks",
               .def = "H1,H2,H3 (the paper's)"),
      CLI_INT("--episodes", "N", &o.episodes, 1, 100000, "episodes per instruction"),
      CLI_FLAG("--no-thermal", &o.thermal, 0,
               "leave observation/thermal_image out (the RGB-only condition)"),
      CLI_U64("--seed", "N", &o.seed, "layout seed (as collection)"),
      CLI_STR("--release", "ROOT", &release, "assets from a release (derived/)",
              .def = "virtual rig"),
      CLI_FLAG("--ground-truth", &gt, 1,
               "with --release: a virtual-rig release's ground_truth/ assets (as sim collect)"),
      CLI_INT("--size", "N", &o.render_size, 16, 2048,
              "rendered view side (as sim collect stores)"),
      CLI_FLAG("--shadows", &o.shadows, 1,
               "shadow-mapped light in the RGB views (as at collection)"),
      CLI_CHOICE("--thermal", &o.thermal_mode, k_thermal_names, k_thermal_values,
                 "static: fixed temperature textures (the paper); dynamic: lumped thermal "
                 "networks (as sim collect --thermal)",
                 .def = "static"),
      CLI_STR("--renderer", "soft|gl", &o.renderer,
              "soft: hearth's deterministic software rasteriser; gl: MuJoCo's OpenGL renderer "
              "(needed for --shadows); the same default as sim collect",
              .def = "$HEARTH_RENDERER, else gl with --shadows and soft without"),
      CLI_STR("--gl", "osmesa|egl", &o.gl, "GL back end of --renderer gl",
              .def = "$HEARTH_GL, else osmesa"),
      CLI_INT("--image-size", "N", &o.image_size, 8, 1024, "policy image side"),
      CLI_INT("--max-steps", "N", &o.max_steps, 1, 100000, "time limit in control steps",
              .def = "280"),
      CLI_INT("--replan", "N", &o.replan_steps, 1, 64, "actions executed per chunk"),
      CLI_INT("--wait", "N", &o.wait_steps, 0, 1000, "no-op steps before querying"),
      CLI_NUM("--timeout", "S", &o.timeout_s, 0, CLI_INF, "seconds to wait for the server",
              .flags = CLI_LO_OPEN),
      CLI_STR("--out", "DIR", &out, "also write DIR/results.txt, results.json, results.md"),
      CLI_STR("--video", "DIR", &o.video_dir,
              "an animated PNG per episode (front RGB | thermal | wrist)"),
      CLI_INT("--video-every", "K", &o.video_every, 1, 1000, "keep every K-th step in videos"),
      CLI_FLAG("--quiet", &o.quiet, 1, "no per-episode lines on stderr"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth sim eval", .about = k_about, .opts = opts};
  int rc = cli_parse(&cmd, argc, argv, NULL);
  if (rc != CLI_RUN) return rc;
  o.tasks = tasks;
  char root[4200], tmpdir[4200] = "";
  /* the same virtual-rig assets as `hearth sim collect` makes by default */
  if (sim_cli_assets(release, gt, root, sizeof root, tmpdir, sizeof tmpdir, &o.use_ground_truth,
                     o.quiet))
    return 1;
  o.release_root = root;
  hearth_eval_results res;
  hearth_err err = {0};
  hearth_status st = hearth_eval_run(&o, &res, &err);
  sim_cli_drop_assets(tmpdir);
  if (st) return cli_fail("sim eval", &err);
  char *txt = hearth_eval_format_text(&res);
  rc = 0;
  if (txt) fputs(txt, stdout);
  else rc = 1;
  /* the table is shown, but a run that measured nothing writes no results */
  if (!rc && measured_nothing(&res)) rc = 1;
  if (out && !rc) {
    char *js = hearth_eval_format_json(&res), *md = hearth_eval_format_markdown(&res);
    if (hearth_mkdirs(out, &err)) rc = cli_fail("sim eval", &err);
    else
      rc = write_text(out, "results.txt", txt) || write_text(out, "results.json", js) ||
           write_text(out, "results.md", md);
    free(js), free(md);
  }
  free(txt);
  hearth_eval_results_free(&res);
  return rc;
}
