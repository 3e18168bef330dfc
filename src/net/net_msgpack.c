/* MessagePack: a strict decoder for untrusted bytes (two passes: the first
 * validates and counts values so the second fills one bounded allocation)
 * and a small encoder, plus msgpack_numpy's ndarray maps */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/msgpack.h"

typedef struct mp_ctx {
  const uint8_t *p;
  size_t len, pos;
  size_t max_depth, max_values;
  size_t count;           /* values seen (pass 1) */
  hearth_mp_value *arena; /* pass 2 */
  size_t used;
  hearth_err *err;
} mp_ctx;

static uint64_t rd_be(const uint8_t *p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; i++) v = v << 8 | p[i];
  return v;
}

/* take n bytes or fail naming the offset */
static hearth_status need(mp_ctx *c, size_t n, const char *what) {
  if (n > c->len - c->pos)
    return hearth_err_set(c->err, HEARTH_E_PARSE,
                          "msgpack: byte %zu: expected %zu bytes of %s, only %zu left", c->pos, n,
                          what, c->len - c->pos);
  return HEARTH_OK;
}

static hearth_status parse(mp_ctx *c, size_t depth, hearth_mp_value *out);

/* containers: each element takes at least one byte, so a declared count
 * larger than what is left is rejected before anything is allocated */
static hearth_status parse_container(mp_ctx *c, size_t depth, uint64_t n, int is_map,
                                     hearth_mp_value *out) {
  size_t start = c->pos;
  uint64_t items = is_map ? 2 * n : n;
  if (depth + 1 > c->max_depth)
    return hearth_err_set(c->err, HEARTH_E_LIMIT, "msgpack: byte %zu: nesting deeper than %zu",
                          start, c->max_depth);
  if (items > c->len - c->pos)
    return hearth_err_set(c->err, HEARTH_E_PARSE,
                          "msgpack: byte %zu: %s of %llu entries but only %zu bytes left", start,
                          is_map ? "map" : "array", (unsigned long long)n, c->len - c->pos);
  hearth_mp_value *kids = NULL;
  if (out) {
    out->type = is_map ? HEARTH_MP_MAP : HEARTH_MP_ARRAY;
    out->n = (size_t)n;
    kids = c->arena + c->used;
    c->used += (size_t)items;
    out->items = items ? kids : NULL;
  } else {
    c->count += (size_t)items;
    if (c->count > c->max_values)
      return hearth_err_set(c->err, HEARTH_E_LIMIT, "msgpack: byte %zu: more than %zu values",
                            start, c->max_values);
  }
  for (uint64_t k = 0; k < items; k++) {
    hearth_status st = parse(c, depth + 1, kids ? kids + k : NULL);
    if (st) return st;
  }
  return HEARTH_OK;
}

static hearth_status parse_bytes(mp_ctx *c, hearth_mp_type t, uint64_t n, hearth_mp_value *out) {
  hearth_status st =
      need(c, n > SIZE_MAX ? SIZE_MAX : (size_t)n, t == HEARTH_MP_STR ? "string" : "binary");
  if (st) return st;
  if (out) out->type = t, out->data = c->p + c->pos, out->len = (size_t)n;
  c->pos += (size_t)n;
  return HEARTH_OK;
}

