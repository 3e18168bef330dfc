/* Thermal CSV reader: apparent-temperature matrices in degC.
 *
 * Three phases. Text (io_csv_text.c): byte order marks, UTF-16 and CR line
 * ends become UTF-8 or 8-bit text with '\n' line ends. Scan: one forward
 * pass splits lines, tokenizes cells and parses every number once, keeping
 * one record per non-blank line (its cells, how many are numbers, where its
 * values start, whether it looks like data or text). Layout: from those
 * records alone, find the matrix (the data lines that end the file) and
 * what leads it (metadata lines, a size line, an index row, a frame label),
 * then check every matrix line. Only when something is wrong does it go
 * back over the offending line to say which cell, where, and what was
 * expected. Lines are 1-based counting header lines; columns are 1-based
 * characters (bytes for 8-bit text) from the line start (a BOM is not
 * counted), at the cell's first non-blank character. */
#include <stdlib.h>
#include <string.h>
#include "io/io_csv.h"

#define NONE ((size_t)-1)

/* a non-blank line */
typedef struct csv_row {
  size_t line_no, start, end; /* end excludes "\r\n" */
  size_t ncells, nnum;        /* cells, and cells that are numbers (any value) */
  size_t nbad, nempty;        /* cells that are not temperatures; empty cells */
  size_t voff;                /* index of its first value in the value buffer */
  size_t blank_before;        /* first blank line between it and the row before, or 0 */
  unsigned char first_kind;   /* CELL_* of its first cell */
  unsigned char data;         /* looks like data (else text) */
  unsigned char qcomma;       /* a quoted value with a decimal comma */
} csv_row;

/* the forward pass's output: one value per cell of every kept line */
typedef struct csv_buf {
  float *vals;
  size_t nvals, capvals;
  csv_row *rows;
  size_t nrows, caprows;
  size_t lines, n_lf, n_crlf; /* lines in all; line ends seen */
} csv_buf;

/* NaN / infinity spellings, including the ones spreadsheets and MSVC print
 * ("-1.#IND", "1.#INF", "#N/A"). */
static int is_naninf(const char *s, size_t n) {
  size_t i = 0;
  if (i < n && (s[i] == '+' || s[i] == '-')) i++;
  char w[8];
  size_t k = 0;
  for (; i < n && k < sizeof w - 1; i++) {
    char ch = s[i];
    if (ch >= 'A' && ch <= 'Z') ch = (char)(ch - 'A' + 'a');
    w[k++] = ch;
  }
  w[k] = 0;
  if (!strncmp(w, "nan", 3) || !strncmp(w, "inf", 3) || !strncmp(w, "#n/a", 4)) return 1;
  for (i = 0; i + 1 < n; i++)
    if (s[i] == '.' && s[i + 1] == '#') return 1;
  return 0;
}

/* The value of a plain decimal with at most 15 digits, computed exactly as
 * hearth_parse_double does (one correctly rounded division of exact
 * operands), so both paths give the same bits. */
static const double k_p10[16] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
static inline double plain_value(uint64_t mant, int frac, int neg) {
  double v = mant == 0 ? 0.0 : frac ? (double)mant / k_p10[frac] : (double)mant;
  return neg ? -v : v;
}

/* A bare decimal cell at s[*p..]: optional sign, digits, optionally a
 * decimal mark ('.', or ',' where the separator is not ',') and digits; at
 * most 15 digits in all, ending at the line's end b or at the separator.
 * On success its value goes to *v, *p moves to its end and 1 is returned;
 * otherwise nothing changes. checked 0 skips the bound checks of the scans:
 * only where s[b] exists and is no sign, digit or decimal mark (a line's
 * '\r' or '\n'). */
static inline int plain_cell(const char *s, size_t *p, size_t b, char sep, int checked, double *v) {
  size_t q = *p;
  int neg = 0, nd = 0, frac = 0;
  uint64_t mant = 0;
  if ((!checked || q < b) && (s[q] == '-' || s[q] == '+')) neg = s[q++] == '-';
  while ((!checked || q < b) && (unsigned)(s[q] - '0') < 10) {
    mant = mant * 10 + (uint64_t)(s[q++] - '0');
    nd++;
  }
  if ((!checked || q < b) && (s[q] == '.' || (s[q] == ',' && sep != ','))) {
    q++;
    while ((!checked || q < b) && (unsigned)(s[q] - '0') < 10) {
      mant = mant * 10 + (uint64_t)(s[q++] - '0');
      nd++;
      frac++;
    }
  }
  if (!(nd > 0 && nd <= 15 && (q == b || s[q] == sep))) return 0;
  *v = plain_value(mant, frac, neg);
  *p = q;
  return 1;
}

/* Classify a cell and parse its value. */
static inline int eval_cell(const char *s, const csv_cell *c, double *v) {
  if (c->bad_quote) return CELL_QUOTE;
  if (c->ce == c->cs) return CELL_EMPTY;
  if (hearth_parse_double(s + c->cs, c->ce - c->cs, c->comma, v) == 0) {
    if (!(*v >= HEARTH_THERMAL_MIN_C && *v <= HEARTH_THERMAL_MAX_C)) return CELL_RANGE;
    return CELL_OK;
  }
  return is_naninf(s + c->cs, c->ce - c->cs) ? CELL_NANINF : CELL_GARBAGE;
}

