/* Thermal CSV: round trip, every accepted export variant, and every kind of
 * rejection with its status, line and column. Texts are built here with
 * snprintf (C locale), independently of the writer under test. */
#include <dirent.h>
#include <stdarg.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/thermal.h"
#include "test_util.h"

#define W 256
#define H 192

/* a growable string */
typedef struct sbuf {
  char *s;
  size_t n, cap;
} sbuf;

static void sb_add(sbuf *b, const char *fmt, ...) {
  va_list ap;
  for (;;) {
    va_start(ap, fmt);
    int m = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
    va_end(ap);
    if (b->s && (size_t)m < b->cap - b->n) {
      b->n += (size_t)m;
      return;
    }
    b->cap = (b->cap + (size_t)m + 1) * 2;
    b->s = realloc(b->s, b->cap);
  }
}

/* centi-degrees: value = k / 100 */
static int g_k[H][W];

static void make_matrix(void) {
  hearth_rng r;
  hearth_rng_seed(&r, 42);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) g_k[y][x] = (int)hearth_rng_range(&r, -4999, 64999);
  g_k[0][0] = -5000; /* the range ends are allowed */
  g_k[1][1] = 65000;
  g_k[2][2] = 0;
  g_k[3][3] = -5; /* -0.05 */
}

/* a matrix text: sep between cells, decimal mark dm, optional quotes,
 * line ending eol, trailing separator */
static void emit(sbuf *b, char sep, char dm, int quote, const char *eol, int trailing_sep) {
  for (int y = 0; y < H; y++) {
    for (int x = 0; x < W; x++) {
      int k = g_k[y][x], a = k < 0 ? -k : k;
      if (x) sb_add(b, "%c", sep);
      sb_add(b, "%s%s%d%c%02d%s", quote ? "\"" : "", k < 0 ? "-" : "", a / 100, dm, a % 100,
             quote ? "\"" : "");
    }
    if (trailing_sep) sb_add(b, "%c", sep);
    sb_add(b, "%s", eol);
  }
}

static int matches_reference(const hearth_image *img) {
  if (img->width != W || img->height != H || img->channels != 1 || img->type != HEARTH_PIX_F32)
    return 0;
  const float *t = img->data;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++)
      if (t[y * W + x] != (float)(g_k[y][x] / 100.0)) {
        fprintf(stderr, "  mismatch at (%d,%d): %.9g vs %.9g\n", x, y, t[y * W + x],
                g_k[y][x] / 100.0);
        return 0;
      }
  return 1;
}

static void check_variant(const char *label, const sbuf *b) {
  hearth_image img;
  hearth_err err = {0};
  hearth_status s = hearth_thermal_parse_csv(b->s, b->n, label, NULL, &img, &err);
  CHECK_MSG(s == HEARTH_OK, "%s: %s", label, err.msg);
  if (s == HEARTH_OK) CHECK_MSG(matches_reference(&img), "%s: values differ", label);
  hearth_image_free(&img);
}

