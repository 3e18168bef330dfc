/* Running an outside program (COLMAP): fork + execvp with stdout and stderr
 * on one pipe, its lines copied to a log file and handed to a callback, the
 * last lines kept for the error message of a failed step. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "hearth/recon.h"

#define EX_LINE_MAX 4096
#define EX_TAIL 6 /* lines of output kept for a failure message */

int hearth_program_found(const char *program) {
  if (!program || !*program) return 0;
  if (strchr(program, '/')) return access(program, X_OK) == 0;
  const char *path = getenv("PATH");
  if (!path) path = "/usr/bin:/bin";
  while (*path) {
    const char *colon = strchr(path, ':');
    size_t n = colon ? (size_t)(colon - path) : strlen(path);
    char full[4096];
    if (snprintf(full, sizeof full, "%.*s/%s", (int)n, n ? path : ".", program) <
        (int)sizeof full) {
      struct stat st;
      if (stat(full, &st) == 0 && S_ISREG(st.st_mode) && access(full, X_OK) == 0) return 1;
    }
    if (!colon) break;
    path = colon + 1;
  }
  return 0;
}

typedef struct ex_tail {
  char lines[EX_TAIL][120];
  size_t n; /* lines seen */
} ex_tail;

static void tail_add(ex_tail *t, const char *line) {
  snprintf(t->lines[t->n % EX_TAIL], sizeof t->lines[0], "%s", line);
  t->n++;
}

/* the kept lines, oldest first, each indented, into buf */
static void tail_text(const ex_tail *t, char *buf, size_t bufsz) {
  size_t k = t->n > EX_TAIL ? t->n - EX_TAIL : 0, used = 0;
  buf[0] = 0;
  for (; k < t->n && used + 1 < bufsz; k++) {
    int w = snprintf(buf + used, bufsz - used, "\n    %s", t->lines[k % EX_TAIL]);
    if (w < 0) break;
    used += (size_t)w < bufsz - used ? (size_t)w : bufsz - used - 1;
  }
}

hearth_status hearth_exec(const char *what, const char *const *argv, const char *log_path,
                          hearth_exec_line_fn on_line, void *ctx, hearth_err *err) {
  if (!argv || !argv[0]) return hearth_err_set(err, HEARTH_E_ARG, "hearth_exec: no program");
  if (!what) what = argv[0];
  FILE *log = NULL;
  if (log_path && !(log = fopen(log_path, "a")))
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot open its log %s: %s", what, log_path,
                          strerror(errno));
  int out[2], status_pipe[2];
  if (pipe(out) != 0) {
    if (log) fclose(log);
    return hearth_err_set(err, HEARTH_E_IO, "%s: pipe: %s", what, strerror(errno));
  }
  if (pipe(status_pipe) != 0) {
    close(out[0]);
    close(out[1]);
    if (log) fclose(log);
    return hearth_err_set(err, HEARTH_E_IO, "%s: pipe: %s", what, strerror(errno));
  }
  fcntl(status_pipe[1], F_SETFD, FD_CLOEXEC);
  fcntl(out[0], F_SETFD, FD_CLOEXEC);
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) {
    int e = errno;
    close(out[0]);
    close(out[1]);
    close(status_pipe[0]);
    close(status_pipe[1]);
    if (log) fclose(log);
    return hearth_err_set(err, HEARTH_E_IO, "%s: fork: %s", what, strerror(e));
  }
  if (pid == 0) {
    /* the child: stdin from /dev/null, stdout and stderr into the pipe; an
     * exec failure reports its errno through status_pipe */
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    dup2(out[1], 1);
    dup2(out[1], 2);
    close(out[1]);
    close(status_pipe[0]);
    if (!getenv("QT_QPA_PLATFORM")) setenv("QT_QPA_PLATFORM", "offscreen", 1);
    execvp(argv[0], (char *const *)argv);
    int e = errno;
    ssize_t w = write(status_pipe[1], &e, sizeof e);
    (void)w;
    _exit(127);
  }
  close(out[1]);
  close(status_pipe[1]);
  int exec_errno = 0;
  ssize_t got = read(status_pipe[0], &exec_errno, sizeof exec_errno);
  close(status_pipe[0]);
  ex_tail tail;
  memset(&tail, 0, sizeof tail);
  char line[EX_LINE_MAX];
  size_t len = 0;
  char chunk[4096];
  for (;;) {
    ssize_t n = read(out[0], chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    if (log) fwrite(chunk, 1, (size_t)n, log);
    for (ssize_t i = 0; i < n; i++) {
      char c = chunk[i];
      /* progress output rewrites its line with '\r': treat it as an end */
      if (c == '\n' || c == '\r' || len + 1 >= sizeof line) {
        line[len] = 0;
        if (len) {
          tail_add(&tail, line);
          if (on_line) on_line(ctx, line);
        }
        len = 0;
        if (c == '\n' || c == '\r') continue;
      }
      line[len++] = c;
    }
  }
  if (len) {
    line[len] = 0;
    tail_add(&tail, line);
    if (on_line) on_line(ctx, line);
  }
  close(out[0]);
  if (log) fclose(log);
  int wstatus = 0;
  while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {}
  if (got == (ssize_t)sizeof exec_errno)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: cannot run '%s': %s", what, argv[0],
                          strerror(exec_errno));
  if (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0) return HEARTH_OK;
  char tail_msg[EX_TAIL * 130];
  tail_text(&tail, tail_msg, sizeof tail_msg);
  char how[64];
  if (WIFEXITED(wstatus)) snprintf(how, sizeof how, "exit status %d", WEXITSTATUS(wstatus));
  else if (WIFSIGNALED(wstatus))
    snprintf(how, sizeof how, "killed by signal %d", WTERMSIG(wstatus));
  else snprintf(how, sizeof how, "wait status %d", wstatus);
  return hearth_err_set(err, HEARTH_E_IO, "%s failed (%s)%s%s%s%s%s", what, how,
                        tail.n ? "; the last lines of its output" : "; it printed nothing",
                        log_path && tail.n ? " (all of it in " : "",
                        log_path && tail.n ? log_path : "",
                        log_path && tail.n ? "):" : (tail.n ? ":" : ""), tail_msg);
}
