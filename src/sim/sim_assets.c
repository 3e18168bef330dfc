/* hearth assets as simulation objects: upright metric mesh, colour texture,
 * thermal Turbo texture, per-category mass and friction */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/geom.h"
#include "hearth/npy.h"
#include "hearth/dataset.h"
#include "sim/sim_internal.h"

/* masses are typical for the real objects; the narrow-extent caps keep
 * candidates within the Panda hand's 8 cm opening (the paper's
 * "simulation-scale parameters") */
static const sim_category k_cats[] = {
    {"cup", 0.20, 1.0, 0.062, 0.14},
    {"canned_drink", 0.30, 1.0, 0.062, 0.14},
    {"electric_kettle", 1.00, 1.0, 0.20, 0.20},
    {"eraser", 0.03, 1.0, 0.06, 0.07},
    {"orange", 0.18, 1.0, 0.07, 0.08},
    /* H4's pot is held by a handle, not across its body: 20 cm across the
     * body, 26 cm handle to handle at most; a light (aluminium) pot, so the
     * 15 N pinch on one handle holds it nearly level */
    {"pot", 0.20, 1.0, 0.20, 0.26},
    {"smartphone", 0.18, 1.2, 0.062, 0.15},
    {"sponge", 0.03, 1.5, 0.062, 0.11},
};

const sim_category *sim_category_find(const char *name) {
  for (size_t i = 0; i < sizeof k_cats / sizeof k_cats[0]; i++)
    if (strcmp(k_cats[i].name, name) == 0) return &k_cats[i];
  return NULL;
}

void sim_room_rgb(uint8_t rgb[3]) {
  hearth_turbo((SIM_ROOM_C - SIM_TLO) / (SIM_THI - SIM_TLO), rgb);
}

void sim_asset_free(sim_asset *a) {
  if (!a) return;
  hearth_mesh_free(&a->mesh);
  hearth_image_free(&a->rgb);
  hearth_image_free(&a->thermal);
  free(a->temp);
  memset(a, 0, sizeof *a);
}

/* first instance of the release whose instance.json names the category */
static hearth_status find_instance(const char *root, const char *category, char *id, size_t idsz,
                                   hearth_err *err) {
  char p[4096];
  snprintf(p, sizeof p, "%s/release.json", root);
  hearth_release_doc rd;
  memset(&rd, 0, sizeof rd);
  hearth_status st = hearth_release_read(p, &rd, err);
  if (st) return st;
  int found = 0;
  for (size_t i = 0; i < rd.n_instances && !found; i++) {
    hearth_instance_doc d;
    snprintf(p, sizeof p, "%s/instances/%s/instance.json", root, rd.instances[i]);
    if (hearth_instance_read(p, &d, NULL) == HEARTH_OK && strcmp(d.category, category) == 0) {
      snprintf(id, idsz, "%s", rd.instances[i]);
      found = 1;
    }
  }
  hearth_release_free(&rd);
  if (!found)
    return hearth_err_set(
        err, HEARTH_E_NOT_FOUND,
        "%s/release.json: no instance of category '%s' (the sim tasks need "
        "cup, canned_drink, electric_kettle, eraser, orange, pot, smartphone, sponge)",
        root, category);
  return HEARTH_OK;
}

/* grow valid texels into invalid ones so bilinear lookups at UV seams stay
 * clean; invalid texels beyond `iters` get `fill` */
