/* recon_tsdf.c - the truncated signed distance volume (allocation and
 * fusion of depth maps) and the whole depth-to-mesh reconstruction of a
 * release instance. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/recon_geom.h"
#include "recon_internal.h"

hearth_status hearth_tsdf_init(hearth_tsdf *t, const double lo[3], const double hi[3], double voxel,
                               double trunc, hearth_err *err) {
  memset(t, 0, sizeof *t);
  if (!(voxel > 0) || !(trunc > 0) || !isfinite(voxel) || !isfinite(trunc))
    return hearth_err_set(err, HEARTH_E_ARG, "tsdf: voxel %g and truncation %g must be positive",
                          voxel, trunc);
  int n[3];
  size_t total = 1;
  for (int a = 0; a < 3; a++) {
    if (!isfinite(lo[a]) || !isfinite(hi[a]) || !(hi[a] >= lo[a]))
      return hearth_err_set(err, HEARTH_E_ARG, "tsdf: empty or non-finite bounds on axis %d", a);
    double c = ceil((hi[a] - lo[a]) / voxel) + 1.0;
    if (c > 1e6) return hearth_err_set(err, HEARTH_E_LIMIT, "tsdf: %g samples on axis %d", c, a);
    n[a] = c < 2 ? 2 : (int)c;
    total *= (size_t)n[a];
    if (total > HEARTH_TSDF_MAX_SAMPLES)
      return hearth_err_set(err, HEARTH_E_LIMIT,
                            "tsdf: volume of more than %zu samples (voxel %g m too small?)",
                            (size_t)HEARTH_TSDF_MAX_SAMPLES, voxel);
  }
  t->dist = malloc(total * sizeof(float));
  t->weight = calloc(total, sizeof(float));
  if (!t->dist || !t->weight) {
    hearth_tsdf_free(t);
    return hearth_err_set(err, HEARTH_E_NOMEM, "tsdf: %zu samples", total);
  }
  for (size_t i = 0; i < total; i++) t->dist[i] = 1.0f;
  t->nx = n[0];
  t->ny = n[1];
  t->nz = n[2];
  for (int a = 0; a < 3; a++) t->origin[a] = lo[a];
  t->voxel = voxel;
  t->trunc = trunc;
  return HEARTH_OK;
}

void hearth_tsdf_free(hearth_tsdf *t) {
  if (!t) return;
  free(t->dist);
  free(t->weight);
  memset(t, 0, sizeof *t);
}

hearth_status hearth_tsdf_integrate(hearth_tsdf *t, const hearth_image *depth,
                                    const hearth_camera *cam, const hearth_rigid *T_world_from_cam,
                                    const uint8_t *mask, hearth_err *err) {
  if (!t || !t->dist || !depth || !cam || !T_world_from_cam)
    return hearth_err_set(err, HEARTH_E_ARG, "tsdf integrate: missing argument");
  if (depth->type != HEARTH_PIX_U16 || depth->channels != 1)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "tsdf integrate: depth must be 1-channel 16-bit");
  if ((size_t)cam->width != depth->width || (size_t)cam->height != depth->height)
    return hearth_err_set(err, HEARTH_E_SIZE, "tsdf integrate: depth %zux%zu but camera %dx%d",
                          depth->width, depth->height, cam->width, cam->height);
  hearth_rigid Tcw;
  hearth_rigid_inverse(T_world_from_cam, &Tcw);
  const uint16_t *dp = depth->data;
  const int W = cam->width, H = cam->height;
  const double tr = t->trunc;
  for (int k = 0; k < t->nz; k++) {
    for (int j = 0; j < t->ny; j++) {
      double pw[3] = {0, t->origin[1] + j * t->voxel, t->origin[2] + k * t->voxel};
      size_t row = ((size_t)k * t->ny + j) * t->nx;
      for (int i = 0; i < t->nx; i++) {
        pw[0] = t->origin[0] + i * t->voxel;
        double pc[3];
        hearth_rigid_apply(&Tcw, pw, pc);
        if (pc[2] <= 1e-6) continue;
        double x = pc[0] / pc[2], y = pc[1] / pc[2], xd, yd;
        if (fabs(x) > 3.0 || fabs(y) > 3.0) continue;
        hearth_distort_xy(cam->dist, x, y, &xd, &yd);
        double u = cam->fx * xd + cam->cx, v = cam->fy * yd + cam->cy;
        long ui = lround(u), vi = lround(v);
        if (ui < 0 || vi < 0 || ui >= W || vi >= H) continue;
        size_t p = (size_t)vi * W + ui;
        if (!dp[p]) continue;
        double sdf = dp[p] * 0.001 - pc[2];
        float val;
        if (mask && !mask[p]) {
          /* background pixel: free space in front of it */
          if (sdf <= tr) continue;
          val = 1.0f;
        } else {
          if (sdf < -tr) continue;
          val = sdf >= tr ? 1.0f : (float)(sdf / tr);
        }
        size_t s = row + i;
        float w = t->weight[s];
        t->dist[s] = (t->dist[s] * w + val) / (w + 1.0f);
        t->weight[s] = w + 1.0f;
      }
    }
  }
  return HEARTH_OK;
}

