/* openpi policy server as a policy: the LIBERO client protocol over a
 * WebSocket (msgpack observations out, action chunks back). */
#include <jansson.h>
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

void eval_ws_free(eval_ws_policy *p) {
  if (p->c) eval_ws_drop(p, 1000);
  free(p->metadata_json);
  p->metadata_json = NULL;
}

/* ---- the metadata map as JSON ------------------------------------------------ */
/* bytes as a JSON string: as they are when valid UTF-8, else with every
 * byte above 0x7f shown as '?' */
static json_t *json_text(const uint8_t *s, size_t n) {
  json_t *j = json_stringn((const char *)s, n);
  if (j) return j;
  char *c = malloc(n + 1);
  if (!c) return json_null();
  for (size_t i = 0; i < n; i++) c[i] = s[i] < 0x80 && s[i] ? (char)s[i] : '?';
  c[n] = 0;
  j = json_string(c);
  free(c);
  return j ? j : json_null();
}

static json_t *mp_to_json(const hearth_mp_value *v) {
  switch (v->type) {
    case HEARTH_MP_NIL: return json_null();
    case HEARTH_MP_BOOL: return json_boolean(v->b);
    case HEARTH_MP_INT: return json_integer((json_int_t)v->i);
    case HEARTH_MP_UINT: return json_real((double)v->u);
    case HEARTH_MP_FLOAT: return isfinite(v->f) ? json_real(v->f) : json_null();
    case HEARTH_MP_STR: return json_text(v->data, v->len);
    case HEARTH_MP_BIN: {
      json_t *o = json_object();
      json_object_set_new(o, "__bin__", json_integer((json_int_t)v->len));
      return o;
    }
    case HEARTH_MP_EXT: {
      json_t *o = json_object();
      json_object_set_new(o, "__ext__", json_integer((json_int_t)v->i));
      json_object_set_new(o, "bytes", json_integer((json_int_t)v->len));
      return o;
    }
    case HEARTH_MP_ARRAY: {
      json_t *a = json_array();
      for (size_t i = 0; i < v->n; i++) json_array_append_new(a, mp_to_json(&v->items[i]));
      return a;
    }
    case HEARTH_MP_MAP: {
      /* a numpy array: dtype, shape and (up to 1024 numbers) its values */
      hearth_mp_ndarray nd;
      hearth_err ignore = {0};
      if (hearth_mp_map_get(v, "__ndarray__", HEARTH_MP_BIN) &&
          hearth_mp_ndarray_get(v, "metadata", &nd, &ignore) == HEARTH_OK) {
        json_t *o = json_object(), *shape = json_array();
        json_object_set_new(o, "__ndarray__", json_true());
        json_object_set_new(o, "dtype", json_string(nd.dtype));
        for (int d = 0; d < nd.ndim; d++)
          json_array_append_new(shape, json_integer((json_int_t)nd.shape[d]));
        json_object_set_new(o, "shape", shape);
        if (nd.count <= 1024) {
          json_t *data = json_array();
          for (size_t k = 0; k < nd.count; k++) {
            double x = hearth_mp_ndarray_at(&nd, k);
            json_array_append_new(data, !isfinite(x)     ? json_null()
                                        : nd.kind == 'f' ? json_real(x)
                                        : nd.kind == 'b' ? json_boolean(x != 0)
                                                         : json_integer((json_int_t)x));
          }
          json_object_set_new(o, "data", data);
        }
        return o;
      }
      json_t *o = json_object();
      for (size_t i = 0; i < v->n; i++) {
        const hearth_mp_value *k = &v->items[2 * i];
        json_t *key = k->type == HEARTH_MP_STR || k->type == HEARTH_MP_BIN
                          ? json_text(k->data, k->len)
                          : NULL;
        if (!key || !json_is_string(key)) {
          /* a non-string key (rare): its JSON text becomes the key */
          json_t *kj = mp_to_json(k);
          char *ks = json_dumps(kj, JSON_COMPACT | JSON_ENCODE_ANY);
          json_decref(kj);
          json_decref(key);
          key = json_string(ks ? ks : "?");
          free(ks);
        }
        json_object_set_new(o, json_string_value(key), mp_to_json(&v->items[2 * i + 1]));
        json_decref(key);
      }
      return o;
    }
  }
  return json_null();
}

