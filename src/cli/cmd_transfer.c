/* hearth transfer ROOT: thermal poses from colour poses via the rig. */
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/map.h"
#include "hearth/poses.h"

static const char *k_about =
    "Transfers every colour pose to the thermal camera through the calibrated rig:\n"
    "  T_world_from_th = T_world_from_rgb * inverse(T_thermal_from_rgb)\n"
    "Reads calibration/rig.json and instances/<id>/derived/poses_rgb.json; writes\n"
    "derived/poses_thermal_transferred.json and derived/poses_thermal.json.\n";

static hearth_status transfer_one(void *ctx, const char *instance, hearth_err *err) {
  hearth_transfer_job job = *(const hearth_transfer_job *)ctx;
  job.instance = instance;
  hearth_status s = hearth_transfer_run(&job, err);
  if (!s) printf("transfer %s: derived/poses_thermal_transferred.json written\n", instance);
  return s;
}

int hearth_cmd_transfer(int argc, char **argv) {
  const char *instance = NULL, *rig = NULL, *poses = NULL;
  int keep = 0;
  const cli_opt opts[] = {
      CLI_STR("--instance", "ID", &instance, "only this instance", .def = "all in release.json"),
      CLI_STR("--rig", "FILE", &rig, "rig to use instead of calibration/rig.json"),
      CLI_STR("--poses", "FILE", &poses,
              "colour poses instead of derived/poses_rgb.json (one instance)"),
      CLI_FLAG("--keep-refined", &keep, 1, "leave an existing derived/poses_thermal.json in place"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth transfer",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  hearth_transfer_job job = {root, NULL, rig, poses, keep};
  return cli_each_instance("transfer", root, instance, transfer_one, &job);
}