static void test_variants(void) {
  struct {
    const char *label;
    char sep, dm;
    int quote;
    const char *eol;
    int trailing;
  } v[] = {
      {"canonical", ',', '.', 0, "\n", 0},
      {"semicolon-dot", ';', '.', 0, "\n", 0},
      {"semicolon-comma", ';', ',', 0, "\n", 0},
      {"tab-dot", '\t', '.', 0, "\n", 0},
      {"tab-comma", '\t', ',', 0, "\n", 0},
      {"quoted-dot", ',', '.', 1, "\n", 0},
      {"quoted-comma", ',', ',', 1, "\n", 0},
      {"quoted-semicolon", ';', ',', 1, "\n", 0},
      {"crlf", ',', '.', 0, "\r\n", 0},
      {"trailing-sep", ',', '.', 0, "\n", 1},
      {"trailing-sep-semicolon-crlf", ';', ',', 0, "\r\n", 1},
  };
  for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
    sbuf b = {0};
    emit(&b, v[i].sep, v[i].dm, v[i].quote, v[i].eol, v[i].trailing);
    check_variant(v[i].label, &b);
    free(b.s);
  }

  /* BOM, header lines of several kinds, trailing empty lines */
  sbuf b = {0};
  sb_add(&b, "\xEF\xBB\xBF");
  sb_add(&b,
         "Thermal export \xC2\xB0"
         "C, camera XYZ\r\n");
  sb_add(&b, "Date;2024-05-01 12:00:00\r\n");
  sb_add(&b, "Emissivity;0,95\r\n");
  sb_add(&b,
         "Reflected temperature;20,0;\xC2\xB0"
         "C\r\n");
  sb_add(&b, "\r\n");
  sb_add(&b, "256;192\r\n"); /* a full numeric row of another width is a header */
  emit(&b, ';', ',', 0, "\r\n", 1);
  sb_add(&b, "\r\n\r\n   \r\n");
  check_variant("bom-header-semicolon-crlf", &b);
  free(b.s);

  /* key,value header with a canonical matrix, spaces after separators */
  b = (sbuf){0};
  sb_add(&b, "Frame,1\nEmissivity,0.95\n\n");
  for (int y = 0; y < H; y++) {
    for (int x = 0; x < W; x++) sb_add(&b, "%s%.2f", x ? ", " : "", g_k[y][x] / 100.0);
    sb_add(&b, "\n");
  }
  sb_add(&b, "\n\n");
  check_variant("header-spaces", &b);
  free(b.s);

  /* no final newline */
  b = (sbuf){0};
  emit(&b, ',', '.', 0, "\n", 0);
  b.n--;
  check_variant("no-final-newline", &b);
  free(b.s);
}

/* a small writer round trip + byte-exact comparison with snprintf text */
static void test_round_trip(const char *dir) {
  hearth_image img;
  hearth_err err = {0};
  CHECK_OK(hearth_image_alloc(&img, W, H, 1, HEARTH_PIX_F32, &err), &err);
  float *t = img.data;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) t[y * W + x] = (float)(g_k[y][x] / 100.0);
  char path[1200];
  snprintf(path, sizeof path, "%s/rt.csv", dir);
  CHECK_OK(hearth_thermal_write_csv(path, &img, 2, &err), &err);

  sbuf ref = {0};
  for (int y = 0; y < H; y++) {
    for (int x = 0; x < W; x++) sb_add(&ref, "%s%.2f", x ? "," : "", g_k[y][x] / 100.0);
    sb_add(&ref, "\n");
  }
  uint8_t *data = NULL;
  size_t size = 0;
  CHECK_OK(hearth_read_file(path, 1 << 26, &data, &size, &err), &err);
  CHECK(size == ref.n && data && memcmp(data, ref.s, ref.n) == 0);
  free(data);
  free(ref.s);

  hearth_image back;
  CHECK_OK(hearth_thermal_read_csv(path, NULL, &back, &err), &err);
  CHECK(matches_reference(&back));
  hearth_image_free(&back);

  /* a value too small to show with 1 decimal is written without a "-" */
  t[0] = -0.01f;
  CHECK_OK(hearth_thermal_write_csv(path, &img, 1, &err), &err);
  CHECK_OK(hearth_read_file(path, 1 << 26, &data, &size, &err), &err);
  CHECK(data && strncmp((char *)data, "0.0,", 4) == 0);
  free(data);
  hearth_image_free(&img);

  /* small matrices with explicit and free sizes */
  const char *small = "1.5,2,3\n4,5,-6.25\n";
  hearth_csv_opts any = {0, 0}, exact = {3, 2}, wrong = {3, 3};
  CHECK_OK(hearth_thermal_parse_csv(small, strlen(small), "small", &any, &back, &err), &err);
  CHECK(back.width == 3 && back.height == 2);
  if (back.data) {
    CHECK(((float *)back.data)[0] == 1.5f && ((float *)back.data)[5] == -6.25f);
  }
  hearth_image_free(&back);
  CHECK_OK(hearth_thermal_parse_csv(small, strlen(small), "small", &exact, &back, &err), &err);
  hearth_image_free(&back);
  CHECK(hearth_thermal_parse_csv(small, strlen(small), "small", &wrong, &back, &err) ==
        HEARTH_E_SIZE);
  CHECK(back.data == NULL);
  /* a one-column, one-row matrix */
  CHECK_OK(hearth_thermal_parse_csv("7\n", 2, "one", &any, &back, &err), &err);
  CHECK(back.width == 1 && back.height == 1);
  hearth_image_free(&back);
}

