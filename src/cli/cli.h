/* Private to the command-line tool: each subcommand lives in cmd_<name>.c
 * and exports `int hearth_cmd_<name>(int argc, char **argv)` where argv[0]
 * is the subcommand's name. A command handles `--help` itself, prints errors
 * to stderr and returns the process exit status (0 ok, 1 failure, 2 usage). */
#ifndef HEARTH_CLI_H
#define HEARTH_CLI_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

/* Small option helpers shared by the commands. */
int cli_is_help(const char *arg);
/* Parse "--name=value" or "--name value"; returns 1 and sets *val if argv[*i]
 * is option `name` (advancing *i past a separate value), -1 if the value is
 * missing, 0 otherwise. */
int cli_opt(int argc, char **argv, int *i, const char *name, const char **val);
/* The option whose value cli_opt just returned in val, for messages: the
 * word before a separate value, or the part of "--name=value" before '='
 * (copied into buf). */
const char *cli_opt_name(char **argv, int i, const char *val, char *buf, size_t bufsz);
int cli_parse_int(const char *s, long lo, long hi, long *out);
int cli_parse_u64(const char *s, uint64_t *out);
int cli_parse_num(const char *s, double *out);
/* A non-option argument of a pipeline command: the first is ROOT, a second
 * is an error; an unknown option is an error too. Returns 0 when taken,
 * 2 (the usage exit status) after printing the problem. */
int cli_root_arg(const char *cmd, const char *arg, const char **root, const char *help);
/* Print "hearth <cmd>: missing ROOT" and the help; returns 2. */
int cli_missing_root(const char *cmd, const char *help);
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
