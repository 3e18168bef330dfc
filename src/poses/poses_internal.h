/* Private helpers shared by scale recovery, pose refinement and overlays. */
#ifndef HEARTH_POSES_INTERNAL_H
#define HEARTH_POSES_INTERNAL_H

#include <stdarg.h>
#include <stdio.h>
#include "hearth/poses.h"

#define RF_PATH 4096

/* snprintf into a RF_PATH buffer; HEARTH_E_LIMIT if it does not fit */
static inline hearth_status rf_pathf(char *buf, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static inline hearth_status rf_pathf(char *buf, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(buf, RF_PATH, fmt, ap);
  va_end(ap);
  return (n < 0 || n >= RF_PATH) ? HEARTH_E_LIMIT : HEARTH_OK;
}

/* unit ray directions (camera frame) of every pixel centre, 3 floats per
 * pixel in raster order; NULL on allocation failure */
float *rf_pixel_rays(const hearth_camera *cam);

/* cast the mesh from a pose over the pixel box [x0,x1) x [y0,y1) (zoom
 * sub-pixels per pixel): depth[] along the ray (INFINITY where no surface),
 * tri[] the triangle (UINT32_MAX none). Arrays are (x1-x0)*zoom x (y1-y0)*zoom. */
hearth_status rf_cast_box(const hearth_raycaster *rc, const hearth_camera *cam,
                          const hearth_rigid *T_world_from_cam, int x0, int y0, int x1, int y1,
                          int zoom, float *depth, uint32_t *tri);

/* pixel box around the projection of the mesh (clamped to the image, with
 * margin); returns 0 if nothing projects */
int rf_mesh_box(const hearth_mesh *mesh, const hearth_camera *cam,
                const hearth_rigid *T_world_from_cam, int margin, int box[4]);

#endif
