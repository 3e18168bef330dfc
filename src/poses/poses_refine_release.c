/* hearth refine on a release tree: start poses, per-state refinement,
 * manual nudges, derived/poses_thermal.json and derived/refine_report.json. */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/thermal.h"
#include "poses/poses_internal.h"

void hearth_refine_job_default(hearth_refine_job *job) {
  memset(job, 0, sizeof *job);
  hearth_refine_opts_default(&job->opts);
  job->perturb_seed = 1;
}

/* {"views": [{"state", "view", "d_rot_deg": [3], "d_t_mm": [3]}]} */
hearth_status hearth_pose_nudges_read(const char *path, hearth_pose_nudge **out, size_t *n,
                                      hearth_err *err) {
  *out = NULL;
  *n = 0;
  uint8_t *data = NULL;
  size_t size = 0;
  hearth_status s = hearth_read_file(path, 16u << 20, &data, &size, err);
  if (s) return s;
  json_error_t je;
  json_t *root = json_loadb((const char *)data, size, JSON_REJECT_DUPLICATES, &je);
  free(data);
  if (!root)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: line %d, column %d: %s", path, je.line,
                          je.column, je.text);
  json_t *views = json_is_object(root) ? json_object_get(root, "views") : NULL;
  if (!json_is_array(views)) {
    json_decref(root);
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: views: expected an array of nudges", path);
  }
  size_t m = json_array_size(views);
  hearth_pose_nudge *a = calloc(m ? m : 1, sizeof *a);
  if (!a) {
    json_decref(root);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  }
  for (size_t i = 0; i < m; i++) {
    json_t *v = json_array_get(views, i);
    const char *keys[2] = {"state", "view"};
    char *dst[2] = {a[i].state, a[i].view};
    for (int k = 0; k < 2; k++) {
      json_t *sv = json_is_object(v) ? json_object_get(v, keys[k]) : NULL;
      if (!json_is_string(sv) || json_string_length(sv) == 0 || json_string_length(sv) >= 64) {
        s = hearth_err_set(err, HEARTH_E_PARSE, "%s: views[%zu].%s: expected a name", path, i,
                           keys[k]);
        goto fail;
      }
      snprintf(dst[k], 64, "%s", json_string_value(sv));
    }
    if (!hearth_state_valid(a[i].state)) {
      s = hearth_err_set(err, HEARTH_E_PARSE, "%s: views[%zu].state: '%s' is not a state", path, i,
                         a[i].state);
      goto fail;
    }
    const char *vk[2] = {"d_rot_deg", "d_t_mm"};
    double *vd[2] = {a[i].d_rot_deg, a[i].d_t_mm};
    for (int k = 0; k < 2; k++) {
      json_t *arr = json_object_get(v, vk[k]);
      if (!arr) continue; /* absent: no change of that kind */
      if (!json_is_array(arr) || json_array_size(arr) != 3) {
        s = hearth_err_set(err, HEARTH_E_PARSE, "%s: views[%zu].%s: expected 3 numbers", path, i,
                           vk[k]);
        goto fail;
      }
      for (size_t j = 0; j < 3; j++) {
        json_t *x = json_array_get(arr, j);
        if (!json_is_number(x)) {
          s = hearth_err_set(err, HEARTH_E_PARSE, "%s: views[%zu].%s[%zu]: expected a number", path,
                             i, vk[k], j);
          goto fail;
        }
        vd[k][j] = json_number_value(x);
      }
    }
  }
  json_decref(root);
  *out = a;
  *n = m;
  return HEARTH_OK;
fail:
  json_decref(root);
  free(a);
  return s;
}

/* a random rigid perturbation of exactly deg degrees and mm millimetres */
static void perturb(hearth_rigid *T, double deg, double mm, hearth_rng *r) {
  double a[3], b[3], la = 0, lb = 0;
  do {
    for (int k = 0; k < 3; k++) a[k] = hearth_rng_normal(r);
    la = hearth_norm3(a);
  } while (la < 1e-6);
  do {
    for (int k = 0; k < 3; k++) b[k] = hearth_rng_normal(r);
    lb = hearth_norm3(b);
  } while (lb < 1e-6);
  hearth_pose_nudge n;
  for (int k = 0; k < 3; k++) {
    n.d_rot_deg[k] = deg * a[k] / la;
    n.d_t_mm[k] = mm * b[k] / lb;
  }
  hearth_pose_nudge_apply(&n, T);
}

