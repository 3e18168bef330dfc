/* The unit test cube shared by the mesh tests. */
#ifndef HEARTH_TESTS_CUBE_MESH_H
#define HEARTH_TESTS_CUBE_MESH_H
#include <stdint.h>
#include "hearth/mesh.h"
#include "test_util.h"

/* cube [-0.5, 0.5]^3, outward counter-clockwise faces; face f of 6 has
 * triangles 2f and 2f+1, faces ordered -x +x -y +y -z +z */
static inline void make_cube(hearth_mesh *m) {
  hearth_err err;
  CHECK_OK(hearth_mesh_alloc(m, 8, 12, 0, &err), &err);
  for (int i = 0; i < 8; i++) {
    m->positions[i * 3 + 0] = (i & 1) ? 0.5f : -0.5f;
    m->positions[i * 3 + 1] = (i & 2) ? 0.5f : -0.5f;
    m->positions[i * 3 + 2] = (i & 4) ? 0.5f : -0.5f;
  }
  /* quads listed counter-clockwise seen from outside */
  static const uint32_t quads[6][4] = {
      {0, 4, 6, 2}, /* -x */
      {1, 3, 7, 5}, /* +x */
      {0, 1, 5, 4}, /* -y */
      {2, 6, 7, 3}, /* +y */
      {0, 2, 3, 1}, /* -z */
      {4, 5, 7, 6}, /* +z */
  };
  for (int f = 0; f < 6; f++) {
    uint32_t *t = m->indices + f * 6;
    t[0] = quads[f][0];
    t[1] = quads[f][1];
    t[2] = quads[f][2];
    t[3] = quads[f][0];
    t[4] = quads[f][2];
    t[5] = quads[f][3];
  }
}

#endif
