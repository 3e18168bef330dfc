/* Alignment overlays: the projected mesh outline on the Turbo-coloured
 * thermal image, per view and as a contact sheet (include/hearth/refine.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/thermal.h"
#include "poses/poses_internal.h"

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* mark outline sub-pixels (silhouette and depth jumps) of the mesh seen from T */
static hearth_status outline_mask(const hearth_raycaster *rc, const hearth_camera *cam,
                                  const hearth_rigid *T, int zoom, uint8_t *edge, hearth_err *err) {
  size_t w = (size_t)cam->width * (size_t)zoom, h = (size_t)cam->height * (size_t)zoom;
  float *depth = hearth_alloc_array(w * h, sizeof *depth);
  if (!depth) return hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
  rf_cast_box(rc, cam, T, 0, 0, cam->width, cam->height, zoom, depth, NULL);
  memset(edge, 0, w * h);
  for (size_t y = 0; y < h; y++)
    for (size_t x = 0; x < w; x++) {
      float d = depth[y * w + x];
      if (!isfinite(d)) continue;
      const long dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4; k++) {
        long nx = (long)x + dx[k], ny = (long)y + dy[k];
        if (nx < 0 || ny < 0 || nx >= (long)w || ny >= (long)h) continue;
        float dn = depth[(size_t)ny * w + (size_t)nx];
        /* both sides of the jump, so the line is two sub-pixels wide */
        if (!isfinite(dn) || dn > d * 1.05f) edge[y * w + x] = edge[(size_t)ny * w + (size_t)nx] = 1;
      }
    }
  free(depth);
  return HEARTH_OK;
}

hearth_status hearth_overlay_render(const hearth_raycaster *rc, const hearth_camera *cam,
                                    const hearth_image *temps, const hearth_rigid *T_world_from_cam,
                                    int zoom, double lo, double hi, const uint8_t rgb[3],
                                    hearth_image *out, hearth_err *err) {
  if (!temps || temps->type != HEARTH_PIX_F32 || temps->channels != 1 ||
      temps->width != (size_t)cam->width || temps->height != (size_t)cam->height)
    return hearth_err_set(err, HEARTH_E_SIZE, "overlay: expected a %dx%d temperature image",
                          cam->width, cam->height);
  if (zoom < 1 || zoom > 16) return hearth_err_set(err, HEARTH_E_ARG, "overlay: zoom %d outside 1..16", zoom);
  size_t n = temps->width * temps->height;
  const float *t = temps->data;
  if (!(lo < hi)) {
    /* 2..98 % of the image so low-contrast states stay readable */
    float *tmp = hearth_alloc_array(n, sizeof *tmp);
    if (!tmp) return hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
    memcpy(tmp, t, n * sizeof *tmp);
    qsort(tmp, n, sizeof *tmp, cmp_float);
    lo = tmp[n / 50];
    hi = tmp[n - 1 - n / 50];
    free(tmp);
    if (!(hi > lo)) hi = lo + 1.0;
  }
  size_t w = temps->width * (size_t)zoom, h = temps->height * (size_t)zoom;
  hearth_status s = HEARTH_OK;
  if (!out->data) {
    if ((s = hearth_image_alloc(out, w, h, 3, HEARTH_PIX_U8, err))) return s;
    uint8_t *o = out->data;
    for (size_t y = 0; y < h; y++)
      for (size_t x = 0; x < w; x++)
        hearth_turbo((t[(y / (size_t)zoom) * temps->width + x / (size_t)zoom] - lo) / (hi - lo),
                     o + 3 * (y * w + x));
  } else if (out->width != w || out->height != h || out->channels != 3) {
    return hearth_err_set(err, HEARTH_E_SIZE, "overlay: target image has the wrong size");
  }
  uint8_t *edge = hearth_alloc_array(w * h, 1);
  if (!edge) return hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
  if (!(s = outline_mask(rc, cam, T_world_from_cam, zoom, edge, err))) {
    uint8_t *o = out->data;
    for (size_t i = 0; i < w * h; i++)
      if (edge[i]) memcpy(o + 3 * i, rgb, 3);
  }
  free(edge);
  return s;
}

