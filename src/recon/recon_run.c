/* recon_run.c - `hearth recon ROOT` on the embedded route: turntable poses,
 * the metric mesh from depth with them, its UV atlas, and the
 * reconstruction report. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/mesh.h"
#include "hearth/recon.h"
#include "hearth/recon_geom.h"
#include "recon_internal.h"

void hearth_recon_job_default(hearth_recon_job *job) {
  memset(job, 0, sizeof *job);
  hearth_turntable_opts_default(&job->poses);
  hearth_recon_tsdf_opts_default(&job->geometry);
  /* the turntable route's frame has the turntable top at z = 0: close the
     base the object stands on, leave openings no depth view reached open */
  job->geometry.hole_support_m = HEARTH_RECON_HOLE_SUPPORT_M;
  hearth_atlas_opts_default(&job->atlas);
}

void hearth_recon_summary_free(hearth_recon_summary *s) {
  if (!s) return;
  hearth_turntable_result_free(&s->poses);
  memset(s, 0, sizeof *s);
}

/* the factory colour camera as the one camera of every view (COLMAP's
 * FULL_OPENCV parameters, its pixel convention: principal point + 0.5) */
static hearth_status cameras_of(const hearth_camera *rgb, const hearth_poses *p,
                                hearth_recon_cameras *c, hearth_err *err) {
  memset(c, 0, sizeof *c);
  c->cameras = calloc(1, sizeof *c->cameras);
  c->views = calloc(p->n ? p->n : 1, sizeof *c->views);
  if (!c->cameras || !c->views) {
    hearth_recon_cameras_free(c);
    return hearth_err_set(err, HEARTH_E_NOMEM, "recon: cameras");
  }
  hearth_colmap_camera *k = &c->cameras[0];
  k->id = 1;
  k->model_id = hearth_colmap_model_id("FULL_OPENCV");
  k->n_params = 12;
  const double par[12] = {rgb->fx,
                          rgb->fy,
                          rgb->cx + 0.5,
                          rgb->cy + 0.5,
                          rgb->dist[0],
                          rgb->dist[1],
                          rgb->dist[2],
                          rgb->dist[3],
                          rgb->dist[4],
                          0,
                          0,
                          0};
  memcpy(k->params, par, sizeof par);
  k->width = (uint64_t)rgb->width;
  k->height = (uint64_t)rgb->height;
  k->camera = *rgb;
  c->n_cameras = 1;
  for (size_t i = 0; i < p->n; i++) {
    hearth_recon_view_camera *v = &c->views[i];
    snprintf(v->state, sizeof v->state, "%s", p->views[i].state);
    snprintf(v->view, sizeof v->view, "%s", p->views[i].view);
    v->camera_id = 1;
    v->image_id = (uint32_t)(i + 1);
    snprintf(v->image, sizeof v->image, "%s/%s", p->views[i].state, p->views[i].view);
  }
  c->n_views = p->n;
  return HEARTH_OK;
}

/* "aim": the aim term's axis point per state and its place in the camera
 * frame with its fitted spread; null when the term was off */
