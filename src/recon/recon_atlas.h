/* recon_atlas.h - private to area recon: one chart of the UV atlas
 * (recon_atlas.c makes the charts, recon_atlas_flat.c flattens them,
 * recon_atlas_pack.c packs them). */
#ifndef HEARTH_RECON_ATLAS_H
#define HEARTH_RECON_ATLAS_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"
#include "hearth/mesh.h"

/* A flattened chart; owns its arrays. */
typedef struct atlas_chart {
  uint32_t *face; /* the mesh's triangles, n_faces */
  size_t n_faces;
  uint32_t *vertex; /* the mesh's vertex of each chart vertex, n_vertices */
  size_t n_vertices;
  uint32_t *corner; /* 3 per face: chart vertex of each corner */
  double *uv;       /* 2 per chart vertex: surface-length units until packed,
                        then the atlas's [0,1]^2 */
  double w, h;      /* extent after turning to its minimal box (surface units) */
  int cg_iterations;
} atlas_chart;
void ra_chart_free(atlas_chart *c);

/* Scratch reused from chart to chart (zeroed to start). */
typedef struct ra_flat_scratch {
  uint32_t *vmap;  /* per mesh vertex: its chart vertex, UINT32_MAX outside */
  uint32_t *fmark; /* per mesh face: stamp of the chart it is in */
  uint32_t stamp;
  size_t nv, nt;
} ra_flat_scratch;
void ra_flat_scratch_free(ra_flat_scratch *s);

/* When a flattening is good enough (L2 stretch over its own area). */
typedef struct ra_flat_limits {
  int cg_max;
  double max_chart_stretch, max_face_stretch;
} ra_flat_limits;

/* Flatten faces[0..n) of m (adj: the triangle across each edge, UINT32_MAX
 * where none) by LSCM into *out, scaled so its UV area equals its surface
 * area. Returns 0 with *out filled, 1 when the faces are no topological
 * disc or their flattening folds, overlaps itself or stretches more than
 * lim allows (nothing in *out), -1
 * without memory. A single face always flattens. */
int ra_chart_flatten(const hearth_mesh *m, const uint32_t *adj, const uint32_t *faces, size_t n,
                     const ra_flat_limits *lim, ra_flat_scratch *sc, atlas_chart *out);

/* Charts of at most RA_MERGE_FACES faces are merged into a neighbouring
 * chart of at most RA_MERGE_INTO faces where the two flatten as one. */
#define RA_MERGE_FACES 16
#define RA_MERGE_INTO 1024

/* The packing grid: texture_size cells a side, at most this many. */
#define RA_PACK_GRID_MAX 512
/* Bisection steps of the common scale after the first that fits (each
 * takes the root of the ratio between the largest scale that fitted and
 * the smallest that did not, from at most 2). */
#define RA_PACK_BISECTIONS 7

/* Turn each chart to its minimal-area box lying wide, then place the
 * charts (largest box first) on a grid of min(texture_size,
 * RA_PACK_GRID_MAX) cells a side: each where its cells, grown by the
 * gutter, meet no cell of a chart placed before and it reaches least far
 * down, as it lies or turned a quarter; at the largest common scale that
 * fits. Any two charts end at least gutter_texels texels (of
 * texture_size) apart, and as far from the border. Rewrites the charts'
 * UVs into [0,1]^2. HEARTH_E_LIMIT when the gutters alone do not fit. */
hearth_status ra_pack(atlas_chart *charts, size_t n, int texture_size, double gutter_texels,
                      hearth_err *err);

#endif
