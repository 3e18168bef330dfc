/* Thermal CSV: apparent-temperature matrices in degC.
 *
 * The reader makes one forward pass: it splits lines, tokenizes cells and
 * parses every number once, keeping a "block" of data-like rows. A line that
 * does not look like data (free text, key,value) ends the header: the block
 * restarts after it, so the matrix is the run of data-like lines that ends
 * the file. Only when something is wrong does it go back over the offending
 * line to say which cell, where, and what was expected. Lines are 1-based
 * counting header lines; columns are 1-based UTF-8 characters from the line
 * start (a BOM is not counted), at the cell's first non-blank character. */
#include <stdlib.h>
#include <string.h>
#include "hearth/thermal.h"

/* input larger than this is refused: a 256x192 matrix is ~0.4 MB */
#define CSV_MAX_BYTES ((size_t)64 << 20)

enum { CELL_OK = 0, CELL_RANGE, CELL_NANINF, CELL_EMPTY, CELL_GARBAGE, CELL_QUOTE };

/* one cell as found by the tokenizer */
typedef struct csv_cell {
  size_t at;       /* offset of the cell's first non-blank byte (the quote if quoted) */
  size_t cs, ce;   /* content span, without quotes and surrounding blanks */
  int quoted, comma, bad_quote;
} csv_cell;

/* a data-like line of the current block */
typedef struct csv_row {
  size_t line_no, start, end; /* end excludes "\r\n" */
  size_t ncells, nnum;        /* cells, and cells that are numbers (any value) */
  int ok;                     /* every cell a finite number in range */
} csv_row;

typedef struct csv_buf {
  float *vals;
  size_t nvals, capvals;
  csv_row *rows;
  size_t nrows, caprows;
} csv_buf;

static int is_blank(char c, char sep) { return c == ' ' || (c == '\t' && sep != '\t'); }

/* Take the cell at *p (line ends at b). On return *p is at the separator that
 * ended the cell, or at b. Returns 0 when the line has no more cells (only
 * blanks after a separator, i.e. a trailing separator, or an empty line). */
static inline int next_cell(const char *s, size_t *pp, size_t b, char sep, size_t ncells,
                            csv_cell *c) {
  size_t p = *pp;
  while (p < b && is_blank(s[p], sep)) p++;
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
      while (p < b && is_blank(s[p], sep)) p++;
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
    while (e > c->cs && is_blank(s[e - 1], sep)) e--;
    c->ce = e;
  }
  *pp = p;
  return 1;
}

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

/* 1-based character column of byte offset `at` in a line starting at
 * `start` (UTF-8 continuation bytes do not start a character). */
static size_t column_of(const char *s, size_t start, size_t at) {
  size_t col = 1;
  for (size_t i = start; i < at; i++)
    if (((unsigned char)s[i] & 0xC0) != 0x80) col++;
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

static hearth_status cell_error(const char *name, const char *s, const csv_row *r,
                                const csv_cell *c, int kind, double v, hearth_err *err) {
  char ex[48];
  size_t col = column_of(s, r->start, c->at);
  excerpt(s, c->quoted ? c->cs : c->at, c->ce, ex, sizeof ex);
  switch (kind) {
    case CELL_RANGE: {
      char num[64];
      if (hearth_format_fixed(num, sizeof num, v, 3) < 0) excerpt(s, c->cs, c->ce, num, sizeof num);
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
                            c->bad_quote == 1 ? "unterminated quote" : "text after closing quote");
    default:
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: line %zu, column %zu: '%s' is not a number, expected a "
                            "temperature in degC",
                            name, r->line_no, col, ex);
  }
}

/* Go back over a row known to be wrong and report its first problem. */
static hearth_status row_error(const char *name, const char *s, char sep, const csv_row *r,
                               size_t n_exp, const char *shape, hearth_err *err) {
  size_t p = r->start, n = 0;
  csv_cell c;
  while (next_cell(s, &p, r->end, sep, n, &c)) {
    if (n == n_exp)
      return hearth_err_set(err, HEARTH_E_SIZE,
                            "%s: line %zu, column %zu: row has more than %zu values, expected "
                            "%zu%s",
                            name, r->line_no, column_of(s, r->start, c.at), n_exp, n_exp, shape);
    double v = 0;
    int kind = eval_cell(s, &c, &v);
    if (kind != CELL_OK) return cell_error(name, s, r, &c, kind, v, err);
    n++;
    if (p >= r->end) break;
    p++;
  }
  if (n < n_exp)
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: line %zu, column %zu: row has %zu values, expected %zu%s", name,
                          r->line_no, column_of(s, r->start, r->end) , n, n_exp, shape);
  return hearth_err_set(err, HEARTH_E_PARSE, "%s: line %zu: malformed row", name, r->line_no);
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

