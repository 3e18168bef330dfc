/* Deterministic parallel-for over index ranges, and progress output. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>
#include "hearth/core.h"

int hearth_default_threads(void) {
  const char *env = getenv("HEARTH_THREADS");
  if (env && *env) {
    long v = strtol(env, NULL, 10);
    if (v >= 1 && v <= 1024) return (int)v;
  }
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  if (n < 1) n = 1;
  if (n > 256) n = 256;
  return (int)n;
}

typedef struct par_job {
  hearth_range_fn fn;
  void *ctx;
  size_t begin, end;
  int index;
} par_job;

static void *par_run(void *arg) {
  par_job *j = arg;
  if (j->begin < j->end) j->fn(j->ctx, j->begin, j->end, j->index);
  return NULL;
}

hearth_status hearth_parallel_for(size_t n, int nthreads, hearth_range_fn fn, void *ctx) {
  if (nthreads <= 0) nthreads = hearth_default_threads();
  if ((size_t)nthreads > n) nthreads = n ? (int)n : 1;
  if (nthreads <= 1) {
    if (n) fn(ctx, 0, n, 0);
    return HEARTH_OK;
  }
  par_job *jobs = calloc((size_t)nthreads, sizeof *jobs);
  pthread_t *tids = calloc((size_t)nthreads, sizeof *tids);
  if (!jobs || !tids) {
    free(jobs);
    free(tids);
    fn(ctx, 0, n, 0); /* degrade to serial; same result by construction */
    return HEARTH_OK;
  }
  int started = 0;
  for (int i = 0; i < nthreads; i++) {
    jobs[i] = (par_job){fn, ctx, n * (size_t)i / (size_t)nthreads,
                        n * (size_t)(i + 1) / (size_t)nthreads, i};
  }
  for (int i = 1; i < nthreads; i++) {
    if (pthread_create(&tids[i], NULL, par_run, &jobs[i]) != 0) break;
    started = i;
  }
  par_run(&jobs[0]);
  for (int i = 1; i <= started; i++) pthread_join(tids[i], NULL);
  /* threads that could not start: run their ranges here */
  for (int i = started + 1; i < nthreads; i++) par_run(&jobs[i]);
  free(jobs);
  free(tids);
  return HEARTH_OK;
}

double hearth_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void hearth_progress_begin(hearth_progress *p, const char *label, size_t total, int quiet) {
  p->label = label;
  p->total = total;
  p->done = 0;
  p->out = stderr;
  p->is_tty = isatty(fileno(stderr));
  p->quiet = quiet;
  p->last_percent = -1;
  p->t_start = hearth_now();
}

static void progress_draw(hearth_progress *p, int final) {
  int pct = p->total ? (int)(100.0 * (double)p->done / (double)p->total) : 100;
  double el = hearth_now() - p->t_start;
  if (p->is_tty) {
    int w = 30, fill = pct * w / 100;
    fprintf(p->out, "\r%-18s [", p->label);
    for (int i = 0; i < w; i++) fputc(i < fill ? '#' : '.', p->out);
    fprintf(p->out, "] %3d%% %zu/%zu %.1fs", pct, p->done, p->total, el);
    if (final) fputc('\n', p->out);
    fflush(p->out);
  } else if (final || pct / 5 != p->last_percent / 5) {
    fprintf(p->out, "%s: %d%% (%zu/%zu, %.1fs)\n", p->label, pct, p->done, p->total, el);
    fflush(p->out);
  }
  p->last_percent = pct;
}

void hearth_progress_step(hearth_progress *p, size_t k) {
  p->done += k;
  if (p->done > p->total) p->done = p->total;
  if (p->quiet) return;
  int pct = p->total ? (int)(100.0 * (double)p->done / (double)p->total) : 100;
  if (pct != p->last_percent) progress_draw(p, 0);
}

void hearth_progress_end(hearth_progress *p) {
  p->done = p->total;
  if (!p->quiet) progress_draw(p, 1);
}
