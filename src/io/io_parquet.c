/* Apache Parquet writer (hearth/parquet.h): rows are split into leaf
 * columns as they come, each leaf collects its levels and PLAIN values into
 * data pages in memory, and a full row group is written column chunk after
 * column chunk; the footer (FileMetaData, Thrift compact protocol) follows
 * the last group. Field ids and enum values are those of parquet.thrift. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/parquet.h"

/* ---- growable byte buffer -------------------------------------------------- */
typedef struct bytes {
  uint8_t *p;
  size_t n, cap;
  int failed; /* an allocation failed; later appends do nothing */
} bytes;

static void b_reserve(bytes *b, size_t more) {
  if (b->failed) return;
  if (more > SIZE_MAX / 2 - b->n) {
    b->failed = 1;
    return;
  }
  if (b->n + more <= b->cap) return;
  size_t cap = b->cap ? b->cap : 256;
  while (cap < b->n + more) cap *= 2;
  uint8_t *np = realloc(b->p, cap);
  if (!np) {
    b->failed = 1;
    return;
  }
  b->p = np, b->cap = cap;
}
static void b_put(bytes *b, const void *p, size_t n) {
  b_reserve(b, n);
  if (b->failed || n == 0) return;
  memcpy(b->p + b->n, p, n);
  b->n += n;
}
static void b_byte(bytes *b, uint8_t v) { b_put(b, &v, 1); }
static void b_le32(bytes *b, uint32_t v) {
  uint8_t q[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
  b_put(b, q, 4);
}
static void b_le64(bytes *b, uint64_t v) {
  uint8_t q[8];
  for (int k = 0; k < 8; k++) q[k] = (uint8_t)(v >> (8 * k));
  b_put(b, q, 8);
}
static void b_varint(bytes *b, uint64_t v) {
  while (v >= 0x80) {
    b_byte(b, (uint8_t)(v | 0x80));
    v >>= 7;
  }
  b_byte(b, (uint8_t)v);
}
static void b_free(bytes *b) {
  free(b->p);
  memset(b, 0, sizeof *b);
}

/* ---- Thrift compact protocol ------------------------------------------------ */
enum { T_I32 = 5, T_I64 = 6, T_BINARY = 8, T_LIST = 9, T_STRUCT = 12 };

/* a struct being written: the last field id, for the delta in field headers */
typedef struct thrift {
  bytes *b;
  int16_t last[16];
  int depth;
} thrift;

static uint64_t zigzag(int64_t v) { return ((uint64_t)v << 1) ^ (uint64_t)(v >> 63); }

static void t_field(thrift *t, int type, int id) {
  int delta = id - t->last[t->depth];
  if (delta > 0 && delta <= 15) {
    b_byte(t->b, (uint8_t)(delta << 4 | type));
  } else {
    b_byte(t->b, (uint8_t)type);
    b_varint(t->b, zigzag(id));
  }
  t->last[t->depth] = (int16_t)id;
}
static void t_i32(thrift *t, int id, int32_t v) {
  t_field(t, T_I32, id);
  b_varint(t->b, zigzag(v));
}
static void t_i64(thrift *t, int id, int64_t v) {
  t_field(t, T_I64, id);
  b_varint(t->b, zigzag(v));
}
static void t_binary(thrift *t, int id, const void *p, size_t n) {
  t_field(t, T_BINARY, id);
  b_varint(t->b, n);
  b_put(t->b, p, n);
}
static void t_string(thrift *t, int id, const char *s) { t_binary(t, id, s, strlen(s)); }
/* a struct value: as field `id` of the enclosing struct, or (id 0) as a
 * list element or the top-level message */
static void t_begin(thrift *t, int id) {
  if (id) t_field(t, T_STRUCT, id);
  t->last[++t->depth] = 0;
}
static void t_end(thrift *t) {
  b_byte(t->b, 0);
  t->depth--;
}
static void t_list(thrift *t, int id, int elem_type, size_t n) {
  t_field(t, T_LIST, id);
  if (n < 15) {
    b_byte(t->b, (uint8_t)(n << 4 | (size_t)elem_type));
  } else {
    b_byte(t->b, (uint8_t)(0xf0 | elem_type));
    b_varint(t->b, n);
  }
}

/* parquet.thrift enums */
enum { PQ_INT64 = 2, PQ_FLOAT = 4, PQ_BYTE_ARRAY = 6 }; /* Type */
enum { PQ_OPTIONAL = 1, PQ_REPEATED = 2 };              /* FieldRepetitionType */
enum { PQ_CONV_UTF8 = 0, PQ_CONV_LIST = 3 };            /* ConvertedType */
enum { PQ_LOGICAL_STRING = 1, PQ_LOGICAL_LIST = 3 };    /* LogicalType union */
enum { PQ_PLAIN = 0, PQ_RLE = 3 };                      /* Encoding */

/* ---- leaves and their pages ------------------------------------------------- */
#define PAGE_TARGET ((size_t)1 << 20)

typedef struct leaf {
  char path[2][128]; /* path in the schema: 1 or 3 names (the list levels are fixed) */
  int depth;         /* names in path: 1 (scalar), 2 (struct member) or 3 (list element) */
  int type;          /* PQ_INT64, PQ_FLOAT, PQ_BYTE_ARRAY */
  int max_def, max_rep;
  /* the page being filled */
  bytes values;
  uint8_t *def, *rep;
  size_t nlev, levcap;
  /* this row group's finished pages (headers included) */
  bytes chunk;
  int64_t chunk_values;
  size_t chunk_uncompressed;
  /* statistics of the row group (INT64 and FLOAT leaves) */
  int has_minmax;
  int64_t imin, imax;
  float fmin, fmax;
} leaf;

typedef struct column {
  char name[128];
  hearth_pq_kind kind;
  int first_leaf, nleaves;
} column;

/* one column chunk's place in the file, for the footer */
typedef struct chunk_meta {
  int64_t offset, values, size;
  int has_minmax;
  int64_t imin, imax;
  float fmin, fmax;
} chunk_meta;

typedef struct group_meta {
  int64_t rows, offset, size;
  chunk_meta *chunks; /* one per leaf */
} group_meta;

struct hearth_pq_writer {
  hearth_atomic_file af;
  column cols[HEARTH_PQ_MAX_COLUMNS];
  size_t ncols;
  leaf *leaves;
  size_t nleaves;
  size_t rows_per_group, group_rows;
  int64_t total_rows, offset;
  group_meta *groups;
  size_t ngroups, groups_cap;
  char *kv[HEARTH_PQ_MAX_METADATA][2];
  size_t nkv;
  int failed;
};

static int leaf_level(leaf *l, int def, int rep) {
  if (l->nlev == l->levcap) {
    size_t cap = l->levcap ? l->levcap * 2 : 1024;
    uint8_t *nd = realloc(l->def, cap), *nr = nd ? realloc(l->rep, cap) : NULL;
    if (nd) l->def = nd;
    if (!nd || !nr) return 0;
    l->rep = nr, l->levcap = cap;
  }
  l->def[l->nlev] = (uint8_t)def;
  l->rep[l->nlev] = (uint8_t)rep;
  l->nlev++;
  return 1;
}

static void leaf_int(leaf *l, int64_t v) {
  b_le64(&l->values, (uint64_t)v);
  if (!l->has_minmax || v < l->imin) l->imin = v;
  if (!l->has_minmax || v > l->imax) l->imax = v;
  l->has_minmax = 1;
}

/* statistics skip NaN (put_stats writes a zero minimum as -0, a zero maximum as +0) */
static void leaf_float(leaf *l, float v) {
  uint32_t u;
  memcpy(&u, &v, 4);
  b_le32(&l->values, u);
  if (isnan(v)) return;
  if (!l->has_minmax || v < l->fmin) l->fmin = v;
  if (!l->has_minmax || v > l->fmax) l->fmax = v;
  l->has_minmax = 1;
}

/* RLE/bit-packed hybrid of n levels of bit width bw (1..8): runs of 8 or
 * more equal levels as RLE runs, the rest bit-packed in groups of 8 (at
 * most 63 groups a run; only the last run is padded) */
static void put_levels(bytes *b, const uint8_t *lv, size_t n, int bw) {
  size_t i = 0;
  while (i < n) {
    size_t run = 1;
    while (i + run < n && lv[i + run] == lv[i]) run++;
    if (run >= 8 || i + run == n) {
      b_varint(b, (uint64_t)run << 1);
      b_byte(b, lv[i]); /* ceil(bw / 8) = 1 byte */
      i += run;
      continue;
    }
    size_t start = i, groups = 0;
    while (i < n && groups < 63) {
      if (groups > 0) {
        size_t r = 1;
        while (i + r < n && lv[i + r] == lv[i]) r++;
        if (r >= 8) break;
      }
      i += 8, groups++;
    }
    if (i > n) i = n;
    b_varint(b, (uint64_t)groups << 1 | 1);
    size_t nbytes = groups * (size_t)bw; /* 8 values of bw bits: bw bytes */
    b_reserve(b, nbytes);
    if (b->failed) return;
    uint8_t *o = b->p + b->n;
    memset(o, 0, nbytes);
    for (size_t k = 0; k < groups * 8; k++) {
      unsigned v = start + k < n ? lv[start + k] : 0;
      size_t bit = k * (size_t)bw;
      for (int j = 0; j < bw; j++, bit++)
        if (v >> j & 1) o[bit / 8] |= (uint8_t)(1u << (bit % 8));
    }
    b->n += nbytes;
  }
}

static int bit_width(int max_level) {
  int w = 0;
  while ((1 << w) <= max_level) w++;
  return w;
}

/* close the page being filled: header + levels + values onto the chunk */
static hearth_status flush_page(hearth_pq_writer *w, leaf *l, hearth_err *err) {
  if (l->nlev == 0) return HEARTH_OK;
  bytes body = {0};
  for (int pass = 0; pass < 2; pass++) {
    int maxl = pass == 0 ? l->max_rep : l->max_def;
    if (maxl == 0) continue;
    bytes lev = {0};
    put_levels(&lev, pass == 0 ? l->rep : l->def, l->nlev, bit_width(maxl));
    b_le32(&body, (uint32_t)lev.n);
    b_put(&body, lev.p, lev.n);
    if (lev.failed) body.failed = 1;
    b_free(&lev);
  }
  b_put(&body, l->values.p, l->values.n);
  if (body.failed || l->values.failed) {
    b_free(&body);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet page of column %s", w->af.path,
                          l->path[0]);
  }
  if (body.n > HEARTH_PQ_MAX_PAGE || l->nlev > INT32_MAX) {
    b_free(&body);
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: a parquet page of column %s exceeds %zu bytes",
                          w->af.path, l->path[0], HEARTH_PQ_MAX_PAGE);
  }
  bytes hdr = {0};
  thrift t = {.b = &hdr};
  t_begin(&t, 0);
  t_i32(&t, 1, 0); /* DATA_PAGE */
  t_i32(&t, 2, (int32_t)body.n);
  t_i32(&t, 3, (int32_t)body.n);
  t_begin(&t, 5); /* DataPageHeader */
  t_i32(&t, 1, (int32_t)l->nlev);
  t_i32(&t, 2, PQ_PLAIN);
  t_i32(&t, 3, PQ_RLE);
  t_i32(&t, 4, PQ_RLE);
  t_end(&t);
  t_end(&t);
  b_put(&l->chunk, hdr.p, hdr.n);
  b_put(&l->chunk, body.p, body.n);
  int failed = hdr.failed || l->chunk.failed;
  l->chunk_values += (int64_t)l->nlev;
  l->chunk_uncompressed += hdr.n + body.n;
  b_free(&hdr);
  b_free(&body);
  l->values.n = 0;
  l->nlev = 0;
  if (failed)
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet column %s", w->af.path, l->path[0]);
  return HEARTH_OK;
}

