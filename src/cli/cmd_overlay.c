/* hearth overlay ROOT: mesh outline over the thermal images, before/after refinement. */
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/poses.h"

static const char *k_about =
    "Draws the projected outline of the metric mesh (silhouette and depth edges) on\n"
    "each Turbo-coloured thermal image so alignment can be checked at a glance:\n"
    "derived/overlay/<state>/vNN.png (zoomed; white = derived/poses_thermal.json,\n"
    "magenta = the transferred start poses) and derived/overlay/<state>/contact_sheet.png\n"
    "(every view, before on the left, after on the right).\n";

static hearth_status overlay_one(void *ctx, const char *instance, const char *state,
                                 hearth_err *err) {
  hearth_overlay_job *job = ctx;
  job->instance = instance;
  job->state = state;
  size_t n = 0;
  hearth_status s = hearth_overlay_run(job, &n, err);
  if (!s) printf("overlay %s/%s: %zu images in derived/overlay/%s/\n", instance, state, n, state);
  return s;
}

int hearth_cmd_overlay(int argc, char **argv) {
  const char *instance = NULL, *state = NULL;
  hearth_overlay_job job = {0};
  job.zoom = 3;
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &instance, "only this instance", .def = "all in release.json"),
      CLI_STR("--state", "S", &state, "only this state", .def = "all states"),
      CLI_STR("--before", "FILE", &job.before_path, "poses drawn as 'before'",
              .def = "derived/poses_thermal_transferred.json"),
      CLI_STR("--after", "FILE", &job.after_path, "poses drawn as 'after'",
              .def = "derived/poses_thermal.json"),
      CLI_STR("--mesh", "FILE", &job.mesh_path, "metric mesh", .def = "derived/mesh.glb"),
      CLI_STR("--rig", "FILE", &job.rig_path, "rig", .def = "calibration/rig.json"),
      CLI_INT("--zoom", "K", &job.zoom, 1, 16, "per-view image magnification"),
      CLI_PAIR("--range", "LO,HI", &job.lo, &job.hi, -CLI_INF, CLI_INF, "Turbo range in degC",
               .flags = CLI_ASCENDING, .def = "2..98 % of each image"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth overlay",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  job.root = root;
  return cli_each_state("overlay", root, instance, state, overlay_one, &job);
}
