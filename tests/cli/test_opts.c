/* The option parser of the command-line tool (src/cli/cli_opts.c) on a
 * table with every kind of value: both spellings, ranges, choices, lists,
 * pairs, shards, custom values, groups, required options, positional
 * arguments, the messages of every usage error and the generated help. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli_opts.h"
#include "test_util.h"

typedef struct fixture {
  int quiet, bake, level, jobs, mode, shard_i, shard_n, calls, threads;
  size_t res;
  uint64_t seed;
  double ratio, lo, hi;
  const char *name, *out, *group_seen;
  cli_list items;
  char last_call[64];
} fixture;

static const char *const k_modes[] = {"max", "robust", NULL};
static const int k_mode_values[] = {10, 20};

static int item_ok(const char *s) { return strcmp(s, "bad") != 0; }

/* CALL: accepts words of letters only, remembers the last */
static int letters(void *dst, const char *value, char *why, size_t whysz) {
  fixture *f = dst;
  for (const char *p = value; *p; p++)
    if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z'))) {
      snprintf(why, whysz, "'%s' has a character that is no letter", value);
      return 1;
    }
  snprintf(f->last_call, sizeof f->last_call, "%s", value);
  f->calls++;
  return 0;
}

static void fixture_default(fixture *f) {
  memset(f, 0, sizeof *f);
  f->bake = 1;
  f->level = 3;
  f->res = 1024;
  f->seed = 1;
  f->ratio = 0.5;
  f->mode = 10;
}

/* one table of every kind, bound to f; the group's table goes to grp */
static void make_table(fixture *f, cli_opt grp[3], cli_opt tab[20]) {
  const cli_opt g[3] = {
      CLI_INT("--threads", "N", &f->threads, 1, 64, "worker threads", .def = "all cores"),
      CLI_FLAG("--no-bake", &f->bake, 0, "no baking"),
      CLI_END,
  };
  const cli_opt t[20] = {
      CLI_FLAG("--quiet", &f->quiet, 1, "say less"),
      CLI_INT("--level", "L", &f->level, 1, 9, "how much"),
      CLI_INT("--jobs", "N", &f->jobs, 1, 4096, "parallel jobs", .alias = "-j",
              .def = "one per core"),
      CLI_SIZE("--resolution", "R", &f->res, 16, 8192, "map size"),
      CLI_U64("--seed", "S", &f->seed, "random seed"),
      CLI_NUM("--ratio", "X", &f->ratio, 0, 1, "a fraction", .flags = CLI_LO_OPEN),
      CLI_STR("--name", "ID", &f->name, "a name"),
      CLI_STR("--out", "DIR", &f->out, "where to write", .flags = CLI_REQUIRED),
      CLI_CHOICE("--mode", &f->mode, k_modes, k_mode_values, "fusion", .flags = CLI_NOCASE),
      CLI_LIST("--items", "a,b", &f->items, 3, item_ok, "an item other than 'bad'",
               "up to three items", .def = "none"),
      CLI_PAIR("--range", "LO,HI", &f->lo, &f->hi, -CLI_INF, CLI_INF, "a range",
               .flags = CLI_ASCENDING),
      CLI_SHARD("--shard", "I/N", &f->shard_i, &f->shard_n, "one shard"),
      CLI_CALL("--word", "W", f, letters, "letters", "a word; may be repeated"),
      CLI_GROUP("grouped options", grp, &f->group_seen),
      CLI_END,
  };
  memcpy(grp, g, sizeof g);
  memcpy(tab, t, sizeof t);
}

static char g_out[16384], g_err[4096];

/* Parse the words of `line` (split at spaces) after the command's name;
 * the help lands in g_out, problems in g_err. */
