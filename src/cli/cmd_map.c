/* hearth map ROOT: temperature maps of every state (and the colour texture). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/map.h"

static const char *k_help =
    "usage: hearth map ROOT [--instance ID] [--state S] [options]\n"
    "\n"
    "Casts every thermal pixel's undistorted centre onto the metric mesh (nearest\n"
    "front-facing surface), splats its raw value bilinearly into the UV map, averages\n"
    "within a view, fuses across views, fills unobserved texels from the nearest\n"
    "observed texel of the same UV island, and writes derived/<state>/:\n"
    "temperature_observed.npy, temperature_filled.npy, mask.npy (0 no surface,\n"
    "1 observed, 2 filled, 3 unobserved), thermal_turbo.png (10..60 degC), provenance.json.\n"
    "\n"
    "  --instance ID      only this instance (default: all in release.json)\n"
    "  --state S          only this state (default: all states of the instance)\n"
    "  --resolution R     UV map size R x R (default 1024)\n"
    "  --fusion F         max (paper, default) | robust (silhouette pixels rejected,\n"
    "                     weighted median across views; for iced objects)\n"
    "  --min-cos C        ignore surface seen more obliquely than this cosine (default 0)\n"
    "  --keep-edges       also use pixels within 2 px of a depth discontinuity (the\n"
    "                     paper's literal rule; by default they are skipped because the\n"
    "                     lens blur mixes the two surfaces in them)\n"
    "  --views LIST       comma-separated view names to use (default: all)\n"
    "  --trace-rays       trace every pixel's ray (Embree) instead of rasterising views\n"
    "                     that have the whole mesh in front (the same hits up to float\n"
    "                     rounding; slower; for comparisons)\n"
    "  --mesh FILE        metric mesh instead of derived/mesh.glb\n"
    "  --poses FILE       thermal poses instead of derived/poses_thermal.json\n"
    "  --rig FILE         rig instead of calibration/rig.json\n"
    "  --rgb              also bake the colour texture from the colour views into\n"
    "                     derived/rgb_texture.png and derived/mesh.glb\n"
    "  --threads N        worker threads (default: all cores)\n";

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
  const char *root = NULL, *instance = NULL, *state = NULL;
  hearth_map_job job;
  hearth_map_job_default(&job);
  int rgb = 0;
  for (int i = 1; i < argc; i++) {
    const char *v;
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
    } else if ((r = cli_opt(argc, argv, &i, "--resolution", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 2, 16384, &lv)) goto bad;
      job.map.resolution = (size_t)lv;
    } else if ((r = cli_opt(argc, argv, &i, "--fusion", &v))) {
      if (r < 0) goto missing;
      if (!strcmp(v, "max")) job.map.fusion = HEARTH_FUSE_MAX;
      else if (!strcmp(v, "robust")) job.map.fusion = HEARTH_FUSE_ROBUST;
      else goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--min-cos", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &job.map.min_cos) || job.map.min_cos < 0 || job.map.min_cos >= 1) goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--views", &v))) {
      if (r < 0) goto missing;
      job.views = v;
    } else if ((r = cli_opt(argc, argv, &i, "--mesh", &v))) {
      if (r < 0) goto missing;
      job.mesh_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--poses", &v))) {
      if (r < 0) goto missing;
      job.poses_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--rig", &v))) {
      if (r < 0) goto missing;
      job.rig_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--threads", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 1024, &lv)) goto bad;
      job.map.threads = (int)lv;
    } else if (!strcmp(argv[i], "--keep-edges")) {
      job.map.keep_edges = 1;
    } else if (!strcmp(argv[i], "--trace-rays")) {
      job.map.trace_rays = 1;
    } else if (!strcmp(argv[i], "--rgb")) {
      rgb = 1;
    } else if (cli_root_arg("map", argv[i], &root, k_help)) {
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth map: option '%s' needs a value\n", argv[i]);
    return 2;
  bad:
    fprintf(stderr, "hearth map: bad value '%s' for option '%s'\n", v, argv[i - (argv[i][0] != '-')]);
    return 2;
  }
  if (!root) return cli_missing_root("map", k_help);
  job.root = root;
  int rc = 0;
  if (rgb) rc |= cli_each_instance("map", root, instance, bake_one, &job);
  rc |= cli_each_state("map", root, instance, state, map_one, &job);
  return rc;
}
