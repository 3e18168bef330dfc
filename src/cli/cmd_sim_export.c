/* hearth sim export: collections as a LeRobot dataset for openpi training */
#include <stdio.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"
#include "hearth/export.h"

static const char *k_about =
    "Write the demos of FILE.hdf5... (from `hearth sim collect`, any tasks, exported in\n"
    "the order given) as a LeRobot dataset, codebase version v2.1, in DIR: the files\n"
    "LeRobot's own writer makes (meta/info.json, tasks.jsonl, episodes.jsonl,\n"
    "episodes_stats.jsonl; data/chunk-000/episode_000000.parquet, one per demo) and\n"
    "openpi's norm_stats.json. Features as openpi's LIBERO example (image, wrist_image:\n"
    "PNG; state float32 (8,); actions float32 (7,)) plus thermal_image. Images are\n"
    "rotated 180 degrees from the files' OpenGL order, as `hearth sim eval` sends them;\n"
    "the state's orientation is a continuous axis-angle (no flips near half a turn).\n"
    "The episode-to-layout mapping is in episodes.jsonl (\"hearth\": source file, demo,\n"
    "task, seed, layout, instruction_index). DIR must not exist or be empty; it is\n"
    "written whole or not at all. Every file must have the same image size and rate.\n";

int hearth_cmd_sim_export(int argc, char **argv) {
  hearth_lerobot_opts o;
  hearth_lerobot_opts_default(&o);
  int no_thermal = 0;
  const cli_opt opts[] = {
      CLI_STR("--lerobot", "DIR", &o.out_dir, "the dataset's root directory (created)",
              .flags = CLI_REQUIRED),
      CLI_STR("--robot-type", "NAME", &o.robot_type, "info.json's robot_type"),
      CLI_FLAG("--no-thermal", &no_thermal, 1,
               "leave the thermal_image and thermal_state features out"),
      CLI_INT("--threads", "N", &o.threads, 0, 1024, "PNG encoding threads (0: all cores)"),
      CLI_FLAG("--quiet", &o.quiet, 1, "no progress output"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth sim export",
                           .args = "FILE.hdf5...",
                           .min_args = 1,
                           .max_args = HEARTH_LEROBOT_MAX_INPUTS,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  o.thermal = !no_thermal;
  o.inputs = (const char *const *)args.v;
  o.n_inputs = (size_t)args.n;
  hearth_lerobot_stats s;
  hearth_err err = {0};
  if (hearth_lerobot_export(&o, &s, &err)) return cli_fail("sim export", &err);
  printf("%zu episodes, %zu frames, %zu tasks, %.1f s -> %s\n", s.episodes, s.frames, s.tasks,
         s.seconds, o.out_dir);
  return 0;
}