static hearth_status parse(mp_ctx *c, size_t depth, hearth_mp_value *out) {
  hearth_status st = need(c, 1, "a value");
  if (st) return st;
  if (out) memset(out, 0, sizeof *out);
  size_t at = c->pos;
  uint8_t b = c->p[c->pos++];
  /* fixed-width headers: a length or value of n bytes follows */
  int n = 0;
  switch (b) {
    case 0xc4:
    case 0xc7:
    case 0xcc:
    case 0xd0:
    case 0xd9: n = 1; break;
    case 0xc5:
    case 0xc8:
    case 0xcd:
    case 0xd1:
    case 0xda:
    case 0xdc:
    case 0xde: n = 2; break;
    case 0xc6:
    case 0xc9:
    case 0xca:
    case 0xce:
    case 0xd2:
    case 0xdb:
    case 0xdd:
    case 0xdf: n = 4; break;
    case 0xcb:
    case 0xcf:
    case 0xd3: n = 8; break;
    case 0xd4: n = 1 + 1; break;
    case 0xd5: n = 1 + 2; break;
    case 0xd6: n = 1 + 4; break;
    case 0xd7: n = 1 + 8; break;
    case 0xd8: n = 1 + 16; break;
    default: break;
  }
  if (n) {
    st = need(c, (size_t)n, "a header");
    if (st) return st;
  }
  const uint8_t *q = c->p + c->pos;
  if (b <= 0x7f || b >= 0xe0) {
    if (out) out->type = HEARTH_MP_INT, out->i = b <= 0x7f ? b : (int64_t)(int8_t)b;
    return HEARTH_OK;
  }
  if ((b & 0xf0) == 0x80) return parse_container(c, depth, b & 0x0f, 1, out);
  if ((b & 0xf0) == 0x90) return parse_container(c, depth, b & 0x0f, 0, out);
  if ((b & 0xe0) == 0xa0) return parse_bytes(c, HEARTH_MP_STR, b & 0x1f, out);
  c->pos += (size_t)n;
  switch (b) {
    case 0xc0: return HEARTH_OK; /* nil: memset left type NIL */
    case 0xc2:
    case 0xc3:
      if (out) out->type = HEARTH_MP_BOOL, out->b = b == 0xc3;
      return HEARTH_OK;
    case 0xc4:
    case 0xc5:
    case 0xc6: return parse_bytes(c, HEARTH_MP_BIN, rd_be(q, n), out);
    case 0xd9:
    case 0xda:
    case 0xdb: return parse_bytes(c, HEARTH_MP_STR, rd_be(q, n), out);
    case 0xdc:
    case 0xdd: return parse_container(c, depth, rd_be(q, n), 0, out);
    case 0xde:
    case 0xdf: return parse_container(c, depth, rd_be(q, n), 1, out);
    case 0xca: {
      uint32_t u = (uint32_t)rd_be(q, 4);
      float f;
      memcpy(&f, &u, 4);
      if (out) out->type = HEARTH_MP_FLOAT, out->f = f;
      return HEARTH_OK;
    }
    case 0xcb: {
      uint64_t u = rd_be(q, 8);
      double f;
      memcpy(&f, &u, 8);
      if (out) out->type = HEARTH_MP_FLOAT, out->f = f;
      return HEARTH_OK;
    }
    case 0xcc:
    case 0xcd:
    case 0xce:
    case 0xcf: {
      uint64_t u = rd_be(q, n);
      if (out) {
        if (u > (uint64_t)INT64_MAX) out->type = HEARTH_MP_UINT, out->u = u;
        else out->type = HEARTH_MP_INT, out->i = (int64_t)u;
      }
      return HEARTH_OK;
    }
    case 0xd0:
    case 0xd1:
    case 0xd2:
    case 0xd3: {
      uint64_t u = rd_be(q, n);
      int64_t v;
      if (n == 1) v = (int8_t)u;
      else if (n == 2) v = (int16_t)u;
      else if (n == 4) v = (int32_t)u;
      else memcpy(&v, &u, 8);
      if (out) out->type = HEARTH_MP_INT, out->i = v;
      return HEARTH_OK;
    }
    case 0xd4:
    case 0xd5:
    case 0xd6:
    case 0xd7:
    case 0xd8:
      if (out)
        out->type = HEARTH_MP_EXT, out->i = (int8_t)q[0], out->data = q + 1,
        out->len = (size_t)n - 1;
      return HEARTH_OK;
    case 0xc7:
    case 0xc8:
    case 0xc9: {
      uint64_t len = rd_be(q, n);
      st = need(c, 1, "an ext type");
      if (st) return st;
      int8_t type = (int8_t)c->p[c->pos++];
      st = parse_bytes(c, HEARTH_MP_EXT, len, out);
      if (out) out->i = type;
      return st;
    }
    default:
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "msgpack: byte %zu: 0x%02x is not a valid type byte", at, b);
  }
}