size_t csv_column(const csv_ctx *c, size_t start, size_t at) {
  if (!c->utf8) return at - start + 1;
  size_t col = 1; /* UTF-8 continuation bytes do not start a character */
  for (size_t i = start; i < at; i++)
    if (((unsigned char)c->s[i] & 0xC0) != 0x80) col++;
  return col;
}

/* A printable excerpt of a cell for messages: non-printable bytes as \xNN,
 * cut with "..." when long. outsz must be at least 8. */
static void excerpt(const char *s, size_t a, size_t b, char *out, size_t outsz) {
  static const char hex[] = "0123456789abcdef";
  size_t k = 0;
  for (size_t i = a; i < b; i++) {
    /* room for the widest byte (4), a "..." (3) and the NUL */
    if (k + 8 > outsz) {
      memcpy(out + k, "...", 3);
      k += 3;
      break;
    }
    unsigned char ch = (unsigned char)s[i];
    if (ch >= 0x20 && ch < 0x7F && ch != '\'') {
      out[k++] = (char)ch;
    } else {
      out[k++] = '\\';
      out[k++] = 'x';
      out[k++] = hex[ch >> 4];
      out[k++] = hex[ch & 15];
    }
  }
  out[k] = 0;
}

static hearth_status cell_error(const csv_ctx *c, const csv_row *r, const csv_cell *cell, int kind,
                                double v, hearth_err *err) {
  const char *s = c->s, *name = c->name;
  char ex[48];
  size_t col = csv_column(c, r->start, cell->at);
  excerpt(s, cell->quoted ? cell->cs : cell->at, cell->ce, ex, sizeof ex);
  switch (kind) {
    case CELL_RANGE: {
      char num[64];
      if (hearth_format_fixed(num, sizeof num, v, 3) < 0)
        excerpt(s, cell->cs, cell->ce, num, sizeof num);
      return hearth_err_set(err, HEARTH_E_RANGE,
                            "%s: line %zu, column %zu: temperature %s degC is out of range, "
                            "expected %g..%g degC",
                            name, r->line_no, col, num, HEARTH_THERMAL_MIN_C, HEARTH_THERMAL_MAX_C);
    }
    case CELL_NANINF:
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column %zu: '%s' is not a finite number, expected a "
                            "temperature in degC",
                            name, r->line_no, col, ex);
    case CELL_EMPTY:
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column %zu: empty cell, expected a temperature in degC",
                            name, r->line_no, col);
    case CELL_QUOTE:
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column %zu: %s, expected \"number\" followed by a "
                            "separator or the end of the line",
                            name, r->line_no, col,
                            cell->bad_quote == 1 ? "unterminated quote"
                                                 : "text after closing quote");
    default:
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column %zu: '%s' is not a number, expected a "
                            "temperature in degC",
                            name, r->line_no, col, ex);
  }
}

/* Go back over a row known to be wrong and report its first problem: the
 * `lead` label cells are skipped, then n_exp values are expected. */
static hearth_status row_error(const csv_ctx *c, const csv_row *r, size_t lead, size_t n_exp,
                               const char *shape, hearth_err *err) {
  size_t p = r->start, n = 0, k = 0;
  csv_cell cell;
  while (csv_next_cell(c->s, &p, r->end, c->sep, k, &cell)) {
    if (k++ >= lead) {
      if (n == n_exp)
        return hearth_err_set(err, HEARTH_E_SIZE,
                              "%s: line %zu, column %zu: row has more than %zu values, expected "
                              "%zu%s",
                              c->name, r->line_no, csv_column(c, r->start, cell.at), n_exp, n_exp,
                              shape);
      double v = 0;
      int kind = eval_cell(c->s, &cell, &v);
      if (kind != CELL_OK) return cell_error(c, r, &cell, kind, v, err);
      n++;
    }
    if (p >= r->end) break;
    p++;
  }
  if (n < n_exp)
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: line %zu, column %zu: row has %zu values, expected %zu%s", c->name,
                          r->line_no, csv_column(c, r->start, r->end), n, n_exp, shape);
  return hearth_err_set(err, HEARTH_E_PARSE, "%s: line %zu: malformed row", c->name, r->line_no);
}

static int grow(void **p, size_t *cap, size_t need, size_t elsz) {
  if (need <= *cap) return 1;
  size_t nc = *cap ? *cap : 64;
  while (nc < need) {
    if (nc > ((size_t)-1) / 2) return 0;
    nc *= 2;
  }
  size_t bytes;
  if (!hearth_mul_size(nc, elsz, &bytes)) return 0;
  void *q = realloc(*p, bytes);
  if (!q) return 0;
  *p = q;
  *cap = nc;
  return 1;
}