/* Boyer-Moore majority vote over the cell counts of full numeric rows. */
static size_t majority_cells(const csv_row *rows, size_t n) {
  size_t cand = 0, cnt = 0;
  int any_full = 0;
  for (size_t i = 0; i < n; i++)
    if (rows[i].nnum == rows[i].ncells) any_full = 1;
  for (size_t i = 0; i < n; i++) {
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

hearth_status hearth_thermal_parse_csv(const char *text, size_t len, const char *name,
                                       const hearth_csv_opts *opts, hearth_image *out,
                                       hearth_err *err) {
  if (!out) return hearth_err_set(err, HEARTH_E_ARG, "thermal csv: out is NULL");
  memset(out, 0, sizeof *out);
  if (!name) name = "(thermal csv)";
  if (!text && len) return hearth_err_set(err, HEARTH_E_ARG, "%s: text is NULL", name);
  if (len > CSV_MAX_BYTES)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %zu bytes exceeds the limit of %zu bytes",
                          name, len, CSV_MAX_BYTES);
  size_t want_w = opts ? opts->width : 256, want_h = opts ? opts->height : 192;
  const char *s = text;
  size_t pos = 0;
  if (len >= 3 && (unsigned char)s[0] == 0xEF && (unsigned char)s[1] == 0xBB &&
      (unsigned char)s[2] == 0xBF)
    pos = 3; /* UTF-8 byte order mark */
  char sep = detect_sep(s, pos, len);

  csv_buf B = {0};
  hearth_status st = HEARTH_OK;
  size_t line_no = 0, last_reset_line = 0, last_reset_start = 0, last_reset_end = 0;
  size_t rows_before_reset = 0, reset_cells = 0;
  /* a first guess at the number of values avoids most regrowth */
  if (!grow((void **)&B.vals, &B.capvals, len / 6 + 16, sizeof(float)) ||
      !grow((void **)&B.rows, &B.caprows, 256, sizeof(csv_row))) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
    goto done;
  }

  /* forward pass: one line at a time */
  while (pos < len) {
    const char *nl = memchr(s + pos, '\n', len - pos);
    size_t a = pos, b = nl ? (size_t)(nl - s) : len;
    pos = nl ? b + 1 : len;
    line_no++;
    if (b > a && s[b - 1] == '\r') b--;
    csv_row r = {line_no, a, b, 0, 0, 1};
    size_t p = a;
    int first_numeric = 0, line_done = 0;
    /* fastest path, for the usual file: a run of bare decimals ("-12.34")
     * and separators on a line that a newline ends (s[b] is '\r' or '\n',
     * so every digit scan stops there without a bound check). The first
     * cell that is anything else, or out of range, goes to the loop below
     * from where this one stopped; the values are the same either way. */
    if (b < len && p < b) {
      for (;;) {
        double v;
        size_t q = p;
        /* out of range: left to the loop below, from the cell's start */
        if (!plain_cell(s, &q, b, sep, 0, &v) || !(v >= HEARTH_THERMAL_MIN_C && v <= HEARTH_THERMAL_MAX_C)) break;
        p = q;
        if (B.nvals == B.capvals && !grow((void **)&B.vals, &B.capvals, B.nvals + 1, sizeof(float))) {
          st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
          goto done;
        }
        B.vals[B.nvals++] = (float)v;
        if (r.ncells == 0) first_numeric = 1;
        r.nnum++;
        r.ncells++;
        if (p >= b || ++p >= b) { /* the line's end, or one trailing separator */
          line_done = 1;
          break;
        }
      }
    }
    for (; !line_done;) {
      double v = 0;
      int kind;
      /* fast path: a bare decimal ending at a separator or the line end */
      if (plain_cell(s, &p, b, sep, 1, &v)) {
        kind = v >= HEARTH_THERMAL_MIN_C && v <= HEARTH_THERMAL_MAX_C ? CELL_OK : CELL_RANGE;
      } else {
        csv_cell c;
        if (!next_cell(s, &p, b, sep, r.ncells, &c)) break;
        if (r.ncells == 0 && c.ce == c.cs && !c.quoted && p >= b) break; /* blank line */
        kind = eval_cell(s, &c, &v);
      }
      if (kind != CELL_OK) r.ok = 0;
      if (kind == CELL_OK || kind == CELL_RANGE || kind == CELL_NANINF) {
        r.nnum++;
        if (r.ncells == 0) first_numeric = 1;
      }
      if (B.nvals == B.capvals &&
          !grow((void **)&B.vals, &B.capvals, B.nvals + 1, sizeof(float))) {
        st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
        goto done;
      }
      B.vals[B.nvals++] = kind == CELL_OK ? (float)v : 0.0f;
      r.ncells++;
      if (p >= b) break;
      p++; /* over the separator */
      if (p >= b) break; /* one trailing separator */
    }
    if (r.ncells == 0) continue; /* empty line */
    int data_like = r.nnum == r.ncells || (r.nnum >= 1 && first_numeric) ||
                    (r.nnum >= 8 && 2 * r.nnum > r.ncells);
    if (!data_like) {
      /* header (or footer) text: the matrix starts after it */
      rows_before_reset = B.nrows;
      last_reset_line = line_no;
      last_reset_start = a;
      last_reset_end = b;
      reset_cells = r.ncells;
      B.nrows = 0;
      B.nvals = 0;
      continue;
    }
    if (!grow((void **)&B.rows, &B.caprows, B.nrows + 1, sizeof(csv_row))) {
      st = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
      goto done;
    }
    B.rows[B.nrows++] = r;
  }

  char shape[64] = "";
  if (want_w && want_h) snprintf(shape, sizeof shape, " (a %zux%zu matrix)", want_w, want_h);

  if (B.nrows == 0) {
    if (last_reset_line && rows_before_reset) {
      /* numeric rows were followed by text: report the text */
      csv_row r = {last_reset_line, last_reset_start, last_reset_end, 0, 0, 0};
      st = row_error(name, s, sep, &r, (size_t)-1, shape, err);
      goto done;
    }
    st = hearth_err_set(err, HEARTH_E_PARSE,
                        "%s: line %zu, column 1: no numeric rows found, expected a matrix of "
                        "temperatures%s",
                        name, line_no + 1, shape);
    goto done;
  }

  /* full numeric rows of another width just before the matrix are header
   * values (e.g. "256,192") */
  size_t n_ref = majority_cells(B.rows, B.nrows);
  size_t first = 0, skipped_vals = 0;
  while (first < B.nrows && B.rows[first].nnum == B.rows[first].ncells &&
         B.rows[first].ncells != n_ref) {
    skipped_vals += B.rows[first].ncells;
    first++;
  }
  size_t n_exp = want_w ? want_w : n_ref;
  if (!want_w || !want_h) snprintf(shape, sizeof shape, " (as in the other rows)");
  if (want_w && !want_h) snprintf(shape, sizeof shape, " (a width of %zu)", want_w);

  /* the first wrong row, in file order */
  for (size_t i = first; i < B.nrows; i++) {
    const csv_row *r = &B.rows[i];
    if (r->ok && r->ncells == n_exp) continue;
    st = row_error(name, s, sep, r, n_exp, shape, err);
    goto done;
  }

  size_t nrows = B.nrows - first;
  if ((!want_h || nrows < want_h) && last_reset_line && rows_before_reset &&
      reset_cells == n_ref) {
    /* a text line as wide as the matrix, with numeric rows before it, cut
     * the matrix short: that line is the problem, not a header */
    csv_row r = {last_reset_line, last_reset_start, last_reset_end, 0, 0, 0};
    st = row_error(name, s, sep, &r, n_exp, shape, err);
    goto done;
  }
  if (want_h && nrows != want_h) {
    char want[64];
    if (want_w) snprintf(want, sizeof want, "%zux%zu", want_w, want_h);
    else snprintf(want, sizeof want, "%zu rows", want_h);
    if (nrows < want_h)
      st = hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: line %zu, column 1: matrix ends after %zu rows of %zu values, "
                          "expected %s",
                          name, B.rows[B.nrows - 1].line_no + 1, nrows, n_exp, want);
    else
      st = hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: line %zu, column 1: more than %zu rows, expected %s", name,
                          B.rows[first + want_h].line_no, want_h, want);
    goto done;
  }

  /* the values become the image's: no second buffer, no copy */
  size_t n_vals = n_exp * nrows;
  if (skipped_vals) memmove(B.vals, B.vals + skipped_vals, n_vals * sizeof(float));
  float *data = realloc(B.vals, n_vals * sizeof(float));
  if (data) B.vals = data; /* a failed shrink keeps the larger block */
  *out = (hearth_image){n_exp, nrows, 1, HEARTH_PIX_F32, B.vals};
  B.vals = NULL;

