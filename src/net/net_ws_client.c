/* a small RFC 6455 client for openpi's policy server: handshake with the
 * accept check, masked binary frames, fragmentation, ping/pong, close
 * frames with codes; every wait bounded with poll() */
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "hearth/ws.h"

#define WS_MAX_MESSAGE ((uint64_t)256 << 20)

struct hearth_ws {
  int fd;
  uint8_t *rbuf;
  size_t rlen, rcap;
  hearth_rng rng;
  int close_code, closed;
  char close_reason[128];
  char host[256];
  int pong_pending, ping_wait;
  uint8_t pong_payload[125];
  size_t pong_len;
};

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int wait_fd(int fd, short ev, double deadline) {
  for (;;) {
    double left = deadline - now_s();
    if (left <= 0) return 0;
    struct pollfd p = {fd, ev, 0};
    int ms = left > 1e6 ? 1000000000 : (int)(left * 1000) + 1;
    int r = poll(&p, 1, ms);
    if (r > 0) return 1;
    if (r < 0 && errno != EINTR) return -1;
  }
}

static hearth_status send_all(hearth_ws *c, const uint8_t *p, size_t n, double deadline,
                              hearth_err *err) {
  while (n) {
    int w = wait_fd(c->fd, POLLOUT, deadline);
    if (w == 0) return hearth_err_set(err, HEARTH_E_IO, "websocket %s: send timed out", c->host);
    ssize_t k = send(c->fd, p, n, MSG_NOSIGNAL);
    if (k < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      return hearth_err_set(err, HEARTH_E_IO, "websocket %s: send failed: %s", c->host,
                            strerror(errno));
    }
    p += k, n -= (size_t)k;
  }
  return HEARTH_OK;
}

/* read more bytes into rbuf (at least one) before the deadline */
static hearth_status fill(hearth_ws *c, double deadline, double timeout_s, hearth_err *err) {
  if (c->rcap - c->rlen < 65536) {
    size_t cap = c->rcap ? c->rcap * 2 : 131072;
    uint8_t *nb = realloc(c->rbuf, cap);
    if (!nb) return hearth_err_set(err, HEARTH_E_NOMEM, "websocket: receive buffer");
    c->rbuf = nb, c->rcap = cap;
  }
  for (;;) {
    int w = wait_fd(c->fd, POLLIN, deadline);
    if (w == 0)
      return hearth_err_set(err, HEARTH_E_IO,
                            "websocket %s: no reply from the server within %.1f s", c->host,
                            timeout_s);
    if (w < 0)
      return hearth_err_set(err, HEARTH_E_IO, "websocket %s: poll: %s", c->host, strerror(errno));
    ssize_t k = recv(c->fd, c->rbuf + c->rlen, c->rcap - c->rlen, 0);
    if (k == 0) {
      c->closed = 1;
      return hearth_err_set(err, HEARTH_E_IO,
                            "websocket %s: the server closed the connection without a close frame",
                            c->host);
    }
    if (k < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      c->closed = 1;
      return hearth_err_set(err, HEARTH_E_IO, "websocket %s: receive failed: %s", c->host,
                            strerror(errno));
    }
    c->rlen += (size_t)k;
    return HEARTH_OK;
  }
}

static void consume(hearth_ws *c, size_t n) {
  memmove(c->rbuf, c->rbuf + n, c->rlen - n);
  c->rlen -= n;
}

static hearth_status send_frame(hearth_ws *c, int fin, int op, const uint8_t *p, size_t n,
                                double deadline, hearth_err *err) {
  uint8_t hdr[14], mask[4];
  uint64_t r = hearth_rng_u64(&c->rng);
  memcpy(mask, &r, 4);
  size_t hl = hearth_ws_build_header(hdr, fin, op, n, mask);
  hearth_status st = send_all(c, hdr, hl, deadline, err);
  /* mask in chunks so the caller's buffer stays untouched */
  uint8_t tmp[16384];
  for (size_t off = 0; !st && off < n; off += sizeof tmp) {
    size_t k = n - off < sizeof tmp ? n - off : sizeof tmp;
    memcpy(tmp, p + off, k);
    hearth_ws_apply_mask(tmp, k, mask, off);
    st = send_all(c, tmp, k, deadline, err);
  }
  return st;
}

