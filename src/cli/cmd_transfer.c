/* hearth transfer ROOT: thermal poses from colour poses via the rig. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/map.h"
#include "hearth/poses.h"

static const char *k_help =
    "usage: hearth transfer ROOT [--instance ID] [--rig FILE] [--poses FILE] [--keep-refined]\n"
    "\n"
    "Transfers every colour pose to the thermal camera through the calibrated rig:\n"
    "  T_world_from_th = T_world_from_rgb * inverse(T_thermal_from_rgb)\n"
    "Reads calibration/rig.json and instances/<id>/derived/poses_rgb.json; writes\n"
    "derived/poses_thermal_transferred.json and derived/poses_thermal.json.\n"
    "\n"
    "  --instance ID    only this instance (default: all in release.json)\n"
    "  --rig FILE       rig to use instead of calibration/rig.json\n"
    "  --poses FILE     colour poses instead of derived/poses_rgb.json (one instance)\n"
    "  --keep-refined   leave an existing derived/poses_thermal.json in place\n";

static hearth_status transfer_one(void *ctx, const char *instance, hearth_err *err) {
  hearth_transfer_job job = *(const hearth_transfer_job *)ctx;
  job.instance = instance;
  hearth_status s = hearth_transfer_run(&job, err);
  if (!s) printf("transfer %s: derived/poses_thermal_transferred.json written\n", instance);
  return s;
}

int hearth_cmd_transfer(int argc, char **argv) {
  const char *root = NULL, *instance = NULL, *rig = NULL, *poses = NULL;
  int keep = 0;
  for (int i = 1; i < argc; i++) {
    const char *v;
    int r;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if ((r = cli_opt(argc, argv, &i, "--instance", &v))) {
      if (r < 0) goto missing;
      instance = v;
    } else if ((r = cli_opt(argc, argv, &i, "--rig", &v))) {
      if (r < 0) goto missing;
      rig = v;
    } else if ((r = cli_opt(argc, argv, &i, "--poses", &v))) {
      if (r < 0) goto missing;
      poses = v;
    } else if (!strcmp(argv[i], "--keep-refined")) {
      keep = 1;
    } else if (cli_root_arg("transfer", argv[i], &root, k_help)) {
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth transfer: option '%s' needs a value\n", argv[i]);
    return 2;
  }
  if (!root) return cli_missing_root("transfer", k_help);
  hearth_transfer_job job = {root, NULL, rig, poses, keep};
  return cli_each_instance("transfer", root, instance, transfer_one, &job);
}