/* what the metadata declares about the thermal view */
static void thermal_declaration(eval_ws_policy *p, const hearth_mp_value *root) {
  p->thermal_decl = -1;
  p->thermal_why[0] = 0;
  const hearth_mp_value *ht = hearth_mp_map_get(root, "hearth_thermal", HEARTH_MP_STR);
  const hearth_mp_value *ik = hearth_mp_map_get(root, "image_keys", HEARTH_MP_STR);
  int by_keys = -1;
  if (ik && ik->type == HEARTH_MP_ARRAY) {
    by_keys = 0;
    for (size_t i = 0; i < ik->n; i++)
      by_keys |= hearth_mp_str_eq(&ik->items[i], "observation/thermal_image");
  }
  /* a server that says it ignores the view, either way, ignores it */
  if (ht && ht->type == HEARTH_MP_BOOL && !ht->b) {
    p->thermal_decl = 0;
    snprintf(p->thermal_why, sizeof p->thermal_why, "\"hearth_thermal\": false");
  } else if (by_keys == 0) {
    p->thermal_decl = 0;
    snprintf(p->thermal_why, sizeof p->thermal_why,
             "\"image_keys\" without \"observation/thermal_image\"");
  } else if (ht && ht->type == HEARTH_MP_BOOL) {
    p->thermal_decl = 1;
    snprintf(p->thermal_why, sizeof p->thermal_why, "\"hearth_thermal\": true");
  } else if (by_keys == 1) {
    p->thermal_decl = 1;
    snprintf(p->thermal_why, sizeof p->thermal_why,
             "\"image_keys\" with \"observation/thermal_image\"");
  }
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
    st = hearth_err_set(
        err, HEARTH_E_PARSE,
        "policy server %s: expected the metadata as a binary message, got text \"%.200s\"", p->url,
        (const char *)m);
  hearth_mp_doc doc;
  if (!st) {
    hearth_mp_limits lim = {16, 100000, 16u << 20};
    st = hearth_mp_decode(m, n, &lim, &doc, err);
    if (st) hearth_err_prefix(err, "policy server %s: metadata: ", p->url);
    else {
      if (doc.root->type != HEARTH_MP_MAP) {
        st = hearth_err_set(err, HEARTH_E_PARSE, "policy server %s: metadata: expected a map",
                            p->url);
      } else {
        json_t *j = mp_to_json(doc.root);
        char *text =
            j ? json_dumps(j, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10)) : NULL;
        json_decref(j);
        if (!text) {
          st = hearth_err_set(err, HEARTH_E_NOMEM, "policy server %s: metadata: out of memory",
                              p->url);
        } else {
          free(p->metadata_json);
          p->metadata_json = text;
          thermal_declaration(p, doc.root);
        }
      }
      hearth_mp_doc_free(&doc);
    }
  }
  free(m);
  if (st) eval_ws_drop(p, 1002);
  return st;
}

/* one request: the observation -> a chunk of actions */
hearth_status eval_ws_query(eval_ws_policy *p, const hearth_sim_obs *ob, const char *prompt,
                            hearth_err *err) {
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
    if (hearth_ws_recv(p->c, &m2, &n2, &op2, 2.0, &tmp) != HEARTH_OK || 1)
      code = hearth_ws_close_code(p->c, NULL);
    free(m2);
    return hearth_err_set(err, HEARTH_E_IO, "policy server %s: server error (close code %d): %s",
                          p->url, code, text);
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
  if (!act)
    st = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                        "policy server %s: reply: expected a map with \"actions\"", p->url);
  else st = hearth_mp_ndarray_get(act, "reply.actions", &a, err);
  if (!st && (a.kind != 'f' || a.ndim != 2 || a.shape[1] != 7 || a.shape[0] < (size_t)p->replan)) {
    char shape[96] = "";
    for (int d = 0, used = 0; d < a.ndim && used < (int)sizeof shape - 24; d++)
      used +=
          snprintf(shape + used, sizeof shape - (size_t)used, "%s%zu", d ? ", " : "", a.shape[d]);
    char what[160];
    if (a.kind != 'f') snprintf(what, sizeof what, "dtype %s is not a float type", a.dtype);
    else if (a.ndim != 2) snprintf(what, sizeof what, "%d dimension(s), expected 2", a.ndim);
    else if (a.shape[1] != 7)
      snprintf(what, sizeof what, "width %zu, expected 7 (dx dy dz dax day daz grip)", a.shape[1]);
    else
      snprintf(what, sizeof what, "%zu action(s), fewer than the %d executed per chunk", a.shape[0],
               p->replan);
    st = hearth_err_set(
        err, HEARTH_E_SIZE,
        "policy server %s: reply.actions: expected float (H, 7) with H >= %d, got dtype %s shape (%s): %s",
        p->url, p->replan, a.dtype, shape, what);
  }
  if (!st) {
    static const char *const k_elem[7] = {"dx", "dy", "dz", "dax", "day", "daz", "grip"};
    p->nchunk = p->replan;
    p->next = 0;
    /* the first non-finite number, in chunk order, is the one reported */
    for (int t = 0; t < p->replan && !st; t++)
      for (int k = 0; k < 7 && !st; k++) {
        double v = hearth_mp_ndarray_at(&a, (size_t)t * 7 + k);
        if (!isfinite(v))
          st = hearth_err_set(
              err, HEARTH_E_RANGE,
              "policy server %s: reply.actions[%d][%d] is %s: action %d of the chunk, element %d (%s) "
              "of the action",
              p->url, t, k, isnan(v) ? "NaN" : "infinite", t, k, k_elem[k]);
        p->chunk[t][k] = v;
      }
  }
  hearth_mp_doc_free(&doc);
  free(m);
  return st;
}