static void write_aim(hearth_strbuf *b, const hearth_turntable_result *r, double weight) {
  if (!r->n_aim_places) {
    hearth_strbuf_printf(b, "  \"aim\": null,\n");
    return;
  }
  hearth_strbuf_printf(b, "  \"aim\": {\"weight\": ");
  rc_json_real(b, weight);
  hearth_strbuf_printf(b, ", \"axis_direction\": [0.0, 0.0, 1.0],\n    \"states\": [");
  for (size_t i = 0; i < r->n_aim_states; i++) {
    const hearth_turntable_aim_state *a = &r->aim_states[i];
    hearth_strbuf_printf(b, "%s\n      {\"state\": ", i ? "," : "");
    rc_json_string(b, a->state);
    hearth_strbuf_printf(b, ", \"views\": %zu, \"point_m\": ", a->n_views);
    rc_json_reals(b, a->point_m, 3);
    hearth_strbuf_printf(b, ", \"axis_m\": ");
    rc_json_reals(b, a->axis_m, 3);
    const struct {
      const char *k;
      double v;
    } sg[] = {{"sigma_along_mm", a->sigma_along_m}, {"sigma_across_mm", a->sigma_across_m}};
    for (size_t k = 0; k < 2; k++) {
      hearth_strbuf_printf(b, ", \"%s\": ", sg[k].k);
      if (isfinite(sg[k].v)) rc_json_real(b, 1000.0 * sg[k].v);
      else hearth_strbuf_printf(b, "null");
    }
    hearth_strbuf_printf(b, "}");
  }
  hearth_strbuf_printf(b, "],\n    \"places\": [");
  for (size_t i = 0; i < r->n_aim_places; i++) {
    const hearth_turntable_aim_place *p = &r->aim_places[i];
    hearth_strbuf_printf(b, "%s\n      {\"ring\": ", i ? "," : "");
    if (p->elevation_index < 0) hearth_strbuf_printf(b, "null");
    else hearth_strbuf_printf(b, "%d", p->elevation_index);
    hearth_strbuf_printf(b, ", \"views\": %zu, \"camera_m\": ", p->n_views);
    rc_json_reals(b, p->camera_m, 3);
    const struct {
      const char *k;
      double v;
    } f[] = {{"distance_m", hearth_norm3(p->camera_m)},
             {"side_rms_mm", 1000.0 * p->side_rms_m},
             {"depth_rms_mm", 1000.0 * p->depth_rms_m},
             {"depth_rms_rel", p->depth_rms_rel}};
    for (size_t k = 0; k < sizeof f / sizeof f[0]; k++) {
      hearth_strbuf_printf(b, ", \"%s\": ", f[k].k);
      rc_json_real(b, f[k].v);
    }
    hearth_strbuf_printf(b, "}");
  }
  hearth_strbuf_printf(b, "]},\n");
}

