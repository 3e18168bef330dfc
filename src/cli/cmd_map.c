/* hearth map ROOT: temperature maps of every state (and the colour texture). */
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/map.h"

static const char *k_about =
    "Casts every thermal pixel's undistorted centre onto the metric mesh (nearest\n"
    "front-facing surface), splats its raw value bilinearly into the UV map, averages\n"
    "within a view, fuses across views, fills unobserved texels from the nearest\n"
    "observed texel of the same UV island, and writes derived/<state>/:\n"
    "temperature_observed.npy, temperature_filled.npy, mask.npy (0 no surface,\n"
    "1 observed, 2 filled, 3 unobserved), thermal_turbo.png (10..60 degC), provenance.json.\n";

static hearth_status bake_one(void *ctx, const char *instance, hearth_err *err) {
  const hearth_map_job *job = ctx;
  hearth_bake_job bj = {job->root, instance, NULL, 1024, 2, job->mesh_path, NULL, job->rig_path,
                        job->map.threads};
  double t0 = hearth_now();
  hearth_status s = hearth_bake_rgb_run(&bj, err);
  if (!s) printf("map %s: colour texture baked (%.2f s)\n", instance, hearth_now() - t0);
  return s;
}

static hearth_status map_one(void *ctx, const char *instance, const char *state, hearth_err *err) {
  hearth_map_job *job = ctx;
  job->instance = instance;
  job->state = state;
  hearth_map_result st;
  double t0 = hearth_now();
  hearth_status s = hearth_map_run(job, &st, err);
  if (s) return s;
  double n = st.n_surface ? (double)st.n_surface : 1.0;
  printf("map %s/%s: %zu views, surface %zu texels: %.1f%% observed, %.1f%% filled, "
         "%.1f%% unobserved (%.2f s)\n",
         instance, state, st.n_views, st.n_surface, 100.0 * (double)st.n_observed / n,
         100.0 * (double)st.n_filled / n, 100.0 * (double)st.n_unobserved / n, hearth_now() - t0);
  return HEARTH_OK;
}

int hearth_cmd_map(int argc, char **argv) {
  const char *instance = NULL, *state = NULL;
  hearth_map_job job;
  hearth_map_job_default(&job);
  int rgb = 0, fusion = (int)job.map.fusion;
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &instance, "only this instance", .def = "all in release.json"),
      CLI_STR("--state", "S", &state, "only this state", .def = "all states of the instance"),
      CLI_SIZE("--resolution", "R", &job.map.resolution, 2, 16384, "UV map size R x R"),
      CLI_CHOICE("--fusion", &fusion, cli_fusion_names, cli_fusion_values,
                 "max: the paper's upper envelope of the per-view means; robust: silhouette "
                 "pixels rejected, weighted median across views (for iced objects)"),
      CLI_NUM("--min-cos", "C", &job.map.min_cos, 0, 1,
              "ignore surface seen more obliquely than this cosine", .flags = CLI_HI_OPEN),
      CLI_FLAG("--keep-edges", &job.map.keep_edges, 1,
               "also use pixels within 2 px of a depth discontinuity (the paper's literal rule; "
               "by default they are skipped because the lens blur mixes the two surfaces in "
               "them)"),
      CLI_STR("--views", "LIST", &job.views, "comma-separated view names to use", .def = "all"),
      CLI_FLAG("--trace-rays", &job.map.trace_rays, 1,
               "trace every pixel's ray (Embree) instead of rasterising views that have the "
               "whole mesh in front (the same hits up to float rounding; slower; for "
               "comparisons)"),
      CLI_STR("--mesh", "FILE", &job.mesh_path, "metric mesh instead of derived/mesh.glb"),
      CLI_STR("--poses", "FILE", &job.poses_path,
              "thermal poses instead of derived/poses_thermal.json"),
      CLI_STR("--rig", "FILE", &job.rig_path, "rig instead of calibration/rig.json"),
      CLI_FLAG("--rgb", &rgb, 1,
               "also bake the colour texture from the colour views into "
               "derived/rgb_texture.png and derived/mesh.glb"),
      CLI_INT("--threads", "N", &job.map.threads, 1, 1024, "worker threads", .def = "all cores"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth map", .args = "ROOT", .min_args = 1, .max_args = 1,
                           .about = k_about, .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  job.map.fusion = (hearth_fusion)fusion;
  job.root = root;
  rc = 0;
  if (rgb) rc |= cli_each_instance("map", root, instance, bake_one, &job);
  rc |= cli_each_state("map", root, instance, state, map_one, &job);
  return rc;
}
