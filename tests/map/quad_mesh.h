/* Test scenes on planes: meshes built from axis-aligned rectangles (two
 * triangles each), and views of the plane z = 0 rendered without the ray
 * caster. */
#ifndef HEARTH_TESTS_QUAD_MESH_H
#define HEARTH_TESTS_QUAD_MESH_H
#include "hearth/camera.h"
#include "hearth/geom.h"
#include "hearth/image.h"
#include "hearth/mesh.h"

/* Append the rectangle [x0, x1] x [y0, y1] at height z, facing +z (up) if
 * up else -z, with UVs over [u0, u1] x [v0, v1] (v0 at y1); *nv and *nt
 * count the vertices and triangles written so far. */
static inline void add_quad(hearth_mesh *m, size_t *nv, size_t *nt, double x0, double x1, double y0,
                            double y1, double z, int up, double u0, double u1, double v0,
                            double v1) {
  size_t b = *nv;
  double P[4][3] = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  double U[4][2] = {{u0, v1}, {u1, v1}, {u1, v0}, {u0, v0}};
  for (int i = 0; i < 4; i++) {
    for (int k = 0; k < 3; k++) m->positions[3 * (b + i) + k] = (float)P[i][k];
    m->uvs[2 * (b + i)] = (float)U[i][0];
    m->uvs[2 * (b + i) + 1] = (float)U[i][1];
  }
  uint32_t t[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (int j = 0; j < 2; j++) {
    uint32_t *ix = m->indices + 3 * (*nt + j);
    ix[0] = (uint32_t)b + t[j][0];
    ix[1] = (uint32_t)b + (up ? t[j][1] : t[j][2]);
    ix[2] = (uint32_t)b + (up ? t[j][2] : t[j][1]);
  }
  *nv += 4;
  *nt += 2;
}

/* A single-channel float view of the plane z = 0 rendered the simple way,
 * independent of the ray caster: the ray through each pixel centre of cam
 * (pose T, camera to world) meets the plane at (x, y), in front of the
 * camera when front; value(x, y, front, ctx) is that pixel's reading. */
static inline void render_plane_view(const hearth_camera *cam, const hearth_rigid *T,
                                     double (*value)(double x, double y, int front,
                                                     const void *ctx),
                                     const void *ctx, hearth_image *img) {
  hearth_err err;
  hearth_image_alloc(img, (size_t)cam->width, (size_t)cam->height, 1, HEARTH_PIX_F32, &err);
  float *px = img->data;
  for (int v = 0; v < cam->height; v++)
    for (int u = 0; u < cam->width; u++) {
      double d[3], w[3];
      hearth_camera_ray(cam, u, v, d);
      hearth_rigid_rotate(T, d, w);
      double t = -T->t[2] / w[2];
      px[(size_t)v * (size_t)cam->width + (size_t)u] =
          (float)value(T->t[0] + t * w[0], T->t[1] + t * w[1], t > 0, ctx);
    }
}

#endif
