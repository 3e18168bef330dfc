/* hearth_strbuf: printf-style appends to a growing, NUL-terminated text. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/core.h"

void hearth_strbuf_printf(hearth_strbuf *b, const char *fmt, ...) {
  if (b->failed) return;
  /* format into the free space; when the piece does not fit, grow to
   * hold it (and at least double) and format again */
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(b->data ? b->data + b->len : NULL, b->data ? b->cap - b->len : 0, fmt, ap);
    va_end(ap);
    if (k < 0) {
      b->failed = 1;
      return;
    }
    if (b->data && (size_t)k < b->cap - b->len) {
      b->len += (size_t)k;
      return;
    }
    size_t need = b->len + (size_t)k + 1, cap = b->cap ? b->cap : 256;
    while (cap < need) {
      if (cap > (size_t)-1 / 2) {
        b->failed = 1;
        return;
      }
      cap *= 2;
    }
    char *p = realloc(b->data, cap);
    if (!p) {
      b->failed = 1;
      return;
    }
    b->data = p, b->cap = cap;
  }
}

char *hearth_strbuf_take(hearth_strbuf *b) {
  char *s = b->failed ? NULL : b->data;
  if (b->failed) free(b->data);
  else if (!s && (s = malloc(1))) s[0] = 0;
  memset(b, 0, sizeof *b);
  return s;
}

void hearth_strbuf_free(hearth_strbuf *b) {
  if (!b) return;
  free(b->data);
  memset(b, 0, sizeof *b);
}
