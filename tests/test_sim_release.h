/* For tests that build simulation scenes: the smallest virtual-rig release
 * that still has every category and state the tasks H1-H3 use (two views per
 * state suffice for the up direction; the sim reads no raw colour frames).
 * Include after test_util.h. */
#ifndef HEARTH_TEST_SIM_RELEASE_H
#define HEARTH_TEST_SIM_RELEASE_H

#include "hearth/synth.h"

/* Make it under <dir>/release (replacing what is there); returns that root,
 * in a static buffer. */
static const char *test_sim_release(const char *dir) {
  static char root[1200];
  snprintf(root, sizeof root, "%s/release", dir);
  hearth_remove_tree(root, NULL);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.ideal = 1; /* closed-form: the clean rig */
  so.out_root = root;
  static const char *cats[] = {"cup",    "canned_drink", "electric_kettle", "eraser",
                               "orange", "smartphone",   "sponge"};
  so.n_categories = 7;
  for (int i = 0; i < 7; i++) so.categories[i] = cats[i];
  so.n_states = 3;
  so.states[0] = "neutral", so.states[1] = "hot", so.states[2] = "iced";
  so.n_views = 2;
  so.triangles = 800;
  so.texture_size = 64;
  so.map_resolution = 32;
  so.calibration = 0;
  so.rgb_full_size = 0;
  so.quiet = 1;
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  return root;
}

#endif
