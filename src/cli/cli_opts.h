/* Private to the command-line tool: the one option parser of every command.
 *
 * A command declares its options once, as a table of cli_opt (long name,
 * optional short alias, kind of value with its range or choices, destination,
 * metavar, help text, default), and its positional arguments in a
 * cli_command. cli_parse() reads argv against that table and --help is
 * printed from the same table, so the two cannot disagree.
 *
 * Spelling: `--opt=value` and `--opt value` everywhere; a short alias also
 * takes `-j4`, `-j 4` and `-j=4`. A separate value is the next word, whatever
 * it looks like (so `--range -5,10` works). A flag given `=value` is an
 * error. Every word that starts with '-' is an option; the others are
 * positional arguments, in any order among the options.
 *
 * Errors name the option as the user spelled it and say what was expected:
 *   hearth map: option --resolution: expected an integer in 2..16384, found 'abc'
 * and make cli_parse return 2, the usage exit status. -h/--help anywhere
 * prints the help to stdout and makes it return 0. */
#ifndef HEARTH_CLI_OPTS_H
#define HEARTH_CLI_OPTS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

typedef enum cli_kind {
  CLI_KIND_END = 0, /* terminates a table */
  CLI_KIND_FLAG,    /* no value: stores .value into int *dst */
  CLI_KIND_INT,     /* integer in lo..hi into int *dst */
  CLI_KIND_SIZE,    /* integer in lo..hi into size_t *dst */
  CLI_KIND_U64,     /* non-negative integer into uint64_t *dst */
  CLI_KIND_NUM,     /* decimal number in lo..hi (see CLI_LO_OPEN) into double *dst */
  CLI_KIND_STR,     /* any string (a path, a name) into const char **dst */
  CLI_KIND_CHOICE,  /* one of .choices; its entry of .values (or its index) into int *dst */
  CLI_KIND_LIST,    /* comma-separated items into cli_list *dst, each passing .check */
  CLI_KIND_PAIR,    /* "A,B": two numbers in lo..hi into double *dst and double *dst2 */
  CLI_KIND_SHARD,   /* "I/N" with 0 <= I < N into int *dst (I) and int *dst2 (N) */
  CLI_KIND_CALL,    /* the value handed to .parse(dst, value, why, whysz) */
  CLI_KIND_GROUP    /* the options of table .group, listed under the heading .help */
} cli_kind;

/* .flags */
#define CLI_REQUIRED 1u   /* the option must be given */
#define CLI_LO_OPEN 2u    /* NUM, PAIR: lo itself is refused */
#define CLI_HI_OPEN 4u    /* NUM, PAIR: hi itself is refused */
#define CLI_NOCASE 8u     /* CHOICE: the names match in any case */
#define CLI_ASCENDING 16u /* PAIR: the first number must be below the second */

#define CLI_INF HUGE_VAL /* no bound: lo = -CLI_INF, hi = CLI_INF */

/* Storage of a CLI_KIND_LIST option: the items of the last occurrence;
 * n stays 0 until the option is given (an empty list is refused). */
#define CLI_LIST_MAX 64
typedef struct cli_list {
  size_t n;
  const char *items[CLI_LIST_MAX]; /* point into text */
  char text[1024];
} cli_list;

typedef struct cli_opt {
  const char *name;  /* "--resolution" */
  const char *alias; /* short alias ("-j") or NULL */
  cli_kind kind;
  void *dst;                      /* where the value goes (its type follows the kind) */
  void *dst2;                     /* PAIR, SHARD: the second number; GROUP: const char ** set to the
                          first of the group's options given (NULL if none was) */
  const char *metavar;            /* "R" in "--resolution R"; CHOICE: NULL lists the names */
  const char *help;               /* one sentence or two; wrapped by the help printer */
  const char *def;                /* the default as --help shows it; NULL: *dst's value for numbers,
                          choices and strings that are set, nothing otherwise */
  double lo, hi;                  /* INT, SIZE, NUM, PAIR: the accepted range */
  unsigned flags;                 /* CLI_REQUIRED, CLI_LO_OPEN, ... */
  int value;                      /* FLAG: the value stored */
  const char *const *choices;     /* CHOICE: the names, NULL-terminated */
  const int *values;              /* CHOICE: the value of each name; NULL: its index */
  size_t max;                     /* LIST: most items accepted */
  int (*check)(const char *item); /* LIST: non-zero when an item is acceptable, or NULL */
  const char *expect;             /* LIST: what an item must be; CALL: what the value must be */
  /* CALL: store value into dst; returns 0, or non-zero with the reason in why */
  int (*parse)(void *dst, const char *value, char *why, size_t whysz);
  const struct cli_opt *group; /* GROUP: the table included */
} cli_opt;

/* Table entries. The destination's type is checked at compile time; more
 * fields (.alias, .def, .flags, ...) may follow the help text. */
#define CLI_PTR_(T, p) ((void *)(1 ? (p) : (T *)0))
#define CLI_FLAG(nm, p, v, ...)                                                 \
  {                                                                             \
    .name = (nm), .kind = CLI_KIND_FLAG, .dst = CLI_PTR_(int, p), .value = (v), \
    .help = __VA_ARGS__                                                         \
  }