static hearth_status write_report(const char *path, const char *instance,
                                  const hearth_turntable_result *r, double aim_weight,
                                  const hearth_mesh *m, double voxel, const hearth_atlas_stats *at,
                                  hearth_err *err) {
  hearth_strbuf b = {0};
  hearth_strbuf_printf(&b, "{\n  \"instance\": ");
  rc_json_string(&b, instance);
  hearth_strbuf_printf(&b, ",\n  \"route\": \"turntable\",\n  \"views\": %zu,\n  \"pairs\": %zu,\n",
                       r->n_views, r->n_pairs);
  hearth_strbuf_printf(&b, "  \"iterations\": %d,\n", r->iterations);
  hearth_strbuf_printf(&b,
                       "  \"encoder_views\": %zu,\n  \"colour_views\": %zu,\n"
                       "  \"ring_plane_views\": %zu,\n  \"free_ring_views\": %zu,\n",
                       r->n_encoder_views, r->n_colour_views, r->n_ring_plane_views,
                       r->n_free_ring_views);
  hearth_strbuf_printf(&b, "  \"wall_views\": %zu,\n  \"wall_check_views\": %zu,\n",
                       r->n_wall_views, r->n_wall_check_views);
  hearth_strbuf_printf(&b, "  \"wall_tilt_deg\": ");
  if (isfinite(r->wall_tilt_deg)) rc_json_real(&b, r->wall_tilt_deg);
  else hearth_strbuf_printf(&b, "null");
  hearth_strbuf_printf(&b, ",\n");
  const struct {
    const char *k;
    double v;
  } f[] = {{"icp_rms_start_mm", r->icp_rms_start_mm},
           {"icp_rms_mm", r->icp_rms_mm},
           {"icp_median_mm", r->icp_median_mm}};
  for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) {
    hearth_strbuf_printf(&b, "  \"%s\": ", f[i].k);
    rc_json_real(&b, f[i].v);
    hearth_strbuf_printf(&b, ",\n");
  }
  write_aim(&b, r, aim_weight);
  if (m) {
    /* the openings left where no depth view reached (hearth_hole_rule) */
    size_t loops = 0, edges = 0;
    hearth_status s = hearth_mesh_open_loops(m, &loops, &edges, err);
    if (s) {
      hearth_strbuf_free(&b);
      return hearth_err_prefix(err, "%s", path);
    }
    hearth_strbuf_printf(&b, "  \"mesh\": {\"vertices\": %zu, \"triangles\": %zu, \"voxel_m\": ",
                         m->n_vertices, m->n_triangles);
    rc_json_real(&b, voxel);
    hearth_strbuf_printf(&b, ", \"open_loops\": %zu, \"open_edges\": %zu},\n", loops, edges);
  }
  if (at) {
    hearth_strbuf_printf(&b, "  \"atlas\": {\"charts\": %zu, \"merged\": %zu", at->n_charts,
                         at->n_merges);
    const struct {
      const char *k;
      double v;
    } a[] = {{"stretch_l2", at->stretch_l2},
             {"stretch_l2_max", at->stretch_l2_max},
             {"stretch_l2_chart_max", at->stretch_l2_chart_max},
             {"area_distortion", at->area_distortion},
             {"angle_distortion", at->angle_distortion},
             {"packing_efficiency", at->packing_efficiency}};
    for (size_t i = 0; i < sizeof a / sizeof a[0]; i++) {
      hearth_strbuf_printf(&b, ", \"%s\": ", a[i].k);
      rc_json_real(&b, a[i].v);
    }
    hearth_strbuf_printf(&b, "},\n");
  }
  hearth_strbuf_printf(&b, "  \"per_view\": [");
  for (size_t i = 0; i < r->n_views; i++) {
    const hearth_turntable_view *v = &r->views[i];
    hearth_strbuf_printf(&b, "%s\n    {\"state\": ", i ? "," : "");
    rc_json_string(&b, v->state);
    hearth_strbuf_printf(&b, ", \"view\": ");
    rc_json_string(&b, v->view);
    hearth_strbuf_printf(&b, ", \"points\": %zu, \"plane_inliers\": %zu, \"plane_rms_mm\": ",
                         v->n_points, v->n_plane);
    rc_json_real(&b, v->plane_rms_mm);
    hearth_strbuf_printf(&b, ", \"height_m\": ");
    rc_json_real(&b, v->height_m);
    hearth_strbuf_printf(&b, ", \"elevation_deg\": ");
    rc_json_real(&b, v->elevation_deg);
    hearth_strbuf_printf(&b, ", \"pairs\": %zu, \"matches\": %zu, \"icp_rms_mm\": ", v->n_pairs,
                         v->n_matches);
    rc_json_real(&b, v->icp_rms_mm);
    hearth_strbuf_printf(&b, ", \"d_azimuth_deg\": ");
    rc_json_real(&b, v->d_azimuth_deg);
    hearth_strbuf_printf(&b, "}");
  }
  hearth_strbuf_printf(&b, "\n  ]\n}\n");
  char *text = hearth_strbuf_take(&b);
  if (!text) return hearth_err_set(err, HEARTH_E_NOMEM, "%s", path);
  hearth_status s = hearth_write_file_atomic(path, text, strlen(text), err);
  free(text);
  return s;
}

