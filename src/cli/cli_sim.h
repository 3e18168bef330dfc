/* shared by the hearth-sim commands (cmd_sim.c, cmd_sim_eval.c, cmd_sim_export.c, sim_main.c) */
#ifndef HEARTH_CLI_SIM_H
#define HEARTH_CLI_SIM_H
#include <stddef.h>

/* Asset release for the tasks: `release` as given (ground-truth assets if
 * gt), or, when NULL, the default virtual-rig assets made under a fresh
 * temporary directory (returned in tmpdir, "" otherwise; the assets are
 * ground truth). Prints the error and returns non-zero on failure, leaving
 * no temporary directory behind. */
int sim_cli_assets(const char *release, int gt, char *root, size_t rootsz, char *tmpdir, size_t tsz,
                   int *use_gt, int quiet);
/* Removes what sim_cli_assets made (nothing for a given release). */
void sim_cli_drop_assets(const char *tmpdir);

/* --task of the hearth-sim commands: "H1", "H1,H5" or "all" (any case)
 * into *(unsigned *)dst as bits 1 << task; the CLI_CALL parser */
#define SIM_CLI_ALL_TASKS ((1u << 1) | (1u << 2) | (1u << 3) | (1u << 4) | (1u << 5) | (1u << 6))
#define SIM_CLI_TASK_HELP "H1, H2, H3, H4, H5, H6, a list such as H1,H5, or all"

int sim_cli_parse_tasks(void *dst, const char *value, char *why, size_t whysz);

/* the subcommands (argv[0] is the subcommand's name) */
int hearth_cmd_sim_render(int argc, char **argv);
int hearth_cmd_sim_collect(int argc, char **argv);
int hearth_cmd_sim_merge(int argc, char **argv);
int hearth_cmd_sim_eval(int argc, char **argv);
int hearth_cmd_sim_export(int argc, char **argv);

#endif
