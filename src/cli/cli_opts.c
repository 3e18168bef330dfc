/* The table-driven option parser of every command and the --help printer
 * (see cli_opts.h). It reads argv twice with the same word splitter: first
 * only to find -h/--help (so the help shows the defaults before any option
 * changed them), then to store the values. */
#include "cli/cli_opts.h"

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "hearth/core.h"

/* ---- the table, flattened ----------------------------------------------- */

/* Every option of a command with the group that brought it in. */
#define CLI_MAX_OPTS 96
typedef struct flat_opt {
  const cli_opt *o;
  const cli_opt *group; /* the GROUP entry it came from, or NULL */
} flat_opt;

typedef struct flat_table {
  size_t n;
  flat_opt at[CLI_MAX_OPTS];
} flat_table;

static void flatten(const cli_opt *t, const cli_opt *group, flat_table *f) {
  for (; t && t->kind != CLI_KIND_END; t++) {
    if (t->kind == CLI_KIND_GROUP) {
      flatten(t->group, t, f);
    } else if (f->n < CLI_MAX_OPTS) {
      f->at[f->n].o = t;
      f->at[f->n].group = group;
      f->n++;
    }
  }
}

static int takes_value(const cli_opt *o) { return o->kind != CLI_KIND_FLAG; }

/* ---- words of argv ------------------------------------------------------- */

typedef enum word_kind { W_ARG, W_HELP, W_OPT, W_UNKNOWN } word_kind;

typedef struct word {
  word_kind kind;
  size_t k;            /* W_OPT: index in the flat table */
  const char *spelled; /* the option as written: a table name, or buf */
  char buf[64];
  const char *value; /* the value; NULL when none came */
  int joined;        /* the value was part of the word (--opt=value, -j4) */
} word;

static void set_spelled(word *w, const char *s, size_t len) {
  if (len >= sizeof w->buf) len = sizeof w->buf - 1;
  memcpy(w->buf, s, len);
  w->buf[len] = 0;
  w->spelled = w->buf;
}

/* Classify argv[*i], advancing *i past a separate value. */
static void next_word(const flat_table *f, int argc, char **argv, int *i, word *w) {
  const char *a = argv[*i];
  memset(w, 0, sizeof *w);
  if (a[0] != '-') {
    w->kind = W_ARG;
    return;
  }
  const char *eq = strchr(a, '=');
  size_t len = eq ? (size_t)(eq - a) : strlen(a);
  set_spelled(w, a, len);
  if (eq) {
    w->value = eq + 1;
    w->joined = 1;
  }
  if ((len == 6 && !strncmp(a, "--help", 6)) || (len == 2 && !strncmp(a, "-h", 2))) {
    w->kind = W_HELP;
    return;
  }
  for (size_t k = 0; k < f->n; k++) {
    const cli_opt *o = f->at[k].o;
    const char *hit = NULL;
    if (o->name && strlen(o->name) == len && !strncmp(o->name, a, len)) hit = o->name;
    else if (o->alias && strlen(o->alias) == len && !strncmp(o->alias, a, len)) hit = o->alias;
    if (!hit) continue;
    w->kind = W_OPT;
    w->k = k;
    w->spelled = hit;
    if (!eq && takes_value(o) && *i + 1 < argc) w->value = argv[++*i];
    return;
  }
  /* a short alias with its value attached: -j4 */
  if (a[1] != '-' && a[1] && a[2]) {
    for (size_t k = 0; k < f->n; k++) {
      const cli_opt *o = f->at[k].o;
      if (o->alias && strlen(o->alias) == 2 && !strncmp(o->alias, a, 2) && takes_value(o)) {
        w->kind = W_OPT;
        w->k = k;
        w->spelled = o->alias;
        w->value = a + 2;
        w->joined = 1;
        return;
      }
    }
  }
  w->kind = W_UNKNOWN;
}

/* ---- values -------------------------------------------------------------- */

static int parse_long(const char *s, long *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || end == s || *end) return 0;
  *out = v;
  return 1;
}

static int parse_num(const char *s, size_t len, double *out) {
  return hearth_parse_double(s, len, 0, out) == 0;
}

static int in_range(const cli_opt *o, double x) {
  int lo_ok = (o->flags & CLI_LO_OPEN) ? x > o->lo : x >= o->lo;
  int hi_ok = (o->flags & CLI_HI_OPEN) ? x < o->hi : x <= o->hi;
  return lo_ok && hi_ok;
}

