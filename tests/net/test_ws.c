/* websocket pieces against published vectors (FIPS 180 SHA-1, RFC 4648
 * base64, RFC 6455's accept example and frame examples), the handshake
 * check's errors, and the client against python3-websockets: metadata,
 * a fragmented request, ping/pong */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "hearth/hearth.h"
#include "test_util.h"

static void hex(const uint8_t *d, size_t n, char *out) {
  for (size_t i = 0; i < n; i++) sprintf(out + 2 * i, "%02x", d[i]);
}

/* A one-connection server on 127.0.0.1: mode 0 answers the handshake with
 * "200 OK", 1 says nothing, 2 completes the handshake and then sends a
 * frame with reserved bits set. Returns the port; *pid is the server. */
static int fake_server(int mode, pid_t *pid) {
  int s = socket(AF_INET, SOCK_STREAM, 0);
  struct sockaddr_in a;
  memset(&a, 0, sizeof a);
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t l = sizeof a;
  if (s < 0 || bind(s, (struct sockaddr *)&a, sizeof a) || listen(s, 1) ||
      getsockname(s, (struct sockaddr *)&a, &l))
    return -1;
  *pid = fork();
  if (*pid == 0) {
    int c = accept(s, NULL, NULL);
    char req[4096] = {0}, reply[512];
    ssize_t n = read(c, req, sizeof req - 1);
    (void)n;
    if (mode == 0) {
      snprintf(reply, sizeof reply, "HTTP/1.1 200 OK\r\nContent-Length: 0\r\n\r\n");
    } else if (mode == 2) {
      char key[64] = {0}, acc[29];
      const char *k = strstr(req, "Sec-WebSocket-Key: ");
      if (k) sscanf(k + 19, "%63[^\r]", key);
      hearth_ws_accept(key, acc);
      snprintf(reply, sizeof reply,
               "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Accept: %s\r\n\r\n\xc2",
               acc);
    }
    if (mode != 1 && write(c, reply, strlen(reply) + (mode == 2)) < 0) _exit(1);
    sleep(3);
    _exit(0);
  }
  close(s);
  return ntohs(a.sin_port);
}

/* the server named once, no empty prefix */
static int named_once(const char *msg, int port) {
  char want[64];
  snprintf(want, sizeof want, "websocket 127.0.0.1:%d: ", port);
  const char *w = strstr(msg, "websocket");
  return !strncmp(msg, want, strlen(want)) && w && !strstr(w + 1, "websocket") &&
         !strstr(msg, ": :");
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
  const char *ok =
      "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n\r\n";
  CHECK_OK(hearth_ws_check_handshake(ok, strlen(ok), "dGhlIHNhbXBsZSBub25jZQ==", &err), &err);
  CHECK(hearth_ws_check_handshake(ok, strlen(ok), "AAAAAAAAAAAAAAAAAAAAAA==", &err) ==
            HEARTH_E_PARSE &&
        strstr(err.msg, "line 4"));
  const char *nf = "HTTP/1.1 404 Not Found\r\n\r\n";
  CHECK(hearth_ws_check_handshake(nf, strlen(nf), "x", &err) == HEARTH_E_PARSE &&
        strstr(err.msg, "101"));
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
  CHECK(hearth_ws_build_header(hdr, 1, 1, 5, mk) == 6 &&
        memcmp(hdr, "\x81\x85\x37\xfa\x21\x3d", 6) == 0);
  CHECK(hearth_ws_build_header(hdr, 1, 2, 256, NULL) == 4 && hdr[1] == 126 && hdr[2] == 1 &&
        hdr[3] == 0);
  CHECK(hearth_ws_build_header(hdr, 1, 2, 65536, NULL) == 10 && hdr[1] == 127 && hdr[7] == 1);
  const uint8_t partial[] = {0x82, 0x7e, 0x01};
  CHECK_OK(hearth_ws_parse_header(partial, 3, 0, 1 << 20, &fh, &need, &err), &err);
  CHECK(need == 1);
  const uint8_t rsv[] = {0xc2, 0x00}, bigping[] = {0x89, 0x7e, 0x00, 0x80},
                fragclose[] = {0x08, 0x00}, badop[] = {0x83, 0x00},
                nonmin[] = {0x82, 0x7e, 0x00, 0x05};
  CHECK(hearth_ws_parse_header(rsv, 2, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(bigping, 4, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(fragclose, 2, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(badop, 2, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  CHECK(hearth_ws_parse_header(nonmin, 4, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_PARSE);
  const uint8_t big[] = {0x82, 0x7f, 0, 0, 0, 0, 0x10, 0, 0, 0};
  CHECK(hearth_ws_parse_header(big, 10, 0, 1 << 20, &fh, &need, &err) == HEARTH_E_LIMIT);
  /* a refused connection is a clear error */
  hearth_ws *c = NULL;
  CHECK(hearth_ws_connect("ws://127.0.0.1:1", 2.0, &c, &err) == HEARTH_E_IO &&
        strstr(err.msg, "connect"));
  CHECK(hearth_ws_connect("http://x", 2.0, &c, &err) == HEARTH_E_ARG);
  /* a server that misbehaves: each message names it once */
  for (int mode = 0; mode < 3; mode++) {
    pid_t pid = -1;
    int port = fake_server(mode, &pid);
    CHECK(port > 0);
    char url[64];
    snprintf(url, sizeof url, "ws://127.0.0.1:%d/", port);
    memset(&err, 0, sizeof err);
    hearth_status st = hearth_ws_connect(url, mode == 1 ? 0.3 : 5.0, &c, &err);
    if (mode == 2) {
      CHECK_OK(st, &err);
      uint8_t *msg = NULL;
      size_t n = 0;
      int op = 0;
      if (!st) {
        st = hearth_ws_recv(c, &msg, &n, &op, 5.0, &err);
        free(msg);
        hearth_ws_close(c, 0);
      }
      CHECK_MSG(st == HEARTH_E_PARSE && strstr(err.msg, ": frame: reserved bits"), "%s", err.msg);
    } else if (mode == 0) {
      CHECK_MSG(st == HEARTH_E_PARSE && strstr(err.msg, ": handshake: line 1"), "%s", err.msg);
    } else {
      CHECK_MSG(st == HEARTH_E_IO && strstr(err.msg, "no reply"), "%s", err.msg);
    }
    CHECK_MSG(named_once(err.msg, port), "mode %d: %s", mode, err.msg);
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, NULL, 0);
    }
  }
  return g_test_failures ? 1 : 0;
}
