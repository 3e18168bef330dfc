/* Private to the virtual rig: procedural objects and their temperature
 * fields (synth_objects.c, synth_fields.c, described by the category table
 * of synth_categories.c), used by the renderer and the release writer
 * (synth_render.c, synth_release.c, ...).
 *
 * Object frame: metres, +z up along the turntable axis, the object resting
 * on z = 0 and centred on the axis. UVs in [0,1] (glTF: v down), grouped in
 * connected islands (one per part/surface patch, never one per triangle)
 * separated by gutters of at least 8 texels at 1024 x 1024. */
#ifndef HEARTH_SYNTH_OBJECT_H
#define HEARTH_SYNTH_OBJECT_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"
#include "hearth/image.h"
#include "hearth/mesh.h"

#define SYNTH_MAX_PARTS 16

typedef struct synth_object {
  char category[64];
  hearth_mesh mesh;      /* object frame; mesh.texture unused (see albedo) */
  uint8_t *part_of_tri;  /* n_triangles part ids, < n_parts */
  uint8_t *style_of_tri; /* n_triangles albedo styles (S_*, synth_category.h): the surface's
                            material; NULL for a given mesh (one plain material) */
  int n_parts;
  const char *part_names[SYNTH_MAX_PARTS]; /* static strings: "body", "handle", ... */
  hearth_image albedo;                     /* RGB U8 base colour texture in the mesh's UV layout */
  double height;                           /* max z */
  double radius;                           /* max distance from the z axis */
  /* for containers: height of the liquid line as a fraction of height (0 if none) */
  double fill_level;
} synth_object;

/* The procedural categories, in the order of their table (synth_category.h):
 * fills names[0..max-1], returns how many there are. */
size_t synth_object_categories(const char **names, size_t max);
/* The states a category is captured in by default: "neutral" first, then its
 * second state (cup: hot, canned_drink: iced, smartphone: warm, ...); 1 for
 * names outside the table. */
size_t synth_category_states(const char *category, const char **states, size_t max);

/* Make an instance: shape parameters (sizes in real-world ranges), colours
 * and texture detail drawn from seed. target_triangles sets tessellation
 * (the result is within +-25 % of it for targets 1k..400k). */
hearth_status synth_object_make(const char *category, uint64_t seed, size_t target_triangles,
                                size_t texture_size, synth_object *obj, hearth_err *err);
/* Wrap a given UV-mapped mesh (e.g. from a GLB): rescaled so its largest
 * extent is size_m, recentred on the axis, resting on z = 0; its texture
 * becomes the albedo (or a plain light grey if it has none); one part
 * "body". category picks the temperature behaviour. */
hearth_status synth_object_from_mesh(const hearth_mesh *m, double size_m, const char *category,
                                     size_t texture_size, synth_object *obj, hearth_err *err);
void synth_object_free(synth_object *obj);

/* A temperature field over an object's surface for one state. */
typedef struct synth_field {
  char state[32];
  double ambient_c;  /* room temperature of the capture */
  double params[32]; /* category/state parameters drawn from seed */
  uint64_t seed;
} synth_field;

/* neutral: ambient (about 22 degC) with small smooth variations; hot, warm,
 * iced, used: spatial structure that matters (hot cup: liquid line and
 * handle cooler than the body; iced can colder at the bottom; phone warm at
 * its battery; orange close to ambient ...). */
hearth_status synth_field_make(const synth_object *obj, const char *state, uint64_t seed,
                               double ambient_c, synth_field *f, hearth_err *err);
/* Apparent temperature (degC) at surface point p (object frame) of triangle
 * tri. Smooth within a part; deterministic; thread-safe. */
double synth_field_eval(const synth_field *f, const synth_object *obj, uint32_t tri,
                        const double p[3]);

#endif