static void dilate_rgb(uint8_t *rgb, uint8_t *valid, size_t R, int iters, const uint8_t fill[3]) {
  uint8_t *nv = malloc(R * R);
  if (!nv) return;
  for (int it = 0; it < iters; it++) {
    memcpy(nv, valid, R * R);
    for (size_t y = 0; y < R; y++)
      for (size_t x = 0; x < R; x++) {
        if (valid[y * R + x]) continue;
        int acc[3] = {0, 0, 0}, n = 0;
        for (int dy = -1; dy <= 1; dy++)
          for (int dx = -1; dx <= 1; dx++) {
            long yy = (long)y + dy, xx = (long)x + dx;
            if (yy < 0 || xx < 0 || yy >= (long)R || xx >= (long)R) continue;
            if (!valid[yy * R + xx]) continue;
            for (int c = 0; c < 3; c++) acc[c] += rgb[3 * (yy * R + xx) + c];
            n++;
          }
        if (n) {
          for (int c = 0; c < 3; c++) rgb[3 * (y * R + x) + c] = (uint8_t)(acc[c] / n);
          nv[y * R + x] = 1;
        }
      }
    memcpy(valid, nv, R * R);
  }
  for (size_t i = 0; i < R * R; i++)
    if (!valid[i]) memcpy(rgb + 3 * i, fill, 3);
  free(nv);
}

hearth_status sim_temp_turbo(const float *t, size_t R, hearth_image *out, hearth_err *err) {
  hearth_status st = hearth_image_alloc(out, R, R, 3, HEARTH_PIX_U8, err);
  uint8_t *valid = st ? NULL : malloc(R * R);
  if (!st && !valid) {
    hearth_image_free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory");
  }
  if (st) return st;
  uint8_t *px = out->data;
  for (size_t i = 0; i < R * R; i++) {
    valid[i] = isfinite(t[i]) ? 1 : 0;
    if (valid[i]) hearth_turbo((t[i] - SIM_TLO) / (SIM_THI - SIM_TLO), px + 3 * i);
  }
  uint8_t room[3];
  sim_room_rgb(room);
  dilate_rgb(px, valid, R, 4, room);
  free(valid);
  return HEARTH_OK;
}

/* temperature map -> Turbo texture with dilated seams */
static hearth_status thermal_texture(const char *path, hearth_image *out, float **temp,
                                     hearth_err *err) {
  hearth_npy a;
  memset(&a, 0, sizeof a);
  hearth_status st = hearth_npy_read(path, &a, err);
  if (st) return st;
  if (a.dtype != HEARTH_NPY_F32 || a.ndim != 2 || a.shape[0] != a.shape[1] || a.shape[0] < 2) {
    hearth_npy_free(&a);
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: expected a square float32 [R][R] map", path);
  }
  st = sim_temp_turbo(a.data, a.shape[0], out, err);
  if (st) hearth_err_prefix(err, "%s: ", path);
  if (!st) *temp = a.data, a.data = NULL; /* the map itself, kept for the thermal model */
  hearth_npy_free(&a);
  return st;
}

/* a Turbo image (10..60 degC) read back into temperatures: each texel the
 * nearest of 501 Turbo colours (0.1 degC apart) */
static hearth_status turbo_to_temp(const hearth_image *img, float **temp, hearth_err *err) {
  enum { N = 501 };
  uint8_t lut[N][3];
  for (int i = 0; i < N; i++) hearth_turbo((double)i / (N - 1), lut[i]);
  size_t n = img->width * img->height;
  float *t = hearth_alloc_array(n, sizeof(float));
  if (!t) return hearth_err_set(err, HEARTH_E_NOMEM, "sim: out of memory");
  const uint8_t *px = img->data;
  uint32_t last = 0xffffffffu;
  float last_t = 0;
  for (size_t i = 0; i < n; i++) {
    const uint8_t *c = px + (size_t)img->channels * i;
    uint32_t key = (uint32_t)c[0] << 16 | (uint32_t)c[1] << 8 | c[2];
    if (key != last) {
      int best = 0, bd = 1 << 30;
      for (int j = 0; j < N; j++) {
        int d0 = c[0] - lut[j][0], d1 = c[1] - lut[j][1], d2 = c[2] - lut[j][2];
        int d = d0 * d0 + d1 * d1 + d2 * d2;
        if (d < bd) bd = d, best = j;
      }
      last = key;
      last_t = (float)(SIM_TLO + (SIM_THI - SIM_TLO) * best / (N - 1));
    }
    t[i] = last_t;
  }
  *temp = t;
  return HEARTH_OK;
}

