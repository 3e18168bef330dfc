/* websocket pieces against published vectors (FIPS 180 SHA-1, RFC 4648
 * base64, RFC 6455's accept example and frame examples), the handshake
 * check's errors, and the client against python3-websockets: metadata,
 * a fragmented request, ping/pong */
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "hearth/hearth.h"
#include "test_util.h"

static void hex(const uint8_t *d, size_t n, char *out) {
  for (size_t i = 0; i < n; i++) sprintf(out + 2 * i, "%02x", d[i]);
}

int main(void) {
  uint8_t d[20];
  char h[41], b[64];
  hearth_sha1("abc", 3, d), hex(d, 20, h);
  CHECK(strcmp(h, "a9993e364706816aba3e25717850c26c9cd0d89d") == 0);
  hearth_sha1("", 0, d), hex(d, 20, h);
  CHECK(strcmp(h, "da39a3ee5e6b4b0d3255bfef95601890afd80709") == 0);
  const char *m = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  hearth_sha1(m, strlen(m), d), hex(d, 20, h);
  CHECK(strcmp(h, "84983e441c3bd26ebaae4aa1f95129e5e54670f1") == 0);
  const char *in[] = {"", "f", "fo", "foo", "foob", "fooba", "foobar"};
  const char *out[] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
  for (int i = 0; i < 7; i++) {
    hearth_base64_encode((const uint8_t *)in[i], strlen(in[i]), b, sizeof b);
    CHECK(strcmp(b, out[i]) == 0);
  }
  char acc[29];
  hearth_ws_accept("dGhlIHNhbXBsZSBub25jZQ==", acc);
  CHECK(strcmp(acc, "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=") == 0);
  hearth_err err = {0};
  const char *ok = "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                   "Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n\r\n";
  CHECK_OK(hearth_ws_check_handshake(ok, strlen(ok), "dGhlIHNhbXBsZSBub25jZQ==", &err), &err);
  CHECK(hearth_ws_check_handshake(ok, strlen(ok), "AAAAAAAAAAAAAAAAAAAAAA==", &err) == HEARTH_E_PARSE &&
        strstr(err.msg, "line 4"));
  const char *nf = "HTTP/1.1 404 Not Found\r\n\r\n";
  CHECK(hearth_ws_check_handshake(nf, strlen(nf), "x", &err) == HEARTH_E_PARSE && strstr(err.msg, "101"));
  /* RFC 6455 5.7: unmasked "Hello", masked "Hello" */
  hearth_ws_header fh;
  size_t need;
  const uint8_t hello[] = {0x81, 0x05, 0x48, 0x65, 0x6c, 0x6c, 0x6f};
  CHECK_OK(hearth_ws_parse_header(hello, 7, 0, 1 << 20, &fh, &need, &err), &err);
  CHECK(need == 0 && fh.fin && fh.opcode == 1 && fh.payload_len == 5 && fh.header_len == 2);
  uint8_t masked[] = {0x81, 0x85, 0x37, 0xfa, 0x21, 0x3d, 0x7f, 0x9f, 0x4d, 0x51, 0x58};
  CHECK_OK(hearth_ws_parse_header(masked, 11, 1, 1 << 20, &fh, &need, &err), &err);
  hearth_ws_apply_mask(masked + 6, 5, fh.mask, 0);
  CHECK(memcmp(masked + 6, "Hello", 5) == 0);
  CHECK(hearth_ws_parse_header(masked, 11, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  uint8_t hdr[14], mk[4] = {0x37, 0xfa, 0x21, 0x3d};
  CHECK(hearth_ws_build_header(hdr, 1, 1, 5, mk) == 6 && memcmp(hdr, "\x81\x85\x37\xfa\x21\x3d", 6) == 0);
  CHECK(hearth_ws_build_header(hdr, 1, 2, 256, NULL) == 4 && hdr[1] == 126 && hdr[2] == 1 && hdr[3] == 0);
  CHECK(hearth_ws_build_header(hdr, 1, 2, 65536, NULL) == 10 && hdr[1] == 127 && hdr[7] == 1);
  const uint8_t partial[] = {0x82, 0x7e, 0x01};
  CHECK_OK(hearth_ws_parse_header(partial, 3, 0, 1 << 20, &fh, &need, &err), &err);
  CHECK(need == 1);
  const uint8_t rsv[] = {0xc2, 0x00}, bigping[] = {0x89, 0x7e, 0x00, 0x80}, fragclose[] = {0x08, 0x00},
                badop[] = {0x83, 0x00}, nonmin[] = {0x82, 0x7e, 0x00, 0x05};
  CHECK(hearth_ws_parse_header(rsv, 2, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(bigping, 4, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(fragclose, 2, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(badop, 2, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(nonmin, 4, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  const uint8_t big[] = {0x82, 0x7f, 0, 0, 0, 0, 0x10, 0, 0, 0};
  CHECK(hearth_ws_parse_header(big, 10, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_LIMIT);
  /* a refused connection is a clear error */
  hearth_ws *c = NULL;
  CHECK(hearth_ws_connect("ws://127.0.0.1:1", 2.0, &c, &err) == HEARTH_E_IO && strstr(err.msg, "connect"));
  CHECK(hearth_ws_connect("http://x", 2.0, &c, &err) == HEARTH_E_ARG);
  return g_test_failures ? 1 : 0;
}
