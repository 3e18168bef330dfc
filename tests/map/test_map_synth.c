/* Mapping accuracy against the virtual rig's ground truth, with true poses
 * (issue "temperature mapping" done-means): observed texels seen at least
 * 10 degrees away from grazing agree with temperature_true.npy. Hot, iced
 * and warm states of three categories; fills never cross UV islands. */
#include <stdio.h>
#include "map/map_eval.h"
#include "test_util.h"

int main(void) {
  const char *dir = test_tmpdir("map_synth");
  char root[1200];
  snprintf(root, sizeof root, "%s/release", dir);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.ideal = 1; /* closed-form: the clean rig */
  so.out_root = root;
  so.seed = 11;
  so.n_categories = 3;
  so.categories[0] = "cup";
  so.categories[1] = "canned_drink";
  so.categories[2] = "smartphone";
  so.n_views = 10;
  so.triangles = 4000;
  so.texture_size = 256;
  so.map_resolution = 256;
  so.calibration = 0;
  so.quiet = 1;
  so.rgb_full_size = 0; /* draft colour: these checks do not look at colour */
  hearth_err err = {0};
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  const char *inst[3] = {"cup_01", "canned_drink_01", "smartphone_01"};
  const char *hot[3] = {"hot", "iced", "warm"};
  char rig[1400], mesh[1400], poses[1400];
  snprintf(rig, sizeof rig, "%s/ground_truth/rig.json", root);
  for (int i = 0; i < 3; i++) {
    snprintf(mesh, sizeof mesh, "%s/ground_truth/instances/%s/mesh.glb", root, inst[i]);
    snprintf(poses, sizeof poses, "%s/ground_truth/instances/%s/poses_thermal.json", root, inst[i]);
    const char *states[2] = {"neutral", hot[i]};
    for (int s = 0; s < 2; s++)
      for (int f = 0; f < 3; f++) {
        /* max and robust fusion through the ray fan; max with traced rays
           (the fallback for views that do not have the whole mesh in front)
           must see the same surface */
        hearth_map_opts o;
        hearth_map_opts_default(&o);
        o.resolution = 256;
        o.fusion = f == 1 ? HEARTH_FUSE_ROBUST : HEARTH_FUSE_MAX;
        o.trace_rays = f == 2;
        map_eval ev;
        static map_eval fan_max;
        CHECK_OK(map_eval_state(root, inst[i], states[s], mesh, poses, rig, &o, &ev, &err), &err);
        printf("%-16s %-8s %-6s n=%6zu median=%.3f p95=%.3f max=%.2f coverage=%.3f filled=%zu\n",
               inst[i], states[s],
               f == 1 ? "robust"
               : f    ? "rays"
                      : "max",
               ev.n_eval, ev.median, ev.p95, ev.max_err, ev.coverage, ev.n_filled);
        if (f == 0) fan_max = ev;
        if (f == 2) {
          CHECK_MSG(fabs(ev.coverage - fan_max.coverage) <= 1e-3, "coverage: rays %.4f, fan %.4f",
                    ev.coverage, fan_max.coverage);
          CHECK_MSG(fabs(ev.median - fan_max.median) <= 2e-3 && fabs(ev.p95 - fan_max.p95) <= 2e-3,
                    "errors: rays %.4f/%.4f, fan %.4f/%.4f", ev.median, ev.p95, fan_max.median,
                    fan_max.p95);
        }
        CHECK(ev.n_eval > 1000);
        CHECK_MSG(ev.median <= 0.1, "%s/%s: median %.3f", inst[i], states[s], ev.median);
        CHECK_MSG(ev.p95 <= 0.5, "%s/%s %s: p95 %.3f > 0.5", inst[i], states[s],
                  f == 1 ? "robust" : "max", ev.p95);
        CHECK_MSG(ev.cross_island == 0, "%zu filled texels took a value from another island",
                  ev.cross_island);
      }
  }
  TEST_MAIN_END();
}
