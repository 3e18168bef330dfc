/* Thermal CSV export variants: each fixture (written here with snprintf,
 * independently of the reader and the writer under test) must parse to
 * exactly the float matrix of a canonical CSV of the same values, and report
 * what it is; its mangled forms must fail with the right status, line and
 * column. Fixtures: a seeded matrix of centi-degree values in any of the
 * exported forms (layout, separator, decimal mark, quotes, line ends,
 * metadata block, encoding). */

#include <stdarg.h>
#include "hearth/thermal.h"
#include "test_util.h"

/* a growable byte string */
typedef struct sbuf {
  char *s;
  size_t n, cap;
} sbuf;

static void sb_raw(sbuf *b, const char *p, size_t n) {
  if (b->n + n + 1 > b->cap) {
    b->cap = (b->n + n + 1) * 2;
    b->s = realloc(b->s, b->cap);
  }
  memcpy(b->s + b->n, p, n);
  b->n += n;
  b->s[b->n] = 0;
}

static void sb_add(sbuf *b, const char *fmt, ...) {
  char tmp[512];
  va_list ap;
  va_start(ap, fmt);
  int m = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  if (m >= (int)sizeof tmp) m = (int)sizeof tmp - 1;
  sb_raw(b, tmp, (size_t)m);
}

enum { FX_PLAIN, FX_SIZE, FX_AXIS, FX_FRAME };
enum { ENC_RAW, ENC_UTF8_BOM, ENC_UTF16LE, ENC_UTF16BE };

/* how to write one fixture */
typedef struct fx {
  int w, h;
  char sep, dm;        /* separator and decimal mark */
  int quote, trailing; /* quote every cell; a separator at each line end */
  const char *eol;     /* "\n", "\r\n" or "\r" */
  int sci;             /* scientific notation ("2.345e1") */
  int layout;          /* FX_* */
  const char *label;   /* the axis corner or frame label (bytes) */
  const char *meta;    /* metadata lines, each ending in '\n' (bytes) */
  int enc;             /* ENC_*: the raw bytes, or UTF-8 with BOM, or UTF-16 */
  int blank_after;     /* a blank line after this many matrix rows (0: none) */
} fx;

/* centi-degrees of a seeded matrix: value = k / 100 */
static int *fx_values(int w, int h, uint64_t seed) {
  int *k = malloc(sizeof(int) * (size_t)w * (size_t)h);
  hearth_rng r;
  hearth_rng_seed(&r, seed);
  for (int i = 0; i < w * h; i++) k[i] = (int)hearth_rng_range(&r, -4999, 64999);
  k[0] = -5000; /* the range ends are allowed */
  k[1] = 65000;
  k[2] = 0;
  k[3] = -5;
  return k;
}

static void fx_number(sbuf *b, int k, char dm, int sci) {
  int a = k < 0 ? -k : k;
  if (!sci) {
    sb_add(b, "%s%d%c%02d", k < 0 ? "-" : "", a / 100, dm, a % 100);
    return;
  }
  char d[16];
  int n = snprintf(d, sizeof d, "%d", a);
  sb_add(b, "%s%c", k < 0 ? "-" : "", d[0]);
  if (n > 1) sb_add(b, "%c%s", dm, d + 1);
  sb_add(b, "e%d", n - 1 - 2);
}

static void fx_cell_start(sbuf *b, const fx *f, int x) {
  if (x) sb_add(b, "%c", f->sep);
  if (f->quote) sb_add(b, "\"");
}

static void fx_cell_end(sbuf *b, const fx *f) {
  if (f->quote) sb_add(b, "\"");
}

/* UTF-8 to UTF-16 (BMP and surrogate pairs) with a byte order mark */
static void fx_utf16(sbuf *out, const char *s, size_t n, int be) {
  const unsigned char *u = (const unsigned char *)s;
  sb_raw(out, be ? "\xFE\xFF" : "\xFF\xFE", 2);
  for (size_t i = 0; i < n;) {
    unsigned cp = u[i], len = 1;
    if (cp >= 0xF0) cp &= 0x07, len = 4;
    else if (cp >= 0xE0) cp &= 0x0F, len = 3;
    else if (cp >= 0xC0) cp &= 0x1F, len = 2;
    for (unsigned k = 1; k < len; k++) cp = cp << 6 | (u[i + k] & 0x3F);
    i += len;
    unsigned units[2] = {cp, 0}, nu = 1;
    if (cp >= 0x10000) {
      units[0] = 0xD800 + ((cp - 0x10000) >> 10);
      units[1] = 0xDC00 + ((cp - 0x10000) & 0x3FF);
      nu = 2;
    }
    for (unsigned k = 0; k < nu; k++) {
      char p[2] = {(char)(be ? units[k] >> 8 : units[k] & 0xFF),
                   (char)(be ? units[k] & 0xFF : units[k] >> 8)};
      sb_raw(out, p, 2);
    }
  }
}

