/* hearth/ws.h - area net (src/net/net_ws.c, net_ws_client.c): the pieces
 * of RFC 6455 (WebSocket) that parse untrusted bytes, written here (no
 * third-party code): SHA-1 and base64 for the Sec-WebSocket-Accept check,
 * the handshake response check and the frame header parser/builder; and
 * the small blocking client built on them that policy evaluation (eval.h)
 * uses to talk to openpi policy servers. */
#ifndef HEARTH_WS_H
#define HEARTH_WS_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

void hearth_sha1(const void *data, size_t len, uint8_t out[20]);
/* Standard base64 with padding; writes 4*ceil(n/3) chars and a NUL; returns
 * the length, or 0 if out is too small. */
size_t hearth_base64_encode(const uint8_t *in, size_t n, char *out, size_t outsz);
/* Sec-WebSocket-Accept for a Sec-WebSocket-Key: base64(SHA-1(key + GUID)),
 * NUL-terminated in out. */
void hearth_ws_accept(const char *key, char out[29]);

/* Check an HTTP handshake response (up to and including the blank line):
 * status 101, Upgrade: websocket, Connection: upgrade and the accept value
 * for `key`; no extension may be negotiated. Errors name the line. */
hearth_status hearth_ws_check_handshake(const char *resp, size_t len, const char *key,
                                        hearth_err *err);

enum {
  HEARTH_WS_CONT = 0x0,
  HEARTH_WS_TEXT = 0x1,
  HEARTH_WS_BINARY = 0x2,
  HEARTH_WS_CLOSE = 0x8,
  HEARTH_WS_PING = 0x9,
  HEARTH_WS_PONG = 0xA
};

typedef struct hearth_ws_header {
  int fin, opcode, masked;
  uint8_t mask[4];
  uint64_t payload_len;
  size_t header_len;
} hearth_ws_header;

/* Parse a frame header at buf[0..len). *need > 0: that many more bytes are
 * needed (nothing parsed). Protocol errors: reserved bits set, unknown
 * opcode, control frame fragmented or over 125 bytes, a mask when
 * !allow_masked (frames from a server), a non-minimal or 64-bit length with
 * the top bit set, a payload over max_payload. */
hearth_status hearth_ws_parse_header(const uint8_t *buf, size_t len, int allow_masked,
                                     uint64_t max_payload, hearth_ws_header *h, size_t *need,
                                     hearth_err *err);
/* Write a frame header (2..14 bytes) into out; mask NULL for unmasked. */
size_t hearth_ws_build_header(uint8_t out[14], int fin, int opcode, uint64_t payload_len,
                              const uint8_t mask[4]);
/* XOR p[0..n) with the mask, the payload starting at byte `offset`. */
void hearth_ws_apply_mask(uint8_t *p, size_t n, const uint8_t mask[4], uint64_t offset);

/* ---- client (openpi's policy server speaks it) ----------------------------------------------
 * ws://HOST:PORT[/PATH] (no TLS); every wait is bounded by the timeout in
 * seconds (poll). A connection is an opaque handle made by hearth_ws_connect
 * and released by hearth_ws_close; one thread at a time. */
typedef struct hearth_ws hearth_ws;
hearth_status hearth_ws_connect(const char *url, double timeout_s, hearth_ws **out,
                                hearth_err *err);
/* Send one message (HEARTH_WS_BINARY or HEARTH_WS_TEXT), masked, in
 * fragments of at most frag_size bytes (0 = one frame). */
hearth_status hearth_ws_send(hearth_ws *c, int opcode, const void *data, size_t n, size_t frag_size,
                             hearth_err *err);
/* Receive one whole message (fragments joined, pings answered). A close
 * frame from the server is an error naming its code and reason. *data is
 * malloc'd (NUL-terminated for convenience; the caller frees it), *n its
 * length; opcode (may be NULL) gets HEARTH_WS_BINARY or HEARTH_WS_TEXT. */
hearth_status hearth_ws_recv(hearth_ws *c, uint8_t **data, size_t *n, int *opcode, double timeout_s,
                             hearth_err *err);
/* Send a ping with payload and wait for the matching pong. */
hearth_status hearth_ws_ping(hearth_ws *c, const void *payload, size_t n, double timeout_s,
                             hearth_err *err);
/* Close handshake with `code` (bounded wait), then free. NULL is fine. */
void hearth_ws_close(hearth_ws *c, int code);
/* Close code and reason of the server's close frame, if one came (else 0);
 * *reason (may be NULL) points into c. */
int hearth_ws_close_code(const hearth_ws *c, const char **reason);

#ifdef __cplusplus
}
#endif
#endif
