/* hearth/msgpack.h - area net (src/net/net_msgpack.c): a small MessagePack
 * encoder and a strict decoder for untrusted input (the openpi
 * policy-server protocol), with numpy arrays as openpi-client's
 * msgpack_numpy sends them: maps with the BINARY keys
 * __ndarray__ (true), data (raw C-order bytes), dtype (str such as "<f4")
 * and shape (array of ints). */
#ifndef HEARTH_MSGPACK_H
#define HEARTH_MSGPACK_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum hearth_mp_type {
  HEARTH_MP_NIL = 0,
  HEARTH_MP_BOOL,
  HEARTH_MP_INT,   /* fits int64: value in .i */
  HEARTH_MP_UINT,  /* above INT64_MAX: value in .u */
  HEARTH_MP_FLOAT, /* float32 or float64: value in .f */
  HEARTH_MP_STR,   /* .data/.len, not NUL-terminated, points into the input */
  HEARTH_MP_BIN,   /* .data/.len, points into the input */
  HEARTH_MP_ARRAY, /* .items[0..n) */
  HEARTH_MP_MAP,   /* .items[0..2n): key, value, key, value ... */
  HEARTH_MP_EXT    /* .data/.len; ext type in .i */
} hearth_mp_type;

typedef struct hearth_mp_value {
  hearth_mp_type type;
  int b;
  int64_t i;
  uint64_t u;
  double f;
  const uint8_t *data;
  size_t len;
  struct hearth_mp_value *items;
  size_t n;
} hearth_mp_value;

/* Limits on untrusted input; zero fields take the defaults
 * (depth 32, 1,000,000 values, 256 MiB input). */
typedef struct hearth_mp_limits {
  size_t max_depth, max_values, max_bytes;
} hearth_mp_limits;

typedef struct hearth_mp_doc {
  hearth_mp_value *root;
  hearth_mp_value *values; /* one allocation holding every value */
  size_t n_values;
} hearth_mp_doc;

/* Decode exactly one object filling buf[0..len) (trailing bytes are an
 * error). lim may be NULL (the defaults). Strings and binaries point into
 * buf, which must outlive the document; the values are one allocation,
 * released with hearth_mp_doc_free (which accepts a zeroed doc). Errors name
 * the byte offset and what was expected. */
hearth_status hearth_mp_decode(const uint8_t *buf, size_t len, const hearth_mp_limits *lim,
                               hearth_mp_doc *doc, hearth_err *err);
void hearth_mp_doc_free(hearth_mp_doc *doc);

/* The value of `key` in a map: key_type HEARTH_MP_STR or HEARTH_MP_BIN
 * matches only keys of that type; NULL if absent or not a map. */
const hearth_mp_value *hearth_mp_map_get(const hearth_mp_value *map, const char *key,
                                         hearth_mp_type key_type);
/* 1 if v is a STR equal to s. */
int hearth_mp_str_eq(const hearth_mp_value *v, const char *s);

/* A numpy array decoded from its msgpack_numpy map. */
#define HEARTH_MP_MAX_DIMS 8
typedef struct hearth_mp_ndarray {
  const uint8_t *data; /* points into the input */
  size_t nbytes;
  char dtype[8]; /* e.g. "<f4", "|u1" */
  char kind;     /* 'f', 'u', 'i', 'b' */
  size_t itemsize;
  int big_endian;
  int ndim;
  size_t shape[HEARTH_MP_MAX_DIMS];
  size_t count; /* product of shape */
} hearth_mp_ndarray;
/* Check that v is an ndarray map (binary keys, __ndarray__ true, dtype a
 * supported numeric type, shape non-negative, len(data) = count * itemsize).
 * `where` names the value in errors (e.g. "reply.actions"). */
hearth_status hearth_mp_ndarray_get(const hearth_mp_value *v, const char *where,
                                    hearth_mp_ndarray *out, hearth_err *err);
/* Element k of a numeric ndarray as a double (any byte order). */
double hearth_mp_ndarray_at(const hearth_mp_ndarray *a, size_t k);

/* ---- encoder --------------------------------------------------------------
 * Appends to a growing buffer (buf[0..len), malloc'ed, released with
 * hearth_mp_writer_free); an allocation failure sets .failed and later
 * calls do nothing. Containers are written as a header with their count
 * followed by that many values (maps: 2 per entry). Data passed in is
 * copied. */
typedef struct hearth_mp_writer {
  uint8_t *buf;
  size_t len, cap;
  int failed;
} hearth_mp_writer;
void hearth_mp_writer_init(hearth_mp_writer *w);
void hearth_mp_writer_free(hearth_mp_writer *w);
void hearth_mp_put_nil(hearth_mp_writer *w);
void hearth_mp_put_bool(hearth_mp_writer *w, int b);
void hearth_mp_put_int(hearth_mp_writer *w, int64_t v);
void hearth_mp_put_uint(hearth_mp_writer *w, uint64_t v);
void hearth_mp_put_f32(hearth_mp_writer *w, float v);
void hearth_mp_put_f64(hearth_mp_writer *w, double v);
void hearth_mp_put_str(hearth_mp_writer *w, const char *s, size_t n);
void hearth_mp_put_cstr(hearth_mp_writer *w, const char *s);
void hearth_mp_put_bin(hearth_mp_writer *w, const void *p, size_t n);
void hearth_mp_put_array(hearth_mp_writer *w, size_t n);
void hearth_mp_put_map(hearth_mp_writer *w, size_t n);
/* A numpy array the way msgpack_numpy packs it (4-entry map, binary keys). */
void hearth_mp_put_ndarray(hearth_mp_writer *w, const void *data, size_t nbytes, const char *dtype,
                           const size_t *shape, int ndim);

#ifdef __cplusplus
}
#endif
#endif
