/* A minimal release tree for the recon tests: instances/<id>/instance.json
 * and raw/<state>/manifest.json with views v00.. named in the usual layout
 * (rgb/vNN.jpg, cutout/vNN.png, ...); the image files are the caller's. */
#ifndef HEARTH_TEST_RECON_RELEASE_H
#define HEARTH_TEST_RECON_RELEASE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/dataset.h"
#include "test_util.h"

static inline void rr_write_instance(const char *root, const char *id, const char *category,
                                     size_t n_states, const char *const *states,
                                     const size_t *n_views) {
  hearth_err err = {0};
  char path[2048];
  hearth_instance_doc inst;
  memset(&inst, 0, sizeof inst);
  snprintf(inst.id, sizeof inst.id, "%s", id);
  snprintf(inst.category, sizeof inst.category, "%s", category);
  inst.n_states = n_states;
  for (size_t s = 0; s < n_states; s++) {
    snprintf(inst.states[s], HEARTH_NAME_MAX, "%s", states[s]);
    snprintf(path, sizeof path,
             "mkdir -p '%s/instances/%s/raw/%s/rgb' '%s/instances/%s/raw/%s/cutout'", root, id,
             states[s], root, id, states[s]);
    CHECK(system(path) == 0);
  }
  snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, id);
  CHECK_OK(hearth_instance_write(path, &inst, &err), &err);
  for (size_t s = 0; s < n_states; s++) {
    hearth_view_files *v = calloc(n_views[s], sizeof *v);
    for (size_t i = 0; v && i < n_views[s]; i++) {
      snprintf(v[i].view, sizeof v[i].view, "v%02zu", i);
      v[i].azimuth_index = (int)i;
      snprintf(v[i].rgb, sizeof v[i].rgb, "rgb/v%02zu.jpg", i);
      snprintf(v[i].cutout, sizeof v[i].cutout, "cutout/v%02zu.png", i);
      snprintf(v[i].depth, sizeof v[i].depth, "depth/v%02zu.png", i);
      snprintf(v[i].depth_intrinsics, sizeof v[i].depth_intrinsics, "depth/v%02zu.json", i);
      snprintf(v[i].thermal, sizeof v[i].thermal, "thermal/v%02zu.csv", i);
    }
    hearth_manifest man = {.n_views = n_views[s], .views = v};
    snprintf(man.instance, sizeof man.instance, "%s", id);
    snprintf(man.state, sizeof man.state, "%s", states[s]);
    snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, id, states[s]);
    CHECK_OK(hearth_manifest_write(path, &man, &err), &err);
    free(v);
  }
}

#endif
