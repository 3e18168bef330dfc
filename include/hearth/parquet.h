/* hearth/parquet.h - area io (src/io/io_parquet.c): a small Apache Parquet
 * writer for the column shapes hearth exports (LeRobot datasets): enough of
 * the format for tables of non-null values, nothing to read it back.
 *
 * What a file holds: the magic "PAR1", row groups of at most rows_per_group
 * rows, one column chunk per leaf column and row group made of data pages
 * (version 1, PLAIN values, definition and repetition levels in the
 * RLE/bit-packed hybrid, uncompressed; a page ends at the first row
 * boundary past 1 MiB of values), then the footer: FileMetaData in Thrift's
 * compact protocol with the schema, min/max/null-count statistics of the
 * INT64 and FLOAT leaves, the caller's key-value metadata and created_by
 * "hearth version <v>". No clock, no randomness: the same rows give the
 * same bytes. Column kinds and their Parquet schema (every value present,
 * so each level is its maximum except for empty lists):
 *
 *   HEARTH_PQ_INT64       optional int64 <name>;
 *   HEARTH_PQ_FLOAT       optional float <name>;
 *   HEARTH_PQ_FLOAT_LIST  optional group <name> (LIST) {
 *                           repeated group list { optional float element; } }
 *                         (what Arrow writes for list<float> and fixed_size_list<float>)
 *   HEARTH_PQ_BLOB        optional group <name> {
 *                           optional binary bytes; optional binary path (STRING); }
 *                         (Hugging Face datasets' Image storage: struct<bytes, path>)
 */
#ifndef HEARTH_PARQUET_H
#define HEARTH_PARQUET_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum hearth_pq_kind {
  HEARTH_PQ_INT64 = 1,
  HEARTH_PQ_FLOAT = 2,
  HEARTH_PQ_FLOAT_LIST = 3,
  HEARTH_PQ_BLOB = 4
} hearth_pq_kind;

typedef struct hearth_pq_column {
  const char *name; /* copied at open */
  hearth_pq_kind kind;
} hearth_pq_column;

/* One row's value of one column; the fields of its column's kind are read. */
typedef struct hearth_pq_cell {
  int64_t i;         /* INT64 */
  float f;           /* FLOAT */
  const float *list; /* FLOAT_LIST: list_len floats (list_len may be 0) */
  size_t list_len;
  const uint8_t *bytes; /* BLOB: bytes_len bytes and a UTF-8 path ("" allowed) */
  size_t bytes_len;
  const char *path;
} hearth_pq_cell;

/* Limits: columns per file, bytes of one page (Parquet's page sizes are
 * 32-bit), key-value pairs. */
#define HEARTH_PQ_MAX_COLUMNS 64
#define HEARTH_PQ_MAX_PAGE ((size_t)1 << 30)
#define HEARTH_PQ_MAX_METADATA 16

typedef struct hearth_pq_writer hearth_pq_writer;

/* Start writing path (atomically: a temporary name in the same directory,
 * renamed over path by hearth_pq_close). rows_per_group >= 1. *out is the
 * caller's until close or abort. */
hearth_status hearth_pq_open(const char *path, const hearth_pq_column *cols, size_t ncols,
                             size_t rows_per_group, hearth_pq_writer **out, hearth_err *err);
/* A key-value pair of the footer (both copied), in the order added. */
hearth_status hearth_pq_add_metadata(hearth_pq_writer *w, const char *key, const char *value,
                                     hearth_err *err);
/* Append one row: cells[k] is the value of column k. The data are copied. */
hearth_status hearth_pq_write_row(hearth_pq_writer *w, const hearth_pq_cell *cells,
                                  hearth_err *err);
/* Write the last row group and the footer, rename into place and free w.
 * On failure nothing is left at path (nor the temporary file); w is freed
 * either way. */
hearth_status hearth_pq_close(hearth_pq_writer *w, hearth_err *err);
/* Discard everything written and free w (NULL is fine). */
void hearth_pq_abort(hearth_pq_writer *w);

#ifdef __cplusplus
}
#endif
#endif