static void seed_rng(hearth_rng *r) {
  uint64_t s = 0;
  int fd = open("/dev/urandom", O_RDONLY);
  if (fd >= 0) {
    if (read(fd, &s, sizeof s) != (ssize_t)sizeof s) s = 0;
    close(fd);
  }
  s ^= (uint64_t)(now_s() * 1e9) ^ ((uint64_t)getpid() << 32);
  hearth_rng_seed(r, s);
}

/* A protocol check's message ("websocket handshake: ...", "websocket
 * frame: ...") with the server named once: "websocket HOST:PORT: handshake: ...". */
static void with_host(hearth_err *err, const char *host) {
  if (!err) return;
  const char *m = err->msg;
  if (!strncmp(m, "websocket ", 10)) m += 10;
  char rest[sizeof err->msg];
  snprintf(rest, sizeof rest, "%s", m);
  snprintf(err->msg, sizeof err->msg, "websocket %s: %s", host, rest);
}

hearth_status hearth_ws_connect(const char *url, double timeout_s, hearth_ws **out,
                                hearth_err *err) {
  *out = NULL;
  if (strncmp(url, "ws://", 5) != 0)
    return hearth_err_set(err, HEARTH_E_ARG, "websocket: \"%s\": expected ws://HOST:PORT[/PATH]",
                          url);
  const char *h = url + 5;
  const char *slash = strchr(h, '/');
  size_t hl = slash ? (size_t)(slash - h) : strlen(h);
  char hostport[256], host[256], port[16] = "8000";
  if (hl == 0 || hl >= sizeof hostport)
    return hearth_err_set(err, HEARTH_E_ARG, "websocket: \"%s\": bad host", url);
  memcpy(hostport, h, hl);
  hostport[hl] = 0;
  const char *path = slash ? slash : "/";
  char *colon = strrchr(hostport, ':');
  snprintf(host, sizeof host, "%s", hostport);
  if (colon && !strchr(colon, ']')) {
    host[colon - hostport] = 0;
    if (strlen(colon + 1) == 0 || strlen(colon + 1) >= sizeof port ||
        strspn(colon + 1, "0123456789") != strlen(colon + 1))
      return hearth_err_set(err, HEARTH_E_ARG, "websocket: \"%s\": bad port", url);
    snprintf(port, sizeof port, "%s", colon + 1);
  }
  if (host[0] == '[') {
    memmove(host, host + 1, strlen(host));
    char *e = strchr(host, ']');
    if (e) *e = 0;
  }
  if (strchr(path, '\r') || strchr(path, '\n') || strchr(path, ' '))
    return hearth_err_set(err, HEARTH_E_ARG, "websocket: \"%s\": bad path", url);
  struct addrinfo hints = {0}, *ai = NULL;
  hints.ai_socktype = SOCK_STREAM;
  int g = getaddrinfo(host, port, &hints, &ai);
  if (g)
    return hearth_err_set(err, HEARTH_E_IO, "websocket %s: cannot resolve: %s", hostport,
                          gai_strerror(g));
  hearth_ws *c = calloc(1, sizeof *c);
  if (!c) {
    freeaddrinfo(ai);
    return hearth_err_set(err, HEARTH_E_NOMEM, "websocket: client");
  }
  c->fd = -1;
  snprintf(c->host, sizeof c->host, "%s", hostport);
  seed_rng(&c->rng);
  double deadline = now_s() + timeout_s;
  hearth_status st = HEARTH_E_IO;
  char why[160] = "no address";
  for (struct addrinfo *a = ai; a && c->fd < 0; a = a->ai_next) {
    int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    int r = connect(fd, a->ai_addr, a->ai_addrlen);
    if (r < 0 && errno == EINPROGRESS) {
      int w = wait_fd(fd, POLLOUT, deadline);
      int soerr = 0;
      socklen_t sl = sizeof soerr;
      if (w <= 0) soerr = ETIMEDOUT;
      else getsockopt(fd, SOL_SOCKET, SO_ERROR, &soerr, &sl);
      r = soerr ? -1 : 0;
      errno = soerr;
    }
    if (r == 0) c->fd = fd;
    else {
      snprintf(why, sizeof why, "%s", strerror(errno));
      close(fd);
    }
  }
  freeaddrinfo(ai);
  if (c->fd < 0) {
    free(c);
    return hearth_err_set(err, HEARTH_E_IO, "websocket %s: cannot connect: %s", hostport, why);
  }
  /* handshake: 16 random bytes as the key */
  uint8_t kb[16];
  for (int i = 0; i < 2; i++) {
    uint64_t r = hearth_rng_u64(&c->rng);
    memcpy(kb + 8 * i, &r, 8);
  }
  char key[32];
  hearth_base64_encode(kb, 16, key, sizeof key);
  char req[1024];
  int rl =
      snprintf(req, sizeof req,
               "GET %s HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\nUser-Agent: hearth\r\n\r\n",
               path, hostport, key);
  if (rl < 0 || (size_t)rl >= sizeof req) {
    hearth_ws_close(c, 0);
    return hearth_err_set(err, HEARTH_E_ARG, "websocket: URL too long");
  }
  st = send_all(c, (const uint8_t *)req, (size_t)rl, deadline, err);
  size_t hend = 0;
  while (!st) {
    for (size_t i = 3; i < c->rlen && !hend; i++)
      if (c->rbuf[i - 3] == '\r' && c->rbuf[i - 2] == '\n' && c->rbuf[i - 1] == '\r' &&
          c->rbuf[i] == '\n')
        hend = i + 1;
    if (hend) break;
    if (c->rlen > 16384) {
      st = hearth_err_set(err, HEARTH_E_LIMIT, "websocket %s: handshake response over 16 KiB",
                          hostport);
      break;
    }
    st = fill(c, deadline, timeout_s, err);
  }
  /* the transport's own errors name the host already; the protocol
   * check's get it added */
  if (!st && (st = hearth_ws_check_handshake((const char *)c->rbuf, hend, key, err)))
    with_host(err, hostport);
  if (st) {
    c->closed = 1;
    hearth_ws_close(c, 0);
    return st;
  }
  consume(c, hend);
  *out = c;
  return HEARTH_OK;
}