hearth_status hearth_mp_decode(const uint8_t *buf, size_t len, const hearth_mp_limits *lim,
                               hearth_mp_doc *doc, hearth_err *err) {
  memset(doc, 0, sizeof *doc);
  mp_ctx c = {0};
  c.p = buf;
  c.len = len;
  c.err = err;
  c.max_depth = lim && lim->max_depth ? lim->max_depth : 32;
  c.max_values = lim && lim->max_values ? lim->max_values : 1000000;
  size_t max_bytes = lim && lim->max_bytes ? lim->max_bytes : (size_t)256 << 20;
  if (!buf && len) return hearth_err_set(err, HEARTH_E_ARG, "msgpack: NULL buffer");
  if (len > max_bytes)
    return hearth_err_set(err, HEARTH_E_LIMIT, "msgpack: %zu bytes exceeds the limit of %zu", len,
                          max_bytes);
  /* pass 1: validate and count */
  c.count = 1;
  hearth_status st = parse(&c, 0, NULL);
  if (st) return st;
  if (c.pos != len)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "msgpack: byte %zu: expected the end, %zu bytes remain", c.pos,
                          len - c.pos);
  /* pass 2: fill */
  doc->values = hearth_calloc_array(c.count, sizeof(hearth_mp_value));
  if (!doc->values) return hearth_err_set(err, HEARTH_E_NOMEM, "msgpack: %zu values", c.count);
  doc->n_values = c.count;
  c.arena = doc->values;
  c.used = 1;
  c.pos = 0;
  st = parse(&c, 0, doc->values);
  if (st) {
    hearth_mp_doc_free(doc);
    return st;
  }
  doc->root = doc->values;
  return HEARTH_OK;
}

void hearth_mp_doc_free(hearth_mp_doc *doc) {
  if (!doc) return;
  free(doc->values);
  memset(doc, 0, sizeof *doc);
}

const hearth_mp_value *hearth_mp_map_get(const hearth_mp_value *map, const char *key,
                                         hearth_mp_type key_type) {
  if (!map || map->type != HEARTH_MP_MAP) return NULL;
  size_t kl = strlen(key);
  for (size_t k = 0; k < map->n; k++) {
    const hearth_mp_value *kv = &map->items[2 * k];
    if (kv->type == key_type && kv->len == kl && memcmp(kv->data, key, kl) == 0)
      return &map->items[2 * k + 1];
  }
  return NULL;
}

int hearth_mp_str_eq(const hearth_mp_value *v, const char *s) {
  size_t n = strlen(s);
  return v && v->type == HEARTH_MP_STR && v->len == n && memcmp(v->data, s, n) == 0;
}