static json_t *view_json(const char *state, const char *view, const hearth_refine_view_result *r,
                         int auto_ran, const hearth_pose_nudge *nudge, double reproj0,
                         double reproj1) {
  json_t *o = json_object();
  json_object_set_new(o, "state", json_string(state));
  json_object_set_new(o, "view", json_string(view));
  if (auto_ran) {
    json_object_set_new(o, "refined", json_boolean(r->accepted));
    json_object_set_new(o, "reason", json_string(r->reason));
    json_object_set_new(o, "d_rot_deg", json_real(r->d_rot_deg));
    json_object_set_new(o, "d_t_mm", json_real(r->d_t_mm));
    json_object_set_new(o, "cost_start_px2",
                        json_real(isfinite(r->cost_start) ? r->cost_start : -1));
    json_object_set_new(o, "cost_final_px2",
                        json_real(isfinite(r->cost_final) ? r->cost_final : -1));
    json_object_set_new(o, "contrast_c", json_real(r->contrast_c));
    json_object_set_new(o, "confidence", json_real(r->confidence));
    json_object_set_new(o, "sigma_rot_deg", json_real(r->sigma_rot_deg));
    json_object_set_new(o, "sigma_t_mm", json_real(r->sigma_t_mm));
    json_object_set_new(o, "silhouette_samples", json_integer((json_int_t)r->n_samples));
    json_object_set_new(o, "edge_inliers", json_integer((json_int_t)r->n_inliers));
    /* no wall-clock time here: the report must be the same bytes on every run */
  }
  if (nudge) {
    json_t *a = json_array(), *b = json_array();
    for (int k = 0; k < 3; k++) {
      json_array_append_new(a, json_real(nudge->d_rot_deg[k]));
      json_array_append_new(b, json_real(nudge->d_t_mm[k]));
    }
    json_t *nj = json_object();
    json_object_set_new(nj, "d_rot_deg", a);
    json_object_set_new(nj, "d_t_mm", b);
    json_object_set_new(o, "nudge", nj);
  }
  if (reproj0 >= 0) {
    json_object_set_new(o, "reproj_vs_truth_start_px", json_real(reproj0));
    json_object_set_new(o, "reproj_vs_truth_final_px", json_real(reproj1));
  }
  return o;
}

