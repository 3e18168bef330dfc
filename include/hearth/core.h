/* hearth/core.h - area core (src/core/): status codes, error reports,
 * files, threads, locale-independent numbers, random numbers, progress,
 * growing text buffers.
 *
 * Every fallible function in hearth returns a hearth_status and, when the
 * caller passes a hearth_err, fills it with a message a person can act on:
 * which file, which line/column or view, what was expected. The library
 * never exits the process and keeps no global mutable state.
 * Conventions (frames, units, pixel centres): docs/conventions.md. */
#ifndef HEARTH_CORE_H
#define HEARTH_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum hearth_status {
  HEARTH_OK = 0,
  HEARTH_E_ARG,          /* a caller passed an invalid argument */
  HEARTH_E_NOMEM,        /* allocation failed or a size would overflow */
  HEARTH_E_IO,           /* a file could not be opened, read, written or renamed */
  HEARTH_E_PARSE,        /* input is malformed (syntax) */
  HEARTH_E_UNSUPPORTED,  /* well-formed input using a feature hearth does not read */
  HEARTH_E_RANGE,        /* a value lies outside its allowed range */
  HEARTH_E_SIZE,         /* wrong dimensions or counts */
  HEARTH_E_INCONSISTENT, /* files or fields contradict each other */
  HEARTH_E_NUMERIC,      /* a solver failed: singular system, no convergence */
  HEARTH_E_NOT_FOUND,    /* a required file, key, view or target is absent */
  HEARTH_E_LIMIT         /* input exceeds an explicit safety limit */
} hearth_status;

/* "HEARTH_E_PARSE" etc.; a static string, never NULL. */
const char *hearth_status_name(hearth_status s);
/* A short description of the status; a static string, never NULL. */
const char *hearth_strerror(hearth_status s);

/* An error report. Owned by the caller (usually on the stack, nothing
 * inside to free); functions fill it on failure. */
typedef struct hearth_err {
  hearth_status status;
  char msg[1024];
} hearth_err;

/* Record status s with a printf-style message in err (which may be NULL);
 * returns s so callers can write `return hearth_err_set(err, ...)`. */