static int parse_with(const cli_command *cmd, const char *line, cli_args *args) {
  static char buf[1024];
  static char *argv[64];
  snprintf(buf, sizeof buf, "%s", line);
  int argc = 0;
  argv[argc++] = "test";
  for (char *tok = strtok(buf, " "); tok && argc < 63; tok = strtok(NULL, " ")) argv[argc++] = tok;
  argv[argc] = NULL;
  char *o = NULL, *e = NULL;
  size_t on = 0, en = 0;
  FILE *out = open_memstream(&o, &on), *err = open_memstream(&e, &en);
  int rc = cli_parse_to(cmd, argc, argv, args, out, err);
  fclose(out);
  fclose(err);
  snprintf(g_out, sizeof g_out, "%s", o ? o : "");
  snprintf(g_err, sizeof g_err, "%s", e ? e : "");
  free(o);
  free(e);
  return rc;
}

static fixture g_f;
static cli_opt g_grp[3], g_tab[20];
static const cli_command g_cmd = {.name = "hearth test",
                                  .args = "ROOT",
                                  .min_args = 1,
                                  .max_args = 1,
                                  .about = "Tests the parser.\n",
                                  .opts = g_tab,
                                  .tail = "The end.\n"};

/* parse with fresh defaults */
static int parse(const char *line, cli_args *args) {
  fixture_default(&g_f);
  make_table(&g_f, g_grp, g_tab);
  return parse_with(&g_cmd, line, args);
}

/* a usage error: status 2, nothing run, and the message holds `want` */
static void check_error(const char *line, const char *want) {
  cli_args a;
  int rc = parse(line, &a);
  CHECK_MSG(rc == 2, "'%s': status %d", line, rc);
  CHECK_MSG(strstr(g_err, want) != NULL, "'%s': message '%s' lacks '%s'", line, g_err, want);
  CHECK_MSG(!strncmp(g_err, "hearth test: ", 13), "'%s': message '%s'", line, g_err);
}

static void test_spellings(void) {
  cli_args a;
  const char *joined[] = {"r --out o --level=7", "r --out o --level 7", "--level 7 --out=o r"};
  for (int k = 0; k < 3; k++) {
    CHECK_MSG(parse(joined[k], &a) == CLI_RUN, "%s: %s", joined[k], g_err);
    CHECK(g_f.level == 7);
    CHECK(!strcmp(g_f.out, "o"));
  }
  const char *jobs[] = {"r --out o -j4", "r --out o -j 4", "r --out o -j=4", "r --out o --jobs=4",
                        "r --out o --jobs 4"};
  for (int k = 0; k < 5; k++) {
    CHECK_MSG(parse(jobs[k], &a) == CLI_RUN, "%s: %s", jobs[k], g_err);
    CHECK_MSG(g_f.jobs == 4, "%s: jobs %d", jobs[k], g_f.jobs);
  }
  /* every kind, each spelling */
  for (int eq = 0; eq < 2; eq++) {
    char line[512];
    const char *s = eq ? "=" : " ";
    snprintf(line, sizeof line,
             "r --out%so --quiet --resolution%s64 --seed%s18446744073709551615 --ratio%s1 "
             "--name%sx --mode%sROBUST --items%sa,,b --range%s-5,10 --shard%s2/3 --word%sab "
             "--word%scd --threads%s8 --no-bake",
             s, s, s, s, s, s, s, s, s, s, s, s);
    CHECK_MSG(parse(line, &a) == CLI_RUN, "%s: %s", line, g_err);
    CHECK(g_f.quiet == 1 && g_f.bake == 0 && g_f.res == 64);
    CHECK(g_f.seed == UINT64_MAX);
    CHECK(g_f.ratio == 1.0);
    CHECK(g_f.name && !strcmp(g_f.name, "x"));
    CHECK(g_f.mode == 20);
    CHECK(g_f.items.n == 2 && !strcmp(g_f.items.items[0], "a") && !strcmp(g_f.items.items[1], "b"));
    CHECK(g_f.lo == -5 && g_f.hi == 10);
    CHECK(g_f.shard_i == 2 && g_f.shard_n == 3);
    CHECK(g_f.calls == 2 && !strcmp(g_f.last_call, "cd"));
    CHECK(g_f.threads == 8);
    CHECK(g_f.group_seen && !strcmp(g_f.group_seen, "--threads"));
  }
  /* a separate value is the next word, whatever it looks like */
  CHECK(parse("r --out o --name --quiet", &a) == CLI_RUN);
  CHECK(g_f.name && !strcmp(g_f.name, "--quiet") && g_f.quiet == 0);
  /* an option of no group given: the group's first-seen stays NULL */
  CHECK(parse("r --out o", &a) == CLI_RUN && g_f.group_seen == NULL);
  /* defaults stay where nothing was given */
  CHECK(g_f.level == 3 && g_f.res == 1024 && g_f.seed == 1 && g_f.mode == 10 && g_f.items.n == 0);
}