/* write the buffered row group: every leaf's chunk in schema order */
static hearth_status flush_group(hearth_pq_writer *w, hearth_err *err) {
  if (w->group_rows == 0) return HEARTH_OK;
  for (size_t k = 0; k < w->nleaves; k++) {
    hearth_status s = flush_page(w, &w->leaves[k], err);
    if (s) return s;
  }
  if (w->ngroups == w->groups_cap) {
    size_t cap = w->groups_cap ? w->groups_cap * 2 : 16;
    group_meta *ng = realloc(w->groups, cap * sizeof *ng);
    if (!ng) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet row groups", w->af.path);
    w->groups = ng, w->groups_cap = cap;
  }
  group_meta *g = &w->groups[w->ngroups];
  g->chunks = calloc(w->nleaves, sizeof *g->chunks);
  if (!g->chunks) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet row groups", w->af.path);
  w->ngroups++;
  g->rows = (int64_t)w->group_rows;
  g->offset = w->offset;
  g->size = 0;
  for (size_t k = 0; k < w->nleaves; k++) {
    leaf *l = &w->leaves[k];
    chunk_meta *c = &g->chunks[k];
    c->offset = w->offset;
    c->values = l->chunk_values;
    c->size = (int64_t)l->chunk_uncompressed;
    c->has_minmax = l->has_minmax;
    c->imin = l->imin, c->imax = l->imax, c->fmin = l->fmin, c->fmax = l->fmax;
    if (fwrite(l->chunk.p, 1, l->chunk.n, w->af.fp) != l->chunk.n)
      return hearth_err_set(err, HEARTH_E_IO, "%s: write failed", w->af.path);
    w->offset += (int64_t)l->chunk.n;
    g->size += (int64_t)l->chunk.n;
    l->chunk.n = 0;
    l->chunk_values = 0;
    l->chunk_uncompressed = 0;
    l->has_minmax = 0;
  }
  w->group_rows = 0;
  return HEARTH_OK;
}

