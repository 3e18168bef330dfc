/* Status names and error reports. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/core.h"

const char *hearth_status_name(hearth_status s) {
  switch (s) {
    case HEARTH_OK: return "HEARTH_OK";
    case HEARTH_E_ARG: return "HEARTH_E_ARG";
    case HEARTH_E_NOMEM: return "HEARTH_E_NOMEM";
    case HEARTH_E_IO: return "HEARTH_E_IO";
    case HEARTH_E_PARSE: return "HEARTH_E_PARSE";
    case HEARTH_E_UNSUPPORTED: return "HEARTH_E_UNSUPPORTED";
    case HEARTH_E_RANGE: return "HEARTH_E_RANGE";
    case HEARTH_E_SIZE: return "HEARTH_E_SIZE";
    case HEARTH_E_INCONSISTENT: return "HEARTH_E_INCONSISTENT";
    case HEARTH_E_NUMERIC: return "HEARTH_E_NUMERIC";
    case HEARTH_E_NOT_FOUND: return "HEARTH_E_NOT_FOUND";
    case HEARTH_E_LIMIT: return "HEARTH_E_LIMIT";
  }
  return "HEARTH_E_UNKNOWN";
}

const char *hearth_strerror(hearth_status s) {
  switch (s) {
    case HEARTH_OK: return "success";
    case HEARTH_E_ARG: return "invalid argument";
    case HEARTH_E_NOMEM: return "out of memory or size overflow";
    case HEARTH_E_IO: return "input/output error";
    case HEARTH_E_PARSE: return "malformed input";
    case HEARTH_E_UNSUPPORTED: return "unsupported feature";
    case HEARTH_E_RANGE: return "value out of range";
    case HEARTH_E_SIZE: return "wrong dimensions";
    case HEARTH_E_INCONSISTENT: return "inconsistent data";
    case HEARTH_E_NUMERIC: return "numerical failure";
    case HEARTH_E_NOT_FOUND: return "not found";
    case HEARTH_E_LIMIT: return "safety limit exceeded";
  }
  return "unknown status";
}

hearth_status hearth_err_set(hearth_err *err, hearth_status s, const char *fmt, ...) {
  if (!err) return s;
  err->status = s;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->msg, sizeof err->msg, fmt, ap);
  va_end(ap);
  return s;
}

hearth_status hearth_err_prefix(hearth_err *err, const char *fmt, ...) {
  if (!err) return HEARTH_OK;
  char prefix[512], old[sizeof err->msg];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(prefix, sizeof prefix, fmt, ap);
  va_end(ap);
  memcpy(old, err->msg, sizeof old);
  snprintf(err->msg, sizeof err->msg, "%s: %s", prefix, old);
  return err->status;
}

int hearth_mul_size(size_t a, size_t b, size_t *out) {
  if (a != 0 && b > SIZE_MAX / a) return 0;
  *out = a * b;
  return 1;
}

void *hearth_alloc_array(size_t n, size_t size) {
  size_t bytes;
  if (!hearth_mul_size(n, size, &bytes)) return NULL;
  return malloc(bytes ? bytes : 1);
}

void *hearth_calloc_array(size_t n, size_t size) {
  size_t bytes;
  if (!hearth_mul_size(n, size, &bytes)) return NULL;
  /* written, not left to calloc's lazily mapped zero pages: a zero page
   * that is read and then written costs a copy-on-write fault and a TLB
   * shootdown on every core (the splat and fill loops read before they
   * write; 13% of a mapping run in a VM) */
  void *p = malloc(bytes ? bytes : 1);
  /* explicit_bzero: a plain memset after malloc is turned back into calloc
   * by the compiler */
  if (p) explicit_bzero(p, bytes ? bytes : 1);
  return p;
}
