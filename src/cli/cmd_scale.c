/* hearth scale ROOT: metric scale from rendered vs recorded depth. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/poses.h"

static const char *k_help =
    "usage: hearth scale ROOT [--instance ID] [--state S] [options]\n"
    "\n"
    "Recovers the metric scale of the reconstruction: casts the recon mesh into every\n"
    "depth camera (colour pose from recon/poses_rgb.json, per-frame depth intrinsics and\n"
    "T_depth_from_rgb from raw/<state>/depth/vNN.json) and fits z_measured = s z_rendered\n"
    "robustly (depth holes, object edges, background and outliers excluded).\n"
    "Writes derived/scale.json (scale, residual statistics, views used), the metric\n"
    "derived/mesh.glb (RGB texture embedded) and derived/poses_rgb.json.\n"
    "\n"
    "  --instance ID      only this instance (default: all in release.json)\n"
    "  --state S          use only this state's depth frames (default: all states)\n"
    "  --stride K         cast every K-th depth pixel (default 2)\n"
    "  --edge-rel E       relative depth jump that marks an edge (default 0.02)\n"
    "  --threads N        worker threads (default: all cores)\n";

static hearth_status scale_one(void *ctx, const char *instance, hearth_err *err) {
  hearth_scale_job *job = ctx;
  job->instance = instance;
  hearth_scale_result res;
  double t0 = hearth_now();
  hearth_status s = hearth_scale_run(job, &res, err);
  if (!s)
    printf("scale %s: %.6f m/unit from %d views, %zu of %zu pixels inliers, residual median "
           "%.2f mm, p90 %.2f mm (%.2f s)\n",
           instance, res.scale, res.views_used, res.n_inliers, res.n_candidates,
           res.residual_median_mm, res.residual_p90_mm, hearth_now() - t0);
  return s;
}

int hearth_cmd_scale(int argc, char **argv) {
  const char *root = NULL, *instance = NULL, *state = NULL;
  hearth_scale_job job = {0};
  hearth_scale_opts_default(&job.opts);
  for (int i = 1; i < argc; i++) {
    const char *v = NULL;
    int r;
    long lv;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if ((r = cli_opt(argc, argv, &i, "--instance", &v))) {
      if (r < 0) goto missing;
      instance = v;
    } else if ((r = cli_opt(argc, argv, &i, "--state", &v))) {
      if (r < 0) goto missing;
      state = v;
    } else if ((r = cli_opt(argc, argv, &i, "--stride", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 64, &lv)) goto bad;
      job.opts.pixel_stride = (int)lv;
    } else if ((r = cli_opt(argc, argv, &i, "--edge-rel", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &job.opts.edge_rel) || !(job.opts.edge_rel > 0)) goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--threads", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 1024, &lv)) goto bad;
      job.opts.threads = (int)lv;
    } else if (cli_root_arg("scale", argv[i], &root, k_help)) {
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth scale: option '%s' needs a value\n", argv[i]);
    return 2;
  bad:;
    char optbuf[64];
    fprintf(stderr, "hearth scale: bad value '%s' for option '%s'\n", v, cli_opt_name(argv, i, v, optbuf, sizeof optbuf));
    return 2;
  }
  if (!root) return cli_missing_root("scale", k_help);
  job.root = root;
  job.state = state;
  return cli_each_instance("scale", root, instance, scale_one, &job);
}