/* ---- opening, rows ---------------------------------------------------------- */
static void writer_free(hearth_pq_writer *w) {
  if (!w) return;
  for (size_t k = 0; k < w->nleaves; k++) {
    b_free(&w->leaves[k].values);
    b_free(&w->leaves[k].chunk);
    free(w->leaves[k].def);
    free(w->leaves[k].rep);
  }
  free(w->leaves);
  for (size_t g = 0; g < w->ngroups; g++) free(w->groups[g].chunks);
  free(w->groups);
  for (size_t k = 0; k < w->nkv; k++) free(w->kv[k][0]), free(w->kv[k][1]);
  free(w);
}

static void leaf_init(leaf *l, const char *a, const char *b, int depth, int type, int max_def,
                      int max_rep) {
  snprintf(l->path[0], sizeof l->path[0], "%s", a);
  snprintf(l->path[1], sizeof l->path[1], "%s", b ? b : "");
  l->depth = depth, l->type = type, l->max_def = max_def, l->max_rep = max_rep;
}

hearth_status hearth_pq_open(const char *path, const hearth_pq_column *cols, size_t ncols,
                             size_t rows_per_group, hearth_pq_writer **out, hearth_err *err) {
  *out = NULL;
  if (!path || !cols || ncols == 0 || rows_per_group == 0)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "parquet: a path, columns and rows_per_group >= 1 are needed");
  if (ncols > HEARTH_PQ_MAX_COLUMNS)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: %zu parquet columns (at most %d)", path, ncols,
                          HEARTH_PQ_MAX_COLUMNS);
  hearth_pq_writer *w = calloc(1, sizeof *w);
  if (w) w->leaves = calloc(2 * ncols, sizeof *w->leaves);
  if (!w || !w->leaves) {
    writer_free(w);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet writer", path);
  }
  for (size_t c = 0; c < ncols; c++) {
    const hearth_pq_column *in = &cols[c];
    if (!in->name || !*in->name || strlen(in->name) >= sizeof w->cols[c].name ||
        in->kind < HEARTH_PQ_INT64 || in->kind > HEARTH_PQ_BLOB) {
      writer_free(w);
      return hearth_err_set(err, HEARTH_E_ARG,
                            "%s: parquet column %zu: a name of 1..127 bytes and a kind", path, c);
    }
    column *col = &w->cols[c];
    snprintf(col->name, sizeof col->name, "%s", in->name);
    col->kind = in->kind;
    col->first_leaf = (int)w->nleaves;
    leaf *l = &w->leaves[w->nleaves];
    switch (in->kind) {
      case HEARTH_PQ_INT64: leaf_init(l, in->name, NULL, 1, PQ_INT64, 1, 0); break;
      case HEARTH_PQ_FLOAT: leaf_init(l, in->name, NULL, 1, PQ_FLOAT, 1, 0); break;
      case HEARTH_PQ_FLOAT_LIST: leaf_init(l, in->name, NULL, 3, PQ_FLOAT, 3, 1); break;
      case HEARTH_PQ_BLOB:
        leaf_init(l, in->name, "bytes", 2, PQ_BYTE_ARRAY, 2, 0);
        leaf_init(l + 1, in->name, "path", 2, PQ_BYTE_ARRAY, 2, 0);
        break;
    }
    col->nleaves = in->kind == HEARTH_PQ_BLOB ? 2 : 1;
    w->nleaves += (size_t)col->nleaves;
  }
  w->ncols = ncols;
  w->rows_per_group = rows_per_group;
  hearth_status s = hearth_atomic_open(&w->af, path, err);
  if (s) {
    writer_free(w);
    return s;
  }
  if (fwrite("PAR1", 1, 4, w->af.fp) != 4) {
    hearth_atomic_abort(&w->af);
    writer_free(w);
    return hearth_err_set(err, HEARTH_E_IO, "%s: write failed", path);
  }
  w->offset = 4;
  *out = w;
  return HEARTH_OK;
}

