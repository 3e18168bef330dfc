/* hearth scale ROOT: metric scale from rendered vs recorded depth. */
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/poses.h"

static const char *k_about =
    "Recovers the metric scale of the reconstruction: casts the recon mesh into every\n"
    "depth camera (colour pose from recon/poses_rgb.json, per-frame depth intrinsics and\n"
    "T_depth_from_rgb from raw/<state>/depth/vNN.json) and fits z_measured = s z_rendered\n"
    "robustly (depth holes, object edges, background and outliers excluded).\n"
    "Writes derived/scale.json (scale, residual statistics, views used), the metric\n"
    "derived/mesh.glb (RGB texture embedded) and derived/poses_rgb.json.\n";

static hearth_status scale_one(void *ctx, const char *instance, hearth_err *err) {
  hearth_scale_job *job = ctx;
  job->instance = instance;
  hearth_scale_result res;
  double t0 = hearth_now();
  hearth_status s = hearth_scale_run(job, &res, err);
  if (!s)
    printf(
        "scale %s: %.6f m/unit from %d views, %zu of %zu pixels inliers, residual median "
        "%.2f mm, p90 %.2f mm (%.2f s)\n",
        instance, res.scale, res.views_used, res.n_inliers, res.n_candidates,
        res.residual_median_mm, res.residual_p90_mm, hearth_now() - t0);
  return s;
}

int hearth_cmd_scale(int argc, char **argv) {
  const char *instance = NULL, *state = NULL;
  hearth_scale_job job = {0};
  hearth_scale_opts_default(&job.opts);
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &instance, "only this instance", .def = "all in release.json"),
      CLI_STR("--state", "S", &state, "use only this state's depth frames", .def = "all states"),
      CLI_INT("--stride", "K", &job.opts.pixel_stride, 1, 64, "cast every K-th depth pixel"),
      CLI_NUM("--edge-rel", "E", &job.opts.edge_rel, 0, CLI_INF,
              "relative depth jump that marks an edge", .flags = CLI_LO_OPEN),
      CLI_INT("--threads", "N", &job.opts.threads, 1, 1024, "worker threads", .def = "all cores"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth scale",
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
  job.state = state;
  return cli_each_instance("scale", root, instance, scale_one, &job);
}
