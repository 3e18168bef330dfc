/* Private to the map area: the mapping layout, made by map_layout.c and
 * read by the casting and fusion of map_core.c. */
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

#endif