/* the reader's values are bit-identical to hearth_parse_double on each cell,
 * for plain decimals of every length (short ones take a faster path) and
 * other forms (exponents, '+', leading '.', decimal commas) */
static void test_parse_identity(void) {
  hearth_rng r;
  hearth_rng_seed(&r, 7);
  enum { ROWS = 40, COLS = 25 };
  static char cells[ROWS][COLS][40];
  for (int pass = 0; pass < 2; pass++) {
    char sep = pass ? ';' : ',', dm = pass ? ',' : '.';
    sbuf b = {0};
    for (int y = 0; y < ROWS; y++) {
      for (int x = 0; x < COLS; x++) {
        char *c = cells[y][x];
        int k = 0, form = (int)(hearth_rng_u64(&r) % 8);
        int sign = (int)(hearth_rng_u64(&r) % 3);
        if (sign == 1 && form != 3) c[k++] = '-'; /* keep x10 values in range */
        if (sign == 2) c[k++] = '+';
        int ni = (int)(hearth_rng_u64(&r) % 3), nf = (int)(hearth_rng_u64(&r) % 19);
        if (form == 0) ni = 0, nf = nf ? nf : 1; /* ".5" */
        k +=
            snprintf(c + k, 8, "%d", ni == 0 ? 0 : (int)(hearth_rng_u64(&r) % (ni == 1 ? 10 : 49)));
        if (form == 0) k = sign ? 1 : 0; /* drop the 0 */
        if (form != 1) {
          c[k++] = dm;
          for (int i = 0; i < nf; i++) c[k++] = (char)('0' + hearth_rng_u64(&r) % 10);
        }
        if (form == 2) k += snprintf(c + k, 8, "e-%d", (int)(hearth_rng_u64(&r) % 3));
        if (form == 3) k += snprintf(c + k, 8, "E+1");
        c[k] = 0;
        sb_add(&b, "%s%s", x ? (pass ? ";" : ",") : "", c);
      }
      sb_add(&b, "\n");
    }
    (void)sep;
    hearth_csv_opts any = {0, 0};
    hearth_image img;
    hearth_err err = {0};
    CHECK_OK(hearth_thermal_parse_csv(b.s, b.n, "identity", &any, &img, &err), &err);
    if (img.data && img.width == COLS && img.height == ROWS) {
      const float *t = img.data;
      for (int y = 0; y < ROWS; y++)
        for (int x = 0; x < COLS; x++) {
          double d = 0;
          const char *c = cells[y][x];
          CHECK(hearth_parse_double(c, strlen(c), pass, &d) == 0);
          float f = (float)d;
          CHECK_MSG(memcmp(&f, &t[y * COLS + x], sizeof f) == 0, "'%s': %.9g vs %.9g", c, f,
                    t[y * COLS + x]);
        }
    } else {
      CHECK(0);
    }
    hearth_image_free(&img);
    free(b.s);
  }
}

/* ---- rejections ------------------------------------------------------------ */
/* constant "20.00" cells: cell j (0-based) starts at column 1 + 6 j */
static char *const_text(int rows, int cols, size_t *len) {
  sbuf b = {0};
  for (int y = 0; y < rows; y++) {
    for (int x = 0; x < cols; x++) sb_add(&b, "%s20.00", x ? "," : "");
    sb_add(&b, "\n");
  }
  *len = b.n;
  return b.s;
}

/* replace cell (line, cell) of a const text (lines 1-based, cells 0-based,
 * no header) by `cell` */
static char *with_cell(int line, int cell, const char *rep, size_t *len) {
  sbuf b = {0};
  for (int y = 1; y <= H; y++) {
    for (int x = 0; x < W; x++)
      sb_add(&b, "%s%s", x ? "," : "", (y == line && x == cell) ? rep : "20.00");
    sb_add(&b, "\n");
  }
  *len = b.n;
  return b.s;
}

