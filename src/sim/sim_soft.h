/* private: hearth's software renderer of a MuJoCo scene (sim_soft.c).
 *
 * It draws the geoms of an mjModel at the poses of an mjData from one of
 * its cameras with a z-buffer, perspective-correct texture mapping
 * (bilinear, one mip level per triangle) and MuJoCo's fixed-function
 * lighting as its OpenGL renderer sets it up: the headlight and the
 * model's lights (directional or spot, attenuation), ambient + Lambert
 * diffuse + Blinn-Phong specular evaluated at the vertices (local viewer)
 * and interpolated, emission, GL_MODULATE texturing, no shadows, no
 * reflections. Geometry comes from the model: mesh vertices, normals and
 * texture coordinates, and MuJoCo's tessellation sizes for boxes,
 * spheres, cylinders and capsules.
 *
 * Deterministic: single-threaded per call, float arithmetic in a fixed
 * order (the file is compiled with -ffp-contract=off, so no fused
 * multiply-adds), no state outside the context: the same scene gives the
 * same bytes on any x86-64 or AArch64 machine, at any optimisation level
 * and whatever other threads do (on x86-64 the pixel loops also have AVX2
 * builds, picked by the CPU, that do the same operations per pixel). Images are RGB U8, bottom row first. */
#ifndef HEARTH_SIM_SOFT_H
#define HEARTH_SIM_SOFT_H

#include <mujoco/mujoco.h>
#include <stdint.h>

/* named in hearth_sim_renderer; raised when the images it makes change */
#define SIM_SOFT_VERSION "1"

typedef struct sim_soft sim_soft;

typedef enum sim_soft_mode {
  SIM_SOFT_LIT = 0,     /* lit, textured RGB */
  SIM_SOFT_UNLIT = 1,   /* every geom flat: the textured ones (tex_geom) show
                         * their texture's colours, the others flat_rgb */
  SIM_SOFT_SEGMENT = 2, /* geom ids only (ids_out) */
} sim_soft_mode;

typedef struct sim_soft_view {
  int cam; /* model camera id */
  sim_soft_mode mode;
  unsigned char groups[6];       /* geom groups drawn (mjNGROUP) */
  int only_geom;                 /* >= 0: draw just this geom */
  const unsigned char *tex_geom; /* UNLIT: ngeom flags, 1 = show its texture */
  uint8_t flat_rgb[3];           /* UNLIT, twin: the colour of every other geom */
  const int *twin_tex;           /* LIT with a twin image: ngeom texture ids, the
                             * texture geom g shows there unlit at its own
                             * texture coordinates (-1: flat_rgb) */
} sim_soft_view;

/* A context for w x h images of model m: the geoms' triangles in their own
 * frames, mip pyramids of the 2D textures, a depth buffer. NULL when out
 * of memory. It keeps no pointer into m. */
sim_soft *sim_soft_new(const mjModel *m, int w, int h);
void sim_soft_free(sim_soft *s);
/* Re-read 2D texture id from m->tex_rgb (same size as when the context was
 * made) and rebuild its mip levels: for textures the caller rewrites. */
void sim_soft_update_tex(sim_soft *s, const mjModel *m, int id);

/* Render view v of (m, d) into rgb (w*h*3; may be NULL in SEGMENT mode)
 * and, when ids is not NULL, the geom id of each pixel (-1: background).
 * In LIT mode a non-NULL twin (w*h*3) receives, from the same pass, the
 * unlit image of v->twin_tex: what an UNLIT render shows when geoms with
 * the same mesh and pose carry those textures (one geometry pass for the
 * front RGB and thermal views). */
void sim_soft_render(sim_soft *s, const mjModel *m, const mjData *d, const sim_soft_view *v,
                     uint8_t *rgb, uint8_t *twin, int *ids);

#endif
