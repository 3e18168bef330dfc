/* msgpack: bytes match python3-msgpack's for the same values (an
 * independent encoder), decoding round trips, ndarray maps as
 * msgpack_numpy writes them, and strict errors with byte offsets */
#include <string.h>

#include "hearth/msgpack.h"
#include "test_util.h"

/* python3 -c 'import msgpack; print(msgpack.packb([0,127,128,255,256,65535,65536,2**32,-1,-32,-33,-128,-129,-32768,-32769,-2**31-1,1.5,None,True,False,"hi",b"\x01"]).hex())' */
static const char *k_py =
    "dc0016007fcc80ccffcd0100cdffffce00010000cf0000000100000000ffe0d0dfd080d1ff7fd18000d2ffff7fffd3ffffffff7fffffff"
    "cb3ff8000000000000c0c3c2a26869c40101";

static int hexval(char c) { return c <= '9' ? c - '0' : c - 'a' + 10; }

int main(void) {
  hearth_mp_writer w;
  hearth_mp_writer_init(&w);
  int64_t ints[] = {0,  127, 128, 255,  256,  65535,  65536,  4294967296LL,
                    -1, -32, -33, -128, -129, -32768, -32769, -2147483649LL};
  hearth_mp_put_array(&w, 22);
  for (int i = 0; i < 16; i++) hearth_mp_put_int(&w, ints[i]);
  hearth_mp_put_f64(&w, 1.5);
  hearth_mp_put_nil(&w);
  hearth_mp_put_bool(&w, 1);
  hearth_mp_put_bool(&w, 0);
  hearth_mp_put_cstr(&w, "hi");
  hearth_mp_put_bin(&w, "\x01", 1);
  size_t n = strlen(k_py) / 2;
  uint8_t ref[256];
  for (size_t i = 0; i < n; i++)
    ref[i] = (uint8_t)(hexval(k_py[2 * i]) << 4 | hexval(k_py[2 * i + 1]));
  CHECK(!w.failed && w.len == n && memcmp(w.buf, ref, n) == 0);
  hearth_mp_doc doc;
  hearth_err err = {0};
  CHECK_OK(hearth_mp_decode(ref, n, NULL, &doc, &err), &err);
  if (doc.root) {
    CHECK(doc.root->type == HEARTH_MP_ARRAY && doc.root->n == 22);
    for (int i = 0; i < 16; i++)
      CHECK(doc.root->items[i].type == HEARTH_MP_INT && doc.root->items[i].i == ints[i]);
    CHECK(doc.root->items[16].f == 1.5 && doc.root->items[17].type == HEARTH_MP_NIL);
    CHECK(doc.root->items[18].b == 1 && doc.root->items[19].type == HEARTH_MP_BOOL &&
          !doc.root->items[19].b);
    CHECK(hearth_mp_str_eq(&doc.root->items[20], "hi") &&
          doc.root->items[21].type == HEARTH_MP_BIN);
  }
  hearth_mp_doc_free(&doc);
  /* ndarray round trip */
  hearth_mp_writer_free(&w);
  hearth_mp_writer_init(&w);
  float a[6] = {1, -2, 3.5f, 4, 5, 6};
  size_t shape[2] = {2, 3};
  hearth_mp_put_map(&w, 1);
  hearth_mp_put_cstr(&w, "actions");
  hearth_mp_put_ndarray(&w, a, sizeof a, "<f4", shape, 2);
  CHECK_OK(hearth_mp_decode(w.buf, w.len, NULL, &doc, &err), &err);
  hearth_mp_ndarray nd;
  CHECK_OK(hearth_mp_ndarray_get(hearth_mp_map_get(doc.root, "actions", HEARTH_MP_STR), "x", &nd,
                                 &err),
           &err);
  CHECK(nd.ndim == 2 && nd.shape[0] == 2 && nd.shape[1] == 3 &&
        hearth_mp_ndarray_at(&nd, 2) == 3.5);
  CHECK(hearth_mp_map_get(doc.root, "actions", HEARTH_MP_BIN) == NULL);
  hearth_mp_doc_free(&doc);
  /* errors: truncation names the offset, trailing bytes, bad byte, limits */
  CHECK(hearth_mp_decode(w.buf, w.len - 3, NULL, &doc, &err) == HEARTH_E_PARSE);
  CHECK(strstr(err.msg, "byte ") != NULL);
  uint8_t two[2] = {0xc0, 0xc0};
  CHECK(hearth_mp_decode(two, 2, NULL, &doc, &err) == HEARTH_E_PARSE && strstr(err.msg, "byte 1"));
  uint8_t c1 = 0xc1;
  CHECK(hearth_mp_decode(&c1, 1, NULL, &doc, &err) == HEARTH_E_PARSE && strstr(err.msg, "0xc1"));
  uint8_t huge[6] = {0xdd, 0xff, 0xff, 0xff, 0xff, 0xc0};
  CHECK(hearth_mp_decode(huge, 6, NULL, &doc, &err) == HEARTH_E_PARSE);
  uint8_t deep[64];
  memset(deep, 0x91, 63);
  deep[63] = 0xc0;
  hearth_mp_limits lim = {16, 0, 0};
  CHECK(hearth_mp_decode(deep, 64, &lim, &doc, &err) == HEARTH_E_LIMIT);
  /* string keys where msgpack_numpy uses binaries are rejected by name */
  hearth_mp_writer_free(&w);
  hearth_mp_writer_init(&w);
  hearth_mp_put_map(&w, 1);
  hearth_mp_put_cstr(&w, "__ndarray__");
  hearth_mp_put_bool(&w, 1);
  CHECK_OK(hearth_mp_decode(w.buf, w.len, NULL, &doc, &err), &err);
  CHECK(hearth_mp_ndarray_get(doc.root, "reply.actions", &nd, &err) == HEARTH_E_PARSE &&
        strstr(err.msg, "reply.actions") && strstr(err.msg, "binaries"));
  hearth_mp_doc_free(&doc);
  hearth_mp_writer_free(&w);
  return g_test_failures ? 1 : 0;
}
