/* Thermal CSV text: byte order marks, UTF-16 and CR line ends turned into
 * UTF-8 with '\n' line ends, and the metadata lines before the matrix
 * (key/value pairs, the temperature unit). */
#include <stdlib.h>
#include <string.h>
#include "io/io_csv.h"

/* ---- decoding --------------------------------------------------------------- */
static hearth_status utf16_decode(csv_text *t, const unsigned char *u, size_t n, int be,
                                  const char *name, hearth_err *err) {
  /* a code unit becomes at most 3 bytes, a surrogate pair 4 */
  char *o = malloc(n / 2 * 3 + 1);
  if (!o) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
  size_t k = 0, line = 1, col = 1;
  for (size_t i = 0; i + 1 < n; i += 2) {
    unsigned cp = be ? (unsigned)u[i] << 8 | u[i + 1] : (unsigned)u[i + 1] << 8 | u[i];
    if (cp >= 0xD800 && cp <= 0xDFFF) {
      unsigned lo = 0;
      if (cp <= 0xDBFF && i + 3 < n)
        lo = be ? (unsigned)u[i + 2] << 8 | u[i + 3] : (unsigned)u[i + 3] << 8 | u[i + 2];
      if (!(lo >= 0xDC00 && lo <= 0xDFFF)) {
        free(o);
        return hearth_err_set(err, HEARTH_E_PARSE,
                              "%s: line %zu, column %zu: unpaired UTF-16 surrogate 0x%04X, "
                              "expected UTF-16 text after the byte order mark",
                              name, line, col, cp);
      }
      cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
      i += 2;
    }
    if (cp < 0x80) {
      o[k++] = (char)cp;
    } else if (cp < 0x800) {
      o[k++] = (char)(0xC0 | cp >> 6);
      o[k++] = (char)(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      o[k++] = (char)(0xE0 | cp >> 12);
      o[k++] = (char)(0x80 | (cp >> 6 & 0x3F));
      o[k++] = (char)(0x80 | (cp & 0x3F));
    } else {
      o[k++] = (char)(0xF0 | cp >> 18);
      o[k++] = (char)(0x80 | (cp >> 12 & 0x3F));
      o[k++] = (char)(0x80 | (cp >> 6 & 0x3F));
      o[k++] = (char)(0x80 | (cp & 0x3F));
    }
    if (cp == '\n') {
      line++;
      col = 1;
    } else {
      col++;
    }
  }
  if (n % 2) {
    free(o);
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line %zu, column %zu: a lone byte ends the UTF-16 text, expected "
                          "pairs of bytes",
                          name, line, col);
  }
  o[k] = 0;
  t->own = o;
  t->s = o;
  t->len = k;
  t->start = 0;
  return HEARTH_OK;
}

hearth_status csv_text_open(csv_text *t, const char *text, size_t len, const char *name,
                            hearth_err *err) {
  const unsigned char *u = (const unsigned char *)text;
  memset(t, 0, sizeof *t);
  t->s = text;
  t->len = len;
  if (len >= 3 && u[0] == 0xEF && u[1] == 0xBB && u[2] == 0xBF) {
    t->start = 3;
    t->bom = "utf-8-bom";
  } else if (len >= 2 && ((u[0] == 0xFF && u[1] == 0xFE) || (u[0] == 0xFE && u[1] == 0xFF))) {
    int be = u[0] == 0xFE;
    t->bom = be ? "utf-16be-bom" : "utf-16le-bom";
    hearth_status st = utf16_decode(t, u + 2, len - 2, be, name, err);
    if (st) return st;
  } else if (len >= 4 && ((u[0] && !u[1] && u[2] && !u[3]) || (!u[0] && u[1] && !u[2] && u[3]))) {
    /* every other byte zero: UTF-16 that lost its byte order mark */
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: line 1, column 1: the text looks like UTF-16 without a byte "
                          "order mark, expected UTF-8, an 8-bit code page, or UTF-16 with a "
                          "byte order mark",
                          name);
  }
  /* lines ended by '\r' alone (classic Mac OS): scanned with '\n' instead */
  size_t a = t->start;
  if (t->len > a && !memchr(t->s + a, '\n', t->len - a) && memchr(t->s + a, '\r', t->len - a)) {
    if (!t->own) {
      t->own = malloc(t->len + 1);
      if (!t->own) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", name);
      memcpy(t->own, t->s, t->len);
      t->own[t->len] = 0;
      t->s = t->own;
    }
    for (size_t i = a; i < t->len; i++)
      if (t->own[i] == '\r') t->own[i] = '\n';
    t->cr_only = 1;
  }
  return HEARTH_OK;
}

