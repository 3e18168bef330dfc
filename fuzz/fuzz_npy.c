/* Fuzz target for the NPY reader: a success must describe exactly the bytes
 * it returned; a failure leaves nothing allocated. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/npy.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_npy a;
  hearth_err err = {0};
  hearth_status s = hearth_npy_parse(data, size, "fuzz.npy", &a, &err);
  if (s == HEARTH_OK) {
    if (a.ndim < 0 || a.ndim > 4 || !a.data) abort();
    size_t bytes = hearth_npy_count(&a) * (a.dtype == HEARTH_NPY_F32 ? 4 : 1);
    if (bytes > size || memcmp((const uint8_t *)data + size - bytes, a.data, bytes) != 0) abort();
  } else if (a.data || strncmp(err.msg, "fuzz.npy: ", 10) != 0) {
    abort();
  }
  hearth_npy_free(&a);
  return 0;
}