hearth_status hearth_pq_add_metadata(hearth_pq_writer *w, const char *key, const char *value,
                                     hearth_err *err) {
  if (!w || !key || !value)
    return hearth_err_set(err, HEARTH_E_ARG, "parquet: metadata needs a key and a value");
  if (w->nkv == HEARTH_PQ_MAX_METADATA)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: more than %d metadata pairs", w->af.path,
                          HEARTH_PQ_MAX_METADATA);
  char *k = strdup(key), *v = strdup(value);
  if (!k || !v) {
    free(k), free(v);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet metadata", w->af.path);
  }
  w->kv[w->nkv][0] = k, w->kv[w->nkv][1] = v;
  w->nkv++;
  return HEARTH_OK;
}

hearth_status hearth_pq_write_row(hearth_pq_writer *w, const hearth_pq_cell *cells,
                                  hearth_err *err) {
  if (!w || !cells) return hearth_err_set(err, HEARTH_E_ARG, "parquet: no writer or no row");
  if (w->failed)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: the writer failed earlier", w->af.path);
  int ok = 1;
  for (size_t c = 0; c < w->ncols && ok; c++) {
    const hearth_pq_cell *v = &cells[c];
    leaf *l = &w->leaves[w->cols[c].first_leaf];
    switch (w->cols[c].kind) {
      case HEARTH_PQ_INT64:
        ok = leaf_level(l, 1, 0);
        leaf_int(l, v->i);
        break;
      case HEARTH_PQ_FLOAT:
        ok = leaf_level(l, 1, 0);
        leaf_float(l, v->f);
        break;
      case HEARTH_PQ_FLOAT_LIST:
        if (v->list_len == 0) {
          ok = leaf_level(l, 1, 0); /* an empty list: present, no element */
          break;
        }
        if (!v->list) {
          w->failed = 1;
          return hearth_err_set(err, HEARTH_E_ARG, "%s: column %s: no list data", w->af.path,
                                l->path[0]);
        }
        for (size_t k = 0; k < v->list_len && ok; k++) {
          ok = leaf_level(l, 3, k ? 1 : 0);
          leaf_float(l, v->list[k]);
        }
        break;
      case HEARTH_PQ_BLOB: {
        const char *p = v->path ? v->path : "";
        if ((!v->bytes && v->bytes_len) || v->bytes_len > UINT32_MAX || strlen(p) > UINT32_MAX) {
          w->failed = 1;
          return hearth_err_set(err, HEARTH_E_ARG, "%s: column %s: bad blob", w->af.path,
                                l->path[0]);
        }
        ok = leaf_level(l, 2, 0) && leaf_level(l + 1, 2, 0);
        b_le32(&l->values, (uint32_t)v->bytes_len);
        b_put(&l->values, v->bytes, v->bytes_len);
        b_le32(&l[1].values, (uint32_t)strlen(p));
        b_put(&l[1].values, p, strlen(p));
        break;
      }
    }
  }
  for (size_t k = 0; k < w->nleaves; k++)
    if (w->leaves[k].values.failed) ok = 0;
  if (!ok) {
    w->failed = 1;
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet row %lld", w->af.path,
                          (long long)w->total_rows);
  }
  w->group_rows++;
  w->total_rows++;
  /* pages end at row boundaries */
  for (size_t k = 0; k < w->nleaves; k++) {
    if (w->leaves[k].values.n < PAGE_TARGET) continue;
    hearth_status s = flush_page(w, &w->leaves[k], err);
    if (s) return w->failed = 1, s;
  }
  if (w->group_rows == w->rows_per_group) {
    hearth_status s = flush_group(w, err);
    if (s) return w->failed = 1, s;
  }
  return HEARTH_OK;
}

