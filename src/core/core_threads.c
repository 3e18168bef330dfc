/* Deterministic parallel-for over index ranges, and progress output. */
#include <pthread.h>
#include <stdatomic.h>
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

/* the shared state of hearth_parallel_chunks: chunks are taken in index
   order by whichever worker is free */
typedef struct chunk_job {
  hearth_range_fn fn;
  void *ctx;
  size_t n, chunk;
  _Atomic size_t next;
} chunk_job;

typedef struct chunk_worker {
  chunk_job *job;
  int index;
} chunk_worker;

static void *chunk_run(void *arg) {
  chunk_worker *w = arg;
  chunk_job *j = w->job;
  for (;;) {
    size_t b = atomic_fetch_add_explicit(&j->next, j->chunk, memory_order_relaxed);
    if (b >= j->n) break;
    size_t e = j->n - b > j->chunk ? b + j->chunk : j->n;
    j->fn(j->ctx, b, e, w->index);
  }
  return NULL;
}

hearth_status hearth_parallel_chunks(size_t n, size_t chunk, int nthreads, hearth_range_fn fn,
                                     void *ctx) {
  if (chunk < 1) chunk = 1;
  if (nthreads <= 0) nthreads = hearth_default_threads();
  size_t n_chunks = (n + chunk - 1) / chunk;
  if ((size_t)nthreads > n_chunks) nthreads = n_chunks ? (int)n_chunks : 1;
  chunk_job job = {fn, ctx, n, chunk, 0};
  atomic_init(&job.next, 0);
  chunk_worker *ws = calloc((size_t)nthreads, sizeof *ws);
  pthread_t *tids = calloc((size_t)nthreads, sizeof *tids);
  if (nthreads <= 1 || !ws || !tids) {
    /* one worker: every chunk in order on this thread */
    chunk_worker w = {&job, 0};
    chunk_run(&w);
    free(ws);
    free(tids);
    return HEARTH_OK;
  }
  int started = 0;
  for (int i = 0; i < nthreads; i++) ws[i] = (chunk_worker){&job, i};
  for (int i = 1; i < nthreads; i++) {
    if (pthread_create(&tids[i], NULL, chunk_run, &ws[i]) != 0) break;
    started = i;
  }
  chunk_run(&ws[0]); /* this thread takes chunks too, and whatever is left */
  for (int i = 1; i <= started; i++) pthread_join(tids[i], NULL);
  free(ws);
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
