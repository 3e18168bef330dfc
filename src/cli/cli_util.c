/* Option parsing helpers for the subcommands. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"

int cli_is_help(const char *arg) { return !strcmp(arg, "--help") || !strcmp(arg, "-h"); }

int cli_opt(int argc, char **argv, int *i, const char *name, const char **val) {
  const char *a = argv[*i];
  size_t n = strlen(name);
  if (strncmp(a, name, n) != 0) return 0;
  if (a[n] == '=') {
    *val = a + n + 1;
    return 1;
  }
  if (a[n] != 0) return 0;
  if (*i + 1 >= argc) return -1;
  *val = argv[++*i];
  return 1;
}

const char *cli_opt_name(char **argv, int i, const char *val, char *buf, size_t bufsz) {
  if (val == argv[i] && i > 0) return argv[i - 1];
  const char *eq = strchr(argv[i], '=');
  size_t n = eq ? (size_t)(eq - argv[i]) : strlen(argv[i]);
  if (n >= bufsz) n = bufsz - 1;
  memcpy(buf, argv[i], n);
  buf[n] = 0;
  return buf;
}

int cli_parse_int(const char *s, long lo, long hi, long *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

int cli_parse_u64(const char *s, uint64_t *out) {
  char *end;
  errno = 0;
  if (*s == '-') return 0;
  unsigned long long v = strtoull(s, &end, 10);
  if (errno || end == s || *end) return 0;
  *out = (uint64_t)v;
  return 1;
}

int cli_parse_num(const char *s, double *out) {
  return hearth_parse_double(s, strlen(s), 0, out) == 0;
}

int cli_fail(const char *cmd, const hearth_err *err) {
  fprintf(stderr, "hearth %s: %s (%s)\n", cmd, err->msg[0] ? err->msg : hearth_strerror(err->status),
          hearth_status_name(err->status));
  return 1;
}

int cli_root_arg(const char *cmd, const char *arg, const char **root, const char *help) {
  if (arg[0] == '-') {
    fprintf(stderr, "hearth %s: unknown option '%s'\n%s", cmd, arg, help);
    return 2;
  }
  if (*root) {
    fprintf(stderr, "hearth %s: unexpected argument '%s'\n", cmd, arg);
    return 2;
  }
  *root = arg;
  return 0;
}

int cli_missing_root(const char *cmd, const char *help) {
  fprintf(stderr, "hearth %s: missing ROOT\n%s", cmd, help);
  return 2;
}