hearth_status hearth_recon_run(const hearth_recon_job *job, hearth_recon_summary *sum,
                               hearth_err *err) {
  memset(sum, 0, sizeof *sum);
  char dir[1400], rel[1400], path[1400];
  if (snprintf(dir, sizeof dir, "%s/instances/%s/recon", job->root, job->instance) >=
          (int)sizeof dir ||
      snprintf(rel, sizeof rel, "instances/%s/recon/poses_rgb.json", job->instance) >=
          (int)sizeof rel)
    return hearth_err_set(err, HEARTH_E_LIMIT, "recon: path too long");
  snprintf(sum->poses_path, sizeof sum->poses_path, "%s/poses_rgb.json", dir);
  snprintf(sum->mesh_path, sizeof sum->mesh_path, "%s/mesh_geometry.glb", dir);
  snprintf(sum->atlas_path, sizeof sum->atlas_path, "%s/mesh.glb", dir);
  snprintf(sum->report_path, sizeof sum->report_path, "%s/report.json", dir);
  if (hearth_path_exists(sum->poses_path) && !job->force)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "%s exists (poses in the frame of the reconstruction beside it); "
                          "--force replaces it",
                          sum->poses_path);
  /* a mesh and texture handed over by another tool are in another frame:
   * they go with the poses they belong to */
  static const char *const k_stale[] = {"mesh.glb", "rgb_texture.png"};
  for (size_t i = 0; i < 2; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, k_stale[i]);
    if (!hearth_path_exists(path)) continue;
    if (!job->force)
      return hearth_err_set(err, HEARTH_E_ARG,
                            "%s exists (another reconstruction's frame); --force replaces it",
                            path);
    if (remove(path) != 0) return hearth_err_set(err, HEARTH_E_IO, "%s: cannot remove it", path);
  }
  hearth_factory_calib fac;
  snprintf(path, sizeof path, "%s/calibration/factory.json", job->root);
  hearth_status s = hearth_factory_read(path, &fac, err);
  if (s) return s;
  hearth_turntable_opts po = job->poses;
  po.quiet = job->quiet;
  hearth_poses poses = {0};
  if ((s = hearth_recon_turntable(job->root, job->instance, NULL, 0, &po, &poses, &sum->poses,
                                  err)))
    return s;
  hearth_recon_cameras cams = {0};
  char cam_path[1400];
  s = hearth_mkdirs(dir, err);
  if (!s) s = cameras_of(&fac.rgb, &poses, &cams, err);
  if (!s && hearth_recon_cameras_path(sum->poses_path, cam_path, sizeof cam_path))
    s = hearth_err_set(err, HEARTH_E_LIMIT, "recon: path too long");
  if (!s) s = hearth_poses_write(sum->poses_path, &poses, err);
  if (!s) s = hearth_recon_cameras_write(cam_path, &cams, err);
  hearth_recon_cameras_free(&cams);
  hearth_poses_free(&poses);
  hearth_mesh mesh = {0};
  int have_mesh = 0;
  if (!s && !job->no_mesh) {
    hearth_recon_tsdf_opts go = job->geometry;
    go.poses = rel;
    if (!job->quiet) fprintf(stderr, "recon: fusing depth (voxel %.1f mm)\n", go.voxel_m * 1e3);
    s = hearth_recon_tsdf(job->root, job->instance, NULL, 0, &go, &mesh, err);
    if (!s) s = hearth_glb_write(sum->mesh_path, &mesh, err);
    if (!s) {
      have_mesh = 1;
      sum->mesh_vertices = mesh.n_vertices;
      sum->mesh_triangles = mesh.n_triangles;
    }
  }
  hearth_mesh atlas = {0};
  if (!s && have_mesh) {
    if (!job->quiet) fprintf(stderr, "recon: UV atlas of %zu triangles\n", mesh.n_triangles);
    s = hearth_mesh_atlas(&mesh, &job->atlas, &atlas, NULL, &sum->atlas, err);
    if (!s) s = hearth_glb_write(sum->atlas_path, &atlas, err);
    if (!s && !job->quiet)
      fprintf(stderr, "recon: %zu charts, L2 stretch %.3f (max %.2f), packing %.2f\n",
              sum->atlas.n_charts, sum->atlas.stretch_l2, sum->atlas.stretch_l2_max,
              sum->atlas.packing_efficiency);
  }
  if (!s)
    s = write_report(sum->report_path, job->instance, &sum->poses, job->poses.aim_prior,
                     have_mesh ? &mesh : NULL, job->geometry.voxel_m,
                     have_mesh ? &sum->atlas : NULL, err);
  hearth_mesh_free(&atlas);
  hearth_mesh_free(&mesh);
  if (s) hearth_recon_summary_free(sum);
  return s;
}