/* The separator: ';' or tab if the last non-empty line uses them outside
 * quotes, else ','. */
static char detect_sep(const char *s, size_t a, size_t len) {
  size_t e = len;
  while (e > a && (s[e - 1] == '\n' || s[e - 1] == '\r' || s[e - 1] == ' ' || s[e - 1] == '\t'))
    e--;
  size_t b = e;
  while (b > a && s[b - 1] != '\n') b--;
  size_t semi = 0, tab = 0;
  int inq = 0;
  for (size_t i = b; i < e; i++) {
    if (s[i] == '"') inq = !inq;
    else if (!inq && s[i] == ';') semi++;
    else if (!inq && s[i] == '\t') tab++;
  }
  if (tab && tab >= semi) return '\t';
  if (semi) return ';';
  return ',';
}

/* The fastest path, for the usual file: a run of bare decimals ("-12.34")
 * in range and separators from s[*pp] on a line that a newline ends (s[b]
 * is '\r' or '\n', so every digit scan stops there without a bound check).
 * Their values go to vals (room for (b - *pp) / 2 + 1); *pp stops at the
 * first cell that is anything else, or out of range, for the general loop
 * to take from there (the values are the same either way). *done is set
 * when the line ended. Returns the cells taken. */
static size_t fast_cells(const char *s, size_t *pp, size_t b, char sep, float *vals, int *done) {
  size_t p = *pp, n = 0;
  for (;;) {
    double v;
    size_t q = p;
    if (!plain_cell(s, &q, b, sep, 0, &v) ||
        !(v >= HEARTH_THERMAL_MIN_C && v <= HEARTH_THERMAL_MAX_C))
      break;
    p = q;
    vals[n++] = (float)v;
    if (p >= b || ++p >= b) { /* the line's end, or one trailing separator */
      *done = 1;
      break;
    }
  }
  *pp = p;
  return n;
}

/* ---- scan: the forward pass ------------------------------------------------ */
static hearth_status scan(const csv_ctx *c, size_t pos, csv_buf *B, hearth_err *err) {
  const char *s = c->s, *name = c->name;
  size_t len = c->len, line_no = 0, pending_blank = 0;
  char sep = c->sep;
  /* a first guess at the number of values avoids most regrowth */
  if (!grow((void **)&B->vals, &B->capvals, len / 6 + 16, sizeof(float)) ||
      !grow((void **)&B->rows, &B->caprows, 256, sizeof(csv_row)))
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
  /* the value buffer in locals, which the compiler keeps in registers
   * (B->vals and B->capvals stay current; B->nvals is set at the end) */
  float *vals = B->vals;
  size_t nvals = 0, capvals = B->capvals;

  while (pos < len) {
    const char *nl = memchr(s + pos, '\n', len - pos);
    size_t a = pos, b = nl ? (size_t)(nl - s) : len;
    pos = nl ? b + 1 : len;
    line_no++;
    if (b > a && s[b - 1] == '\r') {
      b--;
      B->n_crlf += nl != NULL;
    } else {
      B->n_lf += nl != NULL;
    }
    csv_row r = {line_no, a, b, 0, 0, 0, 0, nvals, 0, CELL_OK, 0, 0};
    size_t p = a;
    int first_numeric = 0, line_done = 0;
    /* the usual line first (fast_cells), then the rest of it cell by cell */
    if (b < len && p < b) {
      /* room for every cell fast_cells can take: a byte and a separator each */
      if (capvals - nvals < (b - a) / 2 + 2) {
        if (!grow((void **)&B->vals, &B->capvals, nvals + (b - a) / 2 + 2, sizeof(float)))
          return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
        vals = B->vals;
        capvals = B->capvals;
      }
      size_t taken = fast_cells(s, &p, b, sep, vals + nvals, &line_done);
      nvals += taken;
      r.nnum = r.ncells = taken;
      first_numeric = r.ncells > 0; /* every cell this path took is a number */
    }
    for (; !line_done;) {
      double v = 0;
      int kind;
      /* fast path: a bare decimal ending at a separator or the line end */
      if (plain_cell(s, &p, b, sep, 1, &v)) {
        kind = v >= HEARTH_THERMAL_MIN_C && v <= HEARTH_THERMAL_MAX_C ? CELL_OK : CELL_RANGE;
      } else {
        csv_cell cell;
        if (!csv_next_cell(s, &p, b, sep, r.ncells, &cell)) break;
        if (r.ncells == 0 && cell.ce == cell.cs && !cell.quoted && p >= b) break; /* blank line */
        kind = eval_cell(s, &cell, &v);
        if (kind == CELL_OK && cell.quoted && cell.comma) r.qcomma = 1;
      }
      if (kind != CELL_OK) r.nbad++;
      if (kind == CELL_EMPTY) r.nempty++;
      if (r.ncells == 0) r.first_kind = (unsigned char)kind;
      if (kind == CELL_OK || kind == CELL_RANGE || kind == CELL_NANINF) {
        r.nnum++;
        if (r.ncells == 0) first_numeric = 1;
      }
      if (nvals == capvals) {
        if (!grow((void **)&B->vals, &B->capvals, nvals + 1, sizeof(float)))
          return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
        vals = B->vals;
        capvals = B->capvals;
      }
      vals[nvals++] = kind == CELL_OK ? (float)v : 0.0f;
      r.ncells++;
      if (p >= b) break;
      p++;               /* over the separator */
      if (p >= b) break; /* one trailing separator */
    }
    if (r.ncells == r.nempty) { /* an empty line, or separators only */
      nvals = r.voff;
      if (B->nrows && !pending_blank) pending_blank = line_no;
      continue;
    }
    r.data = r.nnum == r.ncells || (r.nnum >= 1 && first_numeric) ||
             (r.nnum >= 8 && 2 * r.nnum > r.ncells) ||
             (r.first_kind == CELL_EMPTY && r.ncells >= 2 && r.nnum + 1 == r.ncells);
    r.blank_before = pending_blank;
    pending_blank = 0;
    if (!grow((void **)&B->rows, &B->caprows, B->nrows + 1, sizeof(csv_row)))
      return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
    B->rows[B->nrows++] = r;
  }
  B->nvals = nvals;
  B->lines = line_no;
  return HEARTH_OK;
}

