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

/* 1 if the mesh is closed (vertices welded by exact position, every
 * directed edge once and its reverse once), so consistently oriented, and
 * faces outward (positive signed volume); 0 otherwise and when out of
 * memory. From a camera with every vertex in front of it, the nearest
 * surface of such a mesh along any ray is a front face. */
int rf_mesh_closed_outward(const hearth_mesh *m);

/* the k-th smallest of v[0..n) (0-based, n > 0; v is reordered so that
 * v[0..k) <= v[k] <= v(k..n)): quickselect, linear on average */
double rf_select(double *v, size_t n, size_t k);

/* the q-quantile of v[0..n) with linear interpolation between the order
 * statistics around q (n - 1) (0 for n == 0); v is reordered. Equal to
 * interpolating in the sorted array. */
double rf_quantile(double *v, size_t n, double q);

/* pixel box around the projection of the mesh (clamped to the image, with
 * margin); returns 0 if nothing projects */
int rf_mesh_box(const hearth_mesh *mesh, const hearth_camera *cam,
                const hearth_rigid *T_world_from_cam, int margin, int box[4]);

#endif
