/* hearth sim render, hearth sim collect: scene pictures and demonstrations */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"
#include "hearth/hearth.h"
#include "hearth/sim.h"

static const char *k_usage_render =
    "usage: hearth sim render --out DIR [options]\n"
    "\n"
    "Render layout 0 of each task into DIR/<task>_rgb.png, <task>_thermal.png and\n"
    "<task>_wrist.png (top row first).\n"
    "\n"
    "options:\n"
    "  --out DIR         output directory (created)\n"
    "  --task H1|H2|H3   only this task (default: all three)\n"
    "  --release ROOT    assets from a release (derived/ meshes and thermal_turbo.png);\n"
    "                    default: a small release made by the virtual rig\n"
    "  --ground-truth    with --release: a virtual-rig release's ground_truth/ meshes\n"
    "                    and temperature_true.npy instead of derived/\n"
    "  --size N          image side in pixels (default 256)\n"
    "  --seed N          layout seed (default 1)\n"
    "  --shadows         shadow-mapped light in the RGB views (off by default)\n"
    "  --gl osmesa|egl   GL back end (default $HEARTH_GL, else osmesa: CPU; egl: a\n"
    "                    GPU through EGL, else Mesa's surfaceless platform)\n"
    "  -h, --help        this text\n";

static const char *k_usage_collect =
    "usage: hearth sim collect --task H1|H2|H3 --out FILE.hdf5 [options]\n"
    "\n"
    "Run the scripted expert (privileged state: approach, grasp, lift, transport,\n"
    "release) on N layouts x 2 instructions and store the successful demonstrations\n"
    "in LIBERO's HDF5 layout with obs/agentview_thermal added. Same seed, same file.\n"
    "\n"
    "Layouts: objects jittered in 5 x 5 cm squares around fixed spots, fixed\n"
    "orientations, redrawn until both candidates are at least 70% visible in the\n"
    "front view. Even layouts put the first instruction's object in slot A, odd\n"
    "ones in slot B; a layout where the expert fails either instruction is replaced\n"
    "by the next unused layout of the same parity, so assignments stay balanced.\n"
    "\n"
    "One file holds both instructions (demo_0, demo_1 from layout 1, ...). LIBERO's\n"
    "loaders read data.attrs['problem_info']['language_instruction'] as one string:\n"
    "it holds the first instruction; every demo has its own `language_instruction`\n"
    "attribute, and data.attrs['instructions'] lists both (JSON). Images are stored\n"
    "in OpenGL row order (bottom row first, data.attrs['image_row_order']).\n"
    "\n"
    "options:\n"
    "  --task H1|H2|H3   the task (required)\n"
    "  --out FILE.hdf5   output file (written atomically)\n"
    "  --layouts N       layouts (default 200, as in the paper: 400 demos per task)\n"
    "  --seed N          layout seed (default 1)\n"
    "  --size N          stored image side (default 128, LIBERO's)\n"
    "  --max-steps N     time limit per episode in control steps (default 400)\n"
    "  --release ROOT    assets from a release (derived/); default: virtual rig\n"
    "  --ground-truth    with --release: a virtual-rig release's ground_truth/ assets\n"
    "  --keep-failures   also store episodes that did not succeed\n"
    "  --shadows         shadow-mapped light in the RGB views (off by default)\n"
    "  --gl osmesa|egl   GL back end (default $HEARTH_GL, else osmesa)\n"
    "  --quiet           no progress output\n"
    "  -h, --help        this text\n";

int hearth_cmd_sim_render(int argc, char **argv) {
  const char *out = NULL, *release = NULL, *v;
  hearth_sim_task only = 0;
  long size = 256;
  uint64_t seed = 1;
  int gt = 0, shadows = 0;
  const char *gl = NULL;
  for (int i = 1; i < argc; i++) {
    int r;
    if (cli_is_help(argv[i])) {
      fputs(k_usage_render, stdout);
      return 0;
    }
    if (strcmp(argv[i], "--ground-truth") == 0) {
      gt = 1;
      continue;
    }
    if (strcmp(argv[i], "--shadows") == 0) {
      shadows = 1;
      continue;
    }
    if ((r = cli_opt(argc, argv, &i, "--out", &v)) == 1) out = v;
    else if (r == 0 && (r = cli_opt(argc, argv, &i, "--release", &v)) == 1) release = v;
    else if (r == 0 && (r = cli_opt(argc, argv, &i, "--gl", &v)) == 1) gl = v;
    else if (r == 0 && (r = cli_opt(argc, argv, &i, "--task", &v)) == 1) {
      if (!(only = hearth_sim_task_parse(v))) {
        fprintf(stderr, "hearth sim render: --task must be H1, H2 or H3, got '%s'\n", v);
        return 2;
      }
    } else if (r == 0 && (r = cli_opt(argc, argv, &i, "--size", &v)) == 1) {
      if (!cli_parse_int(v, 16, 4096, &size)) {
        fprintf(stderr, "hearth sim render: --size must be 16..4096\n");
        return 2;
      }
    } else if (r == 0 && (r = cli_opt(argc, argv, &i, "--seed", &v)) == 1) {
      if (!cli_parse_u64(v, &seed)) {
        fprintf(stderr, "hearth sim render: bad --seed '%s'\n", v);
        return 2;
      }
    }
    if (r == -1) {
      fprintf(stderr, "hearth sim render: %s needs a value\n", argv[i]);
      return 2;
    }
    if (r == 0) {
      fprintf(stderr, "hearth sim render: unknown option '%s'\n%s", argv[i], k_usage_render);
      return 2;
    }
  }
  if (!out) {
    fprintf(stderr, "hearth sim render: --out is required\n%s", k_usage_render);
    return 2;
  }
  hearth_err err = {0};
  if (hearth_mkdirs(out, &err)) return cli_fail("sim render", &err);
  char root[4096], tmpdir[4096];
  int use_gt;
  if (sim_cli_assets(release, gt, root, sizeof root, tmpdir, sizeof tmpdir, &use_gt, 0)) return 1;
  int rc = 0;
  for (int t = 1; t <= 3 && !rc; t++) {
    if (only && t != (int)only) continue;
    hearth_sim_opts o;
    hearth_sim_opts_default(&o);
    o.task = (hearth_sim_task)t;
    o.release_root = root;
    o.use_ground_truth = use_gt;
    o.width = o.height = (int)size;
    o.shadows = shadows;
    o.gl = gl;
    char prefix[4200];
    snprintf(prefix, sizeof prefix, "%s/%s", out, hearth_sim_task_name(o.task));
    if (hearth_sim_render_scene(&o, seed, prefix, &err)) rc = cli_fail("sim render", &err);
    else printf("%s_{rgb,thermal,wrist}.png\n", prefix);
  }
  sim_cli_drop_assets(tmpdir);
  return rc;
}

