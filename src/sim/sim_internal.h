/* private to the sim area: assets, the env struct and the renderer */
#ifndef HEARTH_SIM_INTERNAL_H
#define HEARTH_SIM_INTERNAL_H

#include <mujoco/mujoco.h>
#include "hearth/image.h"
#include "hearth/mesh.h"
#include "hearth/sim.h"

/* physical parameters per category */
typedef struct sim_category {
  const char *name;
  double mass, friction;
  double max_narrow; /* candidates: largest allowed narrow horizontal extent (gripper) */
  double max_extent; /* largest allowed extent of any axis */
} sim_category;
const sim_category *sim_category_find(const char *name);

/* one object: upright metric mesh (bottom centre at the origin, long
 * horizontal axis along x), its colour texture and a thermal Turbo texture */
typedef struct sim_asset {
  char instance[64], category[64], state[32];
  hearth_mesh mesh;     /* no texture inside */
  hearth_image rgb;     /* U8 RGB */
  hearth_image thermal; /* U8 RGB Turbo 10..60 degC */
  float *temp;          /* temp_R x temp_R degC per texel (NaN: no surface), rows as
                         * in thermal: the true map (ground truth), or NULL until
                         * sim_asset_temperatures reads the Turbo image back */
  size_t temp_R;
  char map_dir[4096]; /* derived assets: derived/<state>/ of the instance (the
                       * map's mask and observed and filled arrays); "" with
                       * ground truth */
  double size[3];     /* bounding box extents */
  double mass, friction;
} sim_asset;
void sim_asset_free(sim_asset *a);
/* Load <category>'s first instance of root in `state`. */
hearth_status sim_asset_load(const char *root, int use_gt, const char *category, const char *state,
                             sim_asset *a, hearth_err *err);
/* a->temp from the thermal texture read back through the Turbo scale
 * (0.1 degC steps) when the load kept no temperature map (derived assets) */
hearth_status sim_asset_temperatures(sim_asset *a, hearth_err *err);
/* A Turbo texture (10..60 degC) of the R x R map t: NaN texels (no
 * surface) take their valued neighbours' colour up to 4 texels away, the
 * room's beyond. */
hearth_status sim_temp_turbo(const float *t, size_t R, hearth_image *out, hearth_err *err);
/* Turbo colour of the room temperature (22 degC over 10..60). */
void sim_room_rgb(uint8_t rgb[3]);
#define SIM_ROOM_C 22.0
#define SIM_TLO 10.0
#define SIM_THI 60.0

#endif