static void expect_reject(const char *label, const char *text, size_t len, hearth_status want,
                          size_t line, size_t col, const char *also) {
  hearth_image img;
  hearth_err err = {0};
  hearth_status s = hearth_thermal_parse_csv(text, len, "cam/hot.csv", NULL, &img, &err);
  CHECK_MSG(s == want, "%s: got %s (%s), expected %s", label, hearth_status_name(s), err.msg,
            hearth_status_name(want));
  CHECK_MSG(img.data == NULL, "%s: image left allocated", label);
  char where[96];
  snprintf(where, sizeof where, "cam/hot.csv: line %zu, column %zu: ", line, col);
  CHECK_MSG(strncmp(err.msg, where, strlen(where)) == 0, "%s: message '%s' does not start '%s'",
            label, err.msg, where);
  CHECK_MSG(strstr(err.msg, "expected") != NULL, "%s: no 'expected' in '%s'", label, err.msg);
  if (also) CHECK_MSG(strstr(err.msg, also) != NULL, "%s: '%s' lacks '%s'", label, err.msg, also);
  hearth_image_free(&img);
}

static void test_rejections(void) {
  size_t n;
  char *t;
  /* NaN / infinity spellings at line 10, cell 5 -> column 31 */
  const char *naninf[] = {"nan",  "NaN",    "-nan",    "inf",    "-Infinity",
                          "+INF", "1.#INF", "-1.#IND", "\"NaN\""};
  for (size_t i = 0; i < sizeof naninf / sizeof naninf[0]; i++) {
    t = with_cell(10, 5, naninf[i], &n);
    expect_reject(naninf[i], t, n, HEARTH_E_PARSE, 10, 31, "finite");
    free(t);
  }
  /* empty cells: first cell of line 3, cell 7 of line 4, last cell of line 5 */
  t = with_cell(3, 0, "", &n);
  expect_reject("empty-first", t, n, HEARTH_E_PARSE, 3, 1, "empty");
  free(t);
  t = with_cell(4, 7, "", &n);
  expect_reject("empty-mid", t, n, HEARTH_E_PARSE, 4, 43, "empty");
  free(t);
  t = with_cell(5, 7, "\"\"", &n);
  expect_reject("empty-quoted", t, n, HEARTH_E_PARSE, 5, 43, "empty");
  free(t);
  /* two trailing separators: the second leaves an empty cell 256 */
  t = with_cell(6, 200, "20.00,,20.00", &n);
  expect_reject("double-sep", t, n, HEARTH_E_PARSE, 6, 1 + 6 * 201, "empty");
  free(t);
  /* two trailing separators: the second leaves a 257th (empty) cell */
  t = with_cell(6, 255, "20.00,,", &n);
  expect_reject("double-trailing-sep", t, n, HEARTH_E_SIZE, 6, 1 + 6 * 256, "256x192");
  free(t);

  /* out of range: 700 at line 7 cell 100, -60 and 650.01 elsewhere */
  t = with_cell(7, 100, "700.00", &n);
  expect_reject("range-high", t, n, HEARTH_E_RANGE, 7, 601, "-50..650");
  free(t);
  t = with_cell(192, 255, "-50.01", &n);
  expect_reject("range-low", t, n, HEARTH_E_RANGE, 192, 1531, "-50..650");
  free(t);
  t = with_cell(1, 1, "6.5e2", &n); /* exactly 650: allowed */
  {
    hearth_image img;
    hearth_err err = {0};
    CHECK_OK(hearth_thermal_parse_csv(t, n, "x", NULL, &img, &err), &err);
    hearth_image_free(&img);
  }
  free(t);
  t = with_cell(1, 1, "6.5001e2", &n);
  expect_reject("range-exp", t, n, HEARTH_E_RANGE, 1, 7, NULL);
  free(t);

  /* garbage characters */
  const char *junk[] = {"20.0x", "2O.00", "20..0", "--1", "1e", "0x10", "20.00 C", "\"20.00\"x",
                        "20\r00",
                        "\xC2\xB0"
                        "C",
                        /* long and non-printable: the message excerpt is cut safely */
                        "\x01\x02\x03\x04\x05\x06\x07\x08\x0b\x0c\x0e\x0f\x10\x11\x12\x13\x14\x15"
                        "\x16\x17\x18\x19\x1a\x1b\x1c\x1d\x1e\x1f\x7f\x80\x81\x82"};
  for (size_t i = 0; i < sizeof junk / sizeof junk[0]; i++) {
    t = with_cell(20, 2, junk[i], &n);
    expect_reject(junk[i], t, n, HEARTH_E_PARSE, 20, 13, NULL);
    free(t);
  }
  t = with_cell(20, 2, "\"20.00", &n);
  expect_reject("unterminated-quote", t, n, HEARTH_E_PARSE, 20, 13, "quote");
  free(t);
  /* a decimal comma with ',' separators splits the cell: one value too many */
  t = with_cell(30, 10, "20,5", &n);
  expect_reject("comma-in-comma-csv", t, n, HEARTH_E_SIZE, 30, 6 * 255, "256");
  free(t);
  /* a byte order mark does not count as a column */
  {
    sbuf b = {0};
    sb_add(&b, "\xEF\xBB\xBF");
    for (int y = 1; y <= H; y++) {
      for (int x = 0; x < W; x++)
        sb_add(&b, "%s%s", x ? "," : "", y == 1 && x == 2 ? "?" : "20.00");
      sb_add(&b, "\n");
    }
    expect_reject("bom-column", b.s, b.n, HEARTH_E_PARSE, 1, 13, NULL);
    free(b.s);
  }

  /* ragged rows: 255 values on line 50, 257 on line 60 */
  t = with_cell(50, 255, "", &n); /* "...,20.00,\n": a trailing separator, 255 values */
  expect_reject("ragged-short", t, n, HEARTH_E_SIZE, 50, 1 + 255 * 6, "256x192");
  free(t);
  t = with_cell(60, 255, "20.00,20.00", &n);
  expect_reject("ragged-long", t, n, HEARTH_E_SIZE, 60, 1 + 256 * 6, "256x192");
  free(t);
  /* a ragged last row */
  {
    sbuf b = {0};
    for (int y = 1; y <= H; y++) {
      int cols = y == H ? 201 : W;
      for (int x = 0; x < cols; x++) sb_add(&b, "%s20.00", x ? "," : "");
      sb_add(&b, "\n");
    }
    expect_reject("ragged-last", b.s, b.n, HEARTH_E_SIZE, 192, 201 * 6, "256x192");
    free(b.s);
  }

  /* wrong size: 255 columns everywhere, 191 rows, 193 rows */
  t = const_text(H, 255, &n);
  expect_reject("255-columns", t, n, HEARTH_E_SIZE, 1, 255 * 6, "256x192");
  free(t);
  t = const_text(191, W, &n);
  expect_reject("191-rows", t, n, HEARTH_E_SIZE, 192, 1, "256x192");
  free(t);
  t = const_text(193, W, &n);
  expect_reject("193-rows", t, n, HEARTH_E_SIZE, 193, 1, "256x192");
  free(t);

  /* line numbers count header lines */
  {
    sbuf b = {0};
    sb_add(&b, "Camera,XYZ\nEmissivity,0.95\n");
    for (int y = 1; y <= H; y++) {
      for (int x = 0; x < W; x++)
        sb_add(&b, "%s%s", x ? "," : "", y == 10 && x == 3 ? "x" : "20.00");
      sb_add(&b, "\n");
    }
    expect_reject("header-offset", b.s, b.n, HEARTH_E_PARSE, 12, 19, NULL);
    free(b.s);
  }
  /* a text row as wide as the matrix inside it */
  {
    sbuf b = {0};
    for (int y = 1; y <= H; y++) {
      for (int x = 0; x < W; x++) sb_add(&b, "%s%s", x ? "," : "", y == 70 ? "abcde" : "20.00");
      sb_add(&b, "\n");
    }
    expect_reject("text-row", b.s, b.n, HEARTH_E_PARSE, 70, 1, NULL);
    free(b.s);
  }
  /* text after the matrix */
  {
    size_t m;
    char *base = const_text(H, W, &m);
    sbuf b = {0};
    sb_add(&b, "%s", base);
    sb_add(&b, "End of data\n");
    expect_reject("footer", b.s, b.n, HEARTH_E_PARSE, 193, 1, NULL);
    free(b.s);
    free(base);
  }
  /* empty input and header only */
  expect_reject("empty", "", 0, HEARTH_E_PARSE, 1, 1, "256x192");
  expect_reject("header-only", "Camera,XYZ\nDate,today\n", 22, HEARTH_E_PARSE, 3, 1, NULL);
}

