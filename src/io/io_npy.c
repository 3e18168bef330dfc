/* NumPy .npy files, format 1.0 and 2.0 (the layout is documented in
 * numpy.lib.format): magic "\x93NUMPY", major and minor version bytes, a
 * little-endian header length (2 bytes in 1.0, 4 in 2.0), then a Python dict
 * literal with exactly the keys 'descr', 'fortran_order' and 'shape', padded
 * with spaces and ending in '\n', then the raw array data. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/npy.h"

/* refuse larger files and headers outright */
#define NPY_MAX_FILE ((size_t)1 << 31)
#define NPY_MAX_HEADER ((size_t)1 << 16)
#define NPY_MAGIC "\x93NUMPY"
#define NPY_MAGIC_LEN 6

static size_t dtype_size(hearth_npy_dtype d) { return d == HEARTH_NPY_F32 ? 4 : 1; }

static int host_is_little(void) {
  const uint16_t one = 1;
  uint8_t b;
  memcpy(&b, &one, 1);
  return b == 1;
}

size_t hearth_npy_count(const hearth_npy *a) {
  if (!a) return 0;
  size_t n = 1;
  for (int i = 0; i < a->ndim && i < 4; i++) n *= a->shape[i];
  return n;
}

void hearth_npy_free(hearth_npy *a) {
  if (!a) return;
  free(a->data);
  memset(a, 0, sizeof *a);
}

/* ---- header parser ---------------------------------------------------------- */
/* A cursor over the header text; errors say the byte offset in the file. */
typedef struct hdr {
  const char *s;
  size_t n, i, base; /* base: file offset of s[0] */
  const char *name;
  hearth_err *err;
} hdr;

static void skip_ws(hdr *h) {
  while (h->i < h->n && (h->s[h->i] == ' ' || h->s[h->i] == '\t')) h->i++;
}

static hearth_status hdr_fail(hdr *h, hearth_status st, const char *what, const char *expected) {
  return hearth_err_set(h->err, st, "%s: header byte %zu: %s, expected %s", h->name, h->base + h->i,
                        what, expected);
}

static const char *found_desc(hdr *h, char *buf, size_t bufsz) {
  if (h->i >= h->n) return "end of header";
  unsigned char c = (unsigned char)h->s[h->i];
  if (c >= 0x20 && c < 0x7F) snprintf(buf, bufsz, "found '%c'", c);
  else snprintf(buf, bufsz, "found byte 0x%02x", c);
  return buf;
}

static hearth_status expect_char(hdr *h, char c, const char *expected) {
  skip_ws(h);
  if (h->i < h->n && h->s[h->i] == c) {
    h->i++;
    return HEARTH_OK;
  }
  char b[32];
  return hdr_fail(h, HEARTH_E_PARSE, found_desc(h, b, sizeof b), expected);
}

/* A quoted string without escapes; [*a, *b) is its content. */
static hearth_status read_string(hdr *h, size_t *a, size_t *b, const char *expected) {
  skip_ws(h);
  if (h->i >= h->n || (h->s[h->i] != '\'' && h->s[h->i] != '"')) {
    char buf[32];
    return hdr_fail(h, HEARTH_E_PARSE, found_desc(h, buf, sizeof buf), expected);
  }
  char q = h->s[h->i++];
  *a = h->i;
  while (h->i < h->n && h->s[h->i] != q) {
    if (h->s[h->i] == '\\' || h->s[h->i] == '\n')
      return hdr_fail(h, HEARTH_E_PARSE, "escape or newline in string", "a plain quoted string");
    h->i++;
  }
  if (h->i >= h->n) return hdr_fail(h, HEARTH_E_PARSE, "unterminated string", "a closing quote");
  *b = h->i++;
  return HEARTH_OK;
}

static int span_is(hdr *h, size_t a, size_t b, const char *lit) {
  size_t n = strlen(lit);
  return b - a == n && memcmp(h->s + a, lit, n) == 0;
}

static hearth_status read_descr(hdr *h, hearth_npy_dtype *dt) {
  skip_ws(h);
  if (h->i < h->n && h->s[h->i] == '[')
    return hdr_fail(h, HEARTH_E_UNSUPPORTED, "structured dtype",
                    "'<f4' (float32) or '|u1' (uint8)");
  size_t at = h->i, a, b;
  hearth_status st = read_string(h, &a, &b, "a dtype string such as '<f4'");
  if (st) return st;
  if (span_is(h, a, b, "<f4")) *dt = HEARTH_NPY_F32;
  else if (span_is(h, a, b, "|u1") || span_is(h, a, b, "u1") || span_is(h, a, b, "<u1"))
    *dt = HEARTH_NPY_U8;
  else {
    char what[96];
    size_t len = b - a > 32 ? 32 : b - a;
    snprintf(what, sizeof what, "unsupported dtype '%.*s'", (int)len, h->s + a);
    for (char *p = what; *p; p++)
      if ((unsigned char)*p < 0x20 || (unsigned char)*p >= 0x7F) *p = '?';
    h->i = at;
    return hdr_fail(h, HEARTH_E_UNSUPPORTED, what, "'<f4' (float32) or '|u1' (uint8)");
  }
  return HEARTH_OK;
}