int hearth_cmd_sim_collect(int argc, char **argv) {
  hearth_sim_collect_opts o;
  hearth_sim_collect_opts_default(&o);
  o.task = 0;
  const char *release = NULL, *v;
  int gt = 0;
  for (int i = 1; i < argc; i++) {
    int r;
    long n;
    if (strcmp(argv[i], "--ground-truth") == 0) { gt = 1; continue; }
    if (cli_is_help(argv[i])) {
      fputs(k_usage_collect, stdout);
      return 0;
    }
    if (strcmp(argv[i], "--quiet") == 0) { o.quiet = 1; continue; }
    if (strcmp(argv[i], "--keep-failures") == 0) { o.keep_failures = 1; continue; }
    if (strcmp(argv[i], "--shadows") == 0) { o.shadows = 1; continue; }
    if ((r = cli_opt(argc, argv, &i, "--out", &v)) == 1) o.out_path = v;
    else if (r == 0 && (r = cli_opt(argc, argv, &i, "--release", &v)) == 1) release = v;
    else if (r == 0 && (r = cli_opt(argc, argv, &i, "--gl", &v)) == 1) o.gl = v;
    else if (r == 0 && (r = cli_opt(argc, argv, &i, "--task", &v)) == 1) {
      if (!(o.task = hearth_sim_task_parse(v))) {
        fprintf(stderr, "hearth sim collect: --task must be H1, H2 or H3, got '%s'\n", v);
        return 2;
      }
    } else if (r == 0 && (r = cli_opt(argc, argv, &i, "--layouts", &v)) == 1) {
      if (!cli_parse_int(v, 1, 100000, &n)) { fprintf(stderr, "hearth sim collect: --layouts must be 1..100000\n"); return 2; }
      o.layouts = (int)n;
    } else if (r == 0 && (r = cli_opt(argc, argv, &i, "--size", &v)) == 1) {
      if (!cli_parse_int(v, 16, 1024, &n)) { fprintf(stderr, "hearth sim collect: --size must be 16..1024\n"); return 2; }
      o.image_size = (int)n;
    } else if (r == 0 && (r = cli_opt(argc, argv, &i, "--max-steps", &v)) == 1) {
      if (!cli_parse_int(v, 1, 100000, &n)) { fprintf(stderr, "hearth sim collect: --max-steps must be 1..100000\n"); return 2; }
      o.max_steps = (int)n;
    } else if (r == 0 && (r = cli_opt(argc, argv, &i, "--seed", &v)) == 1) {
      if (!cli_parse_u64(v, &o.seed)) { fprintf(stderr, "hearth sim collect: bad --seed '%s'\n", v); return 2; }
    }
    if (r == -1) { fprintf(stderr, "hearth sim collect: %s needs a value\n", argv[i]); return 2; }
    if (r == 0) { fprintf(stderr, "hearth sim collect: unknown option '%s'\n%s", argv[i], k_usage_collect); return 2; }
  }
  if (!o.task || !o.out_path) {
    fprintf(stderr, "hearth sim collect: --task and --out are required\n%s", k_usage_collect);
    return 2;
  }
  char root[4096], tmpdir[4096];
  if (sim_cli_assets(release, gt, root, sizeof root, tmpdir, sizeof tmpdir, &o.use_ground_truth, o.quiet))
    return 1;
  o.release_root = root;
  hearth_err err = {0};
  hearth_sim_collect_stats s;
  hearth_status st = hearth_sim_collect(&o, &s, &err);
  sim_cli_drop_assets(tmpdir);
  if (st) return cli_fail("sim collect", &err);
  for (int i = 0; i < 2; i++)
    printf("instruction %d \"%s\": %d/%d successful\n", i + 1, hearth_sim_instruction_text(o.task, i),
           s.successes[i], s.attempts[i]);
  printf("%d demos, %d layouts replaced, %ld steps, %.1f s (%.1f steps/s) -> %s\n", s.demos,
         s.rejected_layouts, s.steps, s.seconds, s.seconds > 0 ? s.steps / s.seconds : 0.0,
         o.out_path);
  return 0;
}
