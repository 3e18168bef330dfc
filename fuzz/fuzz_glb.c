/* Fuzz target: the GLB reader on arbitrary bytes, texture decoding on; once
 * as a read that does not need UVs and, when that gives UVs, once as a read
 * that requires them (the UV tile folding's refusals). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include "hearth/mesh.h"

/* a successful parse must give an index-valid mesh with finite UVs */
static void check_mesh(const hearth_mesh *m) {
  for (size_t i = 0; i < 3 * m->n_triangles; i++)
    if (m->indices[i] >= m->n_vertices) abort();
  for (size_t i = 0; m->uvs && i < 2 * m->n_vertices; i++)
    if (!isfinite(m->uvs[i])) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_mesh m;
  hearth_err err;
  hearth_glb_report rep;
  /* a small triangle limit keeps hostile counts from allocating much */
  hearth_glb_read_opts opts = {0, 1, 1u << 20, 0, &rep};
  if (hearth_glb_parse(data, size, "fuzz.glb", &opts, &m, &err) != HEARTH_OK) return 0;
  check_mesh(&m);
  int had_uvs = m.uvs != NULL;
  hearth_mesh_free(&m);
  if (!had_uvs) return 0;
  opts.require_uvs = 1;
  opts.load_texture = 0;
  if (hearth_glb_parse(data, size, "fuzz.glb", &opts, &m, &err) == HEARTH_OK) {
    /* everything was folded: no island left outside */
    if (rep.uv_islands_left) abort();
    check_mesh(&m);
    hearth_mesh_free(&m);
  }
  return 0;
}