void csv_text_free(csv_text *t) {
  free(t->own);
  t->own = NULL;
}

int csv_utf8_valid(const char *s, size_t a, size_t b) {
  const unsigned char *u = (const unsigned char *)s;
  for (size_t i = a; i < b;) {
    unsigned c = u[i];
    if (c < 0x80) {
      i++;
      continue;
    }
    size_t n = c >= 0xC2 && c <= 0xDF   ? 1
               : c >= 0xE0 && c <= 0xEF ? 2
               : c >= 0xF0 && c <= 0xF4 ? 3
                                        : 0;
    if (!n || i + n >= b) return 0;
    unsigned c1 = u[i + 1];
    /* no overlong forms, surrogates or code points past U+10FFFF */
    if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 > 0x9F) || (c == 0xF0 && c1 < 0x90) ||
        (c == 0xF4 && c1 > 0x8F))
      return 0;
    for (size_t k = 1; k <= n; k++)
      if ((u[i + k] & 0xC0) != 0x80) return 0;
    i += n + 1;
  }
  return 1;
}

/* ---- metadata text -------------------------------------------------------- */
/* a bounded string of printable UTF-8 */
typedef struct tbuf {
  char b[CSV_MAX_META_TEXT + 1];
  size_t n;
} tbuf;

static void tb_add(tbuf *t, const char *p, size_t n) {
  if (t->n + n > CSV_MAX_META_TEXT) return; /* whole pieces only: no cut sequences */
  memcpy(t->b + t->n, p, n);
  t->n += n;
}

/* s[a..b) into t: control characters, and bytes >= 0x80 of an 8-bit text,
 * as \xNN */
static void tb_text(tbuf *t, const csv_ctx *c, size_t a, size_t b) {
  static const char hex[] = "0123456789abcdef";
  const unsigned char *u = (const unsigned char *)c->s;
  for (size_t i = a; i < b;) {
    unsigned ch = u[i];
    if (ch < 0x20 || ch == 0x7F || (ch >= 0x80 && !c->utf8)) {
      char e[4] = {'\\', 'x', hex[ch >> 4], hex[ch & 15]};
      tb_add(t, e, 4);
      i++;
    } else if (ch < 0x80) {
      tb_add(t, c->s + i, 1);
      i++;
    } else {
      size_t n = 1;
      while (i + n < b && (u[i + n] & 0xC0) == 0x80) n++;
      tb_add(t, c->s + i, n);
      i += n;
    }
  }
  t->b[t->n] = 0;
}

char *csv_text_copy(const csv_ctx *c, size_t a, size_t b) {
  tbuf t = {{0}, 0};
  tb_text(&t, c, a, b);
  char *r = malloc(t.n + 1);
  if (r) memcpy(r, t.b, t.n + 1);
  return r;
}

/* the non-empty cells of a line, as content spans: the first MAX_SPANS
 * within its first MAX_CELLS cells (a key and a value of at most 255 bytes
 * need no more) */
enum { MAX_SPANS = 64, MAX_CELLS = 1024 };
typedef struct spans {
  size_t a[MAX_SPANS], b[MAX_SPANS], n;
} spans;

static void line_spans(const csv_ctx *c, size_t start, size_t end, spans *sp) {
  size_t p = start, n = 0;
  csv_cell cell;
  sp->n = 0;
  while (sp->n < MAX_SPANS && n < MAX_CELLS && csv_next_cell(c->s, &p, end, c->sep, n, &cell)) {
    n++;
    if (cell.ce > cell.cs) {
      sp->a[sp->n] = cell.cs;
      sp->b[sp->n] = cell.ce;
      sp->n++;
    }
    if (p >= end) break;
    p++;
  }
}

static void trim(const char *s, size_t *a, size_t *b) {
  while (*a < *b && (s[*a] == ' ' || s[*a] == '\t')) (*a)++;
  while (*b > *a && (s[*b - 1] == ' ' || s[*b - 1] == '\t')) (*b)--;
}

/* Key and value spans of a line: see hearth_csv_meta. The value may be
 * several spans (cells), from index *v0 of sp; or one span (*va, *vb) cut
 * from a lone cell. */
