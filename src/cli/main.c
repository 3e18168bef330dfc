/* hearth - the command-line tool: a table of (name, function, summary).
 * A subcommand exists in a build when its cmd_<name>.c is compiled in; the
 * weak references below let areas add commands without touching this file. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli/cli.h"

typedef int (*cmd_fn)(int argc, char **argv);

#define HEARTH_CMD(name) extern int hearth_cmd_##name(int argc, char **argv) __attribute__((weak));
HEARTH_CMD(synth)
HEARTH_CMD(detect)
HEARTH_CMD(calibrate)
HEARTH_CMD(recon)
HEARTH_CMD(scale)
HEARTH_CMD(transfer)
HEARTH_CMD(refine)
HEARTH_CMD(map)
HEARTH_CMD(overlay)
HEARTH_CMD(build)
HEARTH_CMD(validate)
HEARTH_CMD(stats)
HEARTH_CMD(demo)
HEARTH_CMD(inspect)

/* `hearth sim ...` runs hearth-sim (next to this executable) with the
 * arguments after "sim" */
static int run_sim(int argc, char **argv) {
  char self[4096];
  ssize_t n = readlink("/proc/self/exe", self, sizeof self - 16);
  if (n <= 0) {
    fprintf(stderr, "hearth sim: cannot locate this executable: %s\n", strerror(errno));
    return 2;
  }
  self[n] = 0;
  char *slash = strrchr(self, '/');
  if (!slash) return 2;
  snprintf(slash + 1, sizeof self - (size_t)(slash + 1 - self), "hearth-sim");
  char **args = calloc((size_t)argc + 1, sizeof *args);
  if (!args) return 2;
  args[0] = self;
  for (int i = 1; i < argc; i++) args[i] = argv[i];
  execv(self, args);
  fprintf(stderr,
          "hearth sim: cannot run %s (%s): this build has no simulation (HEARTH_SIM=OFF)\n"
          "or hearth-sim was not installed next to hearth\n",
          self, strerror(errno));
  free(args);
  return 2;
}

typedef struct command {
  const char *name;
  cmd_fn fn;
  const char *summary;
} command;

static const command k_cmds[] = {
    {"synth", hearth_cmd_synth,
     "make a release with the virtual capture rig (ground truth included)"},
    {"inspect", hearth_cmd_inspect, "read and summarise one file (CSV, PNG, JPEG, NPY, GLB, JSON)"},
    {"detect", hearth_cmd_detect, "find plate hole centres in the calibration captures"},
    {"calibrate", hearth_cmd_calibrate,
     "thermal intrinsics and RGB-thermal stereo from detections"},
    {"recon", hearth_cmd_recon,
     "camera poses from COLMAP: run it on an instance, or import a model"},
    {"scale", hearth_cmd_scale, "recover metric scale from recorded depth"},
    {"transfer", hearth_cmd_transfer, "thermal poses from colour poses through the rig transform"},
    {"refine", hearth_cmd_refine, "refine thermal poses automatically"},
    {"map", hearth_cmd_map, "map temperatures onto the mesh's UV layout"},
    {"overlay", hearth_cmd_overlay, "draw projected mesh outlines on thermal views"},
    {"build", hearth_cmd_build, "run the whole pipeline over a release"},
    {"validate", hearth_cmd_validate, "check a release against the layout contract"},
    {"stats", hearth_cmd_stats, "dataset overview table of a release"},
    {"demo", hearth_cmd_demo, "make, build and report a small virtual release"},
    {"sim", run_sim, "temperature-aware manipulation tasks (render, collect, eval, export)"},
};
#define N_CMDS (sizeof k_cmds / sizeof k_cmds[0])

/* the commands of this build and the environment, after the options */
static void list_commands(FILE *out) {
  fprintf(out, "\ncommands:\n");
  for (size_t i = 0; i < N_CMDS; i++)
    if (k_cmds[i].fn) fprintf(out, "  %-10s %s\n", k_cmds[i].name, k_cmds[i].summary);
  fprintf(out,
          "\nEnvironment: HEARTH_THREADS sets the default worker count.\n"
          "Conventions and file layout: docs/conventions.md, docs/dataset.md.\n");
}

int main(int argc, char **argv) {
  int version = 0;
  const cli_opt opts[] = {
      CLI_FLAG("--version", &version, 1, "print the version"),
      CLI_END,
  };
  const cli_command cmd = {
      .name = "hearth",
      .args = "COMMAND",
      .min_args = 0,
      .max_args = -1,
      .about = "hearth " HEARTH_VERSION
               " - temperature-textured 3D assets from RGB-thermal-depth captures\n\n"
               "Pipeline commands take the release root as their first argument.\n",
      .opts = opts,
      .more = list_commands,
      .usage = "hearth <command> [ROOT] [options]     hearth <command> --help",
      .stop_at_arg = 1,
  };
  if (argc < 2) {
    cli_help(&cmd, stderr);
    return 2;
  }
  if (!strcmp(argv[1], "help")) {
    cli_help(&cmd, stdout);
    return 0;
  }
  cli_args sub;
  int rc = cli_parse(&cmd, argc, argv, &sub);
  if (rc != CLI_RUN) return rc;
  if (version) {
    printf("hearth %s\n", HEARTH_VERSION);
    return 0;
  }
  if (!sub.n) {
    cli_help(&cmd, stderr);
    return 2;
  }
  for (size_t i = 0; i < N_CMDS; i++) {
    if (!strcmp(sub.v[0], k_cmds[i].name)) {
      if (!k_cmds[i].fn) {
        fprintf(stderr, "hearth: '%s' is not part of this build\n", sub.v[0]);
        return 2;
      }
      return k_cmds[i].fn(sub.n, sub.v);
    }
  }
  fprintf(stderr, "hearth: unknown command '%s' (see 'hearth --help')\n", sub.v[0]);
  return 2;
}
