/* hearth map ROOT: temperature maps of every state (and the colour texture). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/map.h"

static const char *k_about =
    "Casts every thermal pixel's undistorted centre onto the metric mesh (nearest\n"
    "front-facing surface), splats its raw value bilinearly into the UV map, averages\n"
    "within a view, fuses across views, fills unobserved texels from the nearest\n"
    "observed texel of the same UV island, and writes derived/<state>/:\n"
    "temperature_observed.npy, temperature_filled.npy, mask.npy (0 no surface,\n"
    "1 observed, 2 filled, 3 unobserved), thermal_turbo.png (10..60 degC), provenance.json.\n";

typedef struct map_ctx {
  hearth_map_job job;
  const char *root, *only_state;
  cli_names *states;
} map_ctx;

static void print_state(const char *instance, const char *state, const hearth_map_result *st,
                        double secs) {
  double n = st->n_surface ? (double)st->n_surface : 1.0;
  printf(
      "map %s/%s: %zu views, surface %zu texels: %.1f%% observed, %.1f%% filled, "
      "%.1f%% unobserved (%.2f s)\n",
      instance, state, st->n_views, st->n_surface, 100.0 * (double)st->n_observed / n,
      100.0 * (double)st->n_filled / n, 100.0 * (double)st->n_unobserved / n, secs);
}

static hearth_status map_one(void *vctx, const char *instance, const char *state, hearth_err *err) {
  map_ctx *c = vctx;
  c->job.instance = instance;
  c->job.state = state;
  hearth_map_result st;
  double t0 = hearth_now();
  hearth_status s = hearth_map_run(&c->job, &st, err);
  if (!s) print_state(instance, state, &st, hearth_now() - t0);
  return s;
}

/* --rgb: the bake and the instance's maps succeed or fail together, so a
 * failed command leaves no state re-mapped and no texture re-baked */
static hearth_status map_rgb_one(void *vctx, const char *instance, hearth_err *err) {
  map_ctx *c = vctx;
  hearth_status s = cli_states(c->root, instance, c->only_state, c->states, err);
  if (s) return s;
  const hearth_map_job *job = &c->job;
  hearth_bake_job bj = {job->root,     instance,         NULL, 1024, 2, job->mesh_path, NULL,
                        job->rig_path, job->map.threads, NULL, NULL};
  size_t n = c->states->n;
  const char **names = calloc(n ? n : 1, sizeof *names);
  hearth_map_result *st = calloc(n ? n : 1, sizeof *st);
  double *secs = calloc(n + 1, sizeof *secs);
  if (!names || !st || !secs) s = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  for (size_t k = 0; k < n && !s; k++) names[k] = c->states->names[k];
  hearth_map_job mj = c->job;
  mj.instance = instance;
  size_t peak_kib = 0;
  if (!s) s = hearth_map_bake_run(&mj, &bj, names, n, st, secs, &peak_kib, err);
  if (!s) {
    /* the process's peak so far: the bake's own for the first instance */
    printf("map %s: colour texture baked (%.2f s; peak memory so far %.1f MiB)\n", instance,
           secs[0], (double)peak_kib / 1024.0);
    for (size_t k = 0; k < n; k++) print_state(instance, names[k], &st[k], secs[k + 1]);
  }
  free(names);
  free(st);
  free(secs);
  return s;
}

int hearth_cmd_map(int argc, char **argv) {
  const char *instance = NULL, *state = NULL;
  map_ctx ctx;
  memset(&ctx, 0, sizeof ctx);
  hearth_map_job_default(&ctx.job);
  int rgb = 0, fusion = (int)ctx.job.map.fusion;
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &instance, "only this instance", .def = "all in release.json"),
      CLI_STR("--state", "S", &state, "only this state", .def = "all states of the instance"),
      CLI_SIZE("--resolution", "R", &ctx.job.map.resolution, 2, 16384, "UV map size R x R"),
      CLI_CHOICE("--fusion", &fusion, cli_fusion_names, cli_fusion_values,
                 "max: the paper's upper envelope of the per-view means; robust: silhouette "
                 "pixels rejected, weighted median across views (for iced objects); "
                 "corrected: robust near each texel's best angle, with emissivity fall-off "
                 "and cooling during the scan corrected (manifest time_s)"),
      CLI_NUM("--min-cos", "C", &ctx.job.map.min_cos, 0, 1,
              "ignore surface seen more obliquely than this cosine", .flags = CLI_HI_OPEN),
      CLI_FLAG("--keep-edges", &ctx.job.map.keep_edges, 1,
               "also use pixels within 2 px of a depth discontinuity (the paper's literal rule; "
               "by default they are skipped because the lens blur mixes the two surfaces in "
               "them)"),
      CLI_STR("--views", "LIST", &ctx.job.views, "comma-separated view names to use", .def = "all"),
      CLI_INT("--normal-passes", "N", &ctx.job.map.normal_passes, 0, 64,
              "viewing cosines from face normals averaged N times over their neighbours (a "
              "mesh fused from depth has noisy face normals; 0: the faces' own)",
              .def = "2 for hearth recon's fused mesh (recon/report.json), else 0"),
      CLI_NUM("--crease-deg", "DEG", &ctx.job.map.crease_deg, 0, 180,
              "also skip pixels within 1 px of a crease of more than DEG between face normals "
              "(the pixel mixes two surfaces; 0: none)",
              .def = "60 for hearth recon's fused mesh (recon/report.json), else 0"),
      CLI_FLAG("--trace-rays", &ctx.job.map.trace_rays, 1,
               "trace every pixel's ray (Embree) instead of rasterising views that have the "
               "whole mesh in front (the same hits up to float rounding; slower; for "
               "comparisons)"),
      CLI_STR("--mesh", "FILE", &ctx.job.mesh_path, "metric mesh instead of derived/mesh.glb"),
      CLI_STR("--poses", "FILE", &ctx.job.poses_path,
              "thermal poses instead of derived/poses_thermal.json"),
      CLI_STR("--rig", "FILE", &ctx.job.rig_path, "rig instead of calibration/rig.json"),
      CLI_FLAG("--rgb", &rgb, 1,
               "also bake the colour texture from the colour views into "
               "derived/rgb_texture.png and derived/mesh.glb"),
      CLI_INT("--threads", "N", &ctx.job.map.threads, 1, 1024, "worker threads",
              .def = "all cores"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth map",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  ctx.job.map.fusion = (hearth_fusion)fusion;
  ctx.job.root = root;
  if (!rgb) return cli_each_state("map", root, instance, state, map_one, &ctx);
  ctx.root = root;
  ctx.only_state = state;
  ctx.states = malloc(sizeof *ctx.states);
  if (!ctx.states) {
    fprintf(stderr, "hearth map: out of memory\n");
    return 1;
  }
  rc = cli_each_instance("map", root, instance, map_rgb_one, &ctx);
  free(ctx.states);
  return rc;
}
