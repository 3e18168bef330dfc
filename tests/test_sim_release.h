/* For tests that build simulation scenes: the smallest virtual-rig release
 * that still has every category and state the tasks H1-H3 use (two views per
 * state suffice for the up direction; the sim reads no raw colour frames).
 * Include after test_util.h. */
#ifndef HEARTH_TEST_SIM_RELEASE_H
#define HEARTH_TEST_SIM_RELEASE_H

#include "hearth/sim.h"
#include "hearth/synth.h"

/* The options of that release under <dir>/release, root in a static
 * buffer; a test that needs other categories, states or sizes changes
 * them before test_sim_release_make. */
static inline void test_sim_release_opts(const char *dir, hearth_synth_opts *so) {
  static char root[1200];
  snprintf(root, sizeof root, "%s/release", dir);
  hearth_synth_opts_default(so);
  so->ideal = 1; /* closed-form: the clean rig */
  so->out_root = root;
  static const char *cats[] = {"cup",    "canned_drink", "electric_kettle", "eraser",
                               "orange", "smartphone",   "sponge"};
  so->n_categories = 7;
  for (int i = 0; i < 7; i++) so->categories[i] = cats[i];
  so->n_states = 3;
  so->states[0] = "neutral", so->states[1] = "hot", so->states[2] = "iced";
  so->n_views = 2;
  so->triangles = 800;
  so->texture_size = 64;
  so->map_resolution = 32;
  so->calibration = 0;
  so->rgb_full_size = 0;
  so->quiet = 1;
}

/* Synthesise so's release (replacing what is at its root); returns the root. */
static inline const char *test_sim_release_make(const hearth_synth_opts *so) {
  hearth_remove_tree(so->out_root, NULL);
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(so, &err), &err);
  return so->out_root;
}

/* Make it under <dir>/release (replacing what is there); returns that root,
 * in a static buffer. */
static inline const char *test_sim_release(const char *dir) {
  hearth_synth_opts so;
  test_sim_release_opts(dir, &so);
  return test_sim_release_make(&so);
}

/* An environment of task t on the release at root, size x size views
 * without the wrist view, the given renderer and thermal mode. */
static inline hearth_sim_env *test_sim_env(hearth_sim_task t, const char *root, int size,
                                           const char *renderer, int thermal) {
  hearth_sim_opts o;
  hearth_sim_opts_default(&o);
  o.task = t;
  o.release_root = root;
  o.width = o.height = size;
  o.render_wrist = 0;
  o.renderer = renderer;
  o.thermal = thermal;
  hearth_sim_env *e = NULL;
  hearth_err err = {0};
  CHECK_OK(hearth_sim_env_new(&o, &e, &err), &err);
  return e;
}

#endif