static int choice_index(const cli_opt *o, const char *v) {
  for (int k = 0; o->choices[k]; k++)
    if ((o->flags & CLI_NOCASE) ? !strcasecmp(o->choices[k], v) : !strcmp(o->choices[k], v))
      return k;
  return -1;
}

/* "max or robust", "H1, H2 or H3", "max|robust" */
static void join_choices(const cli_opt *o, const char *sep, const char *last_sep, char *buf,
                         size_t sz) {
  size_t off = 0;
  buf[0] = 0;
  for (int k = 0; o->choices[k] && off < sz; k++) {
    const char *s = k == 0 ? "" : o->choices[k + 1] ? sep : last_sep;
    off += (size_t)snprintf(buf + off, sz - off, "%s%s", s, o->choices[k]);
  }
}

/* the range of a NUM or PAIR as words: "in 0..5", "> 0", ">= 0 and < 1" */
static void range_text(const cli_opt *o, char *buf, size_t sz) {
  const char *ge = (o->flags & CLI_LO_OPEN) ? ">" : ">=";
  const char *le = (o->flags & CLI_HI_OPEN) ? "<" : "<=";
  int has_lo = o->lo > -CLI_INF, has_hi = o->hi < CLI_INF;
  if (has_lo && has_hi && !(o->flags & (CLI_LO_OPEN | CLI_HI_OPEN)))
    snprintf(buf, sz, " in %g..%g", o->lo, o->hi);
  else if (has_lo && has_hi) snprintf(buf, sz, " %s %g and %s %g", ge, o->lo, le, o->hi);
  else if (has_lo) snprintf(buf, sz, " %s %g", ge, o->lo);
  else if (has_hi) snprintf(buf, sz, " %s %g", le, o->hi);
  else buf[0] = 0;
}

/* What a value of o looks like, for messages. */
static void expect_text(const cli_opt *o, char *buf, size_t sz) {
  char r[400];
  switch (o->kind) {
    case CLI_KIND_INT:
    case CLI_KIND_SIZE: snprintf(buf, sz, "an integer in %.0f..%.0f", o->lo, o->hi); break;
    case CLI_KIND_U64: snprintf(buf, sz, "a non-negative integer"); break;
    case CLI_KIND_NUM:
      range_text(o, r, sizeof r);
      snprintf(buf, sz, "a number%s", r);
      break;
    case CLI_KIND_CHOICE:
      join_choices(o, ", ", " or ", r, sizeof r);
      snprintf(buf, sz, "%s", r);
      break;
    case CLI_KIND_LIST:
      snprintf(buf, sz, "a comma-separated list of at most %zu items", o->max);
      break;
    case CLI_KIND_PAIR:
      range_text(o, r, sizeof r);
      snprintf(buf, sz, "two comma-separated numbers%s%s", r,
               (o->flags & CLI_ASCENDING) ? ", the first below the second" : "");
      break;
    case CLI_KIND_SHARD: snprintf(buf, sz, "I/N with 0 <= I < N"); break;
    case CLI_KIND_CALL: snprintf(buf, sz, "%s", o->expect ? o->expect : "a value"); break;
    case CLI_KIND_STR: snprintf(buf, sz, "%s", o->metavar ? o->metavar : "a value"); break;
    default: snprintf(buf, sz, "a value"); break;
  }
}

static int store_list(const cli_opt *o, const char *v, char *why, size_t whysz) {
  cli_list *l = o->dst;
  size_t max = o->max && o->max < CLI_LIST_MAX ? o->max : CLI_LIST_MAX;
  size_t len = strlen(v);
  if (len >= sizeof l->text) return -1;
  memcpy(l->text, v, len + 1);
  l->n = 0;
  for (char *p = l->text; *p;) {
    char *comma = strchr(p, ',');
    if (comma) *comma = 0;
    if (*p) {
      if (l->n >= max) return -1;
      l->items[l->n++] = p;
    }
    if (!comma) break;
    p = comma + 1;
  }
  if (!l->n) return -1;
  for (size_t j = 0; o->check && j < l->n; j++) {
    if (!o->check(l->items[j])) {
      snprintf(why, whysz, "expected %s, found '%s'", o->expect ? o->expect : "a valid item",
               l->items[j]);
      l->n = 0;
      return -1;
    }
  }
  return 0;
}

/* Parse v for o and store it. Returns 0, or -1 (with why filled when the
 * reason is more than "not what was expected"). */