/* ---- layout ------------------------------------------------------------------ */
/* Boyer-Moore majority vote over the cell counts of rows[a..b], full numeric
 * rows only when there are any. */
static size_t majority_cells(const csv_row *rows, size_t a, size_t b) {
  size_t cand = 0, cnt = 0;
  int any_full = 0;
  for (size_t i = a; i <= b; i++)
    if (rows[i].nnum == rows[i].ncells) any_full = 1;
  for (size_t i = a; i <= b; i++) {
    if (any_full && rows[i].nnum != rows[i].ncells) continue;
    if (cnt == 0) {
      cand = rows[i].ncells;
      cnt = 1;
    } else if (rows[i].ncells == cand) {
      cnt++;
    } else {
      cnt--;
    }
  }
  return cand;
}

/* Cell k (0-based) of row r into *cell; 0 if the row has fewer cells. */
static int row_cell(const csv_ctx *c, const csv_row *r, size_t k, csv_cell *cell) {
  size_t p = r->start, n = 0;
  while (csv_next_cell(c->s, &p, r->end, c->sep, n, cell)) {
    if (n++ == k) return 1;
    if (p >= r->end) break;
    p++;
  }
  return 0;
}

/* The cell's text as a plain non-negative integer (digits only, at most 9). */
static int cell_uint(const char *s, const csv_cell *cell, size_t *v) {
  size_t n = cell->ce - cell->cs, x = 0;
  if (cell->bad_quote || n == 0 || n > 9) return 0;
  for (size_t i = cell->cs; i < cell->ce; i++) {
    if ((unsigned)(s[i] - '0') >= 10) return 0;
    x = x * 10 + (size_t)(s[i] - '0');
  }
  *v = x;
  return 1;
}

static int row_uint(const csv_ctx *c, const csv_row *r, size_t k, size_t *v) {
  csv_cell cell;
  return row_cell(c, r, k, &cell) && cell_uint(c->s, &cell, v);
}

/* a "W,H" size line candidate: two plain integers */
static int size_pair(const csv_ctx *c, const csv_row *r, size_t *w, size_t *h) {
  return r->ncells == 2 && r->nnum == 2 && row_uint(c, r, 0, w) && row_uint(c, r, 1, h);
}

/* a first cell that is no number (a label, or empty) before numbers */
static int lead_label(const csv_row *r) {
  return (r->first_kind == CELL_GARBAGE || r->first_kind == CELL_EMPTY) && r->ncells >= 2 &&
         r->nnum + 1 == r->ncells;
}

/* row r reads as the column indices "label,0,1,..." of an axis-labelled
 * matrix whose first row d is numbered 0 (r's later cells are checked
 * later, so that a wrong index is reported as one) */
static int index_like(const csv_ctx *c, const csv_row *r, const csv_row *d) {
  size_t v0, v1, d0;
  return (r->first_kind == CELL_GARBAGE || r->first_kind == CELL_EMPTY) && r->ncells >= 2 &&
         row_uint(c, r, 1, &v0) && v0 == 0 && row_uint(c, d, 0, &d0) && d0 == 0 &&
         (r->ncells == d->ncells || (row_uint(c, r, 2, &v1) && v1 == 1));
}

/* what was found: rows are indices into the row records */
typedef struct csv_layout {
  hearth_csv_layout kind;
  size_t top;         /* first matrix row (index row or label row included) */
  size_t first, last; /* rows holding values */
  size_t lead;        /* label cells before the values of each row (0 or 1) */
  size_t index;       /* the index row (axis-labelled), or NONE */
  size_t size;        /* the size line, or NONE */
  size_t size_w, size_h;
  size_t meta_end; /* rows before this are metadata */
} csv_layout;