done:
  free(B.vals);
  free(B.rows);
  if (st && out->data) hearth_image_free(out);
  return st;
}

hearth_status hearth_thermal_read_csv(const char *path, const hearth_csv_opts *opts,
                                      hearth_image *out, hearth_err *err) {
  if (out) memset(out, 0, sizeof *out);
  if (!path || !out) return hearth_err_set(err, HEARTH_E_ARG, "thermal csv: NULL argument");
  uint8_t *data = NULL;
  size_t size = 0;
  hearth_status st = hearth_read_file(path, CSV_MAX_BYTES, &data, &size, err);
  if (st) return st;
  st = hearth_thermal_parse_csv((const char *)data, size, path, opts, out, err);
  free(data);
  return st;
}

hearth_status hearth_thermal_write_csv(const char *path, const hearth_image *temps,
                                       int decimals, hearth_err *err) {
  if (!path || !temps || !temps->data)
    return hearth_err_set(err, HEARTH_E_ARG, "thermal csv: NULL argument");
  if (temps->channels != 1 || temps->type != HEARTH_PIX_F32)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "%s: image has %d channel(s) of %d-byte samples, expected 1-channel "
                          "float32",
                          path, temps->channels, (int)temps->type);
  if (decimals < 0 || decimals > 9)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: %d decimals, expected 0..9", path, decimals);
  size_t w = temps->width, h = temps->height, n;
  if (!w || !h || !hearth_mul_size(w, h, &n))
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: image is %zux%zu, expected a non-empty matrix",
                          path, w, h);
  /* "-50.xxxxxx," at most 4 + 1 + decimals + 1 bytes per value */
  size_t per = (size_t)decimals + 6, cap;
  if (!hearth_mul_size(n, per, &cap))
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: image too large", path);
  char *buf = malloc(cap + 1);
  if (!buf) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  const float *t = temps->data;
  size_t k = 0;
  for (size_t y = 0; y < h; y++) {
    for (size_t x = 0; x < w; x++) {
      double v = t[y * w + x];
      /* refuse what a reader would refuse rather than write it */
      if (!(v >= HEARTH_THERMAL_MIN_C && v <= HEARTH_THERMAL_MAX_C)) {
        free(buf);
        return hearth_err_set(err, HEARTH_E_RANGE,
                              "%s: pixel (%zu, %zu) = %g degC, expected a finite value in "
                              "%g..%g degC",
                              path, x, y, v, HEARTH_THERMAL_MIN_C, HEARTH_THERMAL_MAX_C);
      }
      int m = hearth_format_fixed(buf + k, cap + 1 - k, v, decimals);
      if (m < 0) {
        free(buf);
        return hearth_err_set(err, HEARTH_E_RANGE, "%s: pixel (%zu, %zu) cannot be formatted",
                              path, x, y);
      }
      k += (size_t)m;
      buf[k++] = x + 1 < w ? ',' : '\n';
    }
  }
  hearth_status st = hearth_write_file_atomic(path, buf, k, err);
  free(buf);
  return st;
}

void hearth_csv_opts_default(hearth_csv_opts *o) {
  o->width = 256;
  o->height = 192;
}