/* ---- from a release ------------------------------------------------------ */
void hearth_recon_tsdf_opts_default(hearth_recon_tsdf_opts *o) {
  memset(o, 0, sizeof *o);
  o->voxel_m = 0.002;
  o->trunc_m = 0;
  o->hole_max_edges = 4000;
  o->hole_support_m = 0;
  o->target_triangles = 20000;
  o->poses = NULL;
}

/* One view ready to fuse: its depth map, depth camera, depth-camera pose,
 * its cut-out as a colour-resolution 0/1 mask and the object mask of its
 * depth pixels. */
typedef struct recon_view {
  hearth_image depth;
  hearth_camera cam;
  hearth_rigid T_world_from_depth;
  hearth_rigid T_rgb_from_world;
  uint8_t *cut;  /* rgb width * height: 2 on the cut-out, 1 within
                    RECON_SILHOUETTE_DILATE pixels of it, 0 elsewhere */
  uint8_t *mask; /* depth width * height */
} recon_view;

/* Loops of at most this many edges (about 30 mm round at 2 mm voxels) are
 * closed wherever they lie: specks of missing surface, not openings. */
#define RECON_HOLE_SMALL_EDGES 16

/* Depth step (mm) between 4-neighbours taken as a depth edge. */
#define RECON_EDGE_MM 8
/* Share of the views in whose image a point falls that must see it on
 * their cut-out (less one view) for it to be the object; at least half
 * the other views must have it in their image. */
#define RECON_SILHOUETTE_SHARE 0.9
/* The cut-outs are dilated by this many colour pixels for that test. */
#define RECON_SILHOUETTE_DILATE 3

int rc_cutout_at(const hearth_image *c, size_t p) {
  p *= (size_t)c->channels;
  if (c->type == HEARTH_PIX_U16) {
    const uint16_t *d = c->data;
    return c->channels == 2 || c->channels == 4 ? d[p + c->channels - 1] != 0 : d[p] != 0;
  }
  const uint8_t *d = c->data;
  if (c->channels == 2 || c->channels == 4) return d[p + c->channels - 1] != 0;
  if (c->channels == 3) return d[p] || d[p + 1] || d[p + 2];
  return d[p] != 0;
}

/* Mark (value 1) the pixels within RECON_SILHOUETTE_DILATE (square) of a
 * cut-out pixel (value 2) of the W x H mask c; tmp holds W * H bytes. */
static void dilate_cut(uint8_t *c, uint8_t *tmp, int W, int H) {
  const int r = RECON_SILHOUETTE_DILATE;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      int on = 0;
      for (int d = -r; d <= r && !on; d++)
        on = x + d >= 0 && x + d < W && c[(size_t)y * W + x + d] == 2;
      tmp[(size_t)y * W + x] = (uint8_t)on;
    }
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      uint8_t *p = &c[(size_t)y * W + x];
      if (*p == 2) continue;
      int on = 0;
      for (int d = -r; d <= r && !on; d++)
        on = y + d >= 0 && y + d < H && tmp[(size_t)(y + d) * W + x];
      *p = (uint8_t)on;
    }
}

/* The cut-out value (0, 1, 2 as in recon_view.cut) of world point pw in
 * view w, or -1 if it is outside w's colour image. */
static int on_cutout(const recon_view *w, const hearth_camera *rgb, const double pw[3]) {
  double pr[3], uv[2];
  hearth_rigid_apply(&w->T_rgb_from_world, pw, pr);
  if (!hearth_camera_project(rgb, pr, uv, NULL)) return -1;
  long u = lround(uv[0]), v = lround(uv[1]);
  if (u < 0 || v < 0 || u >= rgb->width || v >= rgb->height) return -1;
  return w->cut[(size_t)v * rgb->width + u];
}

/* Object mask of view i: depth pixels away from depth edges whose points
 * land on the cut-out of view i and of RECON_SILHOUETTE_SHARE of the views
 * that see them (a background point just beside the object, which the
 * colour camera sees behind the object through parallax, falls off the
 * other views' cut-outs). Grows lo/hi by the object's world points. */