static hearth_status to_rgb(hearth_image *img, const char *name, hearth_err *err) {
  if (img->type != HEARTH_PIX_U8 || img->channels < 3)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s: expected an 8-bit RGB(A) texture", name);
  if (img->channels == 3) return HEARTH_OK;
  hearth_image o;
  hearth_status st = hearth_image_alloc(&o, img->width, img->height, 3, HEARTH_PIX_U8, err);
  if (st) return st;
  const uint8_t *s = img->data;
  uint8_t *d = o.data;
  for (size_t i = 0; i < img->width * img->height; i++)
    memcpy(d + 3 * i, s + (size_t)img->channels * i, 3);
  hearth_image_free(img);
  *img = o;
  return HEARTH_OK;
}

/* the object's up direction from the capture poses: turntable cameras keep
 * their x axis horizontal, so up is normal to every camera x axis. The
 * cross products of pairs of x axes (oriented by -mean(camera y), which
 * points roughly up) give it exactly even from two views, where the mean
 * of -y alone stays tilted by the elevations */
static hearth_status capture_up(const char *poses_path, double up[3], hearth_err *err) {
  hearth_poses ps;
  memset(&ps, 0, sizeof ps);
  hearth_status st = hearth_poses_read(poses_path, &ps, err);
  if (st) return st;
  double rough[3] = {0, 0, 0};
  for (size_t i = 0; i < ps.n; i++)
    for (int k = 0; k < 3; k++) rough[k] -= ps.views[i].T_world_from_cam.R[k * 3 + 1];
  up[0] = up[1] = up[2] = 0;
  for (size_t i = 0; i < ps.n; i++)
    for (size_t j = i + 1; j < ps.n; j++) {
      const double *Ri = ps.views[i].T_world_from_cam.R, *Rj = ps.views[j].T_world_from_cam.R;
      double xi[3] = {Ri[0], Ri[3], Ri[6]}, xj[3] = {Rj[0], Rj[3], Rj[6]}, c[3];
      hearth_cross3(xi, xj, c);
      double sgn = hearth_dot3(c, rough) < 0 ? -1.0 : 1.0;
      for (int k = 0; k < 3; k++) up[k] += sgn * c[k];
    }
  hearth_poses_free(&ps);
  /* views sharing one azimuth: fall back to the mean camera up */
  if (hearth_norm3(up) < 1e-3)
    for (int k = 0; k < 3; k++) up[k] = rough[k];
  double n = hearth_norm3(up);
  if (n < 1e-6)
    return hearth_err_set(err, HEARTH_E_NUMERIC, "%s: cannot tell the object's up direction",
                          poses_path);
  for (int k = 0; k < 3; k++) up[k] /= n;
  return HEARTH_OK;
}

/* rotate up to +z, the long horizontal axis to x, scale to the category's
 * caps, bottom centre to the origin */
static void make_upright(hearth_mesh *m, const double up[3], const sim_category *cat,
                         double size[3]) {
  double z[3] = {up[0], up[1], up[2]}, a[3] = {1, 0, 0}, x[3], y[3];
  if (fabs(z[0]) > 0.9) a[0] = 0, a[1] = 1;
  hearth_cross3(a, z, y);
  double n = hearth_norm3(y);
  for (int k = 0; k < 3; k++) y[k] /= n;
  hearth_cross3(y, z, x);
  double R[9] = {x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]}, t0[3] = {0, 0, 0};
  hearth_mesh_transform(m, 1.0, R, t0);
  /* principal horizontal axis */
  double mx = 0, my = 0, sxx = 0, sxy = 0, syy = 0;
  size_t nv = m->n_vertices;
  for (size_t i = 0; i < nv; i++) mx += m->positions[3 * i], my += m->positions[3 * i + 1];
  mx /= (double)nv, my /= (double)nv;
  for (size_t i = 0; i < nv; i++) {
    double dx = m->positions[3 * i] - mx, dy = m->positions[3 * i + 1] - my;
    sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
  }
  double ang = 0.5 * atan2(2 * sxy, sxx - syy);
  double c = cos(-ang), s = sin(-ang);
  double Rz[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
  hearth_mesh_transform(m, 1.0, Rz, t0);
  double lo[3], hi[3];
  hearth_mesh_bounds(m, lo, hi);
  double ext[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  double narrow = fmin(ext[0], ext[1]), big = fmax(ext[0], fmax(ext[1], ext[2]));
  double sc = 1.0;
  if (narrow * sc > cat->max_narrow) sc = cat->max_narrow / narrow;
  if (big * sc > cat->max_extent) sc = cat->max_extent / big;
  double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double t[3] = {-sc * 0.5 * (lo[0] + hi[0]), -sc * 0.5 * (lo[1] + hi[1]), -sc * lo[2]};
  hearth_mesh_transform(m, sc, I, t);
  for (int k = 0; k < 3; k++) size[k] = sc * ext[k];
}

hearth_status sim_asset_temperatures(sim_asset *a, hearth_err *err) {
  if (a->temp) return HEARTH_OK;
  if (a->thermal.width != a->thermal.height || a->thermal.channels < 3)
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "sim asset %s/%s: thermal texture %zux%zu is not square RGB", a->category,
                          a->state, a->thermal.width, a->thermal.height);
  hearth_status st = turbo_to_temp(&a->thermal, &a->temp, err);
  if (!st) a->temp_R = a->thermal.width;
  return st;
}

