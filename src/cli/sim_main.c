/* hearth-sim: the simulation commands (`hearth sim ...`) in their own
 * executable, so that MuJoCo, Mesa and HDF5 (about 50 shared libraries)
 * are loaded only by the commands that use them; `hearth sim` runs this
 * program with the same arguments. */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"

static const char *k_usage =
    "usage: hearth sim <subcommand> [options]\n"
    "\n"
    "The paper's LIBERO-derived tasks on MuJoCo with hearth assets:\n"
    "  H1 study table: hot / normal cup (distractors: hot kettle, eraser)\n"
    "  H2 kitchen table: iced / normal can (distractors: iced orange, cup)\n"
    "  H3 kitchen table: hot phone / hot sponge (distractors: orange, hot cup)\n"
    "\n"
    "subcommands:\n"
    "  render    write PNGs of each task's scene: front RGB, front thermal, wrist RGB\n"
    "  collect   collect scripted-expert demonstrations into a LIBERO HDF5 file\n"
    "\n"
    "Run `hearth sim <subcommand> --help` for its options.\n";


static int cmd_sim(int argc, char **argv) {
  if (argc < 2 || cli_is_help(argv[1])) {
    fputs(k_usage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (strcmp(argv[1], "render") == 0) return hearth_cmd_sim_render(argc - 1, argv + 1);
  if (strcmp(argv[1], "collect") == 0) return hearth_cmd_sim_collect(argc - 1, argv + 1);
  if (strcmp(argv[1], "eval") == 0) return hearth_cmd_sim_eval(argc - 1, argv + 1);
  fprintf(stderr, "hearth sim: unknown subcommand '%s'\n%s", argv[1], k_usage);
  return 2;
}

int main(int argc, char **argv) { return cmd_sim(argc, argv); }
