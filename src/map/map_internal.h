/* Private to the map area: the mapping layout, made by map_layout.c and
 * read by the casting and fusion of map_core.c; the islands' boxes that
 * the fusion gathers for the fill of map_fill.c. */
#ifndef HEARTH_MAP_INTERNAL_H
#define HEARTH_MAP_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/map.h"

/* The part of a mapping fixed by the mesh, the camera, the resolution and
 * the pixel stride; read-only once made (map_layout.c). */
struct hearth_map_layout {
  const hearth_mesh *mesh;
  hearth_camera cam;
  size_t R, stride;
  uint32_t *island_of_tri;
  uint32_t *island_of_texel; /* R * R; UINT32_MAX off the surface */
  uint32_t n_islands;
  float *tri_normal;        /* 3 per triangle, unit */
  double sphere[4];         /* mesh bounding sphere: rays that miss it are not cast */
  size_t pw, ph, np;        /* pixel grid: every stride-th pixel */
  float *pix_dir;           /* 3 per grid pixel, camera frame, unit (0: never cast) */
  uint32_t *pix_index;      /* image pixel index of each grid pixel */
  uint32_t *tile_order;     /* grid pixels in 4x4 tiles: coherent packets of 16 */
  hearth_ray_fan *fan;      /* the pixel grid as a ray fan; NULL where it cannot hold it */
};

/* The islands' bounding boxes and counts, gathered by the fusion for the
 * fill: per worker a set of n_islands + 1 (merged in map_fill_islands). */
typedef struct island_box {
  int32_t x0, y0, x1, y1; /* inclusive; x1 < x0 for an island without texels */
  size_t n_todo;          /* surface texels to fill */
  uint8_t has_seed;       /* any observed texel */
} island_box;

/* For rows [y0, y1) of fused maps: the mask of the observed texels, the
 * filled map as far as observed (NaN elsewhere, for the fill to write),
 * and the islands' boxes grown by the rows' texels. */
void map_fill_prepare_rows(size_t R, size_t C, const uint32_t *island_of_texel, size_t y0, size_t y1,
                           hearth_map_result *out, island_box *box);
/* Fill every island that has observed texels and unobserved ones, from the
 * islands' boxes (nw sets of n_islands + 1); writes filled and marks mask
 * for filled texels. */
hearth_status map_fill_islands(size_t R, size_t C, const uint32_t *island_of_texel, uint32_t n_islands,
                               const island_box *parts, int nw, uint8_t *mask, const float *observed,
                               float *filled, int nthreads);

#endif
