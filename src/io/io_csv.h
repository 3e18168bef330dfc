/* Internal to the thermal CSV reader (io_csv.c: cells, lines and layouts;
 * io_csv_text.c: text decoding, metadata and units). */
#ifndef HEARTH_IO_CSV_H
#define HEARTH_IO_CSV_H

#include <stddef.h>
#include "hearth/thermal.h"

/* input larger than this is refused: a 256x192 matrix is ~0.4 MB, 640x512 ~2.5 MB */
#define CSV_MAX_BYTES ((size_t)64 << 20)
/* metadata pairs kept in a hearth_thermal_info, and bytes per key or value */
#define CSV_MAX_META 256
#define CSV_MAX_META_TEXT 255

enum { CELL_OK = 0, CELL_RANGE, CELL_NANINF, CELL_EMPTY, CELL_GARBAGE, CELL_QUOTE };

/* the text being read and how to report places in it */
typedef struct csv_ctx {
  const char *name; /* file name for messages */
  const char *s;    /* UTF-8 or 8-bit text with '\n' line ends */
  size_t len;
  char sep;
  int utf8; /* columns count UTF-8 characters; else bytes */
} csv_ctx;

/* one cell as found by the tokenizer */
typedef struct csv_cell {
  size_t at;     /* offset of the cell's first non-blank byte (the quote if quoted) */
  size_t cs, ce; /* content span, without quotes and surrounding blanks */
  int quoted, comma, bad_quote;
} csv_cell;

static inline int csv_is_blank(char c, char sep) { return c == ' ' || (c == '\t' && sep != '\t'); }

/* Take the cell at *pp (the line ends at b). On return *pp is at the
 * separator that ended the cell, or at b. Returns 0 when the line has no
 * more cells (only blanks after a separator, i.e. a trailing separator, or
 * an empty line). */
static inline int csv_next_cell(const char *s, size_t *pp, size_t b, char sep, size_t ncells,
                                csv_cell *c) {
  size_t p = *pp;
  while (p < b && csv_is_blank(s[p], sep)) p++;
  if (p >= b && ncells > 0 && *pp > 0 && s[*pp - 1] == sep) {
    /* "1,2,3," : one trailing separator ends the line */
    *pp = p;
    return 0;
  }
  c->at = p;
  c->quoted = c->comma = c->bad_quote = 0;
  if (p < b && s[p] == '"') {
    c->quoted = 1;
    c->cs = ++p;
    while (p < b && s[p] != '"') {
      if (s[p] == ',') c->comma = 1;
      p++;
    }
    c->ce = p;
    if (p >= b) {
      c->bad_quote = 1; /* unterminated */
    } else {
      p++;
      while (p < b && csv_is_blank(s[p], sep)) p++;
      if (p < b && s[p] != sep) {
        c->bad_quote = 2; /* text after the closing quote */
        while (p < b && s[p] != sep) p++;
      }
    }
    /* blanks inside the quotes are tolerated */
    while (c->cs < c->ce && (s[c->cs] == ' ' || s[c->cs] == '\t')) c->cs++;
    while (c->ce > c->cs && (s[c->ce - 1] == ' ' || s[c->ce - 1] == '\t')) c->ce--;
  } else {
    c->cs = p;
    while (p < b && s[p] != sep) {
      if (s[p] == ',') c->comma = 1;
      p++;
    }
    size_t e = p;
    while (e > c->cs && csv_is_blank(s[e - 1], sep)) e--;
    c->ce = e;
  }
  *pp = p;
  return 1;
}

/* 1-based column of byte offset `at` in a line starting at `start`. */
size_t csv_column(const csv_ctx *c, size_t start, size_t at);

/* ---- text decoding (io_csv_text.c) ----------------------------------------- */
/* The text to scan: the caller's bytes, or a decoded copy for UTF-16 input
 * and CR line ends. */
typedef struct csv_text {
  const char *s;
  size_t len, start; /* start: the first byte after a byte order mark */
  char *own;         /* the decoded copy, if any (freed by csv_text_free) */
  const char *bom;   /* "utf-8-bom", "utf-16le-bom", "utf-16be-bom" or NULL */
  int cr_only;       /* line ends were '\r' alone (now '\n' in own) */
} csv_text;
hearth_status csv_text_open(csv_text *t, const char *text, size_t len, const char *name,
                            hearth_err *err);
void csv_text_free(csv_text *t);
/* 1 if s[a..b) is valid UTF-8. */
int csv_utf8_valid(const char *s, size_t a, size_t b);

/* ---- metadata (io_csv_text.c) ---------------------------------------------- */
/* What the metadata lines say of the temperature unit. */
typedef struct csv_unit {
  int celsius;            /* a line says degC */
  int other;              /* 1: another or an unknown unit (refused) */
  size_t line, start, at; /* where (line, line start, byte of the cell) */
  char what[48];          /* the unit as written, printable */
} csv_unit;
/* Look at the metadata line s[start..end) for a unit. */
void csv_unit_scan(const csv_ctx *c, size_t line, size_t start, size_t end, csv_unit *u);
/* Append the line's key/value pair to info->meta (up to CSV_MAX_META).
 * Returns 0 when out of memory. */
int csv_meta_add(const csv_ctx *c, size_t line, size_t start, size_t end,
                 hearth_thermal_info *info);
/* A cell's text as a NUL-terminated UTF-8 copy (see hearth_csv_meta). */
char *csv_text_copy(const csv_ctx *c, size_t a, size_t b);

#endif