hearth_status sim_asset_load(const char *root, int use_gt, const char *category, const char *state,
                             sim_asset *a, hearth_err *err) {
  memset(a, 0, sizeof *a);
  const sim_category *cat = sim_category_find(category);
  if (!cat) return hearth_err_set(err, HEARTH_E_ARG, "sim: unknown category '%s'", category);
  char id[64], p[4096];
  hearth_status st = find_instance(root, category, id, sizeof id, err);
  if (st) return st;
  snprintf(a->instance, sizeof a->instance, "%s", id);
  snprintf(a->category, sizeof a->category, "%s", category);
  snprintf(a->state, sizeof a->state, "%s", state);
  a->mass = cat->mass;
  a->friction = cat->friction;
  hearth_glb_read_opts go = {.require_uvs = 1, .load_texture = 1};
  double up[3];
  if (use_gt) {
    snprintf(p, sizeof p, "%s/ground_truth/instances/%s/mesh.glb", root, id);
    st = hearth_glb_read(p, &go, &a->mesh, err);
    if (!st) {
      hearth_image_free(&a->mesh.texture);
      snprintf(p, sizeof p, "%s/instances/%s/recon/rgb_texture.png", root, id);
      st = hearth_png_read(p, &a->rgb, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/ground_truth/instances/%s/poses_rgb.json", root, id);
      st = capture_up(p, up, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/ground_truth/instances/%s/%s/temperature_true.npy", root, id,
               state);
      st = thermal_texture(p, &a->thermal, &a->temp, err);
      if (!st) a->temp_R = a->thermal.width;
    }
  } else {
    snprintf(p, sizeof p, "%s/instances/%s/derived/mesh.glb", root, id);
    st = hearth_glb_read(p, &go, &a->mesh, err);
    if (!st && !a->mesh.texture.data)
      st = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no embedded colour texture", p);
    if (!st) {
      a->rgb = a->mesh.texture;
      memset(&a->mesh.texture, 0, sizeof a->mesh.texture);
      snprintf(p, sizeof p, "%s/instances/%s/derived/poses_rgb.json", root, id);
      st = capture_up(p, up, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/instances/%s/derived/%s/thermal_turbo.png", root, id, state);
      st = hearth_png_read(p, &a->thermal, err);
      snprintf(a->map_dir, sizeof a->map_dir, "%s/instances/%s/derived/%s", root, id, state);
    }
  }
  if (!st) st = to_rgb(&a->rgb, "colour texture", err);
  if (!st) st = to_rgb(&a->thermal, "thermal texture", err);
  if (st) {
    sim_asset_free(a);
    return hearth_err_prefix(err, "sim asset %s/%s: ", category, state);
  }
  make_upright(&a->mesh, up, cat, a->size);
  return HEARTH_OK;
}