static hearth_status view_mask(recon_view *views, size_t nv, size_t i, const hearth_camera *rgb,
                               double lo[3], double hi[3], size_t *n_obj, hearth_err *err) {
  recon_view *rv = &views[i];
  const int W = rv->cam.width, H = rv->cam.height;
  /* on_cutout reads the dilated cut-outs of the other views */
  float *dirs = malloc((size_t)W * H * 3 * sizeof(float));
  rv->mask = calloc((size_t)W * H, 1);
  if (!dirs || !rv->mask) {
    free(dirs);
    return hearth_err_set(err, HEARTH_E_NOMEM, "recon: depth rays");
  }
  hearth_camera_ray_grid(&rv->cam, 1, dirs);
  const uint16_t *dp = rv->depth.data;
  for (int v = 1; v + 1 < H; v++) {
    for (int u = 1; u + 1 < W; u++) {
      size_t p = (size_t)v * W + u;
      const float *d = dirs + 3 * p;
      if (!dp[p] || !isfinite(d[0]) || d[2] <= 0) continue;
      /* a pixel straddling a depth edge (a neighbour missing or more than
       * RECON_EDGE_MM away) mixes two surfaces: not the object */
      int edge = 0;
      for (int q = 0; q < 4 && !edge; q++) {
        size_t pn = q == 0 ? p - 1 : q == 1 ? p + 1 : q == 2 ? p - W : p + W;
        int dd = (int)dp[pn] - (int)dp[p];
        edge = !dp[pn] || dd > RECON_EDGE_MM || dd < -RECON_EDGE_MM;
      }
      if (edge) continue;
      double z = dp[p] * 0.001;
      double pd[3] = {d[0] / d[2] * z, d[1] / d[2] * z, z}, pw[3];
      hearth_rigid_apply(&rv->T_world_from_depth, pd, pw);
      if (on_cutout(rv, rgb, pw) != 2) continue;
      size_t seen = 0, on = 0;
      for (size_t j = 0; j < nv; j++) {
        if (j == i) continue;
        int r = on_cutout(&views[j], rgb, pw);
        if (r < 0) continue;
        seen++;
        on += r > 0;
      }
      if (2 * seen < nv - 1 || (double)on < RECON_SILHOUETTE_SHARE * (double)seen - 1.0) continue;
      rv->mask[p] = 1;
      for (int a = 0; a < 3; a++) {
        if (pw[a] < lo[a]) lo[a] = pw[a];
        if (pw[a] > hi[a]) hi[a] = pw[a];
      }
      (*n_obj)++;
    }
  }
  free(dirs);
  return HEARTH_OK;
}

static hearth_status load_views(const char *root, const char *instance, const char *state,
                                const hearth_poses *poses, const hearth_factory_calib *fac,
                                recon_view **views, size_t *n_views, size_t *cap, hearth_err *err) {
  char dir[1024], path[1400];
  snprintf(dir, sizeof dir, "%s/instances/%s/raw/%s", root, instance, state);
  snprintf(path, sizeof path, "%s/manifest.json", dir);
  hearth_manifest man = {0};
  hearth_status s = hearth_manifest_read(path, &man, err);
  if (s) return s;
  hearth_rigid T_rgb_from_depth;
  hearth_rigid_inverse(&fac->T_depth_from_rgb, &T_rgb_from_depth);
  for (size_t i = 0; i < man.n_views && !s; i++) {
    const hearth_view_files *vf = &man.views[i];
    const hearth_view_pose *vp = hearth_poses_find(poses, state, vf->view);
    if (!vp) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "recon: no pose for %s/%s", state, vf->view);
      break;
    }
    if (*n_views == *cap) {
      size_t nc = *cap ? 2 * *cap : 32;
      recon_view *nv = realloc(*views, nc * sizeof *nv);
      if (!nv) {
        s = hearth_err_set(err, HEARTH_E_NOMEM, "recon: views");
        break;
      }
      *views = nv;
      *cap = nc;
    }
    recon_view *rv = &(*views)[*n_views];
    memset(rv, 0, sizeof *rv);
    (*n_views)++;
    hearth_depth_intrinsics di;
    snprintf(path, sizeof path, "%s/%s", dir, vf->depth_intrinsics);
    if ((s = hearth_depth_intrinsics_read(path, &di, err))) break;
    rv->cam = di.depth;
    snprintf(path, sizeof path, "%s/%s", dir, vf->depth);
    if ((s = hearth_png_read(path, &rv->depth, err))) break;
    if (rv->depth.type != HEARTH_PIX_U16 || rv->depth.channels != 1 ||
        rv->depth.width != (size_t)rv->cam.width || rv->depth.height != (size_t)rv->cam.height) {
      s = hearth_err_set(err, HEARTH_E_SIZE, "%s: expected a %dx%d 1-channel 16-bit depth image",
                         path, rv->cam.width, rv->cam.height);
      break;
    }
    hearth_rigid_compose(&vp->T_world_from_cam, &T_rgb_from_depth, &rv->T_world_from_depth);
    hearth_rigid_inverse(&vp->T_world_from_cam, &rv->T_rgb_from_world);
    hearth_image cut = {0};
    snprintf(path, sizeof path, "%s/%s", dir, vf->cutout);
    if ((s = hearth_png_read(path, &cut, err))) break;
    if (cut.width != (size_t)fac->rgb.width || cut.height != (size_t)fac->rgb.height) {
      s = hearth_err_set(err, HEARTH_E_SIZE, "%s: %zux%zu, the colour camera is %dx%d", path,
                         cut.width, cut.height, fac->rgb.width, fac->rgb.height);
    } else if (!(rv->cut = malloc(cut.width * cut.height))) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "%s", path);
    } else {
      for (size_t p = 0; p < cut.width * cut.height; p++)
        rv->cut[p] = (uint8_t)(2 * rc_cutout_at(&cut, p));
      uint8_t *tmp = malloc(cut.width * cut.height);
      if (!tmp) s = hearth_err_set(err, HEARTH_E_NOMEM, "%s", path);
      else dilate_cut(rv->cut, tmp, (int)cut.width, (int)cut.height);
      free(tmp);
    }
    hearth_image_free(&cut);
  }
  hearth_manifest_free(&man);
  return s;
}