/* The fixture's text (free .s). */
static sbuf fx_text(const fx *f, const int *k) {
  sbuf b = {0};
  if (f->meta) sb_raw(&b, f->meta, strlen(f->meta));
  if (f->layout == FX_SIZE) sb_add(&b, "%d%c%d\n", f->w, f->sep, f->h);
  if (f->layout == FX_AXIS) {
    fx_cell_start(&b, f, 0);
    sb_raw(&b, f->label, strlen(f->label));
    fx_cell_end(&b, f);
    for (int x = 0; x < f->w; x++) {
      fx_cell_start(&b, f, 1);
      sb_add(&b, "%d", x);
      fx_cell_end(&b, f);
    }
    if (f->trailing) sb_add(&b, "%c", f->sep);
    sb_add(&b, "\n");
  }
  for (int y = 0; y < f->h; y++) {
    int lead = f->layout == FX_AXIS || f->layout == FX_FRAME;
    if (f->layout == FX_AXIS) {
      fx_cell_start(&b, f, 0);
      sb_add(&b, "%d", y);
      fx_cell_end(&b, f);
    } else if (f->layout == FX_FRAME && y == 0) {
      fx_cell_start(&b, f, 0);
      sb_raw(&b, f->label, strlen(f->label));
      fx_cell_end(&b, f);
    }
    for (int x = 0; x < f->w; x++) {
      fx_cell_start(&b, f, x + lead);
      fx_number(&b, k[y * f->w + x], f->dm, f->sci);
      fx_cell_end(&b, f);
    }
    if (f->trailing) sb_add(&b, "%c", f->sep);
    sb_add(&b, "\n");
    if (f->blank_after && y + 1 == f->blank_after) sb_add(&b, "\n");
  }
  /* line ends, then the encoding */
  sbuf e = {0};
  for (size_t i = 0; i < b.n; i++) {
    if (b.s[i] == '\n') sb_raw(&e, f->eol, strlen(f->eol));
    else sb_raw(&e, b.s + i, 1);
  }
  free(b.s);
  if (f->enc == ENC_RAW) return e;
  sbuf o = {0};
  if (f->enc == ENC_UTF8_BOM) {
    sb_raw(&o, "\xEF\xBB\xBF", 3);
    sb_raw(&o, e.s, e.n);
  } else {
    fx_utf16(&o, e.s, e.n, f->enc == ENC_UTF16BE);
  }
  free(e.s);
  return o;
}

/* the same values as a canonical text, parsed: the reference image */
static hearth_image fx_reference(int w, int h, const int *k) {
  fx plain = {w, h, ',', '.', 0, 0, "\n", 0, FX_PLAIN, NULL, NULL, ENC_RAW, 0};
  sbuf t = fx_text(&plain, k);
  hearth_image img = {0};
  hearth_err err = {0};
  hearth_csv_opts any = {0, 0};
  CHECK_OK(hearth_thermal_parse_csv(t.s, t.n, "reference", &any, &img, &err), &err);
  free(t.s);
  return img;
}

/* 1-based column (in bytes) of cell `cell` (0-based) of line `line` of an
 * ASCII text without quotes */
static size_t fx_column(const char *s, size_t n, size_t line, size_t cell, char sep) {
  size_t i = 0, l = 1;
  while (i < n && l < line)
    if (s[i++] == '\n') l++;
  size_t start = i, c = 0;
  while (i < n && c < cell && s[i] != '\n')
    if (s[i++] == sep) c++;
  return i - start + 1;
}

/* a metadata block from a template: '|' is the separator, '~' the decimal mark */
static char *fx_meta(const char *tpl, char sep, char dm) {
  size_t n = strlen(tpl);
  char *m = malloc(n + 1);
  for (size_t i = 0; i <= n; i++) m[i] = tpl[i] == '|' ? sep : tpl[i] == '~' ? dm : tpl[i];
  return m;
}

/* metadata blocks as camera software writes them (see the module notes) */
static const char *const k_meta_en =
    "File: C:\\captures\\HM0001.jpg\nUnit|\xC2\xB0"
    "C\nEmissivity|0~95\nDistance|0~5|m\n"
    "Min|18~20\nMax|45~70\nAvg|26~10\nDate|2024-05-01 12:00:00\n\n";
static const char *const k_meta_hik =
    "\"File\"|\"C:\\HM0001.jpg\"|\"\"|\"\"\n\"Emissivity\"|\"\"|\"\"|\"0~95\"\n"
    "\"Temperature Unit\"|\"\"|\"\"|\"\xC2\xB0"
    "C\"\n\"Min\"|\"\"|\"\"|\"18~2\"\n"
    "\"Max\"|\"\"|\"\"|\"45~7\"\n\"\"|\"\"|\"\"|\"\"\n";
static const char *const k_meta_flir =
    "File:|C:\\IR_0001.jpg\n\nParameters:|Emissivity:|0~95\n|Object distance:|1~0 m\n"
    "|Reflected apparent temperature:|20~0 \xC2\xB0"
    "C\n\n";
