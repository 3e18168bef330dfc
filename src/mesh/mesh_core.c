/* Triangle mesh memory, bounds, transforms and validation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/mesh.h"

void hearth_mesh_free(hearth_mesh *m) {
  if (!m) return;
  free(m->positions);
  free(m->uvs);
  free(m->indices);
  /* the texture is a plain owned buffer; freed here so this file does not
   * depend on the image code */
  free(m->texture.data);
  memset(m, 0, sizeof *m);
}

hearth_status hearth_mesh_alloc(hearth_mesh *m, size_t n_vertices, size_t n_triangles, int with_uvs,
                                hearth_err *err) {
  memset(m, 0, sizeof *m);
  size_t nv3, nt3, nv2;
  if (!hearth_mul_size(n_vertices, 3, &nv3) || !hearth_mul_size(n_triangles, 3, &nt3) ||
      !hearth_mul_size(n_vertices, 2, &nv2))
    return hearth_err_set(err, HEARTH_E_NOMEM, "mesh of %zu vertices, %zu triangles: size overflow",
                          n_vertices, n_triangles);
  if (n_vertices > (size_t)UINT32_MAX)
    return hearth_err_set(err, HEARTH_E_LIMIT,
                          "mesh of %zu vertices: more than 32-bit indices can address", n_vertices);
  /* allocate at least one element so a zero-size mesh still has buffers */
  m->positions = hearth_alloc_array(nv3 ? nv3 : 1, sizeof(float));
  m->indices = hearth_alloc_array(nt3 ? nt3 : 1, sizeof(uint32_t));
  if (with_uvs) m->uvs = hearth_alloc_array(nv2 ? nv2 : 1, sizeof(float));
  if (!m->positions || !m->indices || (with_uvs && !m->uvs)) {
    hearth_mesh_free(m);
    return hearth_err_set(err, HEARTH_E_NOMEM,
                          "cannot allocate a mesh of %zu vertices and %zu triangles", n_vertices,
                          n_triangles);
  }
  m->n_vertices = n_vertices;
  m->n_triangles = n_triangles;
  return HEARTH_OK;
}

hearth_status hearth_mesh_copy(const hearth_mesh *src, hearth_mesh *dst, hearth_err *err) {
  hearth_mesh out;
  hearth_status s =
      hearth_mesh_alloc(&out, src->n_vertices, src->n_triangles, src->uvs != NULL, err);
  if (s != HEARTH_OK) {
    memset(dst, 0, sizeof *dst);
    return s;
  }
  if (src->n_vertices) memcpy(out.positions, src->positions, src->n_vertices * 3 * sizeof(float));
  if (src->uvs && src->n_vertices) memcpy(out.uvs, src->uvs, src->n_vertices * 2 * sizeof(float));
  if (src->n_triangles) memcpy(out.indices, src->indices, src->n_triangles * 3 * sizeof(uint32_t));
  out.texture = src->texture;
  out.texture.data = NULL;
  if (src->texture.data) {
    size_t bytes = 0;
    if (!hearth_mul_size(src->texture.width, src->texture.height, &bytes) ||
        !hearth_mul_size(bytes, (size_t)src->texture.channels, &bytes) ||
        !hearth_mul_size(bytes, (size_t)src->texture.type, &bytes)) {
      hearth_mesh_free(&out);
      memset(dst, 0, sizeof *dst);
      return hearth_err_set(err, HEARTH_E_NOMEM, "copying a %zux%zu texture: size overflow",
                            src->texture.width, src->texture.height);
    }
    out.texture.data = malloc(bytes ? bytes : 1);
    if (!out.texture.data) {
      hearth_mesh_free(&out);
      memset(dst, 0, sizeof *dst);
      return hearth_err_set(err, HEARTH_E_NOMEM, "cannot allocate a %zux%zu texture copy",
                            src->texture.width, src->texture.height);
    }
    memcpy(out.texture.data, src->texture.data, bytes);
  }
  *dst = out;
  return HEARTH_OK;
}

