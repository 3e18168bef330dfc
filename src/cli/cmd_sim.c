/* hearth sim render, collect, merge: scene pictures, demonstrations and
 * the merge of a sharded collection */
#include <stdio.h>
#include <string.h>
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
    "ones in slot B. Slot k of the file tries layout k; where the expert fails either\n"
    "instruction it tries layout k + 200000 j (j = 1..19, the same parity), so\n"
    "assignments stay balanced and a slot's layout depends on the slot alone.\n"
    "\n"
    "One file holds both instructions (demo_0, demo_1 from layout 1, ...). LIBERO's\n"
    "loaders read data.attrs['problem_info']['language_instruction'] as one string:\n"
    "it holds the first instruction; every demo has its own `language_instruction`\n"
    "attribute, and data.attrs['instructions'] lists both (JSON). With\n"
    "--split-instructions, OUT_instr1.hdf5 and OUT_instr2.hdf5 (OUT without .hdf5)\n"
    "each hold one instruction, named by their problem_info as LIBERO reads it.\n"
    "Images are stored in OpenGL row order (bottom row first,\n"
    "data.attrs['macros_image_convention'] 'opengl').\n"
    "\n"
    "Scale-out: --shard I/N collects the slots k with k % N == I (e.g. a Slurm array:\n"
    "--shard $SLURM_ARRAY_TASK_ID/N, the same --layouts and seed in every shard);\n"
    "`hearth sim merge OUT.hdf5 PARTS...` then writes the bytes one run writes\n"
    "(docs/cluster.md).\n";

static const char *k_about_merge =
    "Merge the files of the shards of one `hearth sim collect --shard I/N` run (all N,\n"
    "in any order) into OUT.hdf5, written atomically: the same bytes as the file of\n"
    "one unsharded run with the same options. For --split-instructions, merge the\n"
    "files of each instruction separately.\n";

/* --thermal of render and collect: hearth_sim_thermal values */
static const char *const k_thermal_names[] = {"static", "dynamic", NULL};
static const int k_thermal_values[] = {HEARTH_SIM_THERMAL_STATIC, HEARTH_SIM_THERMAL_DYNAMIC};
#define SIM_THERMAL_HELP                                                                   \
  "static: the assets' fixed temperature textures (the paper); dynamic: a lumped thermal " \
  "network per object, cooling and warming with air, table and finger contacts"