static const char *const k_meta_ko = /* cp949: emissivity, temperature unit, degree C */
    "\xB9\xE6\xBB\xE7\xC0\xB2|0~95\n\xBF\xC2\xB5\xB5\x20\xB4\xDC\xC0\xA7|\xA1\xC6\x43\n";
static const char *const k_meta_zh = /* GBK */
    "\xB7\xA2\xC9\xE4\xC2\xCA|0~95\n\xCE\xC2\xB6\xC8\xB5\xA5\xCE\xBB|\xA1\xE6\n";
static const char *const k_meta_ja = /* Shift-JIS */
    "\x95\xFA\x8E\xCB\x97\xA6|0~95\n\x89\xB7\x93\x78\x92\x50\x88\xCA|\x81\x8E\n";
static const char *const k_meta_de = /* Windows-1252 */
    "Emissionsgrad|0~95\nTemperatureinheit|\xB0"
    "C\nBemerkung|\xC4nderung\n";
static const char *const k_meta_utf8 =
    "\xE6\x94\xBE\xE5\xB0\x84\xE7\x8E\x87|0~95\nEmissivity|0~95\n\xE5\x8D\x95\xE4\xBD\x8D|"
    "\xE2\x84\x83\n";

/* what a variant must be recognised as */
typedef struct expect {
  const char *layout, *encoding, *line_ends;
  char decimal;
  size_t n_meta;
  const char *emissivity; /* hearth_thermal_info_get(info, "Emissivity"), or NULL */
  const char *label;      /* as the info gives it, or NULL */
  int celsius;            /* unit "degC" */
} expect;

typedef struct variant {
  const char *name;
  fx f;
  const char *meta_tpl;
  expect e;
} variant;

static void check_variant(const variant *v, uint64_t seed) {
  fx f = v->f;
  char *meta = v->meta_tpl ? fx_meta(v->meta_tpl, f.sep, f.dm) : NULL;
  f.meta = meta;
  int *k = fx_values(f.w, f.h, seed);
  hearth_image ref = fx_reference(f.w, f.h, k);
  sbuf t = fx_text(&f, k);
  hearth_csv_opts want = {(size_t)f.w, (size_t)f.h}, any = {0, 0};
  for (int pass = 0; pass < 2; pass++) {
    hearth_image img = {0};
    hearth_thermal_info info;
    hearth_err err = {0};
    hearth_status s =
        hearth_thermal_parse_csv_ex(t.s, t.n, v->name, pass ? &any : &want, &img, &info, &err);
    CHECK_MSG(s == HEARTH_OK, "%s: %s", v->name, err.msg);
    if (s == HEARTH_OK) {
      CHECK_MSG(img.width == ref.width && img.height == ref.height && img.data && ref.data &&
                    !memcmp(img.data, ref.data, ref.width * ref.height * sizeof(float)),
                "%s: values differ from the canonical CSV's", v->name);
      const expect *e = &v->e;
      CHECK_MSG(!strcmp(hearth_csv_layout_name(info.layout), e->layout), "%s: layout %s", v->name,
                hearth_csv_layout_name(info.layout));
      CHECK_MSG(info.separator == f.sep, "%s: separator '%c'", v->name, info.separator);
      CHECK_MSG(info.decimal_mark == e->decimal, "%s: decimal mark '%c'", v->name,
                info.decimal_mark ? info.decimal_mark : '0');
      CHECK_MSG(!strcmp(info.encoding, e->encoding), "%s: encoding %s", v->name, info.encoding);
      CHECK_MSG(!strcmp(info.line_ends, e->line_ends), "%s: line ends %s", v->name, info.line_ends);
      CHECK_MSG(info.n_meta == e->n_meta, "%s: %zu metadata pairs", v->name, info.n_meta);
      CHECK_MSG(info.width == (size_t)f.w && info.height == (size_t)f.h, "%s: info size", v->name);
      const char *em = hearth_thermal_info_get(&info, "emissivity");
      CHECK_MSG(e->emissivity ? em && !strcmp(em, e->emissivity) : !em, "%s: emissivity '%s'",
                v->name, em ? em : "(none)");
      CHECK_MSG(e->label ? info.label && !strcmp(info.label, e->label) : !info.label,
                "%s: label '%s'", v->name, info.label ? info.label : "(none)");
      CHECK_MSG(e->celsius ? info.unit && !strcmp(info.unit, "degC") : !info.unit, "%s: unit %s",
                v->name, info.unit ? info.unit : "(none)");
      /* the matrix's lines: after the header lines, one per row (+ index row) */
      size_t rows = (size_t)f.h + (f.layout == FX_AXIS);
      CHECK_MSG(info.last_line - info.first_line + 1 == rows &&
                    info.header_lines + 1 == info.first_line,
                "%s: matrix lines %zu..%zu", v->name, info.first_line, info.last_line);
    }
    hearth_thermal_info_free(&info);
    hearth_image_free(&img);
  }
  free(t.s);
  free(meta);
  free(k);
  hearth_image_free(&ref);
}