static hearth_status read_bool(hdr *h, int *v) {
  skip_ws(h);
  if (h->n - h->i >= 5 && !memcmp(h->s + h->i, "False", 5)) {
    *v = 0;
    h->i += 5;
  } else if (h->n - h->i >= 4 && !memcmp(h->s + h->i, "True", 4)) {
    *v = 1;
    h->i += 4;
  } else {
    char b[32];
    return hdr_fail(h, HEARTH_E_PARSE, found_desc(h, b, sizeof b), "True or False");
  }
  if (h->i < h->n && ((h->s[h->i] >= 'a' && h->s[h->i] <= 'z') || h->s[h->i] == '_'))
    return hdr_fail(h, HEARTH_E_PARSE, "identifier continues", "True or False");
  return HEARTH_OK;
}

/* A non-negative Python int literal (old Python 2 files may add 'L'). */
static hearth_status read_dim(hdr *h, size_t *v) {
  skip_ws(h);
  if (h->i >= h->n || h->s[h->i] < '0' || h->s[h->i] > '9') {
    char b[32];
    return hdr_fail(h, HEARTH_E_PARSE, found_desc(h, b, sizeof b), "a non-negative dimension");
  }
  size_t start = h->i, x = 0;
  while (h->i < h->n && h->s[h->i] >= '0' && h->s[h->i] <= '9') {
    size_t d = (size_t)(h->s[h->i] - '0');
    if (x > (((size_t)-1) - d) / 10)
      return hdr_fail(h, HEARTH_E_LIMIT, "dimension overflows", "a dimension that fits in memory");
    x = x * 10 + d;
    h->i++;
  }
  if (h->i - start > 1 && h->s[start] == '0') {
    h->i = start;
    return hdr_fail(h, HEARTH_E_PARSE, "leading zero", "a decimal integer");
  }
  if (h->i < h->n && h->s[h->i] == 'L') h->i++;
  *v = x;
  return HEARTH_OK;
}

/* '()', '(n,)', '(n, m)', '(n, m,)' ... up to rank 4. */
static hearth_status read_shape(hdr *h, int *ndim, size_t shape[4]) {
  hearth_status st = expect_char(h, '(', "a shape tuple '(...)'");
  if (st) return st;
  int k = 0;
  skip_ws(h);
  if (h->i < h->n && h->s[h->i] == ')') {
    h->i++;
    *ndim = 0;
    return HEARTH_OK;
  }
  for (;;) {
    size_t d = 0;
    if (k == 4)
      return hdr_fail(h, HEARTH_E_UNSUPPORTED, "more than 4 dimensions", "an array of rank 0..4");
    if ((st = read_dim(h, &d))) return st;
    shape[k++] = d;
    skip_ws(h);
    if (h->i < h->n && h->s[h->i] == ',') {
      h->i++;
      skip_ws(h);
      if (h->i < h->n && h->s[h->i] == ')') {
        h->i++;
        break;
      }
      continue;
    }
    if (h->i < h->n && h->s[h->i] == ')') {
      if (k == 1) return hdr_fail(h, HEARTH_E_PARSE, "'(n)' is not a tuple", "',' as in '(n,)'");
      h->i++;
      break;
    }
    char b[32];
    return hdr_fail(h, HEARTH_E_PARSE, found_desc(h, b, sizeof b), "',' or ')' in the shape");
  }
  *ndim = k;
  return HEARTH_OK;
}

