/* hearth sim render, hearth sim collect: scene pictures and demonstrations */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"
#include "hearth/hearth.h"
#include "hearth/sim.h"

static const char *k_about_render =
    "Render layout 0 of each task into DIR/<task>_rgb.png, <task>_thermal.png and\n"
    "<task>_wrist.png (top row first).\n";

static const char *k_about_collect =
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
    "in OpenGL row order (bottom row first, data.attrs['image_row_order']).\n";

/* --task of render and collect: hearth_sim_task values */
static const char *const k_task_names[] = {"H1", "H2", "H3", NULL};
static const int k_task_values[] = {HEARTH_SIM_H1, HEARTH_SIM_H2, HEARTH_SIM_H3};

int hearth_cmd_sim_render(int argc, char **argv) {
  const char *out = NULL, *release = NULL, *gl = NULL;
  int only = 0, size = 256, gt = 0, shadows = 0;
  uint64_t seed = 1;
  const cli_opt opts[] = {
      CLI_STR("--out", "DIR", &out, "output directory (created)", .flags = CLI_REQUIRED),
      CLI_CHOICE("--task", &only, k_task_names, k_task_values, "only this task",
                 .flags = CLI_NOCASE, .def = "all three"),
      CLI_STR("--release", "ROOT", &release,
              "assets from a release (derived/ meshes and thermal_turbo.png)",
              .def = "a small release made by the virtual rig"),
      CLI_FLAG("--ground-truth", &gt, 1,
               "with --release: a virtual-rig release's ground_truth/ meshes and "
               "temperature_true.npy instead of derived/"),
      CLI_INT("--size", "N", &size, 16, 4096, "image side in pixels"),
      CLI_U64("--seed", "N", &seed, "layout seed"),
      CLI_FLAG("--shadows", &shadows, 1, "shadow-mapped light in the RGB views (off by default)"),
      CLI_STR("--gl", "osmesa|egl", &gl,
              "GL back end: osmesa: CPU; egl: a GPU through EGL, else Mesa's surfaceless platform",
              .def = "$HEARTH_GL, else osmesa"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth sim render", .about = k_about_render, .opts = opts};
  int rc = cli_parse(&cmd, argc, argv, NULL);
  if (rc != CLI_RUN) return rc;
  hearth_err err = {0};
  if (hearth_mkdirs(out, &err)) return cli_fail("sim render", &err);
  char root[4096], tmpdir[4096];
  int use_gt;
  if (sim_cli_assets(release, gt, root, sizeof root, tmpdir, sizeof tmpdir, &use_gt, 0)) return 1;
  rc = 0;
  for (int t = 1; t <= 3 && !rc; t++) {
    if (only && t != only) continue;
    hearth_sim_opts o;
    hearth_sim_opts_default(&o);
    o.task = (hearth_sim_task)t;
    o.release_root = root;
    o.use_ground_truth = use_gt;
    o.width = o.height = size;
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
  const char *release = NULL;
  int task = 0, gt = 0;
  const cli_opt opts[] = {
      CLI_CHOICE("--task", &task, k_task_names, k_task_values, "the task",
                 .flags = CLI_REQUIRED | CLI_NOCASE),
      CLI_STR("--out", "FILE.hdf5", &o.out_path, "output file (written atomically)",
              .flags = CLI_REQUIRED),
      CLI_INT("--layouts", "N", &o.layouts, 1, 100000,
              "layouts (200 as in the paper: 400 demos per task)"),
      CLI_U64("--seed", "N", &o.seed, "layout seed"),
      CLI_INT("--size", "N", &o.image_size, 16, 1024, "stored image side (128 is LIBERO's)"),
      CLI_INT("--max-steps", "N", &o.max_steps, 1, 100000,
              "time limit per episode in control steps"),
      CLI_STR("--release", "ROOT", &release, "assets from a release (derived/)",
              .def = "virtual rig"),
      CLI_FLAG("--ground-truth", &gt, 1,
               "with --release: a virtual-rig release's ground_truth/ assets"),
      CLI_FLAG("--keep-failures", &o.keep_failures, 1, "also store episodes that did not succeed"),
      CLI_FLAG("--shadows", &o.shadows, 1, "shadow-mapped light in the RGB views (off by default)"),
      CLI_STR("--gl", "osmesa|egl", &o.gl, "GL back end", .def = "$HEARTH_GL, else osmesa"),
      CLI_FLAG("--quiet", &o.quiet, 1, "no progress output"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth sim collect", .about = k_about_collect, .opts = opts};
  int rc = cli_parse(&cmd, argc, argv, NULL);
  if (rc != CLI_RUN) return rc;
  o.task = (hearth_sim_task)task;
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