hearth_status hearth_refine_run(const hearth_refine_job *job, hearth_refine_summary *sum,
                                hearth_err *err) {
  if (!job || !job->root || !job->instance)
    return hearth_err_set(err, HEARTH_E_ARG, "refine: root and instance are required");
  const char *root = job->root, *inst = job->instance;
  char rig_path[RF_PATH], mesh_path[RF_PATH], start_path[RF_PATH], out_path[RF_PATH],
      rep_path[RF_PATH], path[RF_PATH];
  if (job->rig_path) snprintf(rig_path, RF_PATH, "%s", job->rig_path);
  else rf_pathf(rig_path, "%s/calibration/rig.json", root);
  if (job->mesh_path) snprintf(mesh_path, RF_PATH, "%s", job->mesh_path);
  else rf_pathf(mesh_path, "%s/instances/%s/derived/mesh.glb", root, inst);
  if (job->start_path) snprintf(start_path, RF_PATH, "%s", job->start_path);
  else rf_pathf(start_path, "%s/instances/%s/derived/poses_thermal_transferred.json", root, inst);
  if (job->out_path) snprintf(out_path, RF_PATH, "%s", job->out_path);
  else rf_pathf(out_path, "%s/instances/%s/derived/poses_thermal.json", root, inst);
  if (job->report_path) snprintf(rep_path, RF_PATH, "%s", job->report_path);
  else rf_pathf(rep_path, "%s/instances/%s/derived/refine_report.json", root, inst);

  hearth_refine_summary S;
  memset(&S, 0, sizeof S);
  hearth_rig rig;
  hearth_poses start = {0}, prev = {0}, truth = {0}, outp = {0};
  hearth_mesh mesh = {0};
  hearth_raycaster *rc = NULL;
  hearth_instance_doc idoc;
  hearth_manifest man = {0};
  hearth_image *imgs = NULL;
  hearth_map_view *views = NULL;
  hearth_refine_view_result *res = NULL;
  json_t *report = json_array();
  uint8_t *done_flag = NULL;
  double rsum0 = 0, rsum1 = 0, tsum = 0;
  size_t rn = 0;
  hearth_status s;
  if ((s = hearth_rig_read(rig_path, &rig, err)) ||
      (s = hearth_rig_require_stereo(&rig, rig_path, "pose refinement", err)))
    goto done;
  if ((s = hearth_poses_read(start_path, &start, err))) goto done;
  if (hearth_path_exists(out_path) && (s = hearth_poses_read(out_path, &prev, err))) goto done;
  if (job->truth_path && (s = hearth_poses_read(job->truth_path, &truth, err))) goto done;
  hearth_glb_read_opts gopts = {0};
  if ((s = hearth_glb_read(mesh_path, &gopts, &mesh, err))) goto done;
  if ((s = hearth_raycaster_new(&mesh, &rc, err))) goto done;
  rf_pathf(path, "%s/instances/%s/instance.json", root, inst);
  if ((s = hearth_instance_read(path, &idoc, err))) goto done;
  /* every nudge must name a view of the start poses */
  for (size_t k = 0; k < job->n_nudges; k++)
    if (!hearth_poses_find(&start, job->nudges[k].state, job->nudges[k].view)) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "nudge %s/%s: no such view in %s",
                         job->nudges[k].state, job->nudges[k].view, start_path);
      goto done;
    }
  /* the output starts as: existing refined poses where present, else start */
  outp.n = start.n;
  outp.views = calloc(start.n ? start.n : 1, sizeof *outp.views);
  done_flag = calloc(start.n ? start.n : 1, 1);
  if (!outp.views || !done_flag) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "refine: out of memory");
    goto done;
  }
  for (size_t i = 0; i < start.n; i++) {
    outp.views[i] = start.views[i];
    const hearth_view_pose *pp =
        hearth_poses_find(&prev, start.views[i].state, start.views[i].view);
    if (pp) outp.views[i].T_world_from_cam = pp->T_world_from_cam;
  }
  hearth_rng rng;
  hearth_rng_seed(&rng, job->perturb_seed);
  int any_state = 0;
  for (size_t si = 0; si < idoc.n_states; si++) {
    const char *state = idoc.states[si];
    if (job->state && strcmp(job->state, state)) continue;
    any_state = 1;
    rf_pathf(path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
    hearth_manifest_free(&man);
    if ((s = hearth_manifest_read(path, &man, err))) goto done;
    size_t nv = man.n_views;
    imgs = calloc(nv ? nv : 1, sizeof *imgs);
    views = calloc(nv ? nv : 1, sizeof *views);
    res = calloc(nv ? nv : 1, sizeof *res);
    size_t *slot = calloc(nv ? nv : 1, sizeof *slot);
    if (!imgs || !views || !res || !slot) {
      free(slot);
      s = hearth_err_set(err, HEARTH_E_NOMEM, "refine: out of memory");
      goto done;
    }
    hearth_csv_opts copts = {(size_t)rig.thermal.width, (size_t)rig.thermal.height};
    for (size_t k = 0; k < nv; k++) {
      const hearth_view_files *vf = &man.views[k];
      const hearth_view_pose *vp = hearth_poses_find(&start, state, vf->view);
      if (!vp) {
        free(slot);
        s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no pose for state '%s' view '%s'",
                           start_path, state, vf->view);
        goto done;
      }
      slot[k] = (size_t)(vp - start.views);
      rf_pathf(path, "%s/instances/%s/raw/%s/%s", root, inst, state, vf->thermal);
      if ((s = hearth_thermal_read_csv_camera(path, copts.width, copts.height, rig_path, &imgs[k],
                                              err))) {
        free(slot);
        goto done;
      }
      views[k].image = &imgs[k];
      views[k].T_world_from_cam = vp->T_world_from_cam;
      if (job->perturb_deg > 0 || job->perturb_mm > 0) {
        /* one stream per (state, view): independent of thread count and order */
        hearth_rng r;
        hearth_rng_fork(&rng, (uint64_t)si * 4096u + k, &r);
        perturb(&views[k].T_world_from_cam, job->perturb_deg, job->perturb_mm, &r);
      }
    }
    if (!job->no_auto) {
      if ((s = hearth_refine_views(&mesh, rc, &rig.thermal, views, nv, &job->opts, res, err))) {
        free(slot);
        hearth_err_prefix(err, "%s/%s", inst, state);
        goto done;
      }
    } else {
      for (size_t k = 0; k < nv; k++) res[k].T_world_from_cam = views[k].T_world_from_cam;
    }
    for (size_t k = 0; k < nv; k++) {
      hearth_rigid T = res[k].T_world_from_cam;
      const hearth_pose_nudge *nudge = NULL;
      for (size_t j = 0; j < job->n_nudges; j++)
        if (!strcmp(job->nudges[j].state, state) &&
            !strcmp(job->nudges[j].view, man.views[k].view)) {
          hearth_pose_nudge_apply(&job->nudges[j], &T);
          nudge = &job->nudges[j];
        }
      outp.views[slot[k]].T_world_from_cam = T;
      done_flag[slot[k]] = 1;
      double e0 = -1, e1 = -1;
      const hearth_view_pose *tp =
          truth.n ? hearth_poses_find(&truth, state, man.views[k].view) : NULL;
      if (tp) {
        hearth_err e2;
        if (!hearth_reprojection_error(rc, &rig.thermal, &tp->T_world_from_cam,
                                       &views[k].T_world_from_cam, 2, &e0, &e2) &&
            !hearth_reprojection_error(rc, &rig.thermal, &tp->T_world_from_cam, &T, 2, &e1, &e2)) {
          rsum0 += e0;
          rsum1 += e1;
          rn++;
          if (e1 > S.reproj_final_max_px) S.reproj_final_max_px = e1;
        } else {
          e0 = e1 = -1;
        }
      }
      json_array_append_new(report, view_json(state, man.views[k].view, &res[k], !job->no_auto,
                                              nudge, e0, e1));
      S.n_views++;
      S.n_accepted += res[k].accepted ? 1 : 0;
      tsum += res[k].seconds;
    }
    free(slot);
    for (size_t k = 0; k < nv; k++) hearth_image_free(&imgs[k]);
    free(imgs);
    free(views);
    free(res);
    imgs = NULL;
    views = NULL;
    res = NULL;
  }
  if (!any_state) {
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s/instances/%s/instance.json: no state '%s'",
                       root, inst, job->state ? job->state : "");
    goto done;
  }
  /* the outputs' folders (derived/ need not exist yet with --start/--mesh elsewhere) */
  {
    const char *outs[2] = {out_path, rep_path};
    for (int k = 0; k < 2; k++) {
      snprintf(path, RF_PATH, "%s", outs[k]);
      char *slash = strrchr(path, '/');
      if (slash && slash != path) {
        *slash = 0;
        if ((s = hearth_mkdirs(path, err))) goto done;
      }
    }
  }
  if ((s = hearth_poses_write(out_path, &outp, err))) goto done;
  {
    json_t *doc = json_object();
    json_object_set_new(doc, "instance", json_string(inst));
    json_object_set_new(doc, "start", json_string(hearth_path_under(root, start_path)));
    json_object_set_new(doc, "criterion",
                        json_string(
                            "mean over silhouette samples of min(d, 1.5 px)^2, d = distance "
                            "to the strongest thermal edge within 3 px along the normal"));
    json_object_set_new(doc, "views", report);
    report = NULL;
    char *text = json_dumps(doc, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    json_decref(doc);
    if (!text) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: cannot encode", rep_path);
      goto done;
    }
    s = hearth_write_file_atomic(rep_path, text, strlen(text), err);
    free(text);
  }
  S.mean_seconds_per_view = S.n_views ? tsum / (double)S.n_views : 0;
  if (rn) {
    S.reproj_start_px = rsum0 / (double)rn;
    S.reproj_final_px = rsum1 / (double)rn;
  }
  if (sum) *sum = S;
done:
  free(outp.views);
  if (imgs)
    for (size_t k = 0; k < man.n_views; k++) hearth_image_free(&imgs[k]);
  free(imgs);
  free(views);
  free(res);
  free(done_flag);
  json_decref(report);
  hearth_manifest_free(&man);
  hearth_raycaster_free(rc);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&start);
  hearth_poses_free(&prev);
  hearth_poses_free(&truth);
  return s;
}
