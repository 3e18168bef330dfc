/* Fuzz target for the COLMAP model readers (area recon) and the cameras
 * document reader. The first byte chooses the form (bit 0: binary); the
 * rest is up to three files, cameras, images and points3D, separated by
 * "@@@@", parsed in that order into one model so the cross-checks run. The
 * whole input also goes to each parser alone and to the cameras document
 * reader. What a parser accepts must keep the promised invariants (sorted
 * unique ids, convertible cameras, rotations, known references); what it
 * refuses must leave its array empty and name the file. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/recon.h"

static void check_sorted(const hearth_colmap_model *m) {
  for (size_t i = 1; i < m->n_cameras; i++)
    if (m->cameras[i].id <= m->cameras[i - 1].id) abort();
  for (size_t i = 1; i < m->n_images; i++)
    if (m->images[i].id <= m->images[i - 1].id) abort();
  for (size_t i = 1; i < m->n_points; i++)
    if (m->points[i].id <= m->points[i - 1].id) abort();
  for (size_t i = 0; i < m->n_cameras; i++) {
    const hearth_camera *c = &m->cameras[i].camera;
    if (!(c->fx > 0) || !(c->fy > 0) || c->width < 1 || c->width > 65536 || c->height < 1 ||
        c->height > 65536)
      abort();
  }
  for (size_t i = 0; i < m->n_images; i++) {
    if (!hearth_is_rotation(m->images[i].T_world_from_cam.R, 1e-9)) abort();
    if (!hearth_colmap_find_camera(m, m->images[i].camera_id)) abort();
    if (m->images[i].n_observations > m->images[i].n_points2d) abort();
  }
}

static void parse_one(hearth_colmap_file which, hearth_colmap_format f, const uint8_t *d, size_t n,
                      hearth_colmap_model *m) {
  hearth_err err;
  hearth_status s = hearth_colmap_parse(which, f, d, n, "fuzz", m, &err);
  if (s) {
    size_t count = which == HEARTH_COLMAP_CAMERAS  ? m->n_cameras
                   : which == HEARTH_COLMAP_IMAGES ? m->n_images
                                                   : m->n_points;
    if (count || strncmp(err.msg, "fuzz", 4) != 0) abort();
  }
  check_sorted(m);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_colmap_model m = {0};
  if (size >= 1) {
    hearth_colmap_format f = (data[0] & 1) ? HEARTH_COLMAP_BINARY : HEARTH_COLMAP_TEXT;
    const uint8_t *p = data + 1, *end = data + size;
    for (int which = 0; which < 3; which++) {
      const uint8_t *sep = NULL;
      for (const uint8_t *q = p; q + 4 <= end; q++)
        if (!memcmp(q, "@@@@", 4)) {
          sep = q;
          break;
        }
      const uint8_t *stop = sep ? sep : end;
      parse_one((hearth_colmap_file)which, f, p, (size_t)(stop - p), &m);
      p = sep ? sep + 4 : end;
    }
    hearth_poses poses;
    hearth_recon_cameras cams;
    hearth_err err;
    if (hearth_colmap_to_poses(&m, "neutral", &poses, &cams, &err) == HEARTH_OK) {
      if (poses.n != m.n_images || cams.n_views != m.n_images) abort();
      for (size_t i = 1; i < poses.n; i++)
        if (!strcmp(poses.views[i].state, poses.views[i - 1].state) &&
            !strcmp(poses.views[i].view, poses.views[i - 1].view))
          abort();
    } else if (poses.n || poses.views || cams.n_views) {
      abort();
    }
    hearth_poses_free(&poses);
    hearth_recon_cameras_free(&cams);
    hearth_colmap_model_free(&m);
  }
  /* the whole input as each file alone, in both forms */
  for (int f = 0; f < 2; f++)
    for (int which = 0; which < 3; which++) {
      parse_one((hearth_colmap_file)which, (hearth_colmap_format)f, data, size, &m);
      hearth_colmap_model_free(&m);
    }
  hearth_recon_cameras c;
  hearth_err err;
  if (hearth_recon_cameras_parse((const char *)data, size, "fuzz", &c, &err) == HEARTH_OK) {
    for (size_t i = 1; i < c.n_cameras; i++)
      if (c.cameras[i].id <= c.cameras[i - 1].id) abort();
  } else if (c.n_cameras || c.cameras || c.n_views) {
    abort();
  }
  hearth_recon_cameras_free(&c);
  return 0;
}