static void key_value(const csv_ctx *c, spans *sp, size_t *ka, size_t *kb, size_t *va, size_t *vb,
                      size_t *v0) {
  const char *s = c->s;
  *ka = *kb = *va = *vb = 0;
  *v0 = sp->n;
  if (!sp->n) return;
  *ka = sp->a[0];
  *kb = sp->b[0];
  while (*ka < *kb && s[*ka] == '#') (*ka)++; /* "# key: value" comment lines */
  trim(s, ka, kb);
  if (sp->n == 1) {
    for (size_t i = *ka; i < *kb; i++)
      if (s[i] == '=' || (s[i] == ':' && (i + 1 == *kb || s[i + 1] == ' ' || s[i + 1] == '\t'))) {
        *va = i + 1;
        *vb = *kb;
        *kb = i;
        trim(s, va, vb);
        break;
      }
  } else {
    *v0 = 1;
  }
  while (*kb > *ka && (s[*kb - 1] == ':' || s[*kb - 1] == '=')) (*kb)--;
  trim(s, ka, kb);
}

int csv_meta_add(const csv_ctx *c, size_t line, size_t start, size_t end,
                 hearth_thermal_info *info) {
  info->n_meta_lines++;
  if (info->n_meta >= CSV_MAX_META) return 1;
  spans sp;
  line_spans(c, start, end, &sp);
  size_t ka, kb, va, vb, v0;
  key_value(c, &sp, &ka, &kb, &va, &vb, &v0);
  tbuf k = {{0}, 0}, v = {{0}, 0};
  tb_text(&k, c, ka, kb);
  if (v0 < sp.n) {
    for (size_t i = v0; i < sp.n; i++) {
      if (i > v0) tb_add(&v, " ", 1);
      tb_text(&v, c, sp.a[i], sp.b[i]);
    }
  } else {
    tb_text(&v, c, va, vb);
  }
  if (info->n_meta % 16 == 0) {
    hearth_csv_meta *m = realloc(info->meta, (info->n_meta + 16) * sizeof *m);
    if (!m) return 0;
    info->meta = m;
  }
  char *kv = malloc(k.n + v.n + 2); /* one block: the key's free releases both */
  if (!kv) return 0;
  memcpy(kv, k.b, k.n + 1);
  memcpy(kv + k.n + 1, v.b, v.n + 1);
  info->meta[info->n_meta++] = (hearth_csv_meta){kv, kv + k.n + 1, line};
  return 1;
}

