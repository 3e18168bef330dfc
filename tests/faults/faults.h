/* tests/faults/faults.h - a table of hostile cases run against the built
 * `hearth` command: each case makes its own fixture with a shell script,
 * runs one command under a time limit, and checks that it failed the way a
 * person needs (non-zero exit, a message naming the file and place, no
 * output or temporary left behind, memory bounded).
 *
 * A test program defines a table of fault_case and calls faults_run_all. */
#ifndef HEARTH_TESTS_FAULTS_H
#define HEARTH_TESTS_FAULTS_H

#include <errno.h>
#include <fcntl.h>
#include <glob.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "test_util.h"

#define FAULT_MAX_NEEDLES 4
#define FAULT_MAX_ABSENT 4

typedef struct fault_case {
  const char *name;
  /* sh script run in the case's own empty directory ($D) before the command;
   * $HEARTH is the tool; NULL: nothing */
  const char *setup;
  /* the command, run by sh in $D with $HEARTH set; its stdout and stderr
   * are captured together */
  const char *command;
  /* substrings the output must contain (NULL-terminated early is fine) */
  const char *needles[FAULT_MAX_NEEDLES];
  /* glob patterns (relative to $D) that must match nothing afterwards:
   * outputs the command must not have written, temporaries it must not
   * have left */
  const char *absent[FAULT_MAX_ABSENT];
  double timeout_s;   /* 0: 30 s */
  long max_rss_mb;    /* 0: 300 */
  int expect_success; /* 1: the command must succeed (e.g. a clean-up run) */
} fault_case;

/* Run `script` under sh in dir with HEARTH set, output into out (cap
 * bytes, NUL-terminated). Returns the exit status, 128+signal when killed,
 * -2 on a time-out; *rss_kb gets the peak resident size of the child tree. */
static int faults_sh(const char *dir, const char *script, double timeout_s, char *out, size_t cap,
                     long *rss_kb) {
  int fds[2];
  if (pipe(fds)) return -1;
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    setpgid(0, 0);
    dup2(fds[1], 1);
    dup2(fds[1], 2);
    close(fds[0]);
    close(fds[1]);
    int nul = open("/dev/null", O_RDONLY);
    if (nul >= 0) dup2(nul, 0);
    if (chdir(dir)) _exit(126);
    /* FAULTS_HEARTH: another build's tool (to see a case fail before a fix) */
    const char *exe = getenv("FAULTS_HEARTH");
    setenv("HEARTH", exe && *exe ? exe : HEARTH_EXE, 1);
    setenv("D", dir, 1);
    execl("/bin/sh", "sh", "-c", script, (char *)NULL);
    _exit(127);
  }
  setpgid(pid, pid);
  close(fds[1]);
  fcntl(fds[0], F_SETFL, O_NONBLOCK);
  size_t n = 0;
  out[0] = 0;
  struct timespec t0;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  int status = 0, done = 0, timed_out = 0;
  struct rusage ru;
  memset(&ru, 0, sizeof ru);
  while (!done) {
    char buf[4096];
    ssize_t r;
    while ((r = read(fds[0], buf, sizeof buf)) > 0) {
      size_t k = (size_t)r;
      if (n + k >= cap) k = cap - 1 - n;
      memcpy(out + n, buf, k);
      n += k;
      out[n] = 0;
    }
    pid_t w = wait4(pid, &status, WNOHANG, &ru);
    if (w == pid) {
      done = 1;
      break;
    }
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double el = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (el > timeout_s) {
      kill(-pid, SIGKILL);
      wait4(pid, &status, 0, &ru);
      timed_out = 1;
      done = 1;
      break;
    }
    usleep(2000);
  }
  /* drain what is left */
  char buf[4096];
  ssize_t r;
  while ((r = read(fds[0], buf, sizeof buf)) > 0) {
    size_t k = (size_t)r;
    if (n + k >= cap) k = cap - 1 - n;
    memcpy(out + n, buf, k);
    n += k;
    out[n] = 0;
  }
  close(fds[0]);
  /* wait4 reports the shell's own usage with that of the children it
   * waited for (the hearth process); the test's own RUSAGE_CHILDREN would
   * hold the peak of every earlier case and setup */
  if (rss_kb) *rss_kb = ru.ru_maxrss;
  if (timed_out) return -2;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

/* Run every case of the table; each case gets a fresh directory under the
 * test's temporary folder. Failures are counted by CHECK_MSG. */
static void faults_run_all(const char *suite, const fault_case *cases, size_t n) {
  static char out[1 << 16];
  /* FAULTS_ONLY=SUBSTRING: only the cases whose name has it */
  const char *only = getenv("FAULTS_ONLY");
  for (size_t i = 0; i < n; i++) {
    const fault_case *c = &cases[i];
    if (only && *only && !strstr(c->name, only)) continue;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/%s", test_tmpdir(suite), c->name);
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    if (system(cmd)) {
      CHECK_MSG(0, "%s: cannot make %s", c->name, dir);
      continue;
    }
    long rss = 0;
    if (c->setup) {
      int rs = faults_sh(dir, c->setup, 300, out, sizeof out, &rss);
      if (rs != 0) {
        CHECK_MSG(0, "%s: setup failed (%d): %s", c->name, rs, out);
        continue;
      }
    }
    double tmo = c->timeout_s > 0 ? c->timeout_s : 30;
    int st = faults_sh(dir, c->command, tmo, out, sizeof out, &rss);
    long max_mb = c->max_rss_mb > 0 ? c->max_rss_mb : 300;
#if defined(__SANITIZE_ADDRESS__)
    max_mb *= 4; /* AddressSanitizer's shadow memory and quarantine */
#endif
    if (st == -2) {
      CHECK_MSG(0, "%s: no answer within %.0f s (hang): %s", c->name, tmo, c->command);
      continue;
    }
    if (c->expect_success)
      CHECK_MSG(st == 0, "%s: exit %d, expected success: %s", c->name, st, out);
    else
      CHECK_MSG(st >= 1 && st < 128, "%s: exit %d, expected a clean failure: %s", c->name, st, out);
    for (int k = 0; k < FAULT_MAX_NEEDLES && c->needles[k]; k++)
      CHECK_MSG(strstr(out, c->needles[k]) != NULL, "%s: output lacks \"%s\": %s", c->name,
                c->needles[k], out);
    for (int k = 0; k < FAULT_MAX_ABSENT && c->absent[k]; k++) {
      char pat[2048];
      snprintf(pat, sizeof pat, "%s/%s", dir, c->absent[k]);
      glob_t g;
      memset(&g, 0, sizeof g);
      int gr = glob(pat, GLOB_NOSORT | GLOB_PERIOD, NULL, &g);
      CHECK_MSG(gr == GLOB_NOMATCH, "%s: left behind %s", c->name,
                gr == 0 && g.gl_pathc ? g.gl_pathv[0] : pat);
      globfree(&g);
    }
    CHECK_MSG(rss / 1024 <= max_mb, "%s: peak memory %ld MB (at most %ld)", c->name, rss / 1024,
              max_mb);
    printf("fault %-40s exit %3d  %5ld MB  ok\n", c->name, st, rss / 1024);
  }
}

#endif