hearth_status hearth_err_set(hearth_err *err, hearth_status s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Prefix the existing message with context ("reading cup_03/hot: ...");
 * returns err->status (HEARTH_OK when err is NULL). */
hearth_status hearth_err_prefix(hearth_err *err, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* ---- overflow-checked sizes ---------------------------------------------- */
/* *out = a * b; returns 0 on overflow. */
int hearth_mul_size(size_t a, size_t b, size_t *out);
/* malloc of n * size bytes with overflow check; NULL on failure. */
void *hearth_alloc_array(size_t n, size_t size);
/* The same, zeroed by writing every byte at once (rather than relying on
 * lazily mapped zero pages). Free both with free(). */
void *hearth_calloc_array(size_t n, size_t size);

/* ---- files ----------------------------------------------------------------- */
/* Read a whole file; *data is malloc'ed (caller frees) and NUL-terminated
 * (the NUL is not counted in *size). Files larger than max_size are refused
 * with HEARTH_E_LIMIT. Only regular files are read: a FIFO, device, socket
 * or directory in place of the file is refused ("not a regular file (a
 * FIFO)") without blocking, as by hearth_open_regular. */
hearth_status hearth_read_file(const char *path, size_t max_size, uint8_t **data, size_t *size,
                               hearth_err *err);
/* Open path for reading only if it is a regular file: opened non-blocking
 * (a FIFO without a writer cannot hang the caller), its type checked on the
 * open descriptor, then switched back to blocking reads. *fd (the caller
 * closes it) and *size (optional) are set on success. */
hearth_status hearth_open_regular(const char *path, int *fd, size_t *size, hearth_err *err);
/* Without opening: HEARTH_OK for a regular file (symbolic links followed),
 * HEARTH_E_NOT_FOUND "missing", HEARTH_E_IO "not a regular file (a FIFO)". */
hearth_status hearth_check_regular(const char *path, hearth_err *err);

/* ---- temporaries --------------------------------------------------------------
 * Every temporary hearth writes (atomic files, directories written whole,
 * a directory moved aside for replacement, a release tree being made, an
 * HDF5 file being collected) is named
 *
 *     <final name>.tmp-<pid>-<six letters or digits>
 *
 * beside its final name, <pid> being the writer's process id in decimal.
 * A temporary whose writer is no longer running was left by a killed
 * process; hearth_sweep_temps removes those and nothing else, so a sweep is
 * safe while other hearth processes write on the same machine. */
/* Create an empty temporary file for final (mkstemp, mode 0644) and put its
 * name in buf; *fd (optional; NULL: closed) is open for writing. */
hearth_status hearth_temp_file(const char *final, char *buf, size_t bufsz, int *fd,
                               hearth_err *err);
/* Create an empty temporary directory for final (mkdtemp); name in buf. */
hearth_status hearth_temp_dir(const char *final, char *buf, size_t bufsz, hearth_err *err);
/* 1 if name (a file name, no directory) has the temporary pattern; then
 * *base_len (optional) is the length of its final name and *pid
 * (optional) its writer's process id. */
int hearth_temp_parse(const char *name, size_t *base_len, long *pid);
/* 1 if process pid is running (on this machine). */
int hearth_temp_writer_alive(long pid);
/* Remove from dir the temporaries (files and whole directories) whose
 * writer is not running: of final name base only, or of any name when base
 * is NULL; down to depth levels of subdirectories (0: dir only). A missing
 * dir is not an error. *n_removed (optional) is increased by the count. */
hearth_status hearth_sweep_temps(const char *dir, const char *base, int depth, size_t *n_removed,
                                 hearth_err *err);
/* The same for the temporaries of one final path (in its directory). */
hearth_status hearth_sweep_temps_of(const char *final, size_t *n_removed, hearth_err *err);
/* Put directory tmp_dir in the place of final_dir: the old one (if any) is
 * moved aside to a temporary name, tmp_dir renamed into place, the old one
 * removed; on failure the old one is back in place. */
hearth_status hearth_replace_dir(const char *tmp_dir, const char *final_dir, hearth_err *err);

/* Write data to path atomically: a temporary file beside it, flushed, then
 * renamed over path. On failure nothing is left behind, and a write error
 * carries the system's reason ("write failed: No space left on device"). */
hearth_status hearth_write_file_atomic(const char *path, const void *data, size_t size,
                                       hearth_err *err);

/* A streamed atomic writer for code that writes through FILE*:
 * open -> fwrite/fprintf to af.fp -> commit (flush, close, rename over path)
 * or abort (close, unlink). af is the caller's; after commit or abort
 * af.fp is closed and nothing else needs freeing. */
typedef struct hearth_atomic_file {
  FILE *fp;
  char tmp_path[4096];
  char path[4096];
} hearth_atomic_file;
hearth_status hearth_atomic_open(hearth_atomic_file *af, const char *path, hearth_err *err);
hearth_status hearth_atomic_commit(hearth_atomic_file *af, hearth_err *err);
/* Abort (errno is kept for the caller's message). */
void hearth_atomic_abort(hearth_atomic_file *af);
/* Abort after a failed write and report it with errno's reason:
 * `return hearth_atomic_fail(&af, err);` right after the failing call. */
hearth_status hearth_atomic_fail(hearth_atomic_file *af, hearth_err *err);

/* mkdir -p (mode 0755); directories that exist already are fine. */
hearth_status hearth_mkdirs(const char *path, hearth_err *err);
/* 1 if path exists (file or directory). */
int hearth_path_exists(const char *path);
/* Remove a directory tree (used to discard a half-built temporary tree). */
hearth_status hearth_remove_tree(const char *path, hearth_err *err);
/* snprintf into buf, joining parts with '/'. Returns HEARTH_E_LIMIT if it
 * does not fit. */
hearth_status hearth_path_join(char *buf, size_t bufsz, const char *a, const char *b);
/* path relative to root when it lies under root (textually), else path
 * itself: what documents record, so a moved release keeps its bytes. The
 * result points into path (nothing allocated). */
const char *hearth_path_under(const char *root, const char *path);

/* ---- threads --------------------------------------------------------------- */
/* Number of worker threads to use when a caller passes 0: $HEARTH_THREADS if
 * set to 1..1024, else the online processor count (1..256). */
int hearth_default_threads(void);

/* Run fn over [0, n) split into contiguous chunks, one per thread, in
 * parallel. Chunk boundaries depend only on n and the chunk count, never on
 * timing; callers that need thread-count-independent output write results by
 * index and reduce in index order. thread_index < nthreads identifies
 * per-thread scratch. */
typedef void (*hearth_range_fn)(void *ctx, size_t begin, size_t end, int thread_index);
hearth_status hearth_parallel_for(size_t n, int nthreads, hearth_range_fn fn, void *ctx);
/* Run fn over [0, n) in chunks of `chunk` indices ([b, min(b + chunk, n))),
 * each taken by whichever of nthreads workers is free first: uneven items
 * and a busy machine cannot leave one worker with the tail. Which worker
 * (thread_index) runs a chunk depends on timing, so fn must write results by
 * index only; per-worker scratch is fine, per-worker results only if their
 * reduction does not depend on which indices a worker saw (integer sums,
 * minima, maxima). */
hearth_status hearth_parallel_chunks(size_t n, size_t chunk, int nthreads, hearth_range_fn fn,
                                     void *ctx);

/* ---- locale-independent numbers ------------------------------------------ */
/* Parse a decimal number from s[0..len): optional sign, digits, optional
 * '.' or ',' (if decimal_comma) fraction, optional exponent. The whole span
 * must be consumed. Rejects NaN/Inf spellings. Returns 0 on success. */
int hearth_parse_double(const char *s, size_t len, int decimal_comma, double *out);
/* Write x with `decimals` fixed decimals using '.', independent of locale.
 * Returns the length written (excluding NUL) or -1 if it did not fit. */
int hearth_format_fixed(char *buf, size_t bufsz, double x, int decimals);

/* ---- growing text ------------------------------------------------------------ */
/* A NUL-terminated text that grows as printf-style pieces are appended.
 * Start from a zeroed buffer (hearth_strbuf b = {0}); data stays NULL until
 * the first append and is owned by the buffer until hearth_strbuf_take or
 * hearth_strbuf_free. An allocation or formatting failure sets `failed`;
 * later appends then do nothing, so callers check once at the end. */
typedef struct hearth_strbuf {
  char *data; /* len bytes plus a NUL, or NULL while empty */
  size_t len, cap;
  int failed;
} hearth_strbuf;
void hearth_strbuf_printf(hearth_strbuf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* The text, malloc'ed (the caller frees it; "" when nothing was appended),
 * or NULL after a failure; the buffer is left empty either way. */
char *hearth_strbuf_take(hearth_strbuf *b);
/* Free the text and zero the buffer; accepts a zeroed buffer. */
void hearth_strbuf_free(hearth_strbuf *b);

/* ---- deterministic random numbers ------------------------------------------ */
/* A small counter-based generator (SplitMix64 seeding, xoshiro256**):
 * same seed, same stream on every machine. */
typedef struct hearth_rng {
  uint64_t s[4];
} hearth_rng;
void hearth_rng_seed(hearth_rng *r, uint64_t seed);
/* Derive an independent stream for a named sub-task (e.g. view index);
 * the parent is not advanced, so forks do not depend on call order. */
void hearth_rng_fork(const hearth_rng *parent, uint64_t stream, hearth_rng *child);
uint64_t hearth_rng_u64(hearth_rng *r);
double hearth_rng_uniform(hearth_rng *r);                     /* [0, 1) */
double hearth_rng_range(hearth_rng *r, double lo, double hi); /* [lo, hi) */
double hearth_rng_normal(hearth_rng *r);                      /* N(0, 1) */

/* ---- progress -------------------------------------------------------------- */
/* A progress reporter for long jobs, on stderr: a bar on a terminal, plain
 * lines otherwise (one every ~5 %), silent if quiet. label is borrowed
 * (must outlive the reporter); nothing is allocated. Not thread-safe: call
 * hearth_progress_step (k more items done) from one thread. */
typedef struct hearth_progress {
  const char *label;
  size_t total, done;
  int is_tty, quiet, last_percent;
  double t_start;
  FILE *out;
} hearth_progress;
void hearth_progress_begin(hearth_progress *p, const char *label, size_t total, int quiet);
void hearth_progress_step(hearth_progress *p, size_t k);
void hearth_progress_end(hearth_progress *p);
/* Monotonic seconds (CLOCK_MONOTONIC), for durations only. */
double hearth_now(void);

#ifdef __cplusplus
}
#endif
#endif
