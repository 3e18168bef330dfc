/* Pose transfer over a release tree: thermal poses from the colour poses
 * through the rig (see include/hearth/poses.h). */
#include <stdio.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/poses.h"
#include "poses/poses_internal.h"

hearth_status hearth_transfer_run(const hearth_transfer_job *job, hearth_err *err) {
  if (!job || !job->root || !job->instance)
    return hearth_err_set(err, HEARTH_E_ARG, "transfer: root and instance are required");
  char rig_path[RF_PATH], poses_path[RF_PATH], out1[RF_PATH], out2[RF_PATH];
  if (job->rig_path) snprintf(rig_path, RF_PATH, "%s", job->rig_path);
  else rf_pathf(rig_path, "%s/calibration/rig.json", job->root);
  if (job->poses_path) snprintf(poses_path, RF_PATH, "%s", job->poses_path);
  else rf_pathf(poses_path, "%s/instances/%s/derived/poses_rgb.json", job->root, job->instance);
  rf_pathf(out1, "%s/instances/%s/derived/poses_thermal_transferred.json", job->root,
           job->instance);
  rf_pathf(out2, "%s/instances/%s/derived/poses_thermal.json", job->root, job->instance);
  hearth_rig rig;
  hearth_status s = hearth_rig_read(rig_path, &rig, err);
  if (!s) s = hearth_rig_require_stereo(&rig, rig_path, "the thermal pose transfer", err);
  if (s) return s;
  hearth_poses poses = {0};
  if ((s = hearth_poses_read(poses_path, &poses, err))) return s;
  /* T_world_from_th = T_world_from_rgb * T_rgb_from_th */
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&rig.T_thermal_from_rgb, &T_rgb_from_th);
  for (size_t i = 0; i < poses.n; i++)
    hearth_rigid_compose(&poses.views[i].T_world_from_cam, &T_rgb_from_th,
                         &poses.views[i].T_world_from_cam);
  char dir[RF_PATH];
  rf_pathf(dir, "%s/instances/%s/derived", job->root, job->instance);
  if ((s = hearth_mkdirs(dir, err))) goto done;
  if ((s = hearth_poses_write(out1, &poses, err))) goto done;
  if (!(job->keep_refined && hearth_path_exists(out2))) s = hearth_poses_write(out2, &poses, err);
done:
  hearth_poses_free(&poses);
  return s;
}

void hearth_transfer_job_default(hearth_transfer_job *job) { memset(job, 0, sizeof *job); }