/* The dict literal with exactly the three keys, in any order. */
static hearth_status parse_dict(hdr *h, hearth_npy *out) {
  hearth_status st = expect_char(h, '{', "'{' starting the header dict");
  if (st) return st;
  int have_descr = 0, have_fortran = 0, have_shape = 0, fortran = 0;
  for (;;) {
    skip_ws(h);
    if (h->i < h->n && h->s[h->i] == '}') {
      h->i++;
      break;
    }
    size_t key_at = h->i, a, b;
    if ((st = read_string(h, &a, &b, "a key ('descr', 'fortran_order' or 'shape') or '}'")))
      return st;
    if ((st = expect_char(h, ':', "':' after the key"))) return st;
    int *seen;
    if (span_is(h, a, b, "descr")) seen = &have_descr;
    else if (span_is(h, a, b, "fortran_order")) seen = &have_fortran;
    else if (span_is(h, a, b, "shape")) seen = &have_shape;
    else {
      h->i = key_at;
      return hdr_fail(h, HEARTH_E_PARSE, "unknown key",
                      "only 'descr', 'fortran_order' and 'shape'");
    }
    if (*seen) {
      h->i = key_at;
      return hdr_fail(h, HEARTH_E_PARSE, "duplicate key", "each key once");
    }
    *seen = 1;
    if (seen == &have_descr) st = read_descr(h, &out->dtype);
    else if (seen == &have_shape) st = read_shape(h, &out->ndim, out->shape);
    else {
      size_t at;
      skip_ws(h);
      at = h->i;
      st = read_bool(h, &fortran);
      if (!st && fortran) {
        h->i = at;
        return hdr_fail(h, HEARTH_E_UNSUPPORTED, "fortran_order is True",
                        "C order (fortran_order False)");
      }
    }
    if (st) return st;
    skip_ws(h);
    if (h->i < h->n && h->s[h->i] == ',') {
      h->i++;
      continue;
    }
    if ((st = expect_char(h, '}', "',' or '}' after a value"))) return st;
    break;
  }
  if (!have_descr || !have_fortran || !have_shape)
    return hdr_fail(h, HEARTH_E_PARSE,
                    !have_descr     ? "missing 'descr'"
                    : !have_fortran ? "missing 'fortran_order'"
                                    : "missing 'shape'",
                    "the keys 'descr', 'fortran_order' and 'shape'");
  /* padding: spaces, then the final newline */
  skip_ws(h);
  if (h->i + 1 != h->n || h->s[h->i] != '\n') {
    char b[32];
    return hdr_fail(h, HEARTH_E_PARSE, found_desc(h, b, sizeof b),
                    "space padding and a final '\\n' after the dict");
  }
  return HEARTH_OK;
}

hearth_status hearth_npy_parse(const void *data, size_t size, const char *name, hearth_npy *out,
                               hearth_err *err) {
  if (!out) return hearth_err_set(err, HEARTH_E_ARG, "npy: out is NULL");
  memset(out, 0, sizeof *out);
  if (!name) name = "(npy)";
  if (!data && size) return hearth_err_set(err, HEARTH_E_ARG, "%s: data is NULL", name);
  const uint8_t *b = data;
  if (size < 8 || memcmp(b, NPY_MAGIC, NPY_MAGIC_LEN) != 0)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: byte 0: not a NumPy file, expected the magic \"\\x93NUMPY\"", name);
  int major = b[6], minor = b[7];
  size_t lenbytes;
  if (major == 1 && minor == 0) lenbytes = 2;
  else if (major == 2 && minor == 0) lenbytes = 4;
  else
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "%s: byte 6: format version %d.%d, expected 1.0 or 2.0", name, major,
                          minor);
  if (size < 8 + lenbytes)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: byte 8: file ends inside the header length, expected %zu bytes",
                          name, lenbytes);
  size_t hlen = (size_t)b[8] | (size_t)b[9] << 8;
  if (lenbytes == 4) hlen |= (size_t)b[10] << 16 | (size_t)b[11] << 24;
  size_t hstart = 8 + lenbytes;
  if (hlen > NPY_MAX_HEADER)
    return hearth_err_set(err, HEARTH_E_LIMIT,
                          "%s: byte 8: header length %zu exceeds the limit of %zu bytes", name,
                          hlen, NPY_MAX_HEADER);
  if (hlen > size - hstart)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: byte %zu: header of %zu bytes runs past the end of the file "
                          "(%zu bytes), expected a complete header",
                          name, hstart, hlen, size);
  hdr h = {(const char *)b + hstart, hlen, 0, hstart, name, err};
  hearth_status st = parse_dict(&h, out);
  if (st) {
    memset(out, 0, sizeof *out);
    return st;
  }

  /* the data must be exactly count * itemsize bytes */
  size_t count = 1, bytes;
  for (int i = 0; i < out->ndim; i++)
    if (!hearth_mul_size(count, out->shape[i], &count)) {
      memset(out, 0, sizeof *out);
      return hearth_err_set(
          err, HEARTH_E_LIMIT,
          "%s: shape overflows the address space, expected an array that fits in memory", name);
    }
  if (!hearth_mul_size(count, dtype_size(out->dtype), &bytes)) {
    memset(out, 0, sizeof *out);
    return hearth_err_set(
        err, HEARTH_E_LIMIT,
        "%s: shape overflows the address space, expected an array that fits in memory", name);
  }
  size_t dstart = hstart + hlen, have = size - dstart, item = dtype_size(out->dtype);
  if (have != bytes) {
    memset(out, 0, sizeof *out);
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "%s: byte %zu: %zu bytes of array data, expected %zu bytes (%zu "
                          "elements of %zu bytes)",
                          name, dstart, have, bytes, count, item);
  }
  out->data = malloc(bytes ? bytes : 1);
  if (!out->data) {
    memset(out, 0, sizeof *out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot allocate %zu bytes", name, bytes);
  }
  memcpy(out->data, b + dstart, bytes);
  if (out->dtype == HEARTH_NPY_F32 && !host_is_little()) {
    uint8_t *p = out->data;
    for (size_t i = 0; i < bytes; i += 4) {
      uint8_t t0 = p[i], t1 = p[i + 1];
      p[i] = p[i + 3];
      p[i + 1] = p[i + 2];
      p[i + 2] = t1;
      p[i + 3] = t0;
    }
  }
  return HEARTH_OK;
}

