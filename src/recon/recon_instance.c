/* Imported poses against an instance of a release: every pose must be a
 * colour view of one of the instance's states; views without a pose are
 * counted (the images the mapper did not register). */
#include <stdlib.h>
#include <string.h>

#include "hearth/recon.h"
#include "recon_internal.h"

hearth_status hearth_recon_match_instance(const char *root, const char *instance,
                                          const hearth_poses *p, hearth_recon_coverage *cov,
                                          hearth_err *err) {
  memset(cov, 0, sizeof *cov);
  if (!hearth_instance_id_valid(instance))
    return hearth_err_set(err, HEARTH_E_ARG, "'%s' is not an instance id (<category>_<NN>)",
                          instance);
  char path[4096];
  if (snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, instance) >=
      (int)sizeof path)
    return hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", root);
  hearth_instance_doc inst;
  hearth_status s = hearth_instance_read(path, &inst, err);
  if (s) return s;
  unsigned char *seen = calloc(p->n ? p->n : 1, 1);
  if (!seen) return hearth_err_set(err, HEARTH_E_NOMEM, "out of memory");
  for (size_t k = 0; k < inst.n_states && !s; k++) {
    if (snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, instance,
                 inst.states[k]) >= (int)sizeof path) {
      s = hearth_err_set(err, HEARTH_E_LIMIT, "%s: path too long", root);
      break;
    }
    hearth_manifest man;
    if ((s = hearth_manifest_read(path, &man, err))) break;
    for (size_t i = 0; i < man.n_views; i++) {
      cov->n_views++;
      const hearth_view_pose *v = hearth_poses_find(p, inst.states[k], man.views[i].view);
      if (v) {
        seen[v - p->views] = 1;
      } else {
        if (cov->n_missing < HEARTH_RECON_MISSING_LISTED)
          snprintf(cov->missing[cov->n_missing], sizeof cov->missing[0], "%s/%s", inst.states[k],
                   man.views[i].view);
        cov->n_missing++;
      }
    }
    hearth_manifest_free(&man);
  }
  for (size_t i = 0; i < p->n && !s; i++)
    if (!seen[i])
      s = hearth_err_set(err, HEARTH_E_INCONSISTENT,
                         "pose of state %s, view %s: %s has no such colour view (instance.json "
                         "states and raw/<state>/manifest.json)",
                         p->views[i].state, p->views[i].view, instance);
  free(seen);
  return s;
}

hearth_status recon_instance_inputs(const char *root, const char *instance,
                                    hearth_instance_doc *inst, const char **own,
                                    const char *const **states, size_t *n_states,
                                    hearth_factory_calib *fac, hearth_err *err) {
  char path[1400];
  snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, instance);
  hearth_status s = hearth_instance_read(path, inst, err);
  if (s) return s;
  if (!*states || !*n_states) {
    for (size_t i = 0; i < inst->n_states; i++) own[i] = inst->states[i];
    *states = own;
    *n_states = inst->n_states;
  }
  snprintf(path, sizeof path, "%s/calibration/factory.json", root);
  return hearth_factory_read(path, fac, err);
}