hearth_status hearth_overlay_run(const hearth_overlay_job *job, size_t *n_written, hearth_err *err) {
  if (!job || !job->root || !job->instance || !job->state)
    return hearth_err_set(err, HEARTH_E_ARG, "overlay: root, instance and state are required");
  const char *root = job->root, *inst = job->instance, *state = job->state;
  char rig_path[RF_PATH], mesh_path[RF_PATH], before_path[RF_PATH], after_path[RF_PATH],
      dir[RF_PATH], path[RF_PATH];
  if (job->rig_path) snprintf(rig_path, RF_PATH, "%s", job->rig_path);
  else rf_pathf(rig_path, "%s/calibration/rig.json", root);
  if (job->mesh_path) snprintf(mesh_path, RF_PATH, "%s", job->mesh_path);
  else rf_pathf(mesh_path, "%s/instances/%s/derived/mesh.glb", root, inst);
  if (job->before_path) snprintf(before_path, RF_PATH, "%s", job->before_path);
  else rf_pathf(before_path, "%s/instances/%s/derived/poses_thermal_transferred.json", root, inst);
  if (job->after_path) snprintf(after_path, RF_PATH, "%s", job->after_path);
  else rf_pathf(after_path, "%s/instances/%s/derived/poses_thermal.json", root, inst);
  int zoom = job->zoom > 0 ? job->zoom : 3;
  hearth_rig rig;
  hearth_poses before = {0}, after = {0};
  hearth_mesh mesh = {0};
  hearth_raycaster *rc = NULL;
  hearth_manifest man = {0};
  hearth_image sheet = {0}, temps = {0}, ov = {0}, thumb = {0};
  size_t written = 0;
  hearth_status s;
  if ((s = hearth_rig_read(rig_path, &rig, err))) goto done;
  int have_before = hearth_path_exists(before_path);
  if (have_before && (s = hearth_poses_read(before_path, &before, err))) goto done;
  if ((s = hearth_poses_read(after_path, &after, err))) goto done;
  hearth_glb_read_opts gopts = {0};
  if ((s = hearth_glb_read(mesh_path, &gopts, &mesh, err))) goto done;
  if ((s = hearth_raycaster_new(&mesh, &rc, err))) goto done;
  rf_pathf(path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
  if ((s = hearth_manifest_read(path, &man, err))) goto done;
  rf_pathf(dir, "%s/instances/%s/derived/overlay/%s", root, inst, state);
  if ((s = hearth_mkdirs(dir, err))) goto done;
  /* contact sheet: one cell per view, before (left) and after (right) */
  size_t cw = (size_t)rig.thermal.width, ch = (size_t)rig.thermal.height, label = 12;
  size_t cols = 4, rows = (man.n_views + cols - 1) / cols;
  if ((s = hearth_image_alloc(&sheet, cols * (2 * cw + 8), rows * (ch + label + 8) + 16, 3,
                              HEARTH_PIX_U8, err)))
    goto done;
  memset(sheet.data, 40, hearth_image_bytes(&sheet));
  const uint8_t white[3] = {255, 255, 255}, magenta[3] = {255, 0, 255}, grey[3] = {190, 190, 190};
  char title[160];
  snprintf(title, sizeof title, "%s %s  left: before  right: after (white outline)", inst, state);
  hearth_draw_text(&sheet, 4, 4, title, white, 1);
  for (size_t k = 0; k < man.n_views; k++) {
    const hearth_view_files *vf = &man.views[k];
    const hearth_view_pose *pa = hearth_poses_find(&after, state, vf->view);
    const hearth_view_pose *pb = have_before ? hearth_poses_find(&before, state, vf->view) : NULL;
    if (!pa) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no pose for state '%s' view '%s'", after_path,
                         state, vf->view);
      goto done;
    }
    rf_pathf(path, "%s/instances/%s/raw/%s/%s", root, inst, state, vf->thermal);
    if ((s = hearth_thermal_read_csv_camera(path, cw, ch, rig_path, &temps, err))) goto done;
    /* the per-view file: before in magenta under after in white */
    if (pb && (s = hearth_overlay_render(rc, &rig.thermal, &temps, &pb->T_world_from_cam, zoom,
                                         job->lo, job->hi, magenta, &ov, err)))
      goto done;
    if ((s = hearth_overlay_render(rc, &rig.thermal, &temps, &pa->T_world_from_cam, zoom, job->lo,
                                   job->hi, white, &ov, err)))
      goto done;
    hearth_draw_text(&ov, 4, 4, vf->view, white, 2);
    rf_pathf(path, "%s/%s.png", dir, vf->view);
    if ((s = hearth_png_write(path, &ov, err))) goto done;
    written++;
    hearth_image_free(&ov);
    size_t cx = (k % cols) * (2 * cw + 8) + 4, cy = (k / cols) * (ch + label + 8) + 16;
    hearth_draw_text(&sheet, cx, cy, vf->view, grey, 1);
    for (int side = 0; side < 2; side++) {
      const hearth_view_pose *p = side ? pa : pb;
      if (!p) continue;
      if ((s = hearth_overlay_render(rc, &rig.thermal, &temps, &p->T_world_from_cam, 1, job->lo,
                                     job->hi, white, &thumb, err)))
        goto done;
      hearth_image_blit(&sheet, &thumb, cx + (size_t)side * cw, cy + label);
      hearth_image_free(&thumb);
    }
    hearth_image_free(&temps);
  }
  rf_pathf(path, "%s/contact_sheet.png", dir);
  if ((s = hearth_png_write(path, &sheet, err))) goto done;
  written++;
  if (n_written) *n_written = written;
done:
  hearth_image_free(&sheet);
  hearth_image_free(&temps);
  hearth_image_free(&ov);
  hearth_image_free(&thumb);
  hearth_manifest_free(&man);
  hearth_raycaster_free(rc);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&before);
  hearth_poses_free(&after);
  return s;
}

void hearth_overlay_job_default(hearth_overlay_job *job) {
  memset(job, 0, sizeof *job);
  job->zoom = 3;
}
