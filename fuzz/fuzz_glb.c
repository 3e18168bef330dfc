/* Fuzz target: the GLB reader on arbitrary bytes, texture decoding on. */
#include <stdint.h>
#include <stdlib.h>
#include "hearth/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_mesh m;
  hearth_err err;
  /* a small triangle limit keeps hostile counts from allocating much */
  hearth_glb_read_opts opts = {0, 1, 1u << 20};
  if (hearth_glb_parse(data, size, "fuzz.glb", &opts, &m, &err) == HEARTH_OK) {
    /* a successful parse must give an index-valid mesh */
    for (size_t i = 0; i < 3 * m.n_triangles; i++)
      if (m.indices[i] >= m.n_vertices) abort();
    hearth_mesh_free(&m);
  }
  return 0;
}