static int store(const cli_opt *o, const char *v, char *why, size_t whysz) {
  long n;
  double x, y;
  why[0] = 0;
  switch (o->kind) {
    case CLI_KIND_INT:
      if (!parse_long(v, &n) || n < (long)o->lo || n > (long)o->hi) return -1;
      *(int *)o->dst = (int)n;
      return 0;
    case CLI_KIND_SIZE:
      if (!parse_long(v, &n) || n < (long)o->lo || n > (long)o->hi) return -1;
      *(size_t *)o->dst = (size_t)n;
      return 0;
    case CLI_KIND_U64: {
      char *end;
      errno = 0;
      if (*v == '-') return -1;
      unsigned long long u = strtoull(v, &end, 10);
      if (errno || end == v || *end) return -1;
      *(uint64_t *)o->dst = (uint64_t)u;
      return 0;
    }
    case CLI_KIND_NUM:
      if (!parse_num(v, strlen(v), &x) || !in_range(o, x)) return -1;
      *(double *)o->dst = x;
      return 0;
    case CLI_KIND_STR: *(const char **)o->dst = v; return 0;
    case CLI_KIND_CHOICE: {
      int k = choice_index(o, v);
      if (k < 0) return -1;
      *(int *)o->dst = o->values ? o->values[k] : k;
      return 0;
    }
    case CLI_KIND_LIST: return store_list(o, v, why, whysz);
    case CLI_KIND_PAIR: {
      const char *comma = strchr(v, ',');
      if (!comma || !parse_num(v, (size_t)(comma - v), &x) ||
          !parse_num(comma + 1, strlen(comma + 1), &y) || !in_range(o, x) || !in_range(o, y) ||
          ((o->flags & CLI_ASCENDING) && !(x < y)))
        return -1;
      *(double *)o->dst = x;
      *(double *)o->dst2 = y;
      return 0;
    }
    case CLI_KIND_SHARD: {
      const char *slash = strchr(v, '/');
      long a, b;
      char head[32];
      if (!slash || (size_t)(slash - v) >= sizeof head) return -1;
      memcpy(head, v, (size_t)(slash - v));
      head[slash - v] = 0;
      if (!parse_long(head, &a) || !parse_long(slash + 1, &b) || b < 1 || b > INT_MAX || a < 0 ||
          a >= b)
        return -1;
      *(int *)o->dst = (int)a;
      *(int *)o->dst2 = (int)b;
      return 0;
    }
    case CLI_KIND_CALL: return o->parse(o->dst, v, why, whysz) ? -1 : 0;
    default: return -1;
  }
}

/* ---- help ---------------------------------------------------------------- */

#define HELP_WIDTH 80
#define HELP_MAX_LABEL 22

static void label_of(const cli_opt *o, char *buf, size_t sz) {
  char names[96];
  if (o->kind == CLI_KIND_CHOICE && !o->metavar) join_choices(o, "|", "|", names, sizeof names);
  const char *mv = o->kind == CLI_KIND_CHOICE && !o->metavar ? names : o->metavar;
  snprintf(buf, sz, "%s%s%s%s%s", o->alias ? o->alias : "", o->alias ? ", " : "", o->name,
           mv && takes_value(o) ? " " : "", mv && takes_value(o) ? mv : "");
}

/* The default as help shows it, "" for none. */
static void default_of(const cli_opt *o, char *buf, size_t sz) {
  buf[0] = 0;
  if (o->def) {
    snprintf(buf, sz, "%s", o->def);
    return;
  }
  switch (o->kind) {
    case CLI_KIND_INT: snprintf(buf, sz, "%d", *(const int *)o->dst); break;
    case CLI_KIND_SIZE: snprintf(buf, sz, "%zu", *(const size_t *)o->dst); break;
    case CLI_KIND_U64:
      snprintf(buf, sz, "%llu", (unsigned long long)*(const uint64_t *)o->dst);
      break;
    case CLI_KIND_NUM: snprintf(buf, sz, "%g", *(const double *)o->dst); break;
    case CLI_KIND_STR:
      if (*(const char *const *)o->dst) snprintf(buf, sz, "%s", *(const char *const *)o->dst);
      break;
    case CLI_KIND_CHOICE:
      for (int k = 0; o->choices[k]; k++)
        if ((o->values ? o->values[k] : k) == *(const int *)o->dst) {
          snprintf(buf, sz, "%s", o->choices[k]);
          break;
        }
      break;
    default: break;
  }
}

/* Print text from column `used` on, wrapped at HELP_WIDTH with later lines
 * starting at column col; '\n' in text starts a new line. */