static int dir_entries(const char *dir) {
  DIR *d = opendir(dir);
  if (!d) return -1;
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
  closedir(d);
  return n;
}

static void test_failing_writes(const char *dir) {
  char sub[1200], path[1300];
  snprintf(sub, sizeof sub, "%s/w", dir);
  mkdir(sub, 0755);
  snprintf(path, sizeof path, "%s/out.csv", sub);
  hearth_image img;
  hearth_err err = {0};
  CHECK_OK(hearth_image_alloc(&img, 4, 3, 1, HEARTH_PIX_F32, &err), &err);
  float *t = img.data;
  for (int i = 0; i < 12; i++) t[i] = 20.0f + (float)i;

  /* a NaN pixel: refused, nothing written */
  t[5] = NAN;
  CHECK(hearth_thermal_write_csv(path, &img, 2, &err) == HEARTH_E_RANGE);
  CHECK(strstr(err.msg, "out.csv") != NULL);
  CHECK(dir_entries(sub) == 0);
  t[5] = 700.0f;
  CHECK(hearth_thermal_write_csv(path, &img, 2, &err) == HEARTH_E_RANGE);
  CHECK(dir_entries(sub) == 0);
  t[5] = 25.0f;

  /* an existing file is left intact by a failing write */
  CHECK_OK(hearth_thermal_write_csv(path, &img, 2, &err), &err);
  uint8_t *before = NULL, *after = NULL;
  size_t nb = 0, na = 0;
  CHECK_OK(hearth_read_file(path, 1 << 20, &before, &nb, &err), &err);
  t[0] = INFINITY;
  CHECK(hearth_thermal_write_csv(path, &img, 2, &err) == HEARTH_E_RANGE);
  CHECK_OK(hearth_read_file(path, 1 << 20, &after, &na, &err), &err);
  CHECK(nb == na && before && after && memcmp(before, after, nb) == 0);
  CHECK(dir_entries(sub) == 1);
  free(before);
  free(after);
  t[0] = 20.0f;

  /* a directory that does not exist */
  snprintf(path, sizeof path, "%s/missing/out.csv", dir);
  CHECK(hearth_thermal_write_csv(path, &img, 2, &err) == HEARTH_E_IO);
  CHECK(!hearth_path_exists(path));
  /* wrong pixel type */
  hearth_image u8;
  CHECK_OK(hearth_image_alloc(&u8, 4, 3, 1, HEARTH_PIX_U8, &err), &err);
  snprintf(path, sizeof path, "%s/u8.csv", sub);
  CHECK(hearth_thermal_write_csv(path, &u8, 2, &err) == HEARTH_E_ARG);
  CHECK(!hearth_path_exists(path));
  hearth_image_free(&u8);
  hearth_image_free(&img);

  /* reading: a missing file, and a file over the size limit (sparse) */
  hearth_image back;
  snprintf(path, sizeof path, "%s/nope.csv", dir);
  CHECK(hearth_thermal_read_csv(path, NULL, &back, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "nope.csv") != NULL);
  snprintf(path, sizeof path, "%s/huge.csv", dir);
  FILE *f = fopen(path, "wb");
  CHECK(f != NULL);
  if (f) {
    CHECK(ftruncate(fileno(f), (off_t)65 << 20) == 0);
    fclose(f);
    CHECK(hearth_thermal_read_csv(path, NULL, &back, &err) == HEARTH_E_LIMIT);
    CHECK(back.data == NULL);
    unlink(path);
  }
}

/* not a pass/fail criterion: printed for the report */
static void report_speed(void) {
  sbuf b = {0};
  emit(&b, ',', '.', 0, "\n", 0);
  hearth_image img;
  hearth_err err = {0};
  int reps = 50;
  double t0 = hearth_now();
  for (int i = 0; i < reps; i++) {
    hearth_thermal_parse_csv(b.s, b.n, "speed", NULL, &img, &err);
    hearth_image_free(&img);
  }
  double dt = (hearth_now() - t0) / reps;
  printf("parse 256x192 canonical (%zu bytes): %.3f ms\n", b.n, dt * 1e3);
  free(b.s);
}

int main(void) {
  const char *dir = test_tmpdir("io_test_csv");
  make_matrix();
  test_variants();
  test_round_trip(dir);
  test_parse_identity();
  test_rejections();
  test_failing_writes(dir);
  report_speed();
  TEST_MAIN_END();
}
