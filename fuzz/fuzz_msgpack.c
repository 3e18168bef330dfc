/* fuzz the msgpack decoder and the ndarray view of its values (policy
 * server replies are untrusted input) */
#include <stdint.h>
#include <stdlib.h>

#include "hearth/msgpack.h"
#include "hearth/ws.h"

static void walk(const hearth_mp_value *v, int depth) {
  if (depth > 40) return;
  if (v->type == HEARTH_MP_MAP) {
    hearth_mp_ndarray a;
    if (hearth_mp_ndarray_get(v, "fuzz", &a, NULL) == HEARTH_OK && a.count)
      (void)hearth_mp_ndarray_at(&a, a.count - 1);
    (void)hearth_mp_map_get(v, "actions", HEARTH_MP_STR);
    for (size_t k = 0; k < 2 * v->n; k++) walk(&v->items[k], depth + 1);
  } else if (v->type == HEARTH_MP_ARRAY) {
    for (size_t k = 0; k < v->n; k++) walk(&v->items[k], depth + 1);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_mp_doc doc;
  hearth_mp_limits lim = {16, 100000, 1u << 20};
  if (hearth_mp_decode(data, size, &lim, &doc, NULL) == HEARTH_OK) {
    walk(doc.root, 0);
    hearth_mp_doc_free(&doc);
  }
  /* the same bytes as a websocket frame header from a server */
  hearth_ws_header h;
  size_t need;
  (void)hearth_ws_parse_header(data, size, 0, 1u << 20, &h, &need, NULL);
  return 0;
}