static hearth_status blank_inside(const csv_ctx *c, size_t blank, size_t above, size_t below,
                                  hearth_err *err) {
  return hearth_err_set(err, HEARTH_E_PARSE,
                        "%s: line %zu, column 1: blank line inside the matrix (between its lines "
                        "%zu and %zu), expected its rows without blank lines between them",
                        c->name, blank, above, below);
}

/* Find the matrix and what leads it. */
static hearth_status find_layout(const csv_ctx *c, const csv_buf *B, const char *shape,
                                 csv_layout *L, hearth_err *err) {
  const csv_row *R = B->rows;
  size_t n = B->nrows, last = NONE;
  for (size_t i = n; i-- > 0;)
    if (R[i].data) {
      last = i;
      break;
    }
  if (last == NONE)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line %zu, column 1: no numeric rows found, expected a matrix of "
                          "temperatures%s",
                          c->name, B->lines + 1, shape);
  /* text after the matrix */
  if (last + 1 < n) return row_error(c, &R[last + 1], 0, NONE, shape, err);

  /* the body: the data rows that end the file, without blank or text lines */
  size_t f = last;
  while (f > 0 && R[f - 1].data && !R[f].blank_before) f--;
  size_t above = f > 0 && !R[f - 1].data ? f - 1 : NONE;
  *L = (csv_layout){HEARTH_CSV_PLAIN, f, f, last, 0, NONE, NONE, 0, 0, 0};

  /* a size line at the top of the body */
  size_t sw, sh;
  if (f < last && size_pair(c, &R[f], &sw, &sh)) {
    size_t rest = majority_cells(R, f + 1, last);
    if (rest != 2) {
      L->size = f;
      L->size_w = sw;
      L->size_h = sh;
      f++;
      above = NONE;
    } else if (sw == 2 && sh == last - f) {
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column 1: '%zu%c%zu' may be a W,H size line or the "
                            "first row of the matrix, expected a matrix that tells them apart",
                            c->name, R[f].line_no, sw, c->sep, sh);
    }
  }

  /* an index row, or a frame label, at the top */
  if (f < last && index_like(c, &R[f], &R[f + 1])) {
    L->kind = HEARTH_CSV_AXIS;
    L->index = L->top = f;
    L->first = f + 1;
  } else if (above != NONE && index_like(c, &R[above], &R[f])) {
    L->kind = HEARTH_CSV_AXIS;
    L->index = L->top = above;
    L->first = f;
  } else if (f < last && R[f].first_kind == CELL_GARBAGE && lead_label(&R[f]) &&
             R[f + 1].first_kind == CELL_EMPTY) {
    L->kind = HEARTH_CSV_FRAME;
    L->top = L->first = f;
  } else if (above != NONE && R[above].first_kind == CELL_GARBAGE && lead_label(&R[above]) &&
             R[f].first_kind == CELL_EMPTY) {
    L->kind = HEARTH_CSV_FRAME;
    L->top = L->first = above;
  } else {
    L->top = L->first = f;
  }
  L->lead = L->kind == HEARTH_CSV_PLAIN ? 0 : 1;
  if (L->top == above && R[f].blank_before)
    return blank_inside(c, R[f].blank_before, R[above].line_no, R[f].line_no, err);

  /* a data row above the matrix: a size line after blank lines, or rows of
   * the matrix that a blank line cut off, or numbers that are neither */
  size_t lim = L->size != NONE ? L->size : L->top;
  if (L->size == NONE && lim > 0 && R[lim - 1].data) {
    size_t p = lim - 1, q = p;
    while (q > 0 && R[q - 1].data && !R[q].blank_before) q--;
    if (R[lim].blank_before && R[p].ncells == R[L->first].ncells) {
      return blank_inside(c, R[lim].blank_before, R[p].line_no, R[lim].line_no, err);
    } else if (q == p && size_pair(c, &R[p], &sw, &sh)) {
      L->size = p;
      L->size_w = sw;
      L->size_h = sh;
      lim = p;
    } else {
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column 1: a row of %zu value(s) before the matrix of "
                            "line %zu, expected metadata lines or a W,H size line before the "
                            "matrix",
                            c->name, R[q].line_no, R[q].ncells, R[L->top].line_no);
    }
  }
  /* before that, metadata lines only */
  for (size_t i = 0; i < lim; i++) {
    if (!R[i].data) continue;
    size_t t = i;
    while (t < lim && R[t].data) t++;
    if (t < lim && R[t].ncells == R[L->first].ncells && R[t - 1].ncells == R[t].ncells)
      return row_error(c, &R[t], 0, NONE, shape, err); /* a text row inside the matrix */
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line %zu, column 1: a row of %zu value(s) before the %s of line "
                          "%zu, expected metadata lines first, then the matrix",
                          c->name, R[i].line_no, R[i].ncells, t < lim ? "metadata" : "size line",
                          R[t].line_no);
  }
  L->meta_end = lim;
  return HEARTH_OK;
}