int hearth_cmd_sim_render(int argc, char **argv) {
  const char *out = NULL, *release = NULL, *gl = NULL, *renderer = NULL;
  int size = 256, gt = 0, shadows = 0, thermal = HEARTH_SIM_THERMAL_STATIC;
  unsigned only = 0;
  uint64_t seed = 1;
  const cli_opt opts[] = {
      CLI_STR("--out", "DIR", &out, "output directory (created)", .flags = CLI_REQUIRED),
      CLI_CALL("--task", "LIST", &only, sim_cli_parse_tasks, SIM_CLI_TASK_HELP,
               "the tasks rendered", .def = "all"),
      CLI_STR("--release", "ROOT", &release,
              "assets from a release (derived/ meshes and thermal_turbo.png)",
              .def = "a small release made by the virtual rig"),
      CLI_FLAG("--ground-truth", &gt, 1,
               "with --release: a virtual-rig release's ground_truth/ meshes and "
               "temperature_true.npy instead of derived/"),
      CLI_INT("--size", "N", &size, 16, 4096, "image side in pixels"),
      CLI_U64("--seed", "N", &seed, "layout seed"),
      CLI_FLAG("--shadows", &shadows, 1, "shadow-mapped light in the RGB views (off by default)"),
      CLI_CHOICE("--thermal", &thermal, k_thermal_names, k_thermal_values, SIM_THERMAL_HELP,
                 .def = "static"),
      CLI_STR("--renderer", "soft|gl", &renderer,
              "soft: hearth's deterministic software rasteriser; gl: MuJoCo's OpenGL renderer "
              "(needed for --shadows)",
              .def = "$HEARTH_RENDERER, else gl with --shadows and soft without"),
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
  for (int t = 1; t < HEARTH_SIM_TASK_END && !rc; t++) {
    if (!hearth_sim_task_valid((hearth_sim_task)t) || (only && !(only & (1u << t)))) continue;
    hearth_sim_opts o;
    hearth_sim_opts_default(&o);
    o.task = (hearth_sim_task)t;
    o.release_root = root;
    o.use_ground_truth = use_gt;
    o.width = o.height = size;
    o.shadows = shadows;
    o.gl = gl;
    o.renderer = renderer;
    o.thermal = thermal;
    char prefix[4200];
    snprintf(prefix, sizeof prefix, "%s/%s", out, hearth_sim_task_name(o.task));
    if (hearth_sim_render_scene(&o, seed, prefix, &err)) rc = cli_fail("sim render", &err);
    else printf("%s_{rgb,thermal,wrist}.png\n", prefix);
  }
  sim_cli_drop_assets(tmpdir);
  return rc;
}

static int collect_one(const hearth_sim_collect_opts *op);

int hearth_cmd_sim_collect(int argc, char **argv) {
  hearth_sim_collect_opts o;
  hearth_sim_collect_opts_default(&o);
  const char *release = NULL;
  unsigned tasks = 0;
  int gt = 0;
  const cli_opt opts[] = {
      CLI_CALL("--task", "LIST", &tasks, sim_cli_parse_tasks, SIM_CLI_TASK_HELP,
               "the task; with several, one file each: OUT with _H<n> before .hdf5",
               .flags = CLI_REQUIRED),
      CLI_STR("--out", "FILE.hdf5", &o.out_path, "output file (written atomically)",
              .flags = CLI_REQUIRED),
      CLI_INT("--layouts", "N", &o.layouts, 1, 100000,
              "layouts (200 as in the paper: 400 demos per task)"),
      CLI_U64("--seed", "N", &o.seed, "layout seed"),
      CLI_INT(
          "--size", "N", &o.image_size, 16, 1024,
          "rendered and stored image side (256: openpi's LIBERO data and what sim eval renders)"),
      CLI_INT("--max-steps", "N", &o.max_steps, 1, 100000,
              "time limit per episode in control steps"),
      CLI_STR("--release", "ROOT", &release, "assets from a release (derived/)",
              .def = "virtual rig"),
      CLI_FLAG("--ground-truth", &gt, 1,
               "with --release: a virtual-rig release's ground_truth/ assets"),
      CLI_FLAG("--keep-failures", &o.keep_failures, 1, "also store episodes that did not succeed"),
      CLI_FLAG("--shadows", &o.shadows, 1, "shadow-mapped light in the RGB views (off by default)"),
      CLI_CHOICE("--thermal", &o.thermal, k_thermal_names, k_thermal_values,
                 SIM_THERMAL_HELP "; dynamic stores obs/thermal_state", .def = "static"),
      CLI_NUM("--thermal-speedup", "X", &o.thermal_speedup, 0, 1e6,
              "with --thermal dynamic: thermal seconds per simulated second", .flags = CLI_LO_OPEN,
              .def = "1"),
      CLI_STR("--renderer", "soft|gl|none", &o.renderer,
              "soft: hearth's deterministic software rasteriser; gl: MuJoCo's OpenGL renderer "
              "(needed for --shadows); none: no images (times physics, control and the expert "
              "alone; the file has no obs image datasets)",
              .def = "$HEARTH_RENDERER, else gl with --shadows and soft without"),
      CLI_STR("--gl", "osmesa|egl", &o.gl, "GL back end of --renderer gl",
              .def = "$HEARTH_GL, else osmesa"),
      CLI_SHARD("--shard", "I/N", &o.shard_index, &o.shard_count,
                "collect only the slots k with k % N == I (merge the N files with sim merge)",
                .def = "0/1"),
      CLI_FLAG("--split-instructions", &o.split_instructions, 1,
               "one LIBERO file per instruction: OUT_instr1.hdf5, OUT_instr2.hdf5"),
      CLI_FLAG("--quiet", &o.quiet, 1, "no progress output"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth sim collect", .about = k_about_collect, .opts = opts};
  int rc = cli_parse(&cmd, argc, argv, NULL);
  if (rc != CLI_RUN) return rc;
  char root[4096], tmpdir[4096];
  if (sim_cli_assets(release, gt, root, sizeof root, tmpdir, sizeof tmpdir, &o.use_ground_truth,
                     o.quiet))
    return 1;
  o.release_root = root;
  int n_tasks = 0;
  for (int t = 1; t < HEARTH_SIM_TASK_END; t++) n_tasks += (tasks >> t) & 1;
  const char *out_given = o.out_path;
  rc = 0;
  for (int t = 1; t < HEARTH_SIM_TASK_END && !rc; t++) {
    if (!(tasks & (1u << t))) continue;
    o.task = (hearth_sim_task)t;
    /* several tasks: OUT_H<n>.hdf5 each */
    char per_task[4200];
    if (n_tasks > 1) {
      size_t n = strlen(out_given);
      if (n >= 5 && strcmp(out_given + n - 5, ".hdf5") == 0) n -= 5;
      snprintf(per_task, sizeof per_task, "%.*s_%s.hdf5", (int)n, out_given,
               hearth_sim_task_name(o.task));
      o.out_path = per_task;
    }
    rc = collect_one(&o);
  }
  sim_cli_drop_assets(tmpdir);
  return rc;
}

/* one task's collection and its summary lines */
static int collect_one(const hearth_sim_collect_opts *op) {
  hearth_sim_collect_opts o = *op;
  hearth_err err = {0};
  hearth_sim_collect_stats s;
  hearth_status st = hearth_sim_collect(&o, &s, &err);
  if (st) return cli_fail("sim collect", &err);
  for (int i = 0; i < 2; i++)
    printf("instruction %d \"%s\": %d/%d successful\n", i + 1,
           hearth_sim_instruction_text(o.task, i), s.successes[i], s.attempts[i]);
  char outs[8600];
  if (o.split_instructions) {
    char a[4200], b[4200];
    hearth_sim_split_path(o.out_path, 0, a, sizeof a);
    hearth_sim_split_path(o.out_path, 1, b, sizeof b);
    snprintf(outs, sizeof outs, "%s, %s", a, b);
  } else {
    snprintf(outs, sizeof outs, "%s", o.out_path);
  }
  if (o.shard_count > 1)
    printf("shard %d/%d: %d of %d slots\n", o.shard_index, o.shard_count, s.slots, o.layouts);
  printf("%d demos%s, %d layouts replaced, %ld steps, %.1f s (%.1f steps/s) -> %s\n", s.demos,
         o.split_instructions ? " per file" : "", s.rejected_layouts, s.steps, s.seconds,
         s.seconds > 0 ? s.steps / s.seconds : 0.0, outs);
  return 0;
}

int hearth_cmd_sim_merge(int argc, char **argv) {
  const cli_opt opts[] = {CLI_END};
  const cli_command cmd = {.name = "hearth sim merge",
                           .args = "OUT.hdf5 PART.hdf5...",
                           .min_args = 2,
                           .max_args = -1,
                           .about = k_about_merge,
                           .opts = opts,
                           .usage = "hearth sim merge OUT.hdf5 PART.hdf5... [options]"};
  cli_args a;
  int rc = cli_parse(&cmd, argc, argv, &a);
  if (rc != CLI_RUN) return rc;
  hearth_err err = {0};
  int n = 0;
  if (hearth_sim_merge(a.v[0], (const char *const *)(a.v + 1), a.n - 1, &n, &err))
    return cli_fail("sim merge", &err);
  printf("%d parts, %d demos -> %s\n", a.n - 1, n, a.v[0]);
  return 0;
}