#define PLAIN(w, h, sep, dm, q, tr, eol) \
  w, h, sep, dm, q, tr, eol, 0, FX_PLAIN, NULL, NULL, ENC_RAW, 0
static void test_variants(void) {
  const variant v[] = {
      /* separators, decimal marks, quotes, line ends, trailing separators */
      {"plain",
       {PLAIN(256, 192, ',', '.', 0, 0, "\n")},
       NULL,
       {"plain", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"semicolon-comma-crlf-trailing",
       {PLAIN(256, 192, ';', ',', 0, 1, "\r\n")},
       NULL,
       {"plain", "ascii", "CRLF", ',', 0, NULL, NULL, 0}},
      {"semicolon-dot",
       {PLAIN(256, 192, ';', '.', 0, 0, "\n")},
       NULL,
       {"plain", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"tab-comma-cr",
       {PLAIN(256, 192, '\t', ',', 0, 0, "\r")},
       NULL,
       {"plain", "ascii", "CR", ',', 0, NULL, NULL, 0}},
      {"tab-dot-trailing",
       {PLAIN(256, 192, '\t', '.', 0, 1, "\n")},
       NULL,
       {"plain", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"quoted-comma-in-comma-csv",
       {PLAIN(256, 192, ',', ',', 1, 0, "\r\n")},
       NULL,
       {"plain", "ascii", "CRLF", ',', 0, NULL, NULL, 0}},
      {"quoted-semicolon",
       {PLAIN(256, 192, ';', '.', 1, 1, "\n")},
       NULL,
       {"plain", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"sci-dot",
       {256, 192, ',', '.', 0, 0, "\n", 1, FX_PLAIN, NULL, NULL, ENC_RAW, 0},
       NULL,
       {"plain", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"sci-comma-semicolon",
       {256, 192, ';', ',', 0, 0, "\r\n", 1, FX_PLAIN, NULL, NULL, ENC_RAW, 0},
       NULL,
       {"plain", "ascii", "CRLF", ',', 0, NULL, NULL, 0}},
      /* sizes */
      {"160x120",
       {PLAIN(160, 120, ',', '.', 0, 0, "\n")},
       NULL,
       {"plain", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"640x512-semicolon",
       {PLAIN(640, 512, ';', ',', 0, 1, "\r\n")},
       NULL,
       {"plain", "ascii", "CRLF", ',', 0, NULL, NULL, 0}},
      /* size lines */
      {"size-line",
       {256, 192, ',', '.', 0, 0, "\n", 0, FX_SIZE, NULL, NULL, ENC_RAW, 0},
       NULL,
       {"size-line", "ascii", "LF", '.', 0, NULL, NULL, 0}},
      {"size-line-160x120-metadata",
       {160, 120, ';', ',', 0, 1, "\r\n", 0, FX_SIZE, NULL, NULL, ENC_RAW, 0},
       k_meta_en,
       {"size-line", "utf-8", "CRLF", ',', 8, "0,95", NULL, 1}},
      /* axis-labelled matrices (HIKMICRO Analyzer) with corner labels of several locales */
      {"axis-xy",
       {256, 192, ',', '.', 0, 0, "\n", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0},
       NULL,
       {"axis-labelled", "ascii", "LF", '.', 0, NULL, "X/Y", 0}},
      {"axis-empty-corner",
       {256, 192, ';', ',', 0, 1, "\r\n", 0, FX_AXIS, "", NULL, ENC_RAW, 0},
       NULL,
       {"axis-labelled", "ascii", "CRLF", ',', 0, NULL, "", 0}},
      {"axis-hikmicro-quoted",
       {256, 192, ',', ',', 1, 0, "\r\n", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0},
       k_meta_hik,
       {"axis-labelled", "utf-8", "CRLF", ',', 5, "0,95", "X/Y", 1}},
      {"axis-korean-utf8-bom",
       {256, 192, ',', '.', 0, 0, "\r\n", 0, FX_AXIS, "\xEC\xB6\x95", NULL, ENC_UTF8_BOM, 0},
       NULL,
       {"axis-labelled", "utf-8-bom", "CRLF", '.', 0, NULL, "\xEC\xB6\x95", 0}},
      {"axis-korean-cp949",
       {256, 192, ';', ',', 0, 0, "\r\n", 0, FX_AXIS, "\xC3\xE0", NULL, ENC_RAW, 0},
       k_meta_ko,
       {"axis-labelled", "8-bit", "CRLF", ',', 2, NULL, "\\xc3\\xe0", 1}},
      {"axis-chinese-gbk",
       {256, 192, ',', '.', 0, 0, "\n", 0, FX_AXIS, "\xD6\xE1", NULL, ENC_RAW, 0},
       k_meta_zh,
       {"axis-labelled", "8-bit", "LF", '.', 2, NULL, "\\xd6\\xe1", 1}},
      {"axis-japanese-sjis",
       {256, 192, '\t', ',', 0, 0, "\r\n", 0, FX_AXIS, "\x8E\xB2", NULL, ENC_RAW, 0},
       k_meta_ja,
       {"axis-labelled", "8-bit", "CRLF", ',', 2, NULL, "\\x8e\\xb2", 1}},
      {"axis-german-1252",
       {256, 192, ';', ',', 0, 1, "\r\n", 0, FX_AXIS, "Achse", NULL, ENC_RAW, 0},
       k_meta_de,
       {"axis-labelled", "8-bit", "CRLF", ',', 3, NULL, "Achse", 1}},
      {"axis-russian-utf16le",
       {256, 192, ';', ',', 0, 0, "\r\n", 0, FX_AXIS, "\xD0\x9E\xD1\x81\xD1\x8C", NULL, ENC_UTF16LE,
        0},
       k_meta_utf8,
       {"axis-labelled", "utf-16le-bom", "CRLF", ',', 3, "0,95", "\xD0\x9E\xD1\x81\xD1\x8C", 1}},
      {"axis-japanese-utf16be",
       {256, 192, '\t', '.', 0, 0, "\r\n", 0, FX_AXIS, "\xE8\xBB\xB8", NULL, ENC_UTF16BE, 0},
       k_meta_utf8,
       {"axis-labelled", "utf-16be-bom", "CRLF", '.', 3, "0.95", "\xE8\xBB\xB8", 1}},
      {"axis-160x120",
       {160, 120, ',', '.', 0, 0, "\n", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0},
       NULL,
       {"axis-labelled", "ascii", "LF", '.', 0, NULL, "X/Y", 0}},
      {"axis-640x512-cr",
       {640, 512, ';', ',', 0, 0, "\r", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0},
       NULL,
       {"axis-labelled", "ascii", "CR", ',', 0, NULL, "X/Y", 0}},
      {"axis-4x3",
       {4, 3, ',', '.', 0, 0, "\n", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0},
       NULL,
       {"axis-labelled", "ascii", "LF", '.', 0, NULL, "X/Y", 0}},
      /* frame-labelled matrices (FLIR) */
      {"frame-flir-semicolon",
       {256, 192, ';', ',', 0, 1, "\r\n", 0, FX_FRAME, "Image 1", NULL, ENC_RAW, 0},
       NULL,
       {"frame-labelled", "ascii", "CRLF", ',', 0, NULL, "Image 1", 0}},
      {"frame-flir-metadata",
       {256, 192, ',', '.', 0, 0, "\n", 0, FX_FRAME, "Frame 1", NULL, ENC_RAW, 0},
       k_meta_flir,
       {"frame-labelled", "utf-8", "LF", '.', 4, NULL, "Frame 1", 1}},
      {"frame-3x2",
       {3, 2, ',', '.', 0, 0, "\n", 0, FX_FRAME, "Frame 1", NULL, ENC_RAW, 0},
       NULL,
       {"frame-labelled", "ascii", "LF", '.', 0, NULL, "Frame 1", 0}},
      /* metadata blocks over plain matrices, in each encoding */
      {"meta-en-semicolon",
       {PLAIN(256, 192, ';', ',', 0, 1, "\r\n")},
       k_meta_en,
       {"plain", "utf-8", "CRLF", ',', 8, "0,95", NULL, 1}},
      {"meta-en-comma-bom",
       {256, 192, ',', '.', 0, 0, "\n", 0, FX_PLAIN, NULL, NULL, ENC_UTF8_BOM, 0},
       k_meta_en,
       {"plain", "utf-8-bom", "LF", '.', 8, "0.95", NULL, 1}},
      {"meta-en-utf16le",
       {256, 192, '\t', ',', 0, 0, "\r\n", 0, FX_PLAIN, NULL, NULL, ENC_UTF16LE, 0},
       k_meta_en,
       {"plain", "utf-16le-bom", "CRLF", ',', 8, "0,95", NULL, 1}},
      {"meta-en-utf16be",
       {256, 192, ',', '.', 0, 0, "\n", 0, FX_PLAIN, NULL, NULL, ENC_UTF16BE, 0},
       k_meta_en,
       {"plain", "utf-16be-bom", "LF", '.', 8, "0.95", NULL, 1}},
      {"meta-ko-cp949",
       {PLAIN(256, 192, ';', ',', 0, 0, "\r\n")},
       k_meta_ko,
       {"plain", "8-bit", "CRLF", ',', 2, NULL, NULL, 1}},
      {"meta-zh-gbk",
       {PLAIN(256, 192, ',', '.', 0, 0, "\r\n")},
       k_meta_zh,
       {"plain", "8-bit", "CRLF", '.', 2, NULL, NULL, 1}},
      {"meta-ja-sjis",
       {PLAIN(256, 192, '\t', '.', 0, 0, "\n")},
       k_meta_ja,
       {"plain", "8-bit", "LF", '.', 2, NULL, NULL, 1}},
      {"meta-de-1252-cr",
       {PLAIN(256, 192, ';', ',', 0, 0, "\r")},
       k_meta_de,
       {"plain", "8-bit", "CR", ',', 3, NULL, NULL, 1}},
      {"meta-utf8",
       {PLAIN(160, 120, ';', ',', 0, 0, "\n")},
       k_meta_utf8,
       {"plain", "utf-8", "LF", ',', 3, "0,95", NULL, 1}},
      {"meta-hikmicro-plain",
       {PLAIN(256, 192, ',', ',', 1, 0, "\r\n")},
       k_meta_hik,
       {"plain", "utf-8", "CRLF", ',', 5, "0,95", NULL, 1}},
  };
  for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) check_variant(&v[i], 100 + i);

  /* from a file: the HIKMICRO-like export through hearth_thermal_read_csv_ex */
  const variant *h = v;
  while (strcmp(h->name, "axis-hikmicro-quoted")) h++;
  fx f = h->f;
  char *meta = fx_meta(h->meta_tpl, f.sep, f.dm), path[1200];
  f.meta = meta;
  int *k = fx_values(f.w, f.h, 7);
  sbuf t = fx_text(&f, k);
  snprintf(path, sizeof path, "%s/hikmicro.csv", test_tmpdir("io_test_csv_variants"));
  hearth_err err = {0};
  CHECK_OK(hearth_write_file_atomic(path, t.s, t.n, &err), &err);
  hearth_image img, ref = fx_reference(f.w, f.h, k);
  hearth_thermal_info info;
  CHECK_OK(hearth_thermal_read_csv_ex(path, NULL, &img, &info, &err), &err);
  CHECK(img.data && ref.data && !memcmp(img.data, ref.data, sizeof(float) * 256 * 192));
  CHECK(info.layout == HEARTH_CSV_AXIS && info.n_meta == 5 && info.meta &&
        !strcmp(info.meta[0].key, "File") && !strcmp(info.meta[0].value, "C:\\HM0001.jpg") &&
        info.meta[0].line == 1 && info.first_line == 7);
  CHECK(!strcmp(hearth_thermal_info_get(&info, "temperature unit"),
                "\xC2\xB0"
                "C"));
  hearth_thermal_info_free(&info);
  hearth_thermal_info_free(&info); /* freeing twice (zeroed) is fine */
  hearth_image_free(&img);
  hearth_image_free(&ref);
  free(t.s);
  free(k);
  free(meta);
}

/* ---- mangled forms ------------------------------------------------------------ */
/* offset of line `line` (1-based) of an ASCII text */
static size_t fx_line_start(const sbuf *t, size_t line) {
  size_t i = 0, l = 1;
  while (i < t->n && l < line)
    if (t->s[i++] == '\n') l++;
  return i;
}

/* replace s[a..b) of t by rep */
static void fx_splice(sbuf *t, size_t a, size_t b, const char *rep) {
  sbuf o = {0};
  sb_raw(&o, t->s, a);
  sb_raw(&o, rep, strlen(rep));
  sb_raw(&o, t->s + b, t->n - b);
  free(t->s);
  *t = o;
}

/* replace cell `cell` (0-based) of line `line` of an unquoted ASCII text */
static void fx_set_cell(sbuf *t, size_t line, size_t cell, char sep, const char *rep) {
  size_t a = fx_line_start(t, line) + fx_column(t->s, t->n, line, cell, sep) - 1, b = a;
  while (b < t->n && t->s[b] != sep && t->s[b] != '\n' && t->s[b] != '\r') b++;
  fx_splice(t, a, b, rep);
}

static sbuf fx_make(const fx *f, uint64_t seed) {
  int *k = fx_values(f->w, f->h, seed);
  sbuf t = fx_text(f, k);
  free(k);
  return t;
}

static void expect_fail(const char *label, const sbuf *t, const hearth_csv_opts *opts,
                        hearth_status want, size_t line, size_t col, const char *also) {
  hearth_image img = {0};
  hearth_thermal_info info;
  hearth_err err = {0};
  hearth_status s = hearth_thermal_parse_csv_ex(t->s, t->n, "cam/x.csv", opts, &img, &info, &err);
  CHECK_MSG(s == want, "%s: got %s (%s), expected %s", label, hearth_status_name(s), err.msg,
            hearth_status_name(want));
  CHECK_MSG(img.data == NULL && info.meta == NULL && info.n_meta == 0 && info.label == NULL,
            "%s: output left behind", label);
  char where[96];
  snprintf(where, sizeof where, "cam/x.csv: line %zu, column %zu: ", line, col);
  CHECK_MSG(strncmp(err.msg, where, strlen(where)) == 0, "%s: message '%s' does not start '%s'",
            label, err.msg, where);
  CHECK_MSG(strstr(err.msg, "expected") != NULL, "%s: no 'expected' in '%s'", label, err.msg);
  if (also) CHECK_MSG(strstr(err.msg, also) != NULL, "%s: '%s' lacks '%s'", label, err.msg, also);
  hearth_image_free(&img);
}

static void test_mangled(void) {
  const hearth_csv_opts any = {0, 0}, cam = {256, 192};
  const fx axis = {256, 192, ',', '.', 0, 0, "\n", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0};
  const fx axis_small = {4, 3, ';', ',', 0, 0, "\n", 0, FX_AXIS, "X/Y", NULL, ENC_RAW, 0};
  const fx plain = {PLAIN(256, 192, ',', '.', 0, 0, "\n")};
  const fx plain_semi = {PLAIN(160, 120, ';', ',', 0, 1, "\n")};
  const fx frame = {256, 192, ';', ',', 0, 1, "\n", 0, FX_FRAME, "Frame 1", NULL, ENC_RAW, 0};
  sbuf t;

  /* one cell replaced: the error at cell err_cell of the same line */
  fx axis_meta = axis;
  char *meta = fx_meta(k_meta_en, ',', '.');
  axis_meta.meta = meta; /* 9 lines before the matrix */
  const struct {
    const char *label;
    const fx *f;
    size_t line, cell;
    const char *rep;
    hearth_status st;
    size_t err_cell;
    const char *needle;
  } one[] = {
      /* a wrong index row, an index column skipping a number or not an integer */
      {"index-row", &axis, 1, 100, "100", HEARTH_E_PARSE, 100, "column index '100', expected 99"},
      {"index-row-after-metadata", &axis_meta, 10, 7, "x", HEARTH_E_PARSE, 7, "column index 'x'"},
      {"index-column", &axis, 52, 0, "51", HEARTH_E_PARSE, 0, "row index '51', expected 50"},
      {"index-column-small", &axis_small, 3, 0, "2", HEARTH_E_PARSE, 0,
       "row index '2', expected 1"},
      {"index-column-decimal", &axis, 40, 0, "38.0", HEARTH_E_PARSE, 0, "row index '38.0'"},
      /* a ragged row, garbage, a second frame label */
      {"ragged-long-axis", &axis, 12, 256, "20.00,21.00", HEARTH_E_SIZE, 257,
       "row has more than 256 values, expected 256 (as the index row of line 1)"},
      {"garbage-axis", &axis, 9, 6, "2O.5", HEARTH_E_PARSE, 6, "'2O.5' is not a number"},
      {"nan-frame", &frame, 70, 3, "nan", HEARTH_E_PARSE, 3, "not a finite number"},
      {"second-frame", &frame, 101, 0, "Frame 2", HEARTH_E_PARSE, 0, "one frame per file"},
  };
  for (size_t i = 0; i < sizeof one / sizeof one[0]; i++) {
    t = fx_make(one[i].f, 1 + i);
    fx_set_cell(&t, one[i].line, one[i].cell, one[i].f->sep, one[i].rep);
    size_t col = fx_column(t.s, t.n, one[i].line, one[i].err_cell, one[i].f->sep);
    expect_fail(one[i].label, &t, one[i].f == &axis_small ? &any : &cam, one[i].st, one[i].line,
                col, one[i].needle);
    free(t.s);
  }
  free(meta);

  /* blank lines inside the matrix */
  {
    fx f = plain;
    f.blank_after = 100;
    t = fx_make(&f, 3);
    expect_fail("blank-inside", &t, &cam, HEARTH_E_PARSE, 101, 1, "blank line inside the matrix");
    free(t.s);
    f = plain_semi;
    f.eol = "\r\n";
    f.blank_after = 1;
    t = fx_make(&f, 3);
    expect_fail("blank-inside-crlf", &t, &any, HEARTH_E_PARSE, 2, 1, "blank line");
    free(t.s);
    f = axis;
    f.blank_after = 191;
    t = fx_make(&f, 3);
    expect_fail("blank-inside-axis", &t, &cam, HEARTH_E_PARSE, 193, 1, "blank line");
    free(t.s);
    /* between the index row and the rows */
    t = fx_make(&axis, 3);
    fx_splice(&t, fx_line_start(&t, 2), fx_line_start(&t, 2), "\n");
    expect_fail("blank-after-index-row", &t, &cam, HEARTH_E_PARSE, 2, 1, "blank line");
    free(t.s);
    t = fx_make(&axis_small, 3);
    fx_splice(&t, fx_line_start(&t, 2), fx_line_start(&t, 2), ";;;;\n");
    expect_fail("blank-after-small-index-row", &t, &any, HEARTH_E_PARSE, 2, 1, "blank line");
    free(t.s);
  }

  /* ragged rows */
  t = fx_make(&plain_semi, 4);
  {
    size_t a = fx_line_start(&t, 30) + fx_column(t.s, t.n, 30, 159, ';') - 1, b = a;
    while (t.s[b] != '\n') b++;
    fx_splice(&t, a, b, ""); /* "...;v;" : 159 values and a trailing separator */
    expect_fail("ragged-short", &t, &any, HEARTH_E_SIZE, 30, a - fx_line_start(&t, 30) + 1,
                "row has 159 values, expected 160");
  }
  free(t.s);

  /* text added before or after the matrix */
  const struct {
    const char *label;
    const fx *f;
    const char *before, *after;
    hearth_status st;
    size_t line, col;
    const char *needle;
  } added[] = {
      /* metadata after the data; numbers before the metadata; a size line */
      {"metadata-after", &plain, "", "Emissivity,0.95\n", HEARTH_E_PARSE, 193, 1,
       "'Emissivity' is not a number"},
      {"metadata-after-axis", &axis, "", "\n\nMax,45.2\n", HEARTH_E_PARSE, 196, 1, "'Max'"},
      {"numbers-before-metadata", &plain, "0.95\nDate,2024-05-01\n", "", HEARTH_E_PARSE, 1, 1,
       "before the metadata"},
      {"size-line-disagrees", &plain, "256,191\n", "", HEARTH_E_SIZE, 1, 1,
       "size line says 256x191, expected the 256x192"},
      /* units other than degC are refused, at the unit's column */
      {"unit-degF", &plain,
       "Emissivity,0.95\nUnit,\xC2\xB0"
       "F\n",
       "", HEARTH_E_UNSUPPORTED, 2, 6, "temperature unit '\\xc2\\xb0F'"},
      {"unit-kelvin", &plain, "Temperature unit: K\n", "", HEARTH_E_UNSUPPORTED, 1, 19,
       "temperature unit 'K'"},
      {"unit-hint-degF", &plain,
       "Min: 65.1 \xC2\xB0"
       "F\n",
       "", HEARTH_E_UNSUPPORTED, 1, 11, "expected degC"},
      /* Windows-1252 text: columns count bytes */
      {"unit-hint-1252", &plain_semi,
       "\xC4nderung;x\nMax;98,6\xB0"
       "F\n",
       "", HEARTH_E_UNSUPPORTED, 2, 9, "expected degC"},
      {"unit-unknown", &plain, "Unit,counts\n", "", HEARTH_E_UNSUPPORTED, 1, 6, "'counts'"},
  };
  for (size_t i = 0; i < sizeof added / sizeof added[0]; i++) {
    t = fx_make(added[i].f, 20 + i);
    fx_splice(&t, 0, 0, added[i].before);
    sb_add(&t, "%s", added[i].after);
    expect_fail(added[i].label, &t, added[i].f == &plain_semi ? &any : &cam, added[i].st,
                added[i].line, added[i].col, added[i].needle);
    free(t.s);
  }

  /* sizes */
  t = fx_make(&plain_semi, 8);
  expect_fail("160x120-expected-256x192", &t, NULL, HEARTH_E_SIZE, 1, fx_line_start(&t, 2),
              "row has 160 values, expected 256 (a 256x192 matrix)");
  free(t.s);
  {
    fx f = axis;
    f.w = 160;
    f.h = 120;
    t = fx_make(&f, 8);
    expect_fail("axis-160-expected-256", &t, &cam, HEARTH_E_SIZE, 1, 1,
                "numbers 160 columns, expected 256");
    free(t.s);
    f = plain;
    f.h = 191;
    t = fx_make(&f, 8);
    expect_fail("191-rows-expected-192", &t, &cam, HEARTH_E_SIZE, 192, 1,
                "matrix ends after 191 rows of 256 values, expected 256x192");
    free(t.s);
  }

  /* UTF-16 problems */
  {
    fx f = plain_semi;
    f.enc = ENC_UTF16LE;
    t = fx_make(&f, 10);
    fx_splice(&t, 0, 2, ""); /* the byte order mark lost */
    expect_fail("utf16-no-bom", &t, &any, HEARTH_E_PARSE, 1, 1, "UTF-16 without a byte order mark");
    free(t.s);
    sbuf raw = fx_make(&plain_semi, 10);
    t = fx_make(&f, 10);
    t.n--; /* a lone byte at the end, after line 120's characters */
    expect_fail("utf16-odd", &t, &any, HEARTH_E_PARSE, 120, raw.n - fx_line_start(&raw, 120),
                "pairs of bytes");
    free(t.s);
    /* a high surrogate alone at the start of line 2 */
    t = fx_make(&f, 10);
    size_t at = 2 + 2 * fx_line_start(&raw, 2);
    {
      sbuf o = {0};
      sb_raw(&o, t.s, at);
      sb_raw(&o, "\x00\xD8", 2);
      sb_raw(&o, t.s + at, t.n - at);
      free(t.s);
      t = o;
    }
    expect_fail("utf16-surrogate", &t, &any, HEARTH_E_PARSE, 2, 1, "unpaired UTF-16 surrogate");
    free(t.s);
    free(raw.s);
  }
}

int main(void) {
  test_variants();
  test_mangled();
  TEST_MAIN_END();
}
