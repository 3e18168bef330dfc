/* WebSocket (RFC 6455) pieces that read untrusted bytes: SHA-1 (FIPS 180-4)
 * and base64 for the accept key, the handshake response check and frame
 * headers */
#include <stdio.h>
#include <strings.h>
#include <string.h>

#include "hearth/ws.h"

static uint32_t rol(uint32_t x, int n) { return x << n | x >> (32 - n); }

static void sha1_block(uint32_t h[5], const uint8_t *p) {
  uint32_t w[80];
  for (int i = 0; i < 16; i++)
    w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 | (uint32_t)p[4 * i + 2] << 8 |
           p[4 * i + 3];
  for (int i = 16; i < 80; i++) w[i] = rol(w[i - 3] ^ w[i - 8] ^ w[i - 14] ^ w[i - 16], 1);
  uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4];
  for (int i = 0; i < 80; i++) {
    uint32_t f, k;
    if (i < 20) f = (b & c) | (~b & d), k = 0x5a827999u;
    else if (i < 40) f = b ^ c ^ d, k = 0x6ed9eba1u;
    else if (i < 60) f = (b & c) | (b & d) | (c & d), k = 0x8f1bbcdcu;
    else f = b ^ c ^ d, k = 0xca62c1d6u;
    uint32_t t = rol(a, 5) + f + e + k + w[i];
    e = d, d = c, c = rol(b, 30), b = a, a = t;
  }
  h[0] += a, h[1] += b, h[2] += c, h[3] += d, h[4] += e;
}

void hearth_sha1(const void *data, size_t len, uint8_t out[20]) {
  uint32_t h[5] = {0x67452301u, 0xefcdab89u, 0x98badcfeu, 0x10325476u, 0xc3d2e1f0u};
  const uint8_t *p = data;
  size_t full = len / 64 * 64;
  for (size_t i = 0; i < full; i += 64) sha1_block(h, p + i);
  /* padding: 0x80, zeros, 64-bit big-endian bit length */
  uint8_t tail[128] = {0};
  size_t r = len - full;
  if (r) memcpy(tail, p + full, r);
  tail[r] = 0x80;
  size_t tl = r + 1 + 8 <= 64 ? 64 : 128;
  uint64_t bits = (uint64_t)len * 8;
  for (int i = 0; i < 8; i++) tail[tl - 1 - i] = (uint8_t)(bits >> (8 * i));
  sha1_block(h, tail);
  if (tl == 128) sha1_block(h, tail + 64);
  for (int i = 0; i < 5; i++)
    for (int j = 0; j < 4; j++) out[4 * i + j] = (uint8_t)(h[i] >> (24 - 8 * j));
}

size_t hearth_base64_encode(const uint8_t *in, size_t n, char *out, size_t outsz) {
  static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  size_t need = (n + 2) / 3 * 4;
  if (outsz < need + 1) return 0;
  size_t o = 0;
  for (size_t i = 0; i < n; i += 3) {
    uint32_t v = (uint32_t)in[i] << 16;
    if (i + 1 < n) v |= (uint32_t)in[i + 1] << 8;
    if (i + 2 < n) v |= in[i + 2];
    out[o++] = tab[v >> 18 & 63];
    out[o++] = tab[v >> 12 & 63];
    out[o++] = i + 1 < n ? tab[v >> 6 & 63] : '=';
    out[o++] = i + 2 < n ? tab[v & 63] : '=';
  }
  out[o] = 0;
  return o;
}

void hearth_ws_accept(const char *key, char out[29]) {
  char buf[256];
  int n = snprintf(buf, sizeof buf, "%s258EAFA5-E914-47DA-95CA-C5AB0DC85B11", key);
  uint8_t d[20];
  hearth_sha1(buf, n < 0 ? 0 : (size_t)n >= sizeof buf ? sizeof buf - 1 : (size_t)n, d);
  hearth_base64_encode(d, 20, out, 29);
}

/* case-insensitive: does the comma-separated header value contain token */
static int has_token(const char *v, size_t n, const char *tok) {
  size_t tl = strlen(tok);
  size_t i = 0;
  while (i < n) {
    while (i < n && (v[i] == ' ' || v[i] == '\t' || v[i] == ',')) i++;
    size_t s = i;
    while (i < n && v[i] != ',') i++;
    size_t e = i;
    while (e > s && (v[e - 1] == ' ' || v[e - 1] == '\t')) e--;
    if (e - s == tl && strncasecmp(v + s, tok, tl) == 0) return 1;
  }
  return 0;
}

