/* hearth refine ROOT: automatic thermal-pose refinement plus manual nudges. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/poses.h"

static const char *k_help =
    "usage: hearth refine ROOT [--instance ID] [--state S] [options]\n"
    "\n"
    "Refines each thermal view's 6-DoF pose, starting from the transferred pose\n"
    "(derived/poses_thermal_transferred.json): the metric mesh's projected silhouette\n"
    "is aligned with the thermal image's object/background edges (coarse-to-fine\n"
    "Gauss-Newton, robust weights). A refined pose replaces the start only if its\n"
    "criterion (mean truncated squared silhouette-to-edge distance) is better, the\n"
    "image has enough contrast and enough edges were found; otherwise the start is\n"
    "kept. Writes derived/poses_thermal.json (views of states not refined now are kept\n"
    "from the existing file) and derived/refine_report.json (per view: refined or\n"
    "kept and why, change in degrees and mm, criterion before/after, contrast,\n"
    "confidence, weakest-direction sigmas; no timings, so reruns are byte-identical).\n"
    "\n"
    "  --instance ID       only this instance (default: all in release.json)\n"
    "  --state S           only this state (default: all states)\n"
    "  --nudge S/V:rx,ry,rz,tx,ty,tz\n"
    "                      manual nudge of view V of state S in the thermal camera's\n"
    "                      frame (degrees, millimetres), applied after refinement;\n"
    "                      may be repeated\n"
    "  --nudges FILE       nudges from a JSON file: {\"views\": [{\"state\": \"hot\",\n"
    "                      \"view\": \"v03\", \"d_rot_deg\": [rx,ry,rz], \"d_t_mm\": [x,y,z]}]}\n"
    "  --no-auto           no automatic refinement: start poses plus nudges only\n"
    "  --start FILE        start poses (default derived/poses_thermal_transferred.json)\n"
    "  --out FILE          output poses (default derived/poses_thermal.json)\n"
    "  --mesh FILE         metric mesh (default derived/mesh.glb)\n"
    "  --rig FILE          rig (default calibration/rig.json)\n"
    "  --search PX         first edge-search half window (default 14)\n"
    "  --iterations N      Gauss-Newton iterations (default 12)\n"
    "  --min-contrast C    keep poses of views whose object/background contrast is\n"
    "                      below C degC (default 1.5)\n"
    "  --threads N         worker threads over views (default: all cores)\n"
    "evaluation (virtual-rig releases):\n"
    "  --perturb DEG,MM    perturb every start pose by DEG degrees and MM millimetres\n"
    "                      in random directions (seeded) before refining\n"
    "  --seed N            seed of --perturb (default 1)\n"
    "  --truth FILE        report the mean reprojection error of visible surface\n"
    "                      points against these poses, before and after\n";

static hearth_status refine_one(void *ctx, const char *instance, hearth_err *err) {
  hearth_refine_job *job = ctx;
  job->instance = instance;
  hearth_refine_summary sum;
  double t0 = hearth_now();
  hearth_status s = hearth_refine_run(job, &sum, err);
  if (s) return s;
  printf("refine %s: %zu of %zu views refined, %.1f ms per view (%.2f s)\n", instance,
         sum.n_accepted, sum.n_views, 1e3 * sum.mean_seconds_per_view, hearth_now() - t0);
  if (job->truth_path)
    printf("refine %s: reprojection vs truth: start %.3f px, final %.3f px (worst view %.3f px)\n",
           instance, sum.reproj_start_px, sum.reproj_final_px, sum.reproj_final_max_px);
  return HEARTH_OK;
}

int hearth_cmd_refine(int argc, char **argv) {
  const char *root = NULL, *instance = NULL, *nudge_file = NULL;
  hearth_refine_job job;
  hearth_refine_job_default(&job);
  hearth_pose_nudge *nudges = NULL;
  size_t n_nudges = 0;
  int rc = 0;
  hearth_err err = {0};
  for (int i = 1; i < argc; i++) {
    const char *v = NULL;
    int r;
    long lv;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      free(nudges);
      return 0;
    } else if ((r = cli_opt(argc, argv, &i, "--instance", &v))) {
      if (r < 0) goto missing;
      instance = v;
    } else if ((r = cli_opt(argc, argv, &i, "--state", &v))) {
      if (r < 0) goto missing;
      job.state = v;
    } else if ((r = cli_opt(argc, argv, &i, "--nudges", &v))) {
      if (r < 0) goto missing;
      nudge_file = v;
    } else if ((r = cli_opt(argc, argv, &i, "--nudge", &v))) {
      if (r < 0) goto missing;
      hearth_pose_nudge *nn = realloc(nudges, (n_nudges + 1) * sizeof *nn);
      if (!nn) {
        free(nudges);
        return 1;
      }
      nudges = nn;
      if (hearth_pose_nudge_parse(v, &nudges[n_nudges], &err)) {
        fprintf(stderr, "hearth refine: %s\n", err.msg);
        free(nudges);
        return 2;
      }
      n_nudges++;
    } else if (!strcmp(argv[i], "--no-auto")) {
      job.no_auto = 1;
    } else if ((r = cli_opt(argc, argv, &i, "--start", &v))) {
      if (r < 0) goto missing;
      job.start_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--out", &v))) {
      if (r < 0) goto missing;
      job.out_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--mesh", &v))) {
      if (r < 0) goto missing;
      job.mesh_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--rig", &v))) {
      if (r < 0) goto missing;
      job.rig_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--truth", &v))) {
      if (r < 0) goto missing;
      job.truth_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--search", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &job.opts.search_px) || !(job.opts.search_px >= 1 && job.opts.search_px <= 40))
        goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--iterations", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 0, 200, &lv)) goto bad;
      job.opts.iterations = (int)lv;
    } else if ((r = cli_opt(argc, argv, &i, "--min-contrast", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &job.opts.min_contrast_c) || job.opts.min_contrast_c < 0) goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--threads", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 1024, &lv)) goto bad;
      job.opts.threads = (int)lv;
    } else if ((r = cli_opt(argc, argv, &i, "--seed", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_u64(v, &job.perturb_seed)) goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--perturb", &v))) {
      if (r < 0) goto missing;
      const char *comma = strchr(v, ',');
      if (!comma || hearth_parse_double(v, (size_t)(comma - v), 0, &job.perturb_deg) ||
          !cli_parse_num(comma + 1, &job.perturb_mm) || job.perturb_deg < 0 || job.perturb_mm < 0)
        goto bad;
    } else if (cli_root_arg("refine", argv[i], &root, k_help)) {
      free(nudges);
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth refine: option '%s' needs a value\n", argv[i]);
    free(nudges);
    return 2;
  bad:;
    char optbuf[64];
    fprintf(stderr, "hearth refine: bad value '%s' for option '%s'\n", v, cli_opt_name(argv, i, v, optbuf, sizeof optbuf));
    free(nudges);
    return 2;
  }
  if (!root) {
    free(nudges);
    return cli_missing_root("refine", k_help);
  }
  if (nudge_file) {
    hearth_pose_nudge *fn = NULL;
    size_t nf = 0;
    if (hearth_pose_nudges_read(nudge_file, &fn, &nf, &err)) {
      free(nudges);
      return cli_fail("refine", &err);
    }
    hearth_pose_nudge *nn = realloc(nudges, (n_nudges + nf + 1) * sizeof *nn);
    if (!nn) {
      free(fn);
      free(nudges);
      return 1;
    }
    nudges = nn;
    memcpy(nudges + n_nudges, fn, nf * sizeof *fn);
    n_nudges += nf;
    free(fn);
  }
  job.nudges = nudges;
  job.n_nudges = n_nudges;
  job.root = root;
  rc = cli_each_instance("refine", root, instance, refine_one, &job);
  free(nudges);
  return rc;
}
