/* openpi policy server as a policy: the LIBERO client protocol over a
 * WebSocket (msgpack observations out, action chunks back). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eval/eval_ws.h"
#include "hearth/eval.h"
#include "hearth/msgpack.h"

void eval_ws_drop(eval_ws_policy *p, int code) {
  hearth_ws_close(p->c, code);
  p->c = NULL;
}

/* connect and read the metadata the server sends first */
hearth_status eval_ws_ensure(eval_ws_policy *p, hearth_err *err) {
  if (p->c) return HEARTH_OK;
  hearth_status st = hearth_ws_connect(p->url, p->timeout_s, &p->c, err);
  if (st) return st;
  uint8_t *m = NULL;
  size_t n = 0;
  int op = 0;
  st = hearth_ws_recv(p->c, &m, &n, &op, p->timeout_s, err);
  if (!st && op != HEARTH_WS_BINARY)
    st = hearth_err_set(err, HEARTH_E_PARSE, "policy server %s: expected the metadata as a binary message, got text \"%.200s\"",
                        p->url, (const char *)m);
  hearth_mp_doc doc;
  if (!st) {
    hearth_mp_limits lim = {16, 100000, 16u << 20};
    st = hearth_mp_decode(m, n, &lim, &doc, err);
    if (st) hearth_err_prefix(err, "policy server %s: metadata: ", p->url);
    else {
      if (doc.root->type != HEARTH_MP_MAP)
        st = hearth_err_set(err, HEARTH_E_PARSE, "policy server %s: metadata: expected a map", p->url);
      else
        snprintf(p->metadata, sizeof p->metadata, "%zu keys", doc.root->n);
      hearth_mp_doc_free(&doc);
    }
  }
  free(m);
  if (st) eval_ws_drop(p, 1002);
  return st;
}

/* one request: the observation -> a chunk of actions */
hearth_status eval_ws_query(eval_ws_policy *p, const hearth_sim_obs *ob, const char *prompt, hearth_err *err) {
  hearth_mp_writer w;
  hearth_mp_writer_init(&w);
  hearth_status st = hearth_eval_encode_obs(ob, prompt, p->thermal, p->image_size, &w, err);
  if (!st) st = hearth_ws_send(p->c, HEARTH_WS_BINARY, w.buf, w.len, 0, err);
  hearth_mp_writer_free(&w);
  if (st) return st;
  uint8_t *m = NULL;
  size_t n = 0;
  int op = 0;
  st = hearth_ws_recv(p->c, &m, &n, &op, p->timeout_s, err);
  if (st) return st;
  if (op == HEARTH_WS_TEXT) {
    /* openpi's error path: the traceback as text, then close 1011 */
    /* a traceback ends with the exception: keep the end */
    char text[400];
    while (n && (m[n - 1] == '\n' || m[n - 1] == ' ')) n--;
    size_t k = n < sizeof text - 1 ? n : sizeof text - 1;
    memcpy(text, m + (n - k), k);
    text[k] = 0;
    free(m);
    for (char *q = text; *q; q++)
      if (*q == '\n' || *q == '\r') *q = ' ';
    hearth_err tmp = {0};
    uint8_t *m2 = NULL;
    size_t n2;
    int op2;
    int code = 0;
    if (hearth_ws_recv(p->c, &m2, &n2, &op2, 2.0, &tmp) != HEARTH_OK || 1) code = hearth_ws_close_code(p->c, NULL);
    free(m2);
    return hearth_err_set(err, HEARTH_E_IO, "policy server %s: server error (close code %d): %s", p->url, code, text);
  }
  hearth_mp_doc doc;
  hearth_mp_limits lim = {16, 100000, 64u << 20};
  st = hearth_mp_decode(m, n, &lim, &doc, err);
  if (st) {
    hearth_err_prefix(err, "policy server %s: reply: ", p->url);
    free(m);
    return st;
  }
  const hearth_mp_value *act = hearth_mp_map_get(doc.root, "actions", HEARTH_MP_STR);
  hearth_mp_ndarray a;
  if (!act) st = hearth_err_set(err, HEARTH_E_NOT_FOUND, "policy server %s: reply: expected a map with \"actions\"", p->url);
  else st = hearth_mp_ndarray_get(act, "reply.actions", &a, err);
  if (!st && (a.kind != 'f' || a.ndim != 2 || a.shape[1] != 7 || a.shape[0] < (size_t)p->replan))
    st = hearth_err_set(err, HEARTH_E_SIZE,
                        "policy server %s: reply.actions: expected float (H, 7) with H >= %d, got dtype %s ndim %d shape[0] %zu",
                        p->url, p->replan, a.dtype, a.ndim, a.ndim ? a.shape[0] : 0);
  if (!st) {
    p->nchunk = p->replan;
    p->next = 0;
    for (int t = 0; t < p->replan && !st; t++)
      for (int k = 0; k < 7; k++) {
        double v = hearth_mp_ndarray_at(&a, (size_t)t * 7 + k);
        if (!isfinite(v)) st = hearth_err_set(err, HEARTH_E_RANGE, "policy server %s: reply.actions[%d][%d] is not finite", p->url, t, k);
        p->chunk[t][k] = v;
      }
  }
  hearth_mp_doc_free(&doc);
  free(m);
  return st;
}