hearth_status hearth_ws_check_handshake(const char *resp, size_t len, const char *key,
                                        hearth_err *err) {
  int upgrade = 0, connection = 0, accept_ok = 0;
  char want[29];
  hearth_ws_accept(key, want);
  size_t pos = 0;
  int line = 0;
  while (pos < len) {
    const char *s = resp + pos;
    const char *nl = memchr(s, '\n', len - pos);
    size_t ll = nl ? (size_t)(nl - s) : len - pos;
    pos += ll + (nl ? 1 : 0);
    if (ll && s[ll - 1] == '\r') ll--;
    line++;
    if (line == 1) {
      if (ll < 12 || strncmp(s, "HTTP/1.1 ", 9) != 0)
        return hearth_err_set(err, HEARTH_E_PARSE,
                              "websocket handshake: line 1: expected \"HTTP/1.1 101\", got \"%.*s\"",
                              (int)(ll > 80 ? 80 : ll), s);
      if (strncmp(s + 9, "101", 3) != 0)
        return hearth_err_set(
            err, HEARTH_E_PARSE,
            "websocket handshake: line 1: expected status 101 (switching protocols), got \"%.*s\"",
            (int)(ll > 80 ? 80 : ll), s);
      continue;
    }
    if (ll == 0) break;
    const char *colon = memchr(s, ':', ll);
    if (!colon)
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "websocket handshake: line %d: expected \"Name: value\"", line);
    size_t nl_ = (size_t)(colon - s);
    const char *v = colon + 1;
    size_t vl = ll - nl_ - 1;
    while (vl && (*v == ' ' || *v == '\t')) v++, vl--;
    while (vl && (v[vl - 1] == ' ' || v[vl - 1] == '\t')) vl--;
    if (nl_ == 7 && strncasecmp(s, "Upgrade", 7) == 0) upgrade = has_token(v, vl, "websocket");
    else if (nl_ == 10 && strncasecmp(s, "Connection", 10) == 0)
      connection = has_token(v, vl, "upgrade");
    else if (nl_ == 20 && strncasecmp(s, "Sec-WebSocket-Accept", 20) == 0) {
      if (vl != 28 || memcmp(v, want, 28) != 0)
        return hearth_err_set(
            err, HEARTH_E_PARSE,
            "websocket handshake: line %d: Sec-WebSocket-Accept \"%.*s\" does not match \"%s\"",
            line, (int)(vl > 60 ? 60 : vl), v, want);
      accept_ok = 1;
    } else if (nl_ == 24 && strncasecmp(s, "Sec-WebSocket-Extensions", 24) == 0 && vl)
      return hearth_err_set(
          err, HEARTH_E_UNSUPPORTED,
          "websocket handshake: line %d: the server negotiated extensions \"%.*s\" that were not offered",
          line, (int)(vl > 60 ? 60 : vl), v);
  }
  if (line == 0) return hearth_err_set(err, HEARTH_E_PARSE, "websocket handshake: empty response");
  if (!upgrade)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "websocket handshake: missing \"Upgrade: websocket\"");
  if (!connection)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "websocket handshake: missing \"Connection: Upgrade\"");
  if (!accept_ok)
    return hearth_err_set(err, HEARTH_E_PARSE, "websocket handshake: missing Sec-WebSocket-Accept");
  return HEARTH_OK;
}

hearth_status hearth_ws_parse_header(const uint8_t *buf, size_t len, int allow_masked,
                                     uint64_t max_payload, hearth_ws_header *h, size_t *need,
                                     hearth_err *err) {
  memset(h, 0, sizeof *h);
  *need = 0;
  if (len < 2) {
    *need = 2 - len;
    return HEARTH_OK;
  }
  uint8_t b0 = buf[0], b1 = buf[1];
  h->fin = b0 >> 7;
  h->opcode = b0 & 0x0f;
  h->masked = b1 >> 7;
  if (b0 & 0x70)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "websocket frame: reserved bits 0x%02x set (no extension was negotiated)",
                          b0 & 0x70);
  int op = h->opcode;
  if (!(op == 0 || op == 1 || op == 2 || op == 8 || op == 9 || op == 10))
    return hearth_err_set(err, HEARTH_E_PARSE, "websocket frame: unknown opcode 0x%x", op);
  if (h->masked && !allow_masked)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "websocket frame: a server must not mask its frames");
  uint64_t pl = b1 & 0x7f;
  size_t hl = 2 + (pl == 126 ? 2 : pl == 127 ? 8 : 0) + (h->masked ? 4 : 0);
  if (len < hl) {
    *need = hl - len;
    return HEARTH_OK;
  }
  if (pl == 126) {
    pl = (uint64_t)buf[2] << 8 | buf[3];
    if (pl < 126)
      return hearth_err_set(err, HEARTH_E_PARSE, "websocket frame: non-minimal 16-bit length %llu",
                            (unsigned long long)pl);
  } else if (pl == 127) {
    pl = 0;
    for (int i = 0; i < 8; i++) pl = pl << 8 | buf[2 + i];
    if (pl >> 63)
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "websocket frame: 64-bit length with the top bit set");
    if (pl <= 0xffff)
      return hearth_err_set(err, HEARTH_E_PARSE, "websocket frame: non-minimal 64-bit length %llu",
                            (unsigned long long)pl);
  }
  if (op >= 8 && (!h->fin || pl > 125))
    return hearth_err_set(err, HEARTH_E_PARSE, "websocket frame: control frame 0x%x %s", op,
                          !h->fin ? "fragmented" : "longer than 125 bytes");
  if (pl > max_payload)
    return hearth_err_set(err, HEARTH_E_LIMIT,
                          "websocket frame: payload of %llu bytes exceeds the limit of %llu",
                          (unsigned long long)pl, (unsigned long long)max_payload);
  if (h->masked) memcpy(h->mask, buf + hl - 4, 4);
  h->payload_len = pl;
  h->header_len = hl;
  return HEARTH_OK;
}

size_t hearth_ws_build_header(uint8_t out[14], int fin, int opcode, uint64_t n,
                              const uint8_t mask[4]) {
  size_t k = 0;
  out[k++] = (uint8_t)((fin ? 0x80 : 0) | (opcode & 0x0f));
  uint8_t m = mask ? 0x80 : 0;
  if (n < 126) out[k++] = (uint8_t)(m | n);
  else if (n <= 0xffff) {
    out[k++] = m | 126;
    out[k++] = (uint8_t)(n >> 8), out[k++] = (uint8_t)n;
  } else {
    out[k++] = m | 127;
    for (int i = 7; i >= 0; i--) out[k++] = (uint8_t)(n >> (8 * i));
  }
  if (mask) memcpy(out + k, mask, 4), k += 4;
  return k;
}

void hearth_ws_apply_mask(uint8_t *p, size_t n, const uint8_t mask[4], uint64_t offset) {
  for (size_t i = 0; i < n; i++) p[i] ^= mask[(offset + i) & 3];
}