/* ---- units ---------------------------------------------------------------- */
static int lower(int ch) { return ch >= 'A' && ch <= 'Z' ? ch - 'A' + 'a' : ch; }
static int is_letter(int ch) { return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z'); }

/* does s[a..b) contain the ASCII word w (ignoring case)? */
static int has_word(const char *s, size_t a, size_t b, const char *w) {
  size_t n = strlen(w);
  for (size_t i = a; i + n <= b; i++) {
    size_t k = 0;
    while (k < n && lower((unsigned char)s[i + k]) == (unsigned char)w[k]) k++;
    if (k == n) return 1;
  }
  return 0;
}

static int equals(const char *s, size_t a, size_t b, const char *w) {
  return b - a == strlen(w) && has_word(s, a, b, w);
}

/* A temperature unit written at s[i..b): 'C', 'F' or 'K' and its length, or
 * 0: a word (degC, Celsius...), or a degree sign of one of the usual
 * encodings (UTF-8, Windows-1252, cp949, GBK, Shift-JIS) and C or F. */
static int unit_at(const char *s, size_t i, size_t b, size_t *len) {
  const unsigned char *u = (const unsigned char *)s;
  static const struct {
    const char *w;
    int unit;
  } words[] = {{"celsius", 'C'},      {"centigrade", 'C'},   {"fahrenheit", 'F'}, {"kelvin", 'K'},
               {"degc", 'C'},         {"deg c", 'C'},        {"degf", 'F'},       {"deg f", 'F'},
               {"\xE2\x84\x83", 'C'}, {"\xE2\x84\x89", 'F'}, {"\xA1\xE6", 'C'},   {"\xA1\xC9", 'C'},
               {"\x81\x8E", 'C'}};
  static const char *const degree[] = {"\xC2\xB0", "\xC2\xBA", "\xA1\xC6", "\xA1\xE3",
                                       "\x81\x8B", "\xB0",     "\xBA"};
  for (size_t w = 0; w < sizeof words / sizeof words[0]; w++) {
    size_t n = strlen(words[w].w);
    if (i + n <= b && has_word(s, i, i + n, words[w].w) &&
        !(i + n < b && (is_letter(u[i + n]) || u[i + n] >= 0x80))) {
      *len = n;
      return words[w].unit;
    }
  }
  for (size_t d = 0; d < sizeof degree / sizeof degree[0]; d++) {
    size_t n = strlen(degree[d]);
    if (i + n < b && !memcmp(s + i, degree[d], n) && (u[i + n] == 'C' || u[i + n] == 'F') &&
        !(i + n + 1 < b && (is_letter(u[i + n + 1]) || u[i + n + 1] >= 0x80 ||
                            (u[i + n + 1] >= '0' && u[i + n + 1] <= '9')))) {
      *len = n + 1;
      return u[i + n];
    }
  }
  return 0;
}

/* The unit a whole value names (e.g. "degC", "(F)", "K"), or 0. */
static int unit_value(const char *s, size_t a, size_t b) {
  trim(s, &a, &b);
  while (a < b && (s[a] == '(' || s[a] == '[')) a++;
  while (b > a && (s[b - 1] == ')' || s[b - 1] == ']')) b--;
  trim(s, &a, &b);
  if (b - a == 1 && (lower((unsigned char)s[a]) == 'c' || lower((unsigned char)s[a]) == 'f' ||
                     lower((unsigned char)s[a]) == 'k'))
    return lower((unsigned char)s[a]) - 'a' + 'A';
  size_t n = 0;
  int uu = unit_at(s, a, b, &n);
  return uu && a + n == b ? uu : 0;
}

static void note_other(const csv_ctx *c, size_t line, size_t start, size_t a, size_t b,
                       csv_unit *u) {
  if (u->other) return;
  u->other = 1;
  u->line = line;
  u->start = start;
  u->at = a;
  tbuf t = {{0}, 0};
  csv_ctx bytes = *c; /* escaped as other messages' excerpts: \xNN beyond ASCII */
  bytes.utf8 = 0;
  tb_text(&t, &bytes, a, b - a > 40 ? a + 40 : b);
  memcpy(u->what, t.b, t.n + 1 < sizeof u->what ? t.n + 1 : sizeof u->what);
  u->what[sizeof u->what - 1] = 0;
}

void csv_unit_scan(const csv_ctx *c, size_t line, size_t start, size_t end, csv_unit *u) {
  const char *s = c->s;
  spans sp;
  line_spans(c, start, end, &sp);
  size_t ka, kb, va, vb, v0;
  key_value(c, &sp, &ka, &kb, &va, &vb, &v0);
  /* a line naming the temperature unit: "Unit", "Temperature unit", "Einheit" ... */
  int unit_key = equals(s, ka, kb, "unit") || equals(s, ka, kb, "units") ||
                 equals(s, ka, kb, "einheit") || equals(s, ka, kb, "unidad") ||
                 equals(s, ka, kb, "unit\xC3\xA9") ||
                 ((has_word(s, ka, kb, "unit") || has_word(s, ka, kb, "einheit")) &&
                  has_word(s, ka, kb, "temp"));
  if (unit_key) {
    size_t a = v0 < sp.n ? sp.a[v0] : va, b = v0 < sp.n ? sp.b[sp.n - 1] : vb;
    if (a < b) {
      int uu = unit_value(s, a, b);
      if (uu == 'C') {
        u->celsius = 1;
      } else {
        note_other(c, line, start, a, b, u);
      }
      return;
    }
  }
  /* values written with a unit: "20,0 degC", "68 <degree sign>F" */
  for (size_t i = start; i < end; i++) {
    int ch = lower((unsigned char)s[i]);
    if (!(ch == 'c' || ch == 'f' || ch == 'k' || ch == 'd' || ch >= 0x80)) continue;
    size_t n = 0;
    /* at a word's start, not inside a multi-byte character */
    int uu = i == start || !(is_letter((unsigned char)s[i - 1]) || (unsigned char)s[i - 1] >= 0x80)
                 ? unit_at(s, i, end, &n)
                 : 0;
    if (uu == 'C') u->celsius = 1;
    if (uu == 'F' || uu == 'K') note_other(c, line, start, i, i + n, u);
    if (n) i += n - 1;
  }
}

/* ---- the info ------------------------------------------------------------ */
void hearth_thermal_info_free(hearth_thermal_info *info) {
  if (!info) return;
  for (size_t i = 0; i < info->n_meta; i++) free((void *)info->meta[i].key);
  free(info->meta);
  free((void *)info->label);
  memset(info, 0, sizeof *info);
}

const char *hearth_thermal_info_get(const hearth_thermal_info *info, const char *key) {
  if (!info || !key) return NULL;
  for (size_t i = 0; i < info->n_meta; i++) {
    const char *k = info->meta[i].key;
    size_t j = 0;
    while (k[j] && key[j] && lower((unsigned char)k[j]) == lower((unsigned char)key[j])) j++;
    if (!k[j] && !key[j]) return info->meta[i].value;
  }
  return NULL;
}
