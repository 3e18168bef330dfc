/* hearth refine ROOT: automatic thermal-pose refinement plus manual nudges. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/poses.h"

static const char *k_about =
    "Refines each thermal view's 6-DoF pose, starting from the transferred pose\n"
    "(derived/poses_thermal_transferred.json): the metric mesh's projected silhouette\n"
    "is aligned with the thermal image's object/background edges (coarse-to-fine\n"
    "Gauss-Newton, robust weights). A refined pose replaces the start only if its\n"
    "criterion (mean truncated squared silhouette-to-edge distance) is better, the\n"
    "image has enough contrast and enough edges were found; otherwise the start is\n"
    "kept. Writes derived/poses_thermal.json (views of states not refined now are kept\n"
    "from the existing file) and derived/refine_report.json (per view: refined or\n"
    "kept and why, change in degrees and mm, criterion before/after, contrast,\n"
    "confidence, weakest-direction sigmas; no timings, so reruns are byte-identical).\n";

/* the --nudge options given, in order (malloc'ed) */
typedef struct nudge_list {
  hearth_pose_nudge *v;
  size_t n;
} nudge_list;

static int add_nudge(void *dst, const char *value, char *why, size_t whysz) {
  nudge_list *l = dst;
  hearth_pose_nudge *nn = realloc(l->v, (l->n + 1) * sizeof *nn);
  if (!nn) {
    snprintf(why, whysz, "out of memory");
    return 1;
  }
  l->v = nn;
  hearth_err err = {0};
  if (hearth_pose_nudge_parse(value, &l->v[l->n], &err)) {
    snprintf(why, whysz, "%s", err.msg);
    return 1;
  }
  l->n++;
  return 0;
}

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
  const char *instance = NULL, *nudge_file = NULL;
  hearth_refine_job job;
  hearth_refine_job_default(&job);
  nudge_list given = {NULL, 0};
  hearth_err err = {0};
  const cli_opt eval_opts[] = {
      CLI_PAIR("--perturb", "DEG,MM", &job.perturb_deg, &job.perturb_mm, 0, CLI_INF,
               "perturb every start pose by DEG degrees and MM millimetres in random directions "
               "(seeded) before refining"),
      CLI_U64("--seed", "N", &job.perturb_seed, "seed of --perturb"),
      CLI_STR("--truth", "FILE", &job.truth_path,
              "report the mean reprojection error of visible surface points against these "
              "poses, before and after"),
      CLI_END,
  };
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &instance, "only this instance", .def = "all in release.json"),
      CLI_STR("--state", "S", &job.state, "only this state", .def = "all states"),
      CLI_CALL("--nudge", "S/V:rx,ry,rz,tx,ty,tz", &given, add_nudge,
               "STATE/VIEW:rx,ry,rz,tx,ty,tz (degrees, mm)",
               "manual nudge of view V of state S in the thermal camera's frame (degrees, "
               "millimetres), applied after refinement; may be repeated"),
      CLI_STR("--nudges", "FILE", &nudge_file,
              "nudges from a JSON file: {\"views\": [{\"state\": \"hot\", \"view\": \"v03\", "
              "\"d_rot_deg\": [rx,ry,rz], \"d_t_mm\": [x,y,z]}]}"),
      CLI_FLAG("--no-auto", &job.no_auto, 1,
               "no automatic refinement: start poses plus nudges only"),
      CLI_STR("--start", "FILE", &job.start_path, "start poses",
              .def = "derived/poses_thermal_transferred.json"),
      CLI_STR("--out", "FILE", &job.out_path, "output poses", .def = "derived/poses_thermal.json"),
      CLI_STR("--mesh", "FILE", &job.mesh_path, "metric mesh", .def = "derived/mesh.glb"),
      CLI_STR("--rig", "FILE", &job.rig_path, "rig", .def = "calibration/rig.json"),
      CLI_NUM("--search", "PX", &job.opts.search_px, 1, 40, "first edge-search half window"),
      CLI_INT("--iterations", "N", &job.opts.iterations, 0, 200, "Gauss-Newton iterations"),
      CLI_NUM("--min-contrast", "C", &job.opts.min_contrast_c, 0, CLI_INF,
              "keep poses of views whose object/background contrast is below C degC"),
      CLI_INT("--threads", "N", &job.opts.threads, 1, 1024, "worker threads over views",
              .def = "all cores"),
      CLI_GROUP("evaluation (virtual-rig releases)", eval_opts, NULL),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth refine",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) {
    free(given.v);
    return rc;
  }
  const char *root = args.v[0];
  hearth_pose_nudge *nudges = given.v;
  size_t n_nudges = given.n;
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