hearth_status hearth_mp_ndarray_get(const hearth_mp_value *v, const char *where,
                                    hearth_mp_ndarray *a, hearth_err *err) {
  memset(a, 0, sizeof *a);
  if (!v || v->type != HEARTH_MP_MAP)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: expected a numpy array (a map), got msgpack type %d", where,
                          v ? (int)v->type : -1);
  const hearth_mp_value *flag = hearth_mp_map_get(v, "__ndarray__", HEARTH_MP_BIN);
  const hearth_mp_value *data = hearth_mp_map_get(v, "data", HEARTH_MP_BIN);
  const hearth_mp_value *dtype = hearth_mp_map_get(v, "dtype", HEARTH_MP_BIN);
  const hearth_mp_value *shape = hearth_mp_map_get(v, "shape", HEARTH_MP_BIN);
  if (!flag && hearth_mp_map_get(v, "__ndarray__", HEARTH_MP_STR))
    return hearth_err_set(
        err, HEARTH_E_PARSE,
        "%s: ndarray keys must be msgpack binaries (b\"__ndarray__\"), got strings", where);
  if (!flag || flag->type != HEARTH_MP_BOOL || !flag->b)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: expected the key b\"__ndarray__\" set to true",
                          where);
  if (!data || data->type != HEARTH_MP_BIN)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: expected b\"data\" as a binary", where);
  if (!dtype || dtype->type != HEARTH_MP_STR || dtype->len < 3 || dtype->len >= sizeof a->dtype)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: expected b\"dtype\" as a string like \"<f4\"",
                          where);
  if (!shape || shape->type != HEARTH_MP_ARRAY || shape->n > HEARTH_MP_MAX_DIMS)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: expected b\"shape\" as an array of at most %d ints", where,
                          HEARTH_MP_MAX_DIMS);
  memcpy(a->dtype, dtype->data, dtype->len);
  char order = a->dtype[0];
  a->kind = a->dtype[1];
  long sz = 0;
  for (size_t k = 2; k < dtype->len; k++) {
    if (a->dtype[k] < '0' || a->dtype[k] > '9') sz = -1;
    if (sz >= 0) sz = sz * 10 + (a->dtype[k] - '0');
  }
  int ok_kind =
      (a->kind == 'f' && (sz == 4 || sz == 8)) ||
      ((a->kind == 'u' || a->kind == 'i') && (sz == 1 || sz == 2 || sz == 4 || sz == 8)) ||
      (a->kind == 'b' && sz == 1);
  if (!ok_kind || (order != '<' && order != '>' && order != '|' && order != '='))
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "%s: dtype \"%s\" is not a supported numeric type", where, a->dtype);
  a->itemsize = (size_t)sz;
  a->big_endian = order == '>';
  a->ndim = (int)shape->n;
  size_t count = 1;
  for (size_t k = 0; k < shape->n; k++) {
    const hearth_mp_value *d = &shape->items[k];
    if (d->type != HEARTH_MP_INT || d->i < 0)
      return hearth_err_set(err, HEARTH_E_PARSE, "%s: shape[%zu] is not a non-negative int", where,
                            k);
    a->shape[k] = (size_t)d->i;
    if ((uint64_t)d->i > SIZE_MAX || !hearth_mul_size(count, (size_t)d->i, &count))
      return hearth_err_set(err, HEARTH_E_LIMIT, "%s: shape overflows", where);
  }
  size_t nb;
  if (!hearth_mul_size(count, a->itemsize, &nb) || nb != data->len)
    return hearth_err_set(
        err, HEARTH_E_SIZE,
        "%s: data has %zu bytes but shape and dtype \"%s\" need %zu elements of %zu", where,
        data->len, a->dtype, count, a->itemsize);
  a->count = count;
  a->data = data->data;
  a->nbytes = data->len;
  return HEARTH_OK;
}

double hearth_mp_ndarray_at(const hearth_mp_ndarray *a, size_t k) {
  const uint8_t *p = a->data + k * a->itemsize;
  uint8_t b[8];
  for (size_t i = 0; i < a->itemsize; i++) {
    /* native little-endian host assumed for the fixed layouts below */
    b[i] = a->big_endian ? p[a->itemsize - 1 - i] : p[i];
  }
  uint64_t u = 0;
  for (size_t i = a->itemsize; i-- > 0;) u = u << 8 | b[i];
  switch (a->kind) {
    case 'f':
      if (a->itemsize == 4) {
        uint32_t u32 = (uint32_t)u;
        float f;
        memcpy(&f, &u32, 4);
        return f;
      } else {
        double d;
        memcpy(&d, &u, 8);
        return d;
      }
    case 'i': {
      int sh = 64 - 8 * (int)a->itemsize;
      return (double)((int64_t)(u << sh) >> sh);
    }
    default: return (double)u;
  }
}

/* ---- encoder -------------------------------------------------------------- */
void hearth_mp_writer_init(hearth_mp_writer *w) { memset(w, 0, sizeof *w); }
void hearth_mp_writer_free(hearth_mp_writer *w) {
  free(w->buf);
  memset(w, 0, sizeof *w);
}

static void put(hearth_mp_writer *w, const void *p, size_t n) {
  if (w->failed) return;
  if (n > w->cap - w->len) {
    size_t cap = w->cap ? w->cap : 256;
    while (cap - w->len < n) {
      if (cap > SIZE_MAX / 2) {
        w->failed = 1;
        return;
      }
      cap *= 2;
    }
    uint8_t *nb = realloc(w->buf, cap);
    if (!nb) {
      w->failed = 1;
      return;
    }
    w->buf = nb, w->cap = cap;
  }
  if (n) memcpy(w->buf + w->len, p, n);
  w->len += n;
}

static void put_be(hearth_mp_writer *w, uint8_t tag, uint64_t v, int n) {
  uint8_t b[9];
  b[0] = tag;
  for (int i = 0; i < n; i++) b[1 + i] = (uint8_t)(v >> (8 * (n - 1 - i)));
  put(w, b, (size_t)n + 1);
}

