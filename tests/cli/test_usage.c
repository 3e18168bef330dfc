/* Usage errors of every command of the built `hearth` (and `hearth sim`):
 * no ROOT, an unknown option and a second positional argument each exit 2
 * with a message naming the command and the offending word; a bad value
 * exits 2 naming the option in both spellings, --opt=value and --opt value;
 * --help exits 0 with a usage line and every option of the command. */
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include "test_util.h"

static int run(const char *cmd, char *out, size_t outsz) {
  FILE *p = popen(cmd, "r");
  if (!p) return -1;
  size_t n = fread(out, 1, outsz - 1, p);
  out[n] = 0;
  int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

typedef struct command_case {
  const char *name;    /* as typed after hearth: "map", "sim render" */
  int has_root;        /* takes ROOT */
  const char *opt;     /* an option ... */
  const char *bad;     /* ... and a value it refuses */
  const char *options; /* every option, space-separated */
} command_case;

static const command_case k_cases[] = {
    {"synth", 0, "--views", "0",
     "--out --seed --categories --instances --states --views --triangles --texture --map-res "
     "--no-calibration --thermal-frames --stereo-pairs --mesh --mesh-size --mesh-category "
     "--contact-sheet --draft-rgb --netd --threads --quiet"},
    {"inspect", 0, "--as", "teapot", "--as"},
    {"detect", 1, "--upsample", "0", "--no-overlays --threads --upsample --max-blur --quiet"},
    {"calibrate", 1, "--max-iterations", "0",
     "--detect --no-overlays --max-iterations --outlier-factor --outlier-min "
     "--no-perspective-correction --quiet --threads --upsample --max-blur"},
    {"scale", 1, "--stride", "0", "--instance --state --stride --edge-rel --threads"},
    /* transfer's options are strings and a flag: the flag given a value */
    {"transfer", 1, "--keep-refined", NULL, "--instance --rig --poses --keep-refined"},
    {"refine", 1, "--iterations", "999",
     "--instance --state --nudge --nudges --no-auto --start --out --mesh --rig --search "
     "--iterations --min-contrast --threads --perturb --seed --truth"},
    {"map", 1, "--resolution", "abc",
     "--instance --state --resolution --fusion --min-cos --keep-edges --views --trace-rays "
     "--mesh --poses --rig --rgb --threads"},
    {"overlay", 1, "--zoom", "0",
     "--instance --state --before --after --mesh --rig --zoom --range"},
    {"build", 1, "--min-cos", "1",
     "-j --jobs --threads --shard --instance --resolution --fusion --min-cos --rgb-resolution "
     "--no-bake --no-overlays --force --dry-run --quiet"},
    {"validate", 1, "--threads", "0", "--raw-only --decode --threads --quiet"},
    {"stats", 1, "--format", "yaml", "--json --format"},
    {"demo", 0, "--resolution", "8", "--threads --views --resolution --quiet"},
    {"sim render", 0, "--size", "8",
     "--out --task --release --ground-truth --size --seed --shadows --renderer --gl"},
    {"sim collect", 0, "--layouts", "0",
     "--task --out --layouts --seed --size --max-steps --release --ground-truth "
     "--keep-failures --shadows --renderer --gl --quiet"},
    {"sim eval", 0, "--task", "H7",
     "--policy --task --episodes --no-thermal --seed --release --size --shadows --renderer --gl "
     "--image-size --max-steps --replan --wait --timeout --out --video --video-every --quiet"},
};

/* the bad value in both spellings: status 2, "hearth <cmd>: option <opt>" */
static void check_bad_value(const command_case *c, const char *opt, const char *bad) {
  char cmd[1024], out[8192], want[256];
  for (int joined = 0; joined < 2; joined++) {
    if (!bad) {
      if (!joined) continue;
      snprintf(cmd, sizeof cmd, "'%s' %s%s %s=yes 2>&1", HEARTH_EXE, c->name,
               c->has_root ? " /nonexistent" : "", opt);
    } else {
      snprintf(cmd, sizeof cmd, "'%s' %s%s %s%s%s 2>&1", HEARTH_EXE, c->name,
               c->has_root ? " /nonexistent" : "", opt, joined ? "=" : " ", bad);
    }
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s: %s", cmd, out);
    snprintf(want, sizeof want, "hearth %s: option %s", c->name, opt);
    CHECK_MSG(strstr(out, want), "%s: %s", cmd, out);
    if (bad) {
      snprintf(want, sizeof want, "found '%s'\n", bad);
      CHECK_MSG(strstr(out, want), "%s: %s", cmd, out);
    }
  }
  /* the value missing at the end of the line */
  if (bad) {
    snprintf(cmd, sizeof cmd, "'%s' %s%s %s 2>&1", HEARTH_EXE, c->name,
             c->has_root ? " /nonexistent" : "", opt);
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s: %s", cmd, out);
    snprintf(want, sizeof want, "hearth %s: option %s: missing value", c->name, opt);
    CHECK_MSG(strstr(out, want), "%s: %s", cmd, out);
  }
}

/* opt appears in text as a whole word ("--mesh" is not "--mesh-size") */
static int has_option(const char *text, const char *opt) {
  size_t n = strlen(opt);
  for (const char *p = strstr(text, opt); p; p = strstr(p + 1, opt)) {
    char next = p[n];
    if (next == ' ' || next == '\n' || next == ',') return 1;
  }
  return 0;
}

static void check_command(const command_case *c) {
  char cmd[1024], out[16384], want[256];
  if (c->has_root) {
    snprintf(cmd, sizeof cmd, "'%s' %s 2>&1", HEARTH_EXE, c->name);
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s without ROOT", c->name);
    snprintf(want, sizeof want, "hearth %s:", c->name);
    CHECK_MSG(strstr(out, want) && strstr(out, "ROOT"), "%s: %s", c->name, out);

    snprintf(cmd, sizeof cmd, "'%s' %s /nonexistent/a /nonexistent/b 2>&1", HEARTH_EXE, c->name);
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s with two roots", c->name);
    CHECK_MSG(strstr(out, "/nonexistent/b"), "%s: %s", c->name, out);
  }
  snprintf(cmd, sizeof cmd, "'%s' %s --no-such-option 2>&1", HEARTH_EXE, c->name);
  CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s --no-such-option", c->name);
  CHECK_MSG(strstr(out, "--no-such-option"), "%s: %s", c->name, out);

  check_bad_value(c, c->opt, c->bad);

  /* --help and -h: status 0, the usage line, every option */
  for (int shortform = 0; shortform < 2; shortform++) {
    snprintf(cmd, sizeof cmd, "'%s' %s %s 2>&1", HEARTH_EXE, c->name, shortform ? "-h" : "--help");
    CHECK_MSG(run(cmd, out, sizeof out) == 0, "%s", cmd);
    snprintf(want, sizeof want, "usage: hearth %s", c->name);
    CHECK_MSG(strstr(out, want), "%s: %s", cmd, out);
    char opts[1024];
    snprintf(opts, sizeof opts, "%s", c->options);
    for (char *o = strtok(opts, " "); o; o = strtok(NULL, " "))
      CHECK_MSG(has_option(out, o), "%s --help lacks %s:\n%s", c->name, o, out);
  }
}

int main(void) {
  char cmd[1024], out[8192];
  snprintf(cmd, sizeof cmd, "'%s' sim --help 2>&1", HEARTH_EXE);
  int have_sim = run(cmd, out, sizeof out) == 0;
  if (!have_sim) fprintf(stderr, "no hearth-sim in this build: sim commands skipped\n");
  for (size_t i = 0; i < sizeof k_cases / sizeof k_cases[0]; i++) {
    if (!strncmp(k_cases[i].name, "sim ", 4) && !have_sim) continue;
    check_command(&k_cases[i]);
  }
  /* the short alias in its three spellings */
  const command_case build = {"build", 1, NULL, NULL, NULL};
  check_bad_value(&build, "-j", "0");
  snprintf(cmd, sizeof cmd, "'%s' build /nonexistent -j0 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 2 && strstr(out, "option -j: expected an integer"), "%s",
            out);
  /* calibrate takes detect's options only with --detect */
  snprintf(cmd, sizeof cmd, "'%s' calibrate /nonexistent --upsample 2 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 2 && strstr(out, "--upsample only applies with --detect"),
            "%s", out);
  /* a flag given a value, on a pipeline command */
  snprintf(cmd, sizeof cmd, "'%s' map /nonexistent --rgb=1 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 2 && strstr(out, "option --rgb takes no value"), "%s",
            out);
  /* the top level */
  snprintf(cmd, sizeof cmd, "'%s' --help 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 0 && strstr(out, "usage: hearth") &&
                strstr(out, "--version") && strstr(out, "  map "),
            "%s", out);
  snprintf(cmd, sizeof cmd, "'%s' 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 2 && strstr(out, "usage: hearth"), "%s", out);
  snprintf(cmd, sizeof cmd, "'%s' --version 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 0 && !strncmp(out, "hearth ", 7), "%s", out);
  snprintf(cmd, sizeof cmd, "'%s' no-such-command 2>&1", HEARTH_EXE);
  CHECK_MSG(run(cmd, out, sizeof out) == 2 && strstr(out, "no-such-command"), "%s", out);
  if (have_sim) {
    snprintf(cmd, sizeof cmd, "'%s' sim no-such-subcommand 2>&1", HEARTH_EXE);
    CHECK_MSG(run(cmd, out, sizeof out) == 2 && strstr(out, "no-such-subcommand"), "%s", out);
  }
  TEST_MAIN_END();
}