/* The axis-labelled matrix's index row: 0..w-1 after the corner. */
static hearth_status check_index_row(const csv_ctx *c, const csv_row *r, hearth_err *err) {
  size_t p = r->start, k = 0;
  csv_cell cell;
  while (csv_next_cell(c->s, &p, r->end, c->sep, k, &cell)) {
    size_t v;
    if (k > 0 && !(cell_uint(c->s, &cell, &v) && v == k - 1)) {
      char ex[48];
      excerpt(c->s, cell.cs, cell.ce, ex, sizeof ex);
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column %zu: column index '%s', expected %zu (an "
                            "axis-labelled matrix numbers its columns 0..%zu after the corner "
                            "cell)",
                            c->name, r->line_no, csv_column(c, r->start, cell.at), ex, k - 1,
                            r->ncells - 2);
    }
    k++;
    if (p >= r->end) break;
    p++;
  }
  return HEARTH_OK;
}

/* The lead cell of matrix row r (the k-th, 0-based) of an axis-labelled or
 * frame-labelled matrix. */
static hearth_status check_lead(const csv_ctx *c, const csv_layout *L, const csv_row *R, size_t i,
                                size_t h, hearth_err *err) {
  const csv_row *r = &R[i];
  size_t k = i - L->first, v;
  csv_cell cell;
  int has = row_cell(c, r, 0, &cell);
  if (L->kind == HEARTH_CSV_AXIS) {
    if (has && cell_uint(c->s, &cell, &v) && v == k) return HEARTH_OK;
    char ex[48] = "";
    if (has) excerpt(c->s, cell.cs, cell.ce, ex, sizeof ex);
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line %zu, column %zu: row index '%s', expected %zu (an "
                          "axis-labelled matrix numbers its rows 0..%zu)",
                          c->name, r->line_no, csv_column(c, r->start, has ? cell.at : r->start),
                          ex, k, h - 1);
  }
  if (k == 0 || r->first_kind == CELL_EMPTY) return HEARTH_OK;
  char ex[48];
  excerpt(c->s, cell.quoted ? cell.cs : cell.at, cell.ce, ex, sizeof ex);
  return hearth_err_set(err, HEARTH_E_PARSE,
                        "%s: line %zu, column %zu: '%s' in the label column, expected it empty "
                        "below the frame label of line %zu (one frame per file)",
                        c->name, r->line_no, csv_column(c, r->start, cell.at), ex,
                        R[L->first].line_no);
}

/* A plain matrix whose first row or column counts 0, 1, 2, ...: indices
 * without the rest of an axis-labelled layout, or data? */
static hearth_status check_not_indices(const csv_ctx *c, const csv_buf *B, const csv_layout *L,
                                       size_t w, hearth_err *err) {
  const csv_row *R = B->rows, *r = &R[L->first];
  const float *v = B->vals + r->voff;
  size_t h = L->last - L->first + 1, i = 0;
  while (i < w && v[i] == (float)i) i++;
  int whole = w >= 2 && i == w;
  for (i = 1; i < w && v[i] == (float)(i - 1); i++) {}
  int after_first = !whole && w >= 3 && i == w;
  if (whole || after_first) {
    csv_cell cell;
    size_t col = after_first && row_cell(c, r, 1, &cell) ? csv_column(c, r->start, cell.at) : 1;
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line %zu, column %zu: the first row reads 0, 1, ..., %zu: column "
                          "indices or temperatures? expected an axis-labelled matrix (a corner "
                          "cell such as 'X/Y' before the indices 0..W-1) or a first row of "
                          "temperatures",
                          c->name, r->line_no, col, whole ? w - 1 : w - 2);
  }
  for (i = 0; h >= 2 && i < h && B->vals[R[L->first + i].voff] == (float)i; i++) {}
  if (h >= 2 && i == h)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line %zu, column 1: the first column reads 0, 1, ..., %zu down to "
                          "line %zu: row indices or temperatures? expected an axis-labelled "
                          "matrix (a corner cell and the column indices 0..W-1 above) or a "
                          "first column of temperatures",
                          c->name, r->line_no, h - 1, R[L->last].line_no);
  return HEARTH_OK;
}