/* ---- footer ----------------------------------------------------------------- */
static void put_schema(thrift *t, const hearth_pq_writer *w) {
  size_t nel = 1;
  for (size_t c = 0; c < w->ncols; c++)
    nel += w->cols[c].kind == HEARTH_PQ_INT64 || w->cols[c].kind == HEARTH_PQ_FLOAT ? 1 : 3;
  t_list(t, 2, T_STRUCT, nel);
  t_begin(t, 0);
  t_string(t, 4, "schema");
  t_i32(t, 5, (int32_t)w->ncols);
  t_end(t);
  for (size_t c = 0; c < w->ncols; c++) {
    const column *col = &w->cols[c];
    switch (col->kind) {
      case HEARTH_PQ_INT64:
      case HEARTH_PQ_FLOAT:
        t_begin(t, 0);
        t_i32(t, 1, col->kind == HEARTH_PQ_INT64 ? PQ_INT64 : PQ_FLOAT);
        t_i32(t, 3, PQ_OPTIONAL);
        t_string(t, 4, col->name);
        t_end(t);
        break;
      case HEARTH_PQ_FLOAT_LIST:
        t_begin(t, 0);
        t_i32(t, 3, PQ_OPTIONAL);
        t_string(t, 4, col->name);
        t_i32(t, 5, 1);
        t_i32(t, 6, PQ_CONV_LIST);
        t_begin(t, 10);
        t_begin(t, PQ_LOGICAL_LIST);
        t_end(t);
        t_end(t);
        t_end(t);
        t_begin(t, 0);
        t_i32(t, 3, PQ_REPEATED);
        t_string(t, 4, "list");
        t_i32(t, 5, 1);
        t_end(t);
        t_begin(t, 0);
        t_i32(t, 1, PQ_FLOAT);
        t_i32(t, 3, PQ_OPTIONAL);
        t_string(t, 4, "element");
        t_end(t);
        break;
      case HEARTH_PQ_BLOB:
        t_begin(t, 0);
        t_i32(t, 3, PQ_OPTIONAL);
        t_string(t, 4, col->name);
        t_i32(t, 5, 2);
        t_end(t);
        t_begin(t, 0);
        t_i32(t, 1, PQ_BYTE_ARRAY);
        t_i32(t, 3, PQ_OPTIONAL);
        t_string(t, 4, "bytes");
        t_end(t);
        t_begin(t, 0);
        t_i32(t, 1, PQ_BYTE_ARRAY);
        t_i32(t, 3, PQ_OPTIONAL);
        t_string(t, 4, "path");
        t_i32(t, 6, PQ_CONV_UTF8);
        t_begin(t, 10);
        t_begin(t, PQ_LOGICAL_STRING);
        t_end(t);
        t_end(t);
        t_end(t);
        break;
    }
  }
}

