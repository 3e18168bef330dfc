/* The Parquet writer read back by independent code: files with every column
 * kind and the edge cases of the format (empty and long lists so that levels
 * need RLE runs and many bit-packed groups, a blob past the 1 MiB page
 * target, partial last row group, NaN / -0 / infinities, the int64 extremes,
 * non-ASCII paths, zero rows) are read by DuckDB (tests/io/read_parquet.js)
 * and by the Arrow Rust reader (tests/io/read_parquet_arrow.js) and compared
 * value by value by tests/io/check_parquet.py, which computes the same values
 * from the row number. Also: the same rows give the same
 * bytes, an aborted or failed writer leaves nothing, bad arguments are
 * refused. Missing node, a reader or python3 is a failure, not a skip. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "hearth/parquet.h"
#include "test_util.h"

#define ROWS 2600

/* the values of row r (check_parquet.py computes the same) */
static int64_t int_of(size_t r) {
  if (r == 1) return INT64_MIN;
  if (r == 2) return INT64_MAX;
  return ((int64_t)r * 7919 - 50000) * (r % 3 ? 1 : -1);
}
static float float_of(size_t r) {
  switch (r) {
    case 3: return NAN;
    case 4: return -0.0f;
    case 5: return INFINITY;
    case 6: return -INFINITY;
    case 7: return 1e-45f; /* the smallest denormal */
    default: return (float)r * 0.25f - 100.0f;
  }
}
static size_t list_len(size_t r) { return r == 10 ? 600 : r % 3; }
static float list_item(size_t r, size_t k) { return (float)r + (float)k / 1024.0f; }
static size_t blob_len(size_t r) { return r == 20 ? (size_t)1536 * 1024 : (r * 13) % 500; }
static uint8_t blob_byte(size_t r, size_t k) { return (uint8_t)(r * 31 + k * 7); }
static void path_of(size_t r, char *buf, size_t n) {
  if (r % 5 == 0) snprintf(buf, n, "%s", "");
  else snprintf(buf, n, "fr\xc3\xa4me_%06zu.png", r); /* "främe_..." */
}

static const hearth_pq_column k_cols[] = {{"n", HEARTH_PQ_INT64},
                                          {"x", HEARTH_PQ_FLOAT},
                                          {"v", HEARTH_PQ_FLOAT_LIST},
                                          {"b", HEARTH_PQ_BLOB}};

static void write_file(const char *path, size_t rows) {
  hearth_err e = {0};
  hearth_pq_writer *w = NULL;
  CHECK_OK(hearth_pq_open(path, k_cols, 4, 1000, &w, &e), &e);
  if (!w) return;
  CHECK_OK(hearth_pq_add_metadata(w, "huggingface", "{\"info\": {}}", &e), &e);
  CHECK_OK(hearth_pq_add_metadata(w, "second", "v\xc3\xa4lue", &e), &e);
  float *list = malloc(600 * sizeof *list);
  uint8_t *blob = malloc((size_t)1536 * 1024);
  for (size_t r = 0; r < rows && list && blob; r++) {
    char p[64];
    path_of(r, p, sizeof p);
    for (size_t k = 0; k < list_len(r); k++) list[k] = list_item(r, k);
    for (size_t k = 0; k < blob_len(r); k++) blob[k] = blob_byte(r, k);
    hearth_pq_cell cells[4] = {{.i = int_of(r)},
                               {.f = float_of(r)},
                               {.list = list, .list_len = list_len(r)},
                               {.bytes = blob, .bytes_len = blob_len(r), .path = p}};
    CHECK_OK(hearth_pq_write_row(w, cells, &e), &e);
  }
  free(list), free(blob);
  CHECK_OK(hearth_pq_close(w, &e), &e);
}

static int run(const char *cmd) {
  int rc = system(cmd);
  if (rc == -1 || !WIFEXITED(rc)) return -1;
  return WEXITSTATUS(rc);
}

static uint8_t *slurp(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long sz = ftell(f);
  fseek(f, 0, SEEK_SET);
  uint8_t *p = malloc(sz > 0 ? (size_t)sz : 1);
  if (p && fread(p, 1, (size_t)sz, f) != (size_t)sz) free(p), p = NULL;
  fclose(f);
  *n = (size_t)sz;
  return p;
}