static void test_errors(void) {
  /* ranges and kinds, named as spelled, with what was expected */
  check_error("r --out o --level=0", "option --level: expected an integer in 1..9, found '0'");
  check_error("r --out o --level abc", "option --level: expected an integer in 1..9, found 'abc'");
  check_error("r --out o -j abc", "option -j: expected an integer in 1..4096, found 'abc'");
  check_error("r --out o -jabc", "option -j: expected an integer in 1..4096, found 'abc'");
  check_error("r --out o --jobs=0", "option --jobs: expected an integer in 1..4096, found '0'");
  check_error("r --out o --resolution 8", "option --resolution: expected an integer in 16..8192");
  check_error("r --out o --seed=-1", "option --seed: expected a non-negative integer, found '-1'");
  check_error("r --out o --ratio 0", "option --ratio: expected a number > 0 and <= 1, found '0'");
  check_error("r --out o --ratio=0,5", "found '0,5'");
  check_error("r --out o --ratio nan", "found 'nan'");
  check_error("r --out o --mode=mean", "option --mode: expected max or robust, found 'mean'");
  check_error("r --out o --items a,bad",
              "option --items: expected an item other than 'bad', found 'bad'");
  check_error("r --out o --items a,b,c,d",
              "option --items: expected a comma-separated list of at most 3 items");
  check_error("r --out o --items ,", "option --items: expected a comma-separated list");
  check_error(
      "r --out o --range 2,1",
      "option --range: expected two comma-separated numbers, the first below the second, found '2,1'");
  check_error("r --out o --range=1", "found '1'");
  check_error("r --out o --shard 3/3", "option --shard: expected I/N with 0 <= I < N, found '3/3'");
  check_error("r --out o --shard x/2", "found 'x/2'");
  check_error("r --out o --word a1", "option --word: 'a1' has a character that is no letter");
  check_error("r --out o --threads=0", "option --threads: expected an integer in 1..64");
  /* a flag given a value */
  check_error("r --out o --quiet=yes", "option --quiet takes no value, found 'yes'");
  check_error("r --out o --help=yes", "option --help takes no value");
  /* unknown, missing value, required, positional arguments */
  check_error("r --out o --bogus", "unknown option '--bogus'");
  check_error("r --out o --bogus=3", "unknown option '--bogus'");
  check_error("r --out o -x", "unknown option '-x'");
  check_error("r --out o --level", "option --level: missing value (expected an integer in 1..9)");
  check_error("r --out", "option --out: missing value");
  check_error("r", "option --out is required");
  check_error("--out o", "missing ROOT");
  check_error("r s --out o", "unexpected argument 's'");
}