/* min and max as PLAIN-encoded values (fields 6 and 5 of Statistics) */
static void put_minmax(thrift *t, uint64_t lo, uint64_t hi, int nbytes) {
  uint8_t a[8], b[8];
  for (int k = 0; k < nbytes; k++) a[k] = (uint8_t)(lo >> (8 * k)), b[k] = (uint8_t)(hi >> (8 * k));
  t_binary(t, 5, b, (size_t)nbytes);
  t_binary(t, 6, a, (size_t)nbytes);
}

static void put_stats(thrift *t, const leaf *l, const chunk_meta *c) {
  t_begin(t, 12);
  t_i64(t, 3, 0); /* null_count */
  if (c->has_minmax && l->type == PQ_INT64) {
    put_minmax(t, (uint64_t)c->imin, (uint64_t)c->imax, 8);
  } else if (c->has_minmax && l->type == PQ_FLOAT) {
    float fmin = c->fmin == 0 ? -0.0f : c->fmin, fmax = c->fmax == 0 ? 0.0f : c->fmax;
    uint32_t a, b;
    memcpy(&a, &fmin, 4), memcpy(&b, &fmax, 4);
    put_minmax(t, a, b, 4);
  }
  t_end(t);
}

static void put_footer(thrift *t, const hearth_pq_writer *w) {
  t_begin(t, 0);
  t_i32(t, 1, 2); /* version */
  put_schema(t, w);
  t_i64(t, 3, w->total_rows);
  t_list(t, 4, T_STRUCT, w->ngroups);
  for (size_t g = 0; g < w->ngroups; g++) {
    const group_meta *gm = &w->groups[g];
    t_begin(t, 0);
    t_list(t, 1, T_STRUCT, w->nleaves);
    for (size_t k = 0; k < w->nleaves; k++) {
      const leaf *l = &w->leaves[k];
      const chunk_meta *c = &gm->chunks[k];
      t_begin(t, 0);
      t_i64(t, 2, c->offset);
      t_begin(t, 3); /* ColumnMetaData */
      t_i32(t, 1, l->type);
      t_list(t, 2, T_I32, 2);
      b_varint(t->b, zigzag(PQ_PLAIN));
      b_varint(t->b, zigzag(PQ_RLE));
      int np = l->depth == 3 ? 3 : l->depth;
      t_list(t, 3, T_BINARY, (size_t)np);
      const char *names[3] = {l->path[0], l->depth == 3 ? "list" : l->path[1], "element"};
      for (int k2 = 0; k2 < np; k2++) {
        b_varint(t->b, strlen(names[k2]));
        b_put(t->b, names[k2], strlen(names[k2]));
      }
      t_i32(t, 4, 0); /* UNCOMPRESSED */
      t_i64(t, 5, c->values);
      t_i64(t, 6, c->size);
      t_i64(t, 7, c->size);
      t_i64(t, 9, c->offset);
      if (l->type != PQ_BYTE_ARRAY) put_stats(t, l, c);
      t_end(t);
      t_end(t);
    }
    t_i64(t, 2, gm->size);
    t_i64(t, 3, gm->rows);
    t_i64(t, 5, gm->offset);
    t_i64(t, 6, gm->size);
    t_field(t, 4, 7); /* ordinal: i16 */
    b_varint(t->b, zigzag((int64_t)g));
    t_end(t);
  }
  if (w->nkv) {
    t_list(t, 5, T_STRUCT, w->nkv);
    for (size_t k = 0; k < w->nkv; k++) {
      t_begin(t, 0);
      t_string(t, 1, w->kv[k][0]);
      t_string(t, 2, w->kv[k][1]);
      t_end(t);
    }
  }
  t_string(t, 6, "hearth version " HEARTH_VERSION);
  t_list(t, 7, T_STRUCT, w->nleaves);
  for (size_t k = 0; k < w->nleaves; k++) {
    t_begin(t, 0); /* ColumnOrder union: TYPE_ORDER */
    t_begin(t, 1);
    t_end(t);
    t_end(t);
  }
  t_end(t);
}

