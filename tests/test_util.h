/* Minimal test helpers: CHECK keeps going and counts failures; main returns
 * the count so ctest sees a failure. */
#ifndef HEARTH_TEST_UTIL_H
#define HEARTH_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

static int g_test_failures = 0;

#define CHECK(cond)                                                            \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
      g_test_failures++;                                                       \
    }                                                                          \
  } while (0)

#define CHECK_MSG(cond, ...)                                                   \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                            \
      fputc('\n', stderr);                                                     \
      g_test_failures++;                                                       \
    }                                                                          \
  } while (0)

#define CHECK_NEAR(a, b, tol)                                                                  \
  do {                                                                                         \
    double _a = (double)(a), _b = (double)(b);                                                 \
    if (!(fabs(_a - _b) <= (tol))) {                                                           \
      fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.12g, %s = %.12g (tol %g)\n", __FILE__, \
              __LINE__, #a, _a, #b, _b, (double)(tol));                                        \
      g_test_failures++;                                                                       \
    }                                                                                          \
  } while (0)

/* status must be HEARTH_OK; prints the error otherwise */
#define CHECK_OK(expr, errp)                                                   \
  do {                                                                         \
    hearth_status _s = (expr);                                                 \
    if (_s != HEARTH_OK) {                                                     \
      fprintf(stderr, "%s:%d: %s failed: %s: %s\n", __FILE__, __LINE__, #expr, \
              hearth_status_name(_s), (errp)->msg);                            \
      g_test_failures++;                                                       \
    }                                                                          \
  } while (0)

/* A fresh directory under $HEARTH_TEST_TMP (or /tmp) for this test. */
/* The whole file, NUL-terminated (the caller frees); NULL if it cannot be
 * opened. *len (optional) gets its size. */
static inline char *test_slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *b = malloc(n > 0 ? (size_t)n + 1 : 1);
  if (!b) {
    fclose(f);
    return NULL;
  }
  size_t got = n > 0 ? fread(b, 1, (size_t)n, f) : 0;
  fclose(f);
  b[got] = 0;
  if (len) *len = got;
  return b;
}

static inline const char *test_tmpdir(const char *name) {
  static char buf[1024];
  const char *base = getenv("HEARTH_TEST_TMP");
  if (!base || !*base) base = "/tmp";
  snprintf(buf, sizeof buf, "%s/%s", base, name);
  char cmd[1200];
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", buf, buf);
  if (system(cmd) != 0) {
    fprintf(stderr, "cannot create %s\n", buf);
    exit(2);
  }
  return buf;
}

/* Runs cmd through the shell with stderr joined to stdout, keeping the first
 * cap - 1 bytes of its output in out (NUL-terminated); returns its exit
 * status, -1 if it could not run or did not exit. */
static inline int test_run_capture(const char *cmd, char *out, size_t cap) {
  char full[16384];
  snprintf(full, sizeof full, "%s 2>&1", cmd);
  FILE *p = popen(full, "r");
  if (!p) return -1;
  size_t n = fread(out, 1, cap - 1, p);
  out[n] = 0;
  int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Runs the shell command fmt (a printf format taking two strings, a and b);
 * returns its exit status, -1 if it could not run or did not exit. */
static inline int test_sh(const char *fmt, const char *a, const char *b) {
  char cmd[8192];
  snprintf(cmd, sizeof cmd, fmt, a, b);
  int rc = system(cmd);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

/* sha256 of every file of a release tree except the build's stamps (they
 * record input mtimes), sorted by path, into out_file; the exit status */
static inline int test_tree_hash(const char *root, const char *out_file) {
  return test_sh(
      "cd '%s' && find . -type f ! -path '*/.stamps/*' | LC_ALL=C sort | "
      "xargs sha256sum > '%s'",
      root, out_file);
}

#define TEST_MAIN_END()                                                            \
  do {                                                                             \
    if (g_test_failures) fprintf(stderr, "%d check(s) failed\n", g_test_failures); \
    return g_test_failures ? 1 : 0;                                                \
  } while (0)

#endif