hearth_status hearth_npy_read(const char *path, hearth_npy *out, hearth_err *err) {
  if (out) memset(out, 0, sizeof *out);
  if (!path || !out) return hearth_err_set(err, HEARTH_E_ARG, "npy: NULL argument");
  uint8_t *data = NULL;
  size_t size = 0;
  hearth_status st = hearth_read_file(path, NPY_MAX_FILE, &data, &size, err);
  if (st) return st;
  st = hearth_npy_parse(data, size, path, out, err);
  free(data);
  return st;
}

hearth_status hearth_npy_write(const char *path, hearth_npy_dtype dtype, int ndim,
                               const size_t *shape, const void *data, hearth_err *err) {
  if (!path) return hearth_err_set(err, HEARTH_E_ARG, "npy: path is NULL");
  if (dtype != HEARTH_NPY_F32 && dtype != HEARTH_NPY_U8)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: dtype %d, expected F32 or U8", path, (int)dtype);
  if (ndim < 0 || ndim > 4 || (ndim > 0 && !shape))
    return hearth_err_set(err, HEARTH_E_ARG, "%s: rank %d, expected 0..4 with a shape", path, ndim);
  size_t count = 1, bytes;
  for (int i = 0; i < ndim; i++)
    if (!hearth_mul_size(count, shape[i], &count))
      return hearth_err_set(err, HEARTH_E_LIMIT, "%s: shape overflows", path);
  if (!hearth_mul_size(count, dtype_size(dtype), &bytes))
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: shape overflows", path);
  if (bytes && !data) return hearth_err_set(err, HEARTH_E_ARG, "%s: data is NULL", path);

  /* the dict exactly as numpy writes it, e.g. (5,) for rank 1 */
  char dict[256];
  int n = snprintf(dict, sizeof dict, "{'descr': '%s', 'fortran_order': False, 'shape': (",
                   dtype == HEARTH_NPY_F32 ? "<f4" : "|u1");
  for (int i = 0; i < ndim; i++)
    n += snprintf(dict + n, sizeof dict - (size_t)n, "%s%zu", i ? ", " : "", shape[i]);
  n += snprintf(dict + n, sizeof dict - (size_t)n, "%s), }", ndim == 1 ? "," : "");
  /* pad so magic + version + length + header is a multiple of 64, ending in '\n' */
  size_t pre = NPY_MAGIC_LEN + 2 + 2, used = pre + (size_t)n + 1;
  size_t total = (used + 63) / 64 * 64, hlen = total - pre;
  if (hlen > 65535) return hearth_err_set(err, HEARTH_E_LIMIT, "%s: header too long", path);
  uint8_t head[320];
  memcpy(head, NPY_MAGIC, NPY_MAGIC_LEN);
  head[6] = 1;
  head[7] = 0;
  head[8] = (uint8_t)(hlen & 0xFF);
  head[9] = (uint8_t)(hlen >> 8);
  memcpy(head + pre, dict, (size_t)n);
  memset(head + pre + n, ' ', total - pre - (size_t)n - 1);
  head[total - 1] = '\n';

  hearth_atomic_file af;
  hearth_status st = hearth_atomic_open(&af, path, err);
  if (st) return st;
  errno = 0;
  int bad = fwrite(head, 1, total, af.fp) != total;
  if (!bad && bytes) {
    if (dtype == HEARTH_NPY_F32 && !host_is_little()) {
      const uint8_t *p = data;
      for (size_t i = 0; i < bytes && !bad; i += 4) {
        uint8_t q[4] = {p[i + 3], p[i + 2], p[i + 1], p[i]};
        bad = fwrite(q, 1, 4, af.fp) != 4;
      }
    } else {
      bad = fwrite(data, 1, bytes, af.fp) != bytes;
    }
  }
  if (bad) return hearth_atomic_fail(&af, err);
  return hearth_atomic_commit(&af, err);
}