hearth_status hearth_pq_close(hearth_pq_writer *w, hearth_err *err) {
  if (!w) return hearth_err_set(err, HEARTH_E_ARG, "parquet: no writer");
  hearth_status s =
      w->failed ? hearth_err_set(err, HEARTH_E_ARG, "%s: the writer failed earlier", w->af.path)
                : flush_group(w, err);
  if (!s) {
    bytes foot = {0};
    thrift t = {.b = &foot};
    put_footer(&t, w);
    if (foot.failed || foot.n > UINT32_MAX) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet footer", w->af.path);
    } else {
      b_le32(&foot, (uint32_t)foot.n);
      b_put(&foot, "PAR1", 4);
      if (foot.failed) s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: parquet footer", w->af.path);
      else if (fwrite(foot.p, 1, foot.n, w->af.fp) != foot.n)
        s = hearth_err_set(err, HEARTH_E_IO, "%s: write failed", w->af.path);
    }
    b_free(&foot);
  }
  if (!s) s = hearth_atomic_commit(&w->af, err);
  else hearth_atomic_abort(&w->af);
  writer_free(w);
  return s;
}

void hearth_pq_abort(hearth_pq_writer *w) {
  if (!w) return;
  hearth_atomic_abort(&w->af);
  writer_free(w);
}