int main(void) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (!src || !*src) src = ".";
  if (run("node --version >/dev/null 2>&1") != 0 ||
      run("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0) {
    fprintf(stderr,
            "FAIL: node and /usr/bin/python3 with numpy are needed; run scripts/setup.sh\n");
    return 1;
  }
  const char *dir = test_tmpdir("io_parquet");
  char a[1200], b[1200], empty[1200], dump[1200], cmd[6000];
  snprintf(a, sizeof a, "%s/a.parquet", dir);
  snprintf(b, sizeof b, "%s/b.parquet", dir);
  snprintf(empty, sizeof empty, "%s/empty.parquet", dir);
  snprintf(dump, sizeof dump, "%s/dump.json", dir);
  write_file(a, ROWS);
  write_file(b, ROWS);
  write_file(empty, 0);

  /* the same rows, the same bytes */
  size_t na = 0, nb = 0;
  uint8_t *pa = slurp(a, &na), *pb = slurp(b, &nb);
  CHECK(pa && pb && na == nb && memcmp(pa, pb, na) == 0);
  CHECK(pa && na > 12 && memcmp(pa, "PAR1", 4) == 0 && memcmp(pa + na - 4, "PAR1", 4) == 0);
  free(pa), free(pb);

  /* two readers independent of hearth and of each other: DuckDB and the Arrow Rust reader */
  static const char *const readers[] = {"read_parquet.js", "read_parquet_arrow.js"};
  for (int k = 0; k < 2; k++) {
    snprintf(cmd, sizeof cmd, "node '%s/tests/io/%s' '%s' '%s' '%s'", src, readers[k], dump, a,
             empty);
    int rc = run(cmd);
    CHECK_MSG(rc == 0, "%s exit status %d (1: unreadable, 3: its npm packages missing)", readers[k],
              rc);
    if (rc == 0) {
      snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s/tests/io/check_parquet.py' '%s' %d", src,
               dump, ROWS);
      CHECK_MSG(run(cmd) == 0, "check_parquet.py found differences in what %s read", readers[k]);
    }
  }

  /* an aborted writer and a refused row leave nothing behind */
  char sub[1200];
  snprintf(sub, sizeof sub, "%s/aborted", dir);
  snprintf(cmd, sizeof cmd, "mkdir -p '%s'", sub);
  CHECK(run(cmd) == 0);
  hearth_err e = {0};
  hearth_pq_writer *w = NULL;
  char p[1300];
  snprintf(p, sizeof p, "%s/x.parquet", sub);
  CHECK_OK(hearth_pq_open(p, k_cols, 4, 10, &w, &e), &e);
  hearth_pq_cell bad[4] = {{.i = 1}, {.f = 1}, {.list = NULL, .list_len = 3}, {.path = "p"}};
  CHECK(hearth_pq_write_row(w, bad, &e) == HEARTH_E_ARG && strstr(e.msg, p) != NULL);
  CHECK(hearth_pq_close(w, &e) != HEARTH_OK);
  CHECK_OK(hearth_pq_open(p, k_cols, 4, 10, &w, &e), &e);
  hearth_pq_abort(w);
  hearth_pq_abort(NULL);
  /* refused arguments */
  CHECK(hearth_pq_open(p, k_cols, 0, 10, &w, &e) == HEARTH_E_ARG && w == NULL);
  CHECK(hearth_pq_open(p, k_cols, 4, 0, &w, &e) == HEARTH_E_ARG);
  hearth_pq_column noname[1] = {{"", HEARTH_PQ_INT64}};
  CHECK(hearth_pq_open(p, noname, 1, 10, &w, &e) == HEARTH_E_ARG);
  hearth_pq_column badkind[1] = {{"k", (hearth_pq_kind)9}};
  CHECK(hearth_pq_open(p, badkind, 1, 10, &w, &e) == HEARTH_E_ARG);
  snprintf(p, sizeof p, "%s/no/such/dir/x.parquet", dir);
  CHECK(hearth_pq_open(p, k_cols, 4, 10, &w, &e) == HEARTH_E_IO);
  CHECK(rmdir(sub) == 0); /* only an empty directory goes */
  TEST_MAIN_END();
}