#define CLI_INT(nm, mv, p, l, h, ...)                                                        \
  {                                                                                          \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_INT, .dst = CLI_PTR_(int, p), .lo = (l), \
    .hi = (h), .help = __VA_ARGS__                                                           \
  }
#define CLI_SIZE(nm, mv, p, l, h, ...)                                                           \
  {                                                                                              \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_SIZE, .dst = CLI_PTR_(size_t, p), .lo = (l), \
    .hi = (h), .help = __VA_ARGS__                                                               \
  }
#define CLI_U64(nm, mv, p, ...)                                                        \
  {                                                                                    \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_U64, .dst = CLI_PTR_(uint64_t, p), \
    .help = __VA_ARGS__                                                                \
  }
#define CLI_NUM(nm, mv, p, l, h, ...)                                                           \
  {                                                                                             \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_NUM, .dst = CLI_PTR_(double, p), .lo = (l), \
    .hi = (h), .help = __VA_ARGS__                                                              \
  }
#define CLI_STR(nm, mv, p, ...)                                                            \
  {                                                                                        \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_STR, .dst = CLI_PTR_(const char *, p), \
    .help = __VA_ARGS__                                                                    \
  }
#define CLI_CHOICE(nm, p, names, vals, ...)                                             \
  {                                                                                     \
    .name = (nm), .kind = CLI_KIND_CHOICE, .dst = CLI_PTR_(int, p), .choices = (names), \
    .values = (vals), .help = __VA_ARGS__                                               \
  }
#define CLI_LIST(nm, mv, p, mx, chk, exp, ...)                                          \
  {                                                                                     \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_LIST, .dst = CLI_PTR_(cli_list, p), \
    .max = (mx), .check = (chk), .expect = (exp), .help = __VA_ARGS__                   \
  }
#define CLI_PAIR(nm, mv, p1, p2, l, h, ...)                                            \
  {                                                                                    \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_PAIR, .dst = CLI_PTR_(double, p1), \
    .dst2 = CLI_PTR_(double, p2), .lo = (l), .hi = (h), .help = __VA_ARGS__            \
  }
#define CLI_SHARD(nm, mv, pi, pn, ...)                                               \
  {                                                                                  \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_SHARD, .dst = CLI_PTR_(int, pi), \
    .dst2 = CLI_PTR_(int, pn), .help = __VA_ARGS__                                   \
  }
#define CLI_CALL(nm, mv, p, fn, exp, ...)                                            \
  {                                                                                  \
    .name = (nm), .metavar = (mv), .kind = CLI_KIND_CALL, .dst = (p), .parse = (fn), \
    .expect = (exp), .help = __VA_ARGS__                                             \
  }
#define CLI_GROUP(heading, tab, seen)                          \
  {                                                            \
    .kind = CLI_KIND_GROUP, .help = (heading), .group = (tab), \
    .dst2 = CLI_PTR_(const char *, seen)                       \
  }
#define CLI_END \
  { .kind = CLI_KIND_END }

typedef struct cli_command {
  const char *name;        /* as messages start: "hearth map", "hearth sim render" */
  const char *args;        /* metavar of the positional arguments ("ROOT", "FILE"), NULL: none */
  int min_args;            /* how many positional arguments must be given */
  int max_args;            /* how many may be; -1: any number */
  const char *about;       /* the description paragraphs of --help, each line ending in '\n' */
  const cli_opt *opts;     /* the table, ending with CLI_END */
  const char *tail;        /* printed after the options, or NULL */
  void (*more)(FILE *out); /* prints help that the library knows (lists), or NULL */
  const char *usage;       /* the usage line after "usage: "; NULL: made from the table */
  int stop_at_arg;         /* the options end at the first positional argument: it and all
                        after it are a subcommand's */
} cli_command;

/* What cli_parse returns when the command is to run. */
#define CLI_RUN (-1)

/* The positional arguments after parsing: v[0..n). */
typedef struct cli_args {
  int n;
  char **v;
} cli_args;

/* Parse argv[1..argc) (argv[0] is the command's name) against cmd. Returns
 * CLI_RUN with every option given stored, or the exit status: 0 after
 * printing the help to stdout, 2 after printing the problem to stderr.
 * argv is reordered: the positional arguments move to argv[1..], in their
 * order, and args (may be NULL for a command without any) points at them;
 * with cmd->stop_at_arg, args holds the first positional and everything
 * after it, untouched. The strings stored are argv's own. */
int cli_parse(const cli_command *cmd, int argc, char **argv, cli_args *args);
/* The same, with the help going to out and problems to err. */
int cli_parse_to(const cli_command *cmd, int argc, char **argv, cli_args *args, FILE *out,
                 FILE *err);

/* Print cmd's help: usage line, description, options (metavars, help,
 * defaults as they stand in the destinations), then tail and more(). */
void cli_help(const cli_command *cmd, FILE *out);

/* Print "<cmd name>: <message>\n" to stderr for a usage problem found
 * after parsing; returns 2. */
int cli_usage_error(const cli_command *cmd, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

#endif