static void wrap(FILE *out, const char *text, size_t used, size_t col) {
  const char *p = text;
  while (*p) {
    size_t wl = strcspn(p, " \n");
    if (used > col && used + 1 + wl > HELP_WIDTH) {
      fprintf(out, "\n%*s", (int)col, "");
      used = col;
    }
    if (used > col) {
      fputc(' ', out);
      used++;
    }
    fwrite(p, 1, wl, out);
    used += wl;
    p += wl;
    if (*p == '\n') {
      fprintf(out, "\n%*s", (int)col, "");
      used = col;
      p++;
    }
    while (*p == ' ') p++;
  }
  fputc('\n', out);
}

static void help_line(FILE *out, const char *label, const char *text, size_t col) {
  size_t n = strlen(label);
  fprintf(out, "  %s", label);
  if (2 + n + 2 > col) {
    fprintf(out, "\n%*s", (int)col, "");
  } else {
    fprintf(out, "%*s", (int)(col - 2 - n), "");
  }
  /* `col` counts as used: the first word is not preceded by a space */
  wrap(out, text, col, col);
}

/* The entries of t: with headed 0, the options outside headed groups; with
 * headed 1, each headed group under its heading. */
static void help_opts(FILE *out, const cli_opt *t, size_t col, int headed) {
  for (; t && t->kind != CLI_KIND_END; t++) {
    if (t->kind == CLI_KIND_GROUP) {
      if (!t->help) {
        help_opts(out, t->group, col, headed);
      } else if (headed) {
        fprintf(out, "\n%s:\n", t->help);
        help_opts(out, t->group, col, 0);
        help_opts(out, t->group, col, 1);
      }
      continue;
    }
    if (headed) continue;
    char label[160], def[128], text[1200];
    label_of(t, label, sizeof label);
    default_of(t, def, sizeof def);
    /* a choice under a metavar lists its names after the help */
    char names[400] = "";
    if (t->kind == CLI_KIND_CHOICE && t->metavar) {
      char list[360];
      join_choices(t, ", ", ", ", list, sizeof list);
      snprintf(names, sizeof names, " (%s: %s)", t->metavar, list);
    }
    snprintf(text, sizeof text, "%s%s%s%s%s%s", t->help ? t->help : "", names,
             def[0] ? " (default: " : "", def, def[0] ? ")" : "",
             (t->flags & CLI_REQUIRED) ? " (required)" : "");
    help_line(out, label, text, col);
  }
}

/* "ROOT", "[DIR]", "FILE [FILE...]" */
static void args_text(const cli_command *cmd, char *buf, size_t sz) {
  buf[0] = 0;
  if (!cmd->args) return;
  if (cmd->max_args < 0 && cmd->min_args) snprintf(buf, sz, " %s [%s...]", cmd->args, cmd->args);
  else if (cmd->max_args < 0) snprintf(buf, sz, " [%s...]", cmd->args);
  else if (cmd->min_args) snprintf(buf, sz, " %s", cmd->args);
  else snprintf(buf, sz, " [%s]", cmd->args);
}

static void usage_line(const cli_command *cmd, FILE *out) {
  if (cmd->usage) {
    fprintf(out, "usage: %s\n", cmd->usage);
    return;
  }
  char a[128];
  args_text(cmd, a, sizeof a);
  fprintf(out, "usage: %s%s", cmd->name, a);
  flat_table f = {0};
  flatten(cmd->opts, NULL, &f);
  for (size_t k = 0; k < f.n; k++) {
    if (!(f.at[k].o->flags & CLI_REQUIRED)) continue;
    char label[160];
    label_of(f.at[k].o, label, sizeof label);
    fprintf(out, " %s", label);
  }
  fprintf(out, " [options]\n");
}

void cli_help(const cli_command *cmd, FILE *out) {
  usage_line(cmd, out);
  if (cmd->about) fprintf(out, "\n%s", cmd->about);
  flat_table f = {0};
  flatten(cmd->opts, NULL, &f);
  size_t widest = strlen("-h, --help");
  for (size_t k = 0; k < f.n; k++) {
    char label[160];
    label_of(f.at[k].o, label, sizeof label);
    size_t n = strlen(label);
    if (n <= HELP_MAX_LABEL && n > widest) widest = n;
  }
  size_t col = 2 + widest + 2;
  fprintf(out, "\noptions:\n");
  help_opts(out, cmd->opts, col, 0);
  help_line(out, "-h, --help", "this text", col);
  help_opts(out, cmd->opts, col, 1);
  if (cmd->tail) fprintf(out, "\n%s", cmd->tail);
  if (cmd->more) cmd->more(out);
}

