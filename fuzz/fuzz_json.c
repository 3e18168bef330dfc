/* Fuzz target for the JSON documents of a release: the same bytes go to
 * every parser (rig, factory, depth intrinsics, manifest, poses,
 * detections, scale, instance, release, and hearth validate's check of
 * recon/report.json). Parsers must fail cleanly, never
 * crash, leak or read out of bounds, and what they accept must keep the
 * invariants the readers promise. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/dataset.h"
#include "release/release_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  hearth_err err;

  hearth_rig rig;
  hearth_rig_parse(text, size, "fuzz", &rig, &err);
  hearth_factory_calib fac;
  hearth_factory_parse(text, size, "fuzz", &fac, &err);
  hearth_depth_intrinsics di;
  hearth_depth_intrinsics_parse(text, size, "fuzz", &di, &err);

  hearth_manifest m;
  if (hearth_manifest_parse(text, size, "fuzz", &m, &err) == HEARTH_OK) {
    /* accepted documents keep their invariants */
    if (m.n_views == 0 || !hearth_state_valid(m.state) || !hearth_instance_id_valid(m.instance))
      abort();
  }
  hearth_manifest_free(&m);

  hearth_poses p;
  if (hearth_poses_parse(text, size, "fuzz", &p, &err) == HEARTH_OK) {
    for (size_t i = 0; i < p.n; i++)
      if (!hearth_is_rotation(p.views[i].T_world_from_cam.R, 1e-6)) abort();
  }
  hearth_poses_free(&p);

  hearth_detections d;
  hearth_detections_parse(text, size, "fuzz", &d, &err);
  hearth_detections_free(&d);

  hearth_scale_doc sc;
  if (hearth_scale_doc_parse(text, size, "fuzz", &sc, &err) == HEARTH_OK && !(sc.scale > 0))
    abort();
  hearth_instance_doc in;
  hearth_instance_parse(text, size, "fuzz", &in, &err);
  hearth_release_doc rel;
  hearth_release_parse(text, size, "fuzz", &rel, &err);
  hearth_release_free(&rel);

  /* recon/report.json against a two-state instance with no files beside it:
   * every problem is a line, none may crash */
  static const char *const states[] = {"neutral", "hot"};
  hb_recon_expect x = {"cup_01", 2, states, NULL, -1, NULL, -1, -1, -1, -1};
  hearth_problems pr = {0};
  hb_recon_report_check(text, size, "fuzz", &x, &pr);
  for (size_t i = 0; i < pr.n; i++)
    if (!pr.items[i].what[0]) abort();
  hearth_problems_free(&pr);
  return 0;
}