void hearth_mesh_bounds(const hearth_mesh *m, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; k++) {
    lo[k] = INFINITY;
    hi[k] = -INFINITY;
  }
  for (size_t i = 0; i < m->n_vertices; i++)
    for (int k = 0; k < 3; k++) {
      double p = m->positions[i * 3 + k];
      if (p < lo[k]) lo[k] = p;
      if (p > hi[k]) hi[k] = p;
    }
}

void hearth_mesh_transform(hearth_mesh *m, double s, const double R[9], const double t[3]) {
  for (size_t i = 0; i < m->n_vertices; i++) {
    float *p = m->positions + i * 3;
    double x = p[0], y = p[1], z = p[2];
    for (int k = 0; k < 3; k++)
      p[k] = (float)(s * (R[k * 3] * x + R[k * 3 + 1] * y + R[k * 3 + 2] * z) + t[k]);
  }
}

hearth_status hearth_mesh_validate(const hearth_mesh *m, const char *name, hearth_err *err) {
  if (!name) name = "mesh";
  if ((m->n_vertices && !m->positions) || (m->n_triangles && !m->indices))
    return hearth_err_set(err, HEARTH_E_ARG, "%s: missing position or index buffer", name);
  for (size_t i = 0; i < m->n_vertices; i++) {
    const float *p = m->positions + i * 3;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
      return hearth_err_set(err, HEARTH_E_RANGE,
                            "%s: vertex %zu: position (%g, %g, %g) is not finite", name, i,
                            (double)p[0], (double)p[1], (double)p[2]);
    if (m->uvs && (!isfinite(m->uvs[i * 2]) || !isfinite(m->uvs[i * 2 + 1])))
      return hearth_err_set(err, HEARTH_E_RANGE, "%s: vertex %zu: UV (%g, %g) is not finite", name,
                            i, (double)m->uvs[i * 2], (double)m->uvs[i * 2 + 1]);
  }
  for (size_t t = 0; t < m->n_triangles; t++)
    for (int k = 0; k < 3; k++) {
      uint32_t v = m->indices[t * 3 + k];
      if ((size_t)v >= m->n_vertices)
        return hearth_err_set(err, HEARTH_E_RANGE,
                              "%s: triangle %zu: corner %d index %u is out of range (expected < "
                              "%zu vertices)",
                              name, t, k, (unsigned)v, m->n_vertices);
    }
  return HEARTH_OK;
}

typedef struct weld_key {
  const float *p;
  uint32_t v;
} weld_key;

static int cmp_weld(const void *a, const void *b) {
  const weld_key *x = a, *y = b;
  for (int k = 0; k < 3; k++)
    if (x->p[k] != y->p[k]) return x->p[k] < y->p[k] ? -1 : 1;
  return (x->v > y->v) - (x->v < y->v);
}

hearth_status hearth_mesh_weld_ids(const hearth_mesh *m, uint32_t *id, hearth_err *err) {
  const size_t nv = m->n_vertices;
  if (nv > (size_t)UINT32_MAX)
    return hearth_err_set(err, HEARTH_E_LIMIT, "mesh of %zu vertices: too many to weld", nv);
  for (size_t i = 0; i < nv; i++) {
    const float *p = m->positions + 3 * i;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
      return hearth_err_set(err, HEARTH_E_RANGE, "mesh: vertex %zu: position is not finite", i);
  }
  weld_key *key = hearth_alloc_array(nv ? nv : 1, sizeof *key);
  if (!key) return hearth_err_set(err, HEARTH_E_NOMEM, "mesh: out of memory welding vertices");
  for (size_t i = 0; i < nv; i++) key[i] = (weld_key){m->positions + 3 * i, (uint32_t)i};
  qsort(key, nv, sizeof *key, cmp_weld);
  for (size_t i = 0, first = 0; i < nv; i++) {
    if (i && memcmp(key[i].p, key[i - 1].p, 3 * sizeof(float))) first = i;
    id[key[i].v] = (uint32_t)first;
  }
  free(key);
  return HEARTH_OK;
}
