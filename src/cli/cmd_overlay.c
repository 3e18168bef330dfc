/* hearth overlay ROOT: mesh outline over the thermal images, before/after refinement. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/poses.h"

static const char *k_help =
    "usage: hearth overlay ROOT [--instance ID] [--state S] [options]\n"
    "\n"
    "Draws the projected outline of the metric mesh (silhouette and depth edges) on\n"
    "each Turbo-coloured thermal image so alignment can be checked at a glance:\n"
    "derived/overlay/<state>/vNN.png (zoomed; white = derived/poses_thermal.json,\n"
    "magenta = the transferred start poses) and derived/overlay/<state>/contact_sheet.png\n"
    "(every view, before on the left, after on the right).\n"
    "\n"
    "  --instance ID      only this instance (default: all in release.json)\n"
    "  --state S          only this state (default: all states)\n"
    "  --before FILE      poses drawn as 'before' (default derived/poses_thermal_transferred.json)\n"
    "  --after FILE       poses drawn as 'after' (default derived/poses_thermal.json)\n"
    "  --mesh FILE        metric mesh (default derived/mesh.glb)\n"
    "  --rig FILE         rig (default calibration/rig.json)\n"
    "  --zoom K           per-view image magnification (default 3)\n"
    "  --range LO,HI      Turbo range in degC (default: 2..98 % of each image)\n";

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
  const char *root = NULL, *instance = NULL, *state = NULL;
  hearth_overlay_job job = {0};
  job.zoom = 3;
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
    } else if ((r = cli_opt(argc, argv, &i, "--before", &v))) {
      if (r < 0) goto missing;
      job.before_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--after", &v))) {
      if (r < 0) goto missing;
      job.after_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--mesh", &v))) {
      if (r < 0) goto missing;
      job.mesh_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--rig", &v))) {
      if (r < 0) goto missing;
      job.rig_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--zoom", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 16, &lv)) goto bad;
      job.zoom = (int)lv;
    } else if ((r = cli_opt(argc, argv, &i, "--range", &v))) {
      if (r < 0) goto missing;
      const char *comma = strchr(v, ',');
      if (!comma || hearth_parse_double(v, (size_t)(comma - v), 0, &job.lo) ||
          !cli_parse_num(comma + 1, &job.hi) || !(job.lo < job.hi))
        goto bad;
    } else if (cli_root_arg("overlay", argv[i], &root, k_help)) {
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth overlay: option '%s' needs a value\n", argv[i]);
    return 2;
  bad:;
    char optbuf[64];
    fprintf(stderr, "hearth overlay: bad value '%s' for option '%s'\n", v, cli_opt_name(argv, i, v, optbuf, sizeof optbuf));
    return 2;
  }
  if (!root) return cli_missing_root("overlay", k_help);
  job.root = root;
  return cli_each_state("overlay", root, instance, state, overlay_one, &job);
}