hearth_status hearth_recon_tsdf(const char *root, const char *instance, const char *const *states,
                                size_t n_states, const hearth_recon_tsdf_opts *opts,
                                hearth_mesh *out, hearth_err *err) {
  hearth_recon_tsdf_opts o;
  if (opts) o = *opts;
  else hearth_recon_tsdf_opts_default(&o);
  if (!(o.voxel_m > 0)) o.voxel_m = 0.002;
  if (!(o.trunc_m > 0)) o.trunc_m = 2.0 * o.voxel_m;
  memset(out, 0, sizeof *out);
  char path[1400];
  hearth_instance_doc inst;
  const char *own[HEARTH_MAX_STATES];
  hearth_factory_calib fac;
  hearth_status s =
      recon_instance_inputs(root, instance, &inst, own, &states, &n_states, &fac, err);
  if (s) return s;
  hearth_poses poses = {0};
  if (o.poses) snprintf(path, sizeof path, "%s/%s", root, o.poses);
  else snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, instance);
  if ((s = hearth_poses_read(path, &poses, err))) return s;

  recon_view *views = NULL;
  size_t nv = 0, cap = 0, n_obj = 0;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n_states && !s; i++)
    s = load_views(root, instance, states[i], &poses, &fac, &views, &nv, &cap, err);
  for (size_t i = 0; i < nv && !s; i++) s = view_mask(views, nv, i, &fac.rgb, lo, hi, &n_obj, err);
  hearth_tsdf vol = {0};
  if (!s && n_obj == 0)
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "recon %s: no depth pixel on the cut-outs",
                       instance);
  if (!s) {
    double margin = o.trunc_m + 2.0 * o.voxel_m;
    for (int a = 0; a < 3; a++) {
      lo[a] -= margin;
      hi[a] += margin;
    }
    s = hearth_tsdf_init(&vol, lo, hi, o.voxel_m, o.trunc_m, err);
  }
  for (size_t i = 0; i < nv && !s; i++)
    s = hearth_tsdf_integrate(&vol, &views[i].depth, &views[i].cam, &views[i].T_world_from_depth,
                              views[i].mask, err);
  for (size_t i = 0; i < nv; i++) {
    hearth_image_free(&views[i].depth);
    free(views[i].mask);
    free(views[i].cut);
  }
  free(views);
  hearth_poses_free(&poses);
  if (!s) s = hearth_tsdf_extract(&vol, out, err);
  hearth_tsdf_free(&vol);
  if (!s) s = hearth_mesh_keep_largest(out, err);
  if (!s && o.hole_max_edges) {
    /* the support plane z = 0 only where asked: other pose frames put the
       turntable elsewhere */
    const hearth_hole_rule r = {o.hole_max_edges,
                                o.hole_support_m > 0 ? RECON_HOLE_SMALL_EDGES : o.hole_max_edges,
                                {0, 0, 1, 0},
                                o.hole_support_m};
    s = hearth_mesh_fill_holes_near(out, &r, NULL, NULL, err);
  }
  if (!s && o.target_triangles) s = hearth_mesh_simplify(out, o.target_triangles, err);
  if (s) {
    hearth_mesh_free(out);
    return hearth_err_prefix(err, "recon %s", instance);
  }
  return HEARTH_OK;
}