/* ---- parsing ------------------------------------------------------------- */

/* "<cmd name>: <message>\n" on err; returns 2 */
static int vfail(const cli_command *cmd, FILE *err, const char *fmt, va_list ap) {
  fprintf(err, "%s: ", cmd->name);
  vfprintf(err, fmt, ap);
  fputc('\n', err);
  return 2;
}

int cli_usage_error(const cli_command *cmd, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vfail(cmd, stderr, fmt, ap);
  va_end(ap);
  return 2;
}

static int fail(const cli_command *cmd, FILE *err, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int fail(const cli_command *cmd, FILE *err, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vfail(cmd, err, fmt, ap);
  va_end(ap);
  return 2;
}

/* The value of word w for option o: stored, or the problem printed. */
static int take_value(const cli_command *cmd, const cli_opt *o, const word *w, FILE *err) {
  char exp[512], why[512];
  if (!takes_value(o)) {
    if (w->joined)
      return fail(cmd, err, "option %s takes no value, found '%s'", w->spelled, w->value);
    *(int *)o->dst = o->value;
    return 0;
  }
  expect_text(o, exp, sizeof exp);
  if (!w->value) return fail(cmd, err, "option %s: missing value (expected %s)", w->spelled, exp);
  if (store(o, w->value, why, sizeof why) == 0) return 0;
  if (why[0]) return fail(cmd, err, "option %s: %s", w->spelled, why);
  return fail(cmd, err, "option %s: expected %s, found '%s'", w->spelled, exp, w->value);
}

int cli_parse_to(const cli_command *cmd, int argc, char **argv, cli_args *args, FILE *out,
                 FILE *err) {
  flat_table f = {0};
  flatten(cmd->opts, NULL, &f);
  unsigned char seen[CLI_MAX_OPTS] = {0};
  word w;
  if (args) *args = (cli_args){0, argv + (argc > 0 ? 1 : 0)};

  /* -h/--help wins over everything else on the line */
  for (int i = 1; i < argc; i++) {
    next_word(&f, argc, argv, &i, &w);
    if (w.kind == W_ARG && cmd->stop_at_arg) break;
    if (w.kind == W_HELP && !w.joined) {
      cli_help(cmd, out);
      return 0;
    }
  }
  for (size_t k = 0; k < f.n; k++)
    if (f.at[k].group && f.at[k].group->dst2) *(const char **)f.at[k].group->dst2 = NULL;

  int n_args = 0, i;
  for (i = 1; i < argc; i++) {
    next_word(&f, argc, argv, &i, &w);
    if (w.kind == W_ARG) {
      if (cmd->stop_at_arg) break;
      if (!cmd->args || (cmd->max_args >= 0 && n_args >= cmd->max_args))
        return fail(cmd, err, "unexpected argument '%s'", argv[i]);
      argv[1 + n_args++] = argv[i];
    } else if (w.kind == W_HELP) {
      return fail(cmd, err, "option %s takes no value, found '%s'", w.spelled, w.value);
    } else if (w.kind == W_UNKNOWN) {
      return fail(cmd, err, "unknown option '%s' (see '%s --help')", w.spelled, cmd->name);
    } else {
      const flat_opt *fo = &f.at[w.k];
      if (take_value(cmd, fo->o, &w, err)) return 2;
      seen[w.k] = 1;
      if (fo->group && fo->group->dst2 && !*(const char **)fo->group->dst2)
        *(const char **)fo->group->dst2 = w.spelled;
    }
  }
  for (size_t k = 0; k < f.n; k++)
    if ((f.at[k].o->flags & CLI_REQUIRED) && !seen[k])
      return fail(cmd, err, "option %s is required (see '%s --help')", f.at[k].o->name, cmd->name);
  if (cmd->stop_at_arg) {
    if (i >= argc && cmd->min_args > 0)
      return fail(cmd, err, "missing %s (see '%s --help')", cmd->args, cmd->name);
    if (args) *args = (cli_args){argc - i, argv + i};
    return CLI_RUN;
  }
  if (n_args < cmd->min_args) {
    char a[128];
    args_text(cmd, a, sizeof a);
    return fail(cmd, err, "missing %s (usage: %s%s [options])", cmd->args, cmd->name, a);
  }
  if (args) *args = (cli_args){n_args, argv + 1};
  return CLI_RUN;
}

int cli_parse(const cli_command *cmd, int argc, char **argv, cli_args *args) {
  return cli_parse_to(cmd, argc, argv, args, stdout, stderr);
}