void hearth_mp_put_nil(hearth_mp_writer *w) { put_be(w, 0xc0, 0, 0); }
void hearth_mp_put_bool(hearth_mp_writer *w, int b) { put_be(w, b ? 0xc3 : 0xc2, 0, 0); }

void hearth_mp_put_uint(hearth_mp_writer *w, uint64_t v) {
  if (v <= 0x7f) put_be(w, (uint8_t)v, 0, 0);
  else if (v <= 0xff) put_be(w, 0xcc, v, 1);
  else if (v <= 0xffff) put_be(w, 0xcd, v, 2);
  else if (v <= 0xffffffffu) put_be(w, 0xce, v, 4);
  else put_be(w, 0xcf, v, 8);
}

void hearth_mp_put_int(hearth_mp_writer *w, int64_t v) {
  if (v >= 0) return hearth_mp_put_uint(w, (uint64_t)v);
  if (v >= -32) put_be(w, (uint8_t)(int8_t)v, 0, 0);
  else if (v >= INT8_MIN) put_be(w, 0xd0, (uint64_t)v & 0xff, 1);
  else if (v >= INT16_MIN) put_be(w, 0xd1, (uint64_t)v & 0xffff, 2);
  else if (v >= INT32_MIN) put_be(w, 0xd2, (uint64_t)v & 0xffffffffu, 4);
  else put_be(w, 0xd3, (uint64_t)v, 8);
}

void hearth_mp_put_f32(hearth_mp_writer *w, float v) {
  uint32_t u;
  memcpy(&u, &v, 4);
  put_be(w, 0xca, u, 4);
}

void hearth_mp_put_f64(hearth_mp_writer *w, double v) {
  uint64_t u;
  memcpy(&u, &v, 8);
  put_be(w, 0xcb, u, 8);
}

void hearth_mp_put_str(hearth_mp_writer *w, const char *s, size_t n) {
  if (n <= 31) put_be(w, (uint8_t)(0xa0 | n), 0, 0);
  else if (n <= 0xff) put_be(w, 0xd9, n, 1);
  else if (n <= 0xffff) put_be(w, 0xda, n, 2);
  else if ((uint64_t)n <= 0xffffffffu) put_be(w, 0xdb, n, 4);
  else {
    w->failed = 1;
    return;
  }
  put(w, s, n);
}

void hearth_mp_put_cstr(hearth_mp_writer *w, const char *s) { hearth_mp_put_str(w, s, strlen(s)); }

void hearth_mp_put_bin(hearth_mp_writer *w, const void *p, size_t n) {
  if (n <= 0xff) put_be(w, 0xc4, n, 1);
  else if (n <= 0xffff) put_be(w, 0xc5, n, 2);
  else if ((uint64_t)n <= 0xffffffffu) put_be(w, 0xc6, n, 4);
  else {
    w->failed = 1;
    return;
  }
  put(w, p, n);
}

void hearth_mp_put_array(hearth_mp_writer *w, size_t n) {
  if (n <= 15) put_be(w, (uint8_t)(0x90 | n), 0, 0);
  else if (n <= 0xffff) put_be(w, 0xdc, n, 2);
  else put_be(w, 0xdd, n, 4);
}

void hearth_mp_put_map(hearth_mp_writer *w, size_t n) {
  if (n <= 15) put_be(w, (uint8_t)(0x80 | n), 0, 0);
  else if (n <= 0xffff) put_be(w, 0xde, n, 2);
  else put_be(w, 0xdf, n, 4);
}

void hearth_mp_put_ndarray(hearth_mp_writer *w, const void *data, size_t nbytes, const char *dtype,
                           const size_t *shape, int ndim) {
  hearth_mp_put_map(w, 4);
  hearth_mp_put_bin(w, "__ndarray__", 11);
  hearth_mp_put_bool(w, 1);
  hearth_mp_put_bin(w, "data", 4);
  hearth_mp_put_bin(w, data, nbytes);
  hearth_mp_put_bin(w, "dtype", 5);
  hearth_mp_put_cstr(w, dtype);
  hearth_mp_put_bin(w, "shape", 5);
  hearth_mp_put_array(w, (size_t)ndim);
  for (int k = 0; k < ndim; k++) hearth_mp_put_uint(w, shape[k]);
}
