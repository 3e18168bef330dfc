/* The contact picture of one built state: derived/mesh.glb ray-cast from
 * four viewpoints, the top row in the colour texture (derived/rgb_texture.png,
 * else the one embedded in the mesh) with Lambert shading, the bottom row in
 * the state's Turbo texture (derived/<state>/thermal_turbo.png) unshaded, so
 * its colours read as temperatures. The viewpoints look at the mesh's
 * bounding-box centre from the directions of four of the state's colour
 * views spread over the manifest (derived/poses_rgb.json), with those views'
 * image up, at a distance that frames the bounding sphere. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/image.h"
#include "hearth/mesh.h"
#include "release/release_internal.h"

#define PATH_SZ 4096
#define TILE 256
#define N_VIEWS 4

/* nearest texel of an RGB(A) 8-bit texture at uv (row 0 at v = 0) */
static void sample(const hearth_image *tex, double u, double v, double shade, uint8_t out[3]) {
  long w = (long)tex->width, h = (long)tex->height;
  long x = (long)floor(u * (double)w), y = (long)floor(v * (double)h);
  x = x < 0 ? 0 : x >= w ? w - 1 : x;
  y = y < 0 ? 0 : y >= h ? h - 1 : y;
  const uint8_t *p =
      (const uint8_t *)tex->data + ((size_t)y * (size_t)w + (size_t)x) * (size_t)tex->channels;
  for (int c = 0; c < 3; c++) {
    double s = (tex->channels >= 3 ? p[c] : p[0]) * shade;
    out[c] = (uint8_t)(s > 255 ? 255 : s + 0.5);
  }
}

static void normalize(double v[3]) {
  double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (n > 0)
    for (int a = 0; a < 3; a++) v[a] /= n;
}

static void cross(const double a[3], const double b[3], double o[3]) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}

hearth_status hb_contact_picture(const char *root, const char *inst, const char *state,
                                 const char *out_path, hearth_err *err) {
  char path[PATH_SZ];
  hearth_mesh mesh = {0};
  hearth_image colour = {0}, turbo = {0}, pic = {0};
  hearth_poses poses = {0};
  hearth_manifest man = {0};
  hearth_raycaster *rc = NULL;
  hearth_status s;
  hearth_glb_read_opts go;
  hearth_glb_read_opts_default(&go);
  go.require_uvs = 1;
  snprintf(path, sizeof path, "%s/instances/%s/derived/rgb_texture.png", root, inst);
  go.load_texture = !hearth_path_exists(path);
  if (!go.load_texture && (s = hearth_png_read(path, &colour, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/derived/mesh.glb", root, inst);
  if ((s = hearth_glb_read(path, &go, &mesh, err))) goto done;
  if (go.load_texture && mesh.texture.data) {
    colour = mesh.texture;
    memset(&mesh.texture, 0, sizeof mesh.texture);
  }
  snprintf(path, sizeof path, "%s/instances/%s/derived/%s/thermal_turbo.png", root, inst, state);
  if ((s = hearth_png_read(path, &turbo, err))) goto done;
  if (turbo.type != HEARTH_PIX_U8 || (colour.data && colour.type != HEARTH_PIX_U8)) {
    s = hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s/%s: 8-bit textures expected", inst, state);
    goto done;
  }
  snprintf(path, sizeof path, "%s/instances/%s/derived/poses_rgb.json", root, inst);
  if ((s = hearth_poses_read(path, &poses, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
  if ((s = hearth_manifest_read(path, &man, err))) goto done;
  if ((s = hearth_raycaster_new(&mesh, &rc, err))) goto done;
  if ((s = hearth_image_alloc(&pic, N_VIEWS * TILE, 2 * TILE, 3, HEARTH_PIX_U8, err))) goto done;
  double lo[3], hi[3], ctr[3], rad = 0;
  hearth_mesh_bounds(&mesh, lo, hi);
  for (int a = 0; a < 3; a++) {
    ctr[a] = 0.5 * (lo[a] + hi[a]);
    rad += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
  }
  rad = sqrt(rad);
  const double half_fov = 0.3490658503988659 /* 20 degrees */, tanh_ = tan(half_fov);
  const double dist = rad / sin(half_fov) * 1.05;
  uint8_t *px = pic.data;
  memset(px, 235, hearth_image_bytes(&pic));
  for (int k = 0; k < N_VIEWS && man.n_views; k++) {
    const hearth_view_files *vf = &man.views[(size_t)k * man.n_views / N_VIEWS];
    const hearth_view_pose *vp = hearth_poses_find(&poses, state, vf->view);
    if (!vp) {
      s = hearth_err_set(err, HEARTH_E_NOT_FOUND,
                         "%s/instances/%s/derived/poses_rgb.json: no pose for %s/%s", root, inst,
                         state, vf->view);
      goto done;
    }
    /* forward from the view's centre to the box centre; up: the view's -y */
    const hearth_rigid *T = &vp->T_world_from_cam;
    double fwd[3] = {ctr[0] - T->t[0], ctr[1] - T->t[1], ctr[2] - T->t[2]};
    normalize(fwd);
    double up0[3] = {-T->R[1], -T->R[4], -T->R[7]}, right[3], up[3];
    cross(fwd, up0, right);
    normalize(right);
    cross(right, fwd, up);
    double org[3] = {ctr[0] - dist * fwd[0], ctr[1] - dist * fwd[1], ctr[2] - dist * fwd[2]};
    for (int y = 0; y < TILE; y++)
      for (int x = 0; x < TILE; x++) {
        double sx = ((x + 0.5) / TILE * 2 - 1) * tanh_, sy = ((y + 0.5) / TILE * 2 - 1) * tanh_;
        double dir[3];
        for (int a = 0; a < 3; a++) dir[a] = fwd[a] + sx * right[a] - sy * up[a];
        normalize(dir);
        hearth_ray_hit hit;
        if (!hearth_raycast(rc, org, dir, 0.0, 4 * dist, &hit)) continue;
        const uint32_t *f = mesh.indices + 3 * (size_t)hit.prim;
        double w[3] = {1.0 - hit.b1 - hit.b2, hit.b1, hit.b2}, u = 0, v = 0, p[3][3];
        for (int c = 0; c < 3; c++) {
          u += w[c] * mesh.uvs[2 * (size_t)f[c]];
          v += w[c] * mesh.uvs[2 * (size_t)f[c] + 1];
          for (int a = 0; a < 3; a++) p[c][a] = mesh.positions[3 * (size_t)f[c] + a];
        }
        double e0[3], e1[3], nrm[3];
        for (int a = 0; a < 3; a++) e0[a] = p[1][a] - p[0][a], e1[a] = p[2][a] - p[0][a];
        cross(e0, e1, nrm);
        normalize(nrm);
        double c = fabs(nrm[0] * dir[0] + nrm[1] * dir[1] + nrm[2] * dir[2]);
        uint8_t *top = px + 3 * ((size_t)y * pic.width + (size_t)k * TILE + (size_t)x);
        uint8_t *bot = px + 3 * ((size_t)(y + TILE) * pic.width + (size_t)k * TILE + (size_t)x);
        if (colour.data) sample(&colour, u, v, 0.35 + 0.65 * c, top);
        else top[0] = top[1] = top[2] = (uint8_t)(60 + 170 * c);
        sample(&turbo, u, v, 1.0, bot);
      }
  }
  s = hearth_png_write(out_path, &pic, err);
done:
  hearth_raycaster_free(rc);
  hearth_image_free(&pic);
  hearth_image_free(&colour);
  hearth_image_free(&turbo);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&poses);
  hearth_manifest_free(&man);
  return s;
}