/* Unit, index, values and size of the matrix found. */
static hearth_status check_matrix(const csv_ctx *c, const csv_buf *B, const csv_layout *L,
                                  size_t want_w, size_t want_h, size_t *w_out, int *celsius,
                                  hearth_err *err) {
  const csv_row *R = B->rows;
  const char *name = c->name;
  hearth_status st;
  /* the unit the metadata names */
  csv_unit u;
  memset(&u, 0, sizeof u);
  for (size_t i = 0; i < L->meta_end && !u.other; i++)
    csv_unit_scan(c, R[i].line_no, R[i].start, R[i].end, &u);
  if (u.other)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "%s: line %zu, column %zu: temperature unit '%s', expected degC "
                          "(hearth reads Celsius matrices and never converts them: export the "
                          "matrix in Celsius)",
                          name, u.line, csv_column(c, u.start, u.at), u.what);
  *celsius = u.celsius;

  /* values per row */
  char shape[96] = "";
  size_t w;
  if (L->kind == HEARTH_CSV_AXIS) {
    if ((st = check_index_row(c, &R[L->index], err))) return st;
    w = R[L->index].ncells - 1;
    if (want_w && w != want_w)
      return hearth_err_set(err, HEARTH_E_SIZE,
                            "%s: line %zu, column 1: the index row numbers %zu columns, expected "
                            "%zu (a %zu-wide matrix)",
                            name, R[L->index].line_no, w, want_w, want_w);
    snprintf(shape, sizeof shape, " (as the index row of line %zu)", R[L->index].line_no);
  } else {
    w = want_w ? want_w : majority_cells(R, L->first, L->last) - L->lead;
    if (want_w && want_h) snprintf(shape, sizeof shape, " (a %zux%zu matrix)", want_w, want_h);
    else if (want_w) snprintf(shape, sizeof shape, " (a width of %zu)", want_w);
    else snprintf(shape, sizeof shape, " (as in the other rows)");
  }

  /* every row, in file order */
  size_t h = L->last - L->first + 1;
  for (size_t i = L->first; i <= L->last; i++) {
    const csv_row *r = &R[i];
    if (L->lead && (st = check_lead(c, L, R, i, h, err))) return st;
    size_t bad = r->nbad - (L->lead && r->first_kind != CELL_OK ? 1 : 0);
    if (bad == 0 && r->ncells == w + L->lead) continue;
    return row_error(c, r, L->lead, w, shape, err);
  }

  if (want_h && h != want_h) {
    char want[64];
    if (want_w) snprintf(want, sizeof want, "%zux%zu", want_w, want_h);
    else snprintf(want, sizeof want, "%zu rows", want_h);
    if (h < want_h)
      return hearth_err_set(err, HEARTH_E_SIZE,
                            "%s: line %zu, column 1: matrix ends after %zu rows of %zu values, "
                            "expected %s",
                            name, R[L->last].line_no + 1, h, w, want);
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: line %zu, column 1: more than %zu rows, expected %s", name,
                          R[L->first + want_h].line_no, want_h, want);
  }
  if (L->size != NONE && (L->size_w != w || L->size_h != h))
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: line %zu, column 1: size line says %zux%zu, expected the %zux%zu "
                          "of the matrix below (lines %zu..%zu)",
                          name, R[L->size].line_no, L->size_w, L->size_h, w, h, R[L->top].line_no,
                          R[L->last].line_no);
  if (L->kind == HEARTH_CSV_PLAIN && (st = check_not_indices(c, B, L, w, err))) return st;
  *w_out = w;
  return HEARTH_OK;
}

/* The encoding, from the lines with text (for columns and copies). */
static const char *find_encoding(csv_ctx *c, const csv_text *t, const csv_buf *B) {
  if (t->bom && !strncmp(t->bom, "utf-16", 6)) return t->bom; /* now UTF-8 */
  int high = 0, valid = 1;
  for (size_t i = 0; i < B->nrows && valid; i++) {
    const csv_row *r = &B->rows[i];
    if (r->data && r->first_kind != CELL_GARBAGE) continue; /* text, or a label cell */
    for (size_t k = r->start; k < r->end && !high; k++) high = (unsigned char)c->s[k] >= 0x80;
    if (high) valid = csv_utf8_valid(c->s, r->start, r->end);
  }
  if (!valid) {
    c->utf8 = 0;
    return "8-bit";
  }
  return t->bom ? t->bom : high ? "utf-8" : "ascii";
}

static hearth_status fill_info(const csv_ctx *c, const csv_text *t, const csv_buf *B,
                               const csv_layout *L, const char *encoding, size_t w, int celsius,
                               hearth_thermal_info *info, hearth_err *err) {
  const csv_row *R = B->rows;
  info->layout = L->kind == HEARTH_CSV_PLAIN && L->size != NONE ? HEARTH_CSV_SIZE_LINE : L->kind;
  info->width = w;
  info->height = L->last - L->first + 1;
  info->separator = c->sep;
  /* the decimal mark of the matrix's values */
  const char *m = c->s + R[L->first].start;
  size_t mn = R[L->last].end - R[L->first].start;
  int comma = c->sep != ',' && memchr(m, ',', mn) != NULL;
  for (size_t i = L->first; i <= L->last && !comma; i++) comma = R[i].qcomma;
  info->decimal_mark = comma ? ',' : memchr(m, '.', mn) ? '.' : 0;
  info->encoding = encoding;
  info->line_ends = t->cr_only             ? "CR"
                    : B->n_lf && B->n_crlf ? "mixed"
                    : B->n_crlf            ? "CRLF"
                    : B->n_lf              ? "LF"
                                           : "none";
  info->first_line = R[L->top].line_no;
  info->last_line = R[L->last].line_no;
  info->header_lines = info->first_line - 1;
  info->size_line = L->size != NONE ? R[L->size].line_no : 0;
  if (L->lead) {
    csv_cell cell;
    const csv_row *r = &R[L->kind == HEARTH_CSV_AXIS ? L->index : L->first];
    if (row_cell(c, r, 0, &cell) && !(info->label = csv_text_copy(c, cell.cs, cell.ce)))
      return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", c->name);
  }
  for (size_t i = 0; i < L->meta_end; i++)
    if (!csv_meta_add(c, R[i].line_no, R[i].start, R[i].end, info))
      return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", c->name);
  info->unit = celsius ? "degC" : NULL;
  return HEARTH_OK;
}