hearth_status hearth_ws_send(hearth_ws *c, int opcode, const void *data, size_t n, size_t frag,
                             hearth_err *err) {
  if (c->closed)
    return hearth_err_set(err, HEARTH_E_IO, "websocket %s: connection is closed", c->host);
  double deadline = now_s() + 600;
  if (frag == 0 || frag >= n) return send_frame(c, 1, opcode, data, n, deadline, err);
  const uint8_t *p = data;
  hearth_status st = HEARTH_OK;
  for (size_t off = 0; !st && off < n; off += frag) {
    size_t k = n - off < frag ? n - off : frag;
    st = send_frame(c, off + k == n, off == 0 ? opcode : HEARTH_WS_CONT, p + off, k, deadline, err);
  }
  return st;
}

/* one frame: returns its header; payload at rbuf[header_len..) */
static hearth_status next_frame(hearth_ws *c, hearth_ws_header *h, double deadline,
                                double timeout_s, hearth_err *err) {
  for (;;) {
    size_t need = 0;
    hearth_status st = hearth_ws_parse_header(c->rbuf, c->rlen, 0, WS_MAX_MESSAGE, h, &need, err);
    if (st) {
      c->closed = 1;
      with_host(err, c->host);
      return st;
    }
    if (!need && c->rlen - h->header_len >= h->payload_len) return HEARTH_OK;
    st = fill(c, deadline, timeout_s, err);
    if (st) return st;
  }
}

