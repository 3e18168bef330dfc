/* hearth-sim: the simulation commands (`hearth sim ...`) in their own
 * executable, so that MuJoCo, Mesa and HDF5 (about 50 shared libraries)
 * are loaded only by the commands that use them; `hearth sim` runs this
 * program with the same arguments. */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"

static const char k_about[] =
    "The paper's LIBERO-derived tasks on MuJoCo with hearth assets:\n"
    "  H1 study table: hot / normal cup (distractors: hot kettle, eraser)\n"
    "  H2 kitchen table: iced / normal can (distractors: iced orange, cup)\n"
    "  H3 kitchen table: hot phone / hot sponge (distractors: orange, hot cup)\n"
    "\n"
    "subcommands:\n"
    "  render    write PNGs of each task's scene: front RGB, front thermal, wrist RGB\n"
    "  collect   collect scripted-expert demonstrations into a LIBERO HDF5 file\n"
    "  merge     merge the files of a sharded collection into the file of one run\n"
    "  eval      score a policy on the tasks the way the paper does\n"
    "  export    write collections as a LeRobot dataset (v2.1) for openpi training\n";

static const char k_tail[] = "Run `hearth sim <subcommand> --help` for its options.\n";

static const cli_opt k_opts[] = {CLI_END};

static const cli_command k_cmd = {.name = "hearth sim",
                                  .args = "SUBCOMMAND",
                                  .min_args = 1,
                                  .max_args = -1,
                                  .about = k_about,
                                  .opts = k_opts,
                                  .tail = k_tail,
                                  .usage = "hearth sim <subcommand> [options]",
                                  .stop_at_arg = 1};

int main(int argc, char **argv) {
  if (argc < 2) {
    cli_help(&k_cmd, stderr);
    return 2;
  }
  cli_args sub;
  int rc = cli_parse(&k_cmd, argc, argv, &sub);
  if (rc != CLI_RUN) return rc;
  if (strcmp(sub.v[0], "render") == 0) return hearth_cmd_sim_render(sub.n, sub.v);
  if (strcmp(sub.v[0], "collect") == 0) return hearth_cmd_sim_collect(sub.n, sub.v);
  if (strcmp(sub.v[0], "merge") == 0) return hearth_cmd_sim_merge(sub.n, sub.v);
  if (strcmp(sub.v[0], "eval") == 0) return hearth_cmd_sim_eval(sub.n, sub.v);
  if (strcmp(sub.v[0], "export") == 0) return hearth_cmd_sim_export(sub.n, sub.v);
  return cli_usage_error(&k_cmd, "unknown subcommand '%s' (see 'hearth sim --help')", sub.v[0]);
}