static void test_positional(void) {
  cli_args a;
  /* positional arguments may sit among the options; they keep their order */
  const cli_command many = {.name = "hearth test",
                            .args = "FILE",
                            .min_args = 1,
                            .max_args = -1,
                            .opts = g_tab};
  fixture_default(&g_f);
  make_table(&g_f, g_grp, g_tab);
  CHECK(parse_with(&many, "a --out o b --quiet c", &a) == CLI_RUN);
  CHECK(a.n == 3 && !strcmp(a.v[0], "a") && !strcmp(a.v[1], "b") && !strcmp(a.v[2], "c"));
  CHECK(g_f.quiet == 1);
  CHECK(parse_with(&many, "--out o", &a) == 2 && strstr(g_err, "missing FILE"));
  /* an optional one */
  const cli_command opt = {.name = "hearth test",
                           .args = "DIR",
                           .min_args = 0,
                           .max_args = 1,
                           .opts = g_tab};
  CHECK(parse_with(&opt, "--out o", &a) == CLI_RUN && a.n == 0);
  CHECK(parse_with(&opt, "--out o d", &a) == CLI_RUN && a.n == 1 && !strcmp(a.v[0], "d"));
  /* none at all */
  const cli_command none = {.name = "hearth test", .opts = g_tab};
  CHECK(parse_with(&none, "--out o d", &a) == 2 && strstr(g_err, "unexpected argument 'd'"));
  /* a subcommand: the options end at the first positional argument */
  const cli_command sub = {.name = "hearth test",
                           .args = "COMMAND",
                           .min_args = 1,
                           .max_args = -1,
                           .opts = g_tab,
                           .stop_at_arg = 1};
  CHECK(parse_with(&sub, "--out o --quiet run --bogus --help", &a) == CLI_RUN);
  CHECK(a.n == 3 && !strcmp(a.v[0], "run") && !strcmp(a.v[1], "--bogus") &&
        !strcmp(a.v[2], "--help"));
  CHECK(g_f.quiet == 1);
}

static void test_help(void) {
  cli_args a;
  /* -h and --help anywhere, over any error, with the defaults before parsing */
  const char *lines[] = {"--help", "-h", "r --level 7 --help", "--bogus -h", "r s t --help"};
  for (int k = 0; k < 5; k++) {
    CHECK_MSG(parse(lines[k], &a) == 0, "%s: %s", lines[k], g_err);
    CHECK(g_err[0] == 0);
    CHECK_MSG(strstr(g_out, "(default: 3)") != NULL, "%s: %s", lines[k], g_out);
  }
  /* as a value, --help is a value */
  CHECK(parse("r --out o --name --help", &a) == CLI_RUN && !strcmp(g_f.name, "--help"));

  CHECK(parse("--help", &a) == 0);
  CHECK_MSG(!strncmp(g_out, "usage: hearth test ROOT --out DIR [options]\n\nTests the parser.\n",
                     62),
            "%s", g_out);
  /* every option with its metavar, help and default */
  const char *want[] = {"--quiet",
                        "say less",
                        "--level L",
                        "how much (default: 3)",
                        "-j, --jobs N",
                        "(default: one per core)",
                        "--resolution R",
                        "(default: 1024)",
                        "--seed S",
                        "(default: 1)",
                        "--ratio X",
                        "(default: 0.5)",
                        "--name ID",
                        "--out DIR",
                        "(required)",
                        "--mode max|robust",
                        "(default: max)",
                        "--items a,b",
                        "(default: none)",
                        "--range LO,HI",
                        "--shard I/N",
                        "--word W",
                        "grouped options:",
                        "--threads N",
                        "(default: all cores)",
                        "--no-bake",
                        "-h, --help",
                        "this text",
                        "The end.\n"};
  for (size_t k = 0; k < sizeof want / sizeof want[0]; k++)
    CHECK_MSG(strstr(g_out, want[k]) != NULL, "help lacks '%s':\n%s", want[k], g_out);
  /* no line is wider than 80 columns unless one word is */
  for (const char *p = g_out; *p;) {
    size_t n = strcspn(p, "\n");
    CHECK_MSG(n <= 80, "help line of %zu columns: %.*s", n, (int)n, p);
    p += n + (p[n] == '\n');
  }
  /* a long help text wraps and continues under the help column */
  fixture_default(&g_f);
  const cli_opt wide[] = {
      CLI_FLAG("--x", &g_f.quiet, 1,
               "one two three four five six seven eight nine ten eleven twelve thirteen "
               "fourteen fifteen sixteen seventeen eighteen"),
      CLI_END,
  };
  const cli_command w = {.name = "hearth test", .opts = wide};
  CHECK(parse_with(&w, "-h", &a) == 0);
  CHECK_MSG(strstr(g_out, "\n  --x         one two") && strstr(g_out, "\n              thirteen"),
            "%s", g_out);
}

int main(void) {
  test_spellings();
  test_errors();
  test_positional();
  test_help();
  TEST_MAIN_END();
}