hearth_status hearth_ws_recv(hearth_ws *c, uint8_t **data, size_t *n, int *opcode, double timeout_s,
                             hearth_err *err) {
  *data = NULL, *n = 0;
  if (opcode) *opcode = 0;
  if (c->closed)
    return hearth_err_set(err, HEARTH_E_IO, "websocket %s: connection is closed", c->host);
  double deadline = now_s() + timeout_s;
  uint8_t *msg = NULL;
  size_t mlen = 0;
  int mop = -1;
  for (;;) {
    hearth_ws_header h;
    hearth_status st = next_frame(c, &h, deadline, timeout_s, err);
    if (st) {
      free(msg);
      return st;
    }
    const uint8_t *p = c->rbuf + h.header_len;
    size_t pl = (size_t)h.payload_len;
    if (h.opcode == HEARTH_WS_PING) {
      uint8_t copy[125];
      memcpy(copy, p, pl);
      consume(c, h.header_len + pl);
      st = send_frame(c, 1, HEARTH_WS_PONG, copy, pl, deadline, err);
      if (st) {
        free(msg);
        return st;
      }
      continue;
    }
    if (h.opcode == HEARTH_WS_PONG) {
      if (c->pong_pending && pl == c->pong_len && memcmp(p, c->pong_payload, pl) == 0)
        c->pong_pending = 0;
      consume(c, h.header_len + pl);
      if (!c->pong_pending && c->ping_wait) return HEARTH_OK;
      continue;
    }
    if (h.opcode == HEARTH_WS_CLOSE) {
      c->close_code = pl >= 2 ? (p[0] << 8 | p[1]) : 1005;
      size_t rl = pl > 2 ? pl - 2 : 0;
      if (rl >= sizeof c->close_reason) rl = sizeof c->close_reason - 1;
      memcpy(c->close_reason, p + 2, rl);
      c->close_reason[rl] = 0;
      consume(c, h.header_len + pl);
      /* echo the close and stop */
      uint8_t cb[2] = {(uint8_t)(c->close_code >> 8), (uint8_t)c->close_code};
      if (c->close_code != 1005) send_frame(c, 1, HEARTH_WS_CLOSE, cb, 2, now_s() + 1, NULL);
      c->closed = 1;
      free(msg);
      return hearth_err_set(err, HEARTH_E_IO,
                            "websocket %s: the server closed the connection with code %d%s%s%s",
                            c->host, c->close_code, c->close_reason[0] ? " (" : "", c->close_reason,
                            c->close_reason[0] ? ")" : "");
    }
    if ((h.opcode == HEARTH_WS_CONT) != (mop >= 0)) {
      free(msg);
      c->closed = 1;
      return hearth_err_set(err, HEARTH_E_PARSE, "websocket %s: %s", c->host,
                            mop >= 0 ? "a new message started inside a fragmented one"
                                     : "a continuation frame without a message");
    }
    if (mop < 0) mop = h.opcode;
    if (pl > WS_MAX_MESSAGE - mlen) {
      free(msg);
      c->closed = 1;
      return hearth_err_set(err, HEARTH_E_LIMIT, "websocket %s: message over %llu bytes", c->host,
                            (unsigned long long)WS_MAX_MESSAGE);
    }
    uint8_t *nm = realloc(msg, mlen + pl + 1);
    if (!nm) {
      free(msg);
      return hearth_err_set(err, HEARTH_E_NOMEM, "websocket: message of %zu bytes", mlen + pl);
    }
    msg = nm;
    memcpy(msg + mlen, p, pl);
    mlen += pl;
    msg[mlen] = 0;
    consume(c, h.header_len + pl);
    if (h.fin) {
      if (c->ping_wait) {
        free(msg);
        c->closed = 1;
        return hearth_err_set(err, HEARTH_E_PARSE,
                              "websocket %s: a data message arrived while waiting for a pong",
                              c->host);
      }
      *data = msg, *n = mlen;
      if (opcode) *opcode = mop;
      return HEARTH_OK;
    }
  }
}

hearth_status hearth_ws_ping(hearth_ws *c, const void *payload, size_t n, double timeout_s,
                             hearth_err *err) {
  if (n > 125) return hearth_err_set(err, HEARTH_E_ARG, "websocket: ping payload over 125 bytes");
  if (c->closed)
    return hearth_err_set(err, HEARTH_E_IO, "websocket %s: connection is closed", c->host);
  memcpy(c->pong_payload, payload, n);
  c->pong_len = n;
  c->pong_pending = 1;
  hearth_status st = send_frame(c, 1, HEARTH_WS_PING, payload, n, now_s() + timeout_s, err);
  if (st) return st;
  /* wait for the pong; data messages arriving meanwhile are an error here */
  uint8_t *d;
  size_t dn;
  c->ping_wait = 1;
  st = hearth_ws_recv(c, &d, &dn, NULL, timeout_s, err);
  c->ping_wait = 0;
  return st;
}

void hearth_ws_close(hearth_ws *c, int code) {
  if (!c) return;
  if (c->fd >= 0) {
    if (!c->closed && code) {
      uint8_t cb[2] = {(uint8_t)(code >> 8), (uint8_t)code};
      double deadline = now_s() + 1.0;
      if (send_frame(c, 1, HEARTH_WS_CLOSE, cb, 2, deadline, NULL) == HEARTH_OK) {
        /* wait briefly for the server's close */
        for (int k = 0; k < 64; k++) {
          hearth_ws_header h;
          if (next_frame(c, &h, deadline, 1.0, NULL)) break;
          int op = h.opcode;
          consume(c, h.header_len + (size_t)h.payload_len);
          if (op == HEARTH_WS_CLOSE) break;
        }
      }
    }
    close(c->fd);
  }
  free(c->rbuf);
  free(c);
}

int hearth_ws_close_code(const hearth_ws *c, const char **reason) {
  if (reason) *reason = c ? c->close_reason : "";
  return c ? c->close_code : 0;
}
