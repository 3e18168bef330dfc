/* hearth_sim_render_scene: one layout's three views written as PNG. */
#include <stdio.h>
#include <string.h>

#include "sim/sim_env.h"

/* flip to top-row-first and write */
static hearth_status write_view(const char *path, const uint8_t *img, int w, int h,
                                hearth_err *err) {
  hearth_image im;
  hearth_status st = hearth_image_alloc(&im, (size_t)w, (size_t)h, 3, HEARTH_PIX_U8, err);
  if (st) return st;
  for (int y = 0; y < h; y++)
    memcpy((uint8_t *)im.data + (size_t)y * w * 3, img + (size_t)(h - 1 - y) * w * 3,
           (size_t)w * 3);
  st = hearth_png_write(path, &im, err);
  hearth_image_free(&im);
  return st;
}

hearth_status hearth_sim_render_scene(const hearth_sim_opts *o, uint64_t seed, const char *prefix,
                                      hearth_err *err) {
  hearth_sim_env *e = NULL;
  hearth_status st = hearth_sim_env_new(o, &e, err);
  if (st) return st;
  hearth_sim_obs ob;
  st = hearth_sim_reset(e, seed, 0, 0, err);
  if (!st) st = hearth_sim_observe(e, &ob, err);
  if (!st && !ob.agentview_rgb)
    st = hearth_err_set(err, HEARTH_E_ARG, "sim render: renderer none draws no images");
  char p[4200];
  if (!st) {
    snprintf(p, sizeof p, "%s_rgb.png", prefix);
    st = write_view(p, ob.agentview_rgb, ob.width, ob.height, err);
  }
  if (!st) {
    snprintf(p, sizeof p, "%s_thermal.png", prefix);
    st = write_view(p, ob.agentview_thermal, ob.width, ob.height, err);
  }
  if (!st && ob.eye_in_hand_rgb) {
    snprintf(p, sizeof p, "%s_wrist.png", prefix);
    st = write_view(p, ob.eye_in_hand_rgb, ob.width, ob.height, err);
  }
  hearth_sim_env_free(e);
  return st;
}
