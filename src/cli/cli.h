/* Private to the command-line tool: each subcommand lives in cmd_<name>.c
 * and exports `int hearth_cmd_<name>(int argc, char **argv)` where argv[0]
 * is the subcommand's name. A command declares its options in a cli_opt
 * table and reads argv with cli_parse (cli_opts.h), prints errors to stderr
 * and returns the process exit status (0 ok, 1 failure, 2 usage). */
#ifndef HEARTH_CLI_H
#define HEARTH_CLI_H

#include <stddef.h>
#include <stdint.h>
#include "cli/cli_opts.h"
#include "hearth/calib.h"
#include "hearth/core.h"

/* --fusion of map and build: the names and their hearth_fusion values. */
extern const char *const cli_fusion_names[];
extern const int cli_fusion_values[];

/* detect's options bound to `run`: the one definition that `hearth detect`
 * and `hearth calibrate --detect` both include (as a CLI_GROUP). Fills
 * out[0..CLI_DETECT_OPTS), the last entry being CLI_END. */
#define CLI_DETECT_OPTS 5
void cli_detect_opts(hearth_detect_job *run, cli_opt out[CLI_DETECT_OPTS]);

/* Print "hearth <cmd>: <message>" for a failed status; returns 1. */
int cli_fail(const char *cmd, const hearth_err *err);

/* Instances of a release (release.json) or just `only`; states of an
 * instance (instance.json) or just `only`. */
#define CLI_MAX_NAMES 4096
typedef struct cli_names {
  size_t n;
  char names[CLI_MAX_NAMES][64];
} cli_names;
hearth_status cli_instances(const char *root, const char *only, cli_names *out, hearth_err *err);
hearth_status cli_states(const char *root, const char *instance, const char *only, cli_names *out,
                         hearth_err *err);

/* Call fn for every instance (or just `only`) / every state of every
 * instance (or just the named ones). A failure is printed as
 * "hearth <cmd>: ..." and the loop goes on; returns 0 if every call
 * succeeded, else 1 (the exit status). */
typedef hearth_status (*cli_instance_fn)(void *ctx, const char *instance, hearth_err *err);
typedef hearth_status (*cli_state_fn)(void *ctx, const char *instance, const char *state,
                                      hearth_err *err);
int cli_each_instance(const char *cmd, const char *root, const char *only, cli_instance_fn fn,
                      void *ctx);
int cli_each_state(const char *cmd, const char *root, const char *only_instance,
                   const char *only_state, cli_state_fn fn, void *ctx);

#endif