/* The values of the matrix rows, without lead cells, as the image. */
static void take_values(csv_buf *B, const csv_layout *L, size_t w, hearth_image *out) {
  const csv_row *R = B->rows;
  size_t h = L->last - L->first + 1, n = w * h;
  if (L->lead) {
    for (size_t i = 0; i < h; i++) /* forward: the destination never passes the source */
      memmove(B->vals + i * w, B->vals + R[L->first + i].voff + L->lead, w * sizeof(float));
  } else if (R[L->first].voff) {
    memmove(B->vals, B->vals + R[L->first].voff, n * sizeof(float));
  }
  /* the values become the image's: no second buffer, no copy */
  float *data = realloc(B->vals, n * sizeof(float));
  if (data) B->vals = data; /* a failed shrink keeps the larger block */
  *out = (hearth_image){w, h, 1, HEARTH_PIX_F32, B->vals};
  B->vals = NULL;
}

hearth_status hearth_thermal_parse_csv_ex(const char *text, size_t len, const char *name,
                                          const hearth_csv_opts *opts, hearth_image *out,
                                          hearth_thermal_info *info, hearth_err *err) {
  if (info) memset(info, 0, sizeof *info);
  if (!out) return hearth_err_set(err, HEARTH_E_ARG, "thermal csv: out is NULL");
  memset(out, 0, sizeof *out);
  if (!name) name = "(thermal csv)";
  if (!text && len) return hearth_err_set(err, HEARTH_E_ARG, "%s: text is NULL", name);
  if (len > CSV_MAX_BYTES)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %zu bytes exceeds the limit of %zu bytes", name,
                          len, CSV_MAX_BYTES);
  size_t want_w = opts ? opts->width : 256, want_h = opts ? opts->height : 192;
  csv_text t;
  hearth_status st = csv_text_open(&t, text ? text : "", len, name, err);
  if (st) return st;
  csv_ctx c = {name, t.s, t.len, detect_sep(t.s, t.start, t.len), 1};
  csv_buf B;
  memset(&B, 0, sizeof B);
  csv_layout L = {HEARTH_CSV_PLAIN, 0, 0, 0, 0, NONE, NONE, 0, 0, 0};
  size_t w = 0;
  int celsius = 0;
  char shape[64] = "";
  if (want_w && want_h) snprintf(shape, sizeof shape, " (a %zux%zu matrix)", want_w, want_h);
  if ((st = scan(&c, t.start, &B, err))) goto done;
  const char *encoding = find_encoding(&c, &t, &B);
  if ((st = find_layout(&c, &B, shape, &L, err))) goto done;
  if ((st = check_matrix(&c, &B, &L, want_w, want_h, &w, &celsius, err))) goto done;
  if (info && (st = fill_info(&c, &t, &B, &L, encoding, w, celsius, info, err))) goto done;
  take_values(&B, &L, w, out);

done:
  free(B.vals);
  free(B.rows);
  csv_text_free(&t);
  if (st) {
    if (out->data) hearth_image_free(out);
    hearth_thermal_info_free(info);
  }
  return st;
}

hearth_status hearth_thermal_parse_csv(const char *text, size_t len, const char *name,
                                       const hearth_csv_opts *opts, hearth_image *out,
                                       hearth_err *err) {
  return hearth_thermal_parse_csv_ex(text, len, name, opts, out, NULL, err);
}

hearth_status hearth_thermal_read_csv_ex(const char *path, const hearth_csv_opts *opts,
                                         hearth_image *out, hearth_thermal_info *info,
                                         hearth_err *err) {
  if (info) memset(info, 0, sizeof *info);
  if (out) memset(out, 0, sizeof *out);
  if (!path || !out) return hearth_err_set(err, HEARTH_E_ARG, "thermal csv: NULL argument");
  uint8_t *data = NULL;
  size_t size = 0;
  hearth_status st = hearth_read_file(path, CSV_MAX_BYTES, &data, &size, err);
  if (st) return st;
  st = hearth_thermal_parse_csv_ex((const char *)data, size, path, opts, out, info, err);
  free(data);
  return st;
}

hearth_status hearth_thermal_read_csv(const char *path, const hearth_csv_opts *opts,
                                      hearth_image *out, hearth_err *err) {
  return hearth_thermal_read_csv_ex(path, opts, out, NULL, err);
}

const char *hearth_csv_layout_name(hearth_csv_layout layout) {
  switch (layout) {
    case HEARTH_CSV_PLAIN: return "plain";
    case HEARTH_CSV_SIZE_LINE: return "size-line";
    case HEARTH_CSV_AXIS: return "axis-labelled";
    case HEARTH_CSV_FRAME: return "frame-labelled";
  }
  return "unknown";
}
