/* The virtual rig's release writer: draws the rig, captures the plate for
 * calibration, puts each object on the turntable, renders every view of
 * every state, and writes the reconstruction stand-in and the ground truth.
 * The tree is built under a temporary sibling and renamed into place. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "hearth/npy.h"
#include "hearth/dataset.h"
#include "hearth/thermal.h"
#include "synth/synth_rig.h"

#ifndef HEARTH_VERSION
#define HEARTH_VERSION "0.0.0"
#endif

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

void hearth_synth_opts_default(hearth_synth_opts *o) {
  memset(o, 0, sizeof *o);
  o->seed = 1;
  o->n_categories = 1;
  o->categories[0] = "cup";
  o->instances_per_category = 1;
  o->n_views = 30;
  o->triangles = 20000;
  o->texture_size = 1024;
  o->map_resolution = 1024;
  o->calibration = 1;
  o->n_thermal_frames = 27;
  o->n_stereo_pairs = 24;
  o->rgb_full_size = 1;
  o->mesh_size_m = 0.12;
  o->mesh_category = "cup";
  o->netd_c = 0.05;
  hearth_synth_effects_default(&o->effects);
}

void hearth_synth_opts_sim_assets(hearth_synth_opts *o) {
  static const char *const cats[] = {"cup",    "canned_drink", "electric_kettle", "eraser",
                                     "orange", "pot",          "smartphone",      "sponge"};
  hearth_synth_opts_default(o);
  o->ideal = 1; /* the clean rig: assets as before the effects */
  o->n_categories = sizeof cats / sizeof cats[0];
  for (size_t i = 0; i < o->n_categories; i++) o->categories[i] = cats[i];
  o->n_states = 3;
  o->states[0] = "neutral", o->states[1] = "hot", o->states[2] = "iced";
  o->n_views = 6; /* 2 azimuths per elevation: enough for the up direction */
  o->triangles = 4000;
  o->texture_size = 256;
  o->map_resolution = 256;
  o->calibration = 0;
  o->rgb_full_size = 0; /* draft raw colour frames: the simulator reads none of them */
  o->quiet = 1;
}

void hearth_synth_effects_default(hearth_synth_effects *e) {
  memset(e, 0, sizeof *e);
  e->emissivity = 1.0;
  e->grazing = 1.0;
  e->warm_source_c = 12.0;
  e->cooling = 1.0;
  e->scan_s = 300.0;
  e->camera_emissivity = 0.95;
  e->plate_thickness_m = -1.0;
  e->lamp = 1.0;
  e->plate_warming_c = 1.5;
  e->vignetting = 0.3;
  e->fpn_offset_c = 0.05;
  e->fpn_gain = 0.01;
  e->motion_blur_px = 2.0;
  e->jpeg_quality = 90;
  e->trigger_ms = 2.0;
  e->hand_speed_m_s = 0.05;
  e->hand_turn_rad_s = 0.1;
  e->rs_readout_ms = 20.0;
  e->plate_bow_m = 5e-5;
  e->plate_flex_m = 2e-4;
  e->hole_burr_m = 0.0;
  e->hole_position_m = 4e-5;
  e->plate_roll_deg = 180.0;
  e->lens_residual_px = 0.0;
  e->backing_texture = 0.0;
  e->plate_twist_m = 0.0;
  e->rgb_residual_px = 0.0;
}

size_t hearth_synth_categories(const char **names, size_t max) {
  return synth_object_categories(names, max);
}

/* ---- instances ------------------------------------------------------------------ */
static void random_rotation(hearth_rng *r, double R[9]) {
  /* uniform: a random unit quaternion from four normals */
  double q[4], n = 0;
  for (int i = 0; i < 4; i++) {
    q[i] = hearth_rng_normal(r);
    n += q[i] * q[i];
  }
  n = sqrt(n);
  double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  R[0] = 1 - 2 * (y * y + z * z);
  R[1] = 2 * (x * y - w * z);
  R[2] = 2 * (x * z + w * y);
  R[3] = 2 * (x * y + w * z);
  R[4] = 1 - 2 * (x * x + z * z);
  R[5] = 2 * (y * z - w * x);
  R[6] = 2 * (x * z - w * y);
  R[7] = 2 * (y * z + w * x);
  R[8] = 1 - 2 * (x * x + y * y);
}

hearth_status synth_instance_make(const hearth_synth_opts *o, const hearth_rig *rig,
                                  const char *category, int k, const hearth_mesh *mesh,
                                  synth_instance *inst, hearth_err *err) {
  memset(inst, 0, sizeof *inst);
  snprintf(inst->id, sizeof inst->id, "%s_%02d", category, k + 1);
  snprintf(inst->category, sizeof inst->category, "%s", category);
  hearth_rng base, r;
  hearth_rng_seed(&base, o->seed);
  hearth_rng_fork(&base, synth_hash(category) ^ ((uint64_t)(k + 1) * 0x9E3779B97F4A7C15ULL), &r);
  inst->seed = hearth_rng_u64(&r);
  size_t tex = o->texture_size ? o->texture_size : 1024;
  hearth_status st;
  if (mesh)
    st = synth_object_from_mesh(mesh, o->mesh_size_m > 0 ? o->mesh_size_m : 0.12, category, tex,
                                &inst->obj, err);
  else
    st = synth_object_make(category, inst->seed, o->triangles ? o->triangles : 20000, tex,
                           &inst->obj, err);
  if (st) return hearth_err_prefix(err, "%s: ", inst->id);

  /* states: given, or the category's defaults */
  const char *names[HEARTH_MAX_STATES];
  size_t ns = o->n_states;
  if (ns) {
    if (ns > HEARTH_MAX_STATES) ns = HEARTH_MAX_STATES;
    for (size_t i = 0; i < ns; i++) names[i] = o->states[i];
  } else {
    ns = synth_category_states(category, names, HEARTH_MAX_STATES);
  }
  if (!ns) {
    synth_instance_free(inst);
    return hearth_err_set(err, HEARTH_E_ARG, "%s: no states for category '%s'", inst->id, category);
  }
  inst->n_states = ns;
  inst->ambient_c = hearth_rng_range(&r, 21.0, 23.0);
  for (size_t i = 0; i < ns; i++) {
    snprintf(inst->states[i], HEARTH_NAME_MAX, "%s", names[i]);
    st = synth_field_make(&inst->obj, names[i], inst->seed ^ synth_hash(names[i]), inst->ambient_c,
                          &inst->fields[i], err);
    if (st) {
      synth_instance_free(inst);
      return hearth_err_prefix(err, "%s/%s: ", inst->id, names[i]);
    }
  }

  /* placement on the turntable, shared by all states */
  double yaw = hearth_rng_range(&r, 0, 2 * PI), w[3] = {0, 0, yaw};
  hearth_rotvec_to_matrix(w, inst->T_world_from_obj.R);
  inst->T_world_from_obj.t[0] = hearth_rng_range(&r, -0.004, 0.004);
  inst->T_world_from_obj.t[1] = hearth_rng_range(&r, -0.004, 0.004);
  inst->T_world_from_obj.t[2] = 0.0;

  /* bounding sphere in the world, and the distance that makes the object
   * fill a good part of the thermal frame */
  const hearth_mesh *m = &inst->obj.mesh;
  double lo[3], hi[3], c_obj[3], c[3], rad = 0;
  hearth_mesh_bounds(m, lo, hi);
  for (int i = 0; i < 3; i++) c_obj[i] = 0.5 * (lo[i] + hi[i]);
  for (size_t i = 0; i < m->n_vertices; i++) {
    double d2 = 0;
    for (int j = 0; j < 3; j++) d2 += pow(m->positions[3 * i + j] - c_obj[j], 2);
    if (d2 > rad * rad) rad = sqrt(d2);
  }
  hearth_rigid_apply(&inst->T_world_from_obj, c_obj, c);
  double half_v = atan(0.5 * rig->thermal.height / rig->thermal.fy);
  double dist = rad / sin(0.74 * half_v);
  if (dist < 0.25) dist = 0.25;
  if (dist > 1.5) dist = 1.5;
  double elev[3];
  for (int e = 0; e < 3; e++) elev[e] = (12.0 + 20.0 * e + hearth_rng_range(&r, -2, 2)) * DEG;
  double az0 = hearth_rng_range(&r, 0, 2 * PI);

  /* views: 3 elevations x 10 azimuths, or an evenly spread subset; each
   * state is its own pass, so its poses differ slightly */
  int nv = o->n_views <= 0 || o->n_views > 30 ? 30 : o->n_views;
  inst->n_views = (size_t)nv;
  for (size_t s = 0; s < ns; s++) {
    hearth_rng rs, renc;
    hearth_rng_fork(&r, 100 + s, &rs);
    hearth_rng_fork(&r, 0x656e63ULL + s, &renc); /* the encoder's error, a stream of its own */
    for (int v = 0; v < nv; v++) {
      int idx = v * 30 / nv, e = idx / 10, a = idx % 10;
      synth_view_def *vd = &inst->views[s][v];
      snprintf(vd->name, sizeof vd->name, "v%02d", idx);
      vd->index = idx;
      vd->elevation_index = e;
      vd->azimuth_index = a;
      double scan = o->effects.scan_s > 0 ? o->effects.scan_s : 300.0;
      vd->pass_s = e * scan / 3.0;
      vd->time_s = vd->pass_s + a * scan / 30.0;
      double daz = 36.0 * a + 12.0 * e + hearth_rng_range(&rs, -1.5, 1.5);
      double az = az0 + daz * DEG;
      vd->turntable_deg = round(1000.0 * (daz + 0.05 * hearth_rng_normal(&renc))) / 1000.0;
      double el = elev[e] + hearth_rng_range(&rs, -0.7, 0.7) * DEG;
      double dd = dist * (1.0 + hearth_rng_range(&rs, -0.02, 0.02));
      double eye[3] = {c[0] + dd * cos(el) * cos(az), c[1] + dd * cos(el) * sin(az),
                       c[2] + dd * sin(el)};
      /* the thermal camera (narrowest view) is aimed at the object */
      hearth_rigid T_world_from_th;
      synth_look_at(eye, c, &T_world_from_th);
      hearth_rigid_compose(&T_world_from_th, &rig->T_thermal_from_rgb, &vd->T_world_from_rgb);
    }
  }

  /* the reconstruction's unknown similarity */
  inst->scale = exp(hearth_rng_range(&r, log(0.3), log(3.0)));
  random_rotation(&r, inst->T_derived_from_world.R);
  for (int i = 0; i < 3; i++) inst->T_derived_from_world.t[i] = hearth_rng_range(&r, -1.0, 1.0);
  return HEARTH_OK;
}

void synth_instance_free(synth_instance *inst) {
  synth_object_free(&inst->obj);
  memset(inst, 0, sizeof *inst);
}

/* ---- small writers ----------------------------------------------------------------- */
static hearth_status mkdirf(hearth_err *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static hearth_status mkdirf(hearth_err *err, const char *fmt, ...) {
  char p[4096];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(p, sizeof p, fmt, ap);
  va_end(ap);
  return hearth_mkdirs(p, err);
}

/* calibration/factory.json: what the camera maker ships (colour, depth and
 * their extrinsic), the true values */
static hearth_status write_factory(const char *root, const hearth_rig *rig, hearth_err *err) {
  hearth_factory_calib f = {rig->rgb, rig->depth, rig->T_depth_from_rgb};
  char p[4096];
  snprintf(p, sizeof p, "%s/calibration/factory.json", root);
  return hearth_factory_write(p, &f, err);
}

/* ---- ground-truth temperature maps ----------------------------------------------------- */
typedef struct tmap_ctx {
  const synth_object *obj;
  const synth_field *field;
  const uint32_t *tri;
  const float *bary;
  size_t R;
  float *out;
} tmap_ctx;

static void tmap_rows(void *vctx, size_t b, size_t e, int ti) {
  tmap_ctx *c = vctx;
  const float *P = c->obj->mesh.positions;
  for (size_t i = b * c->R; i < e * c->R; i++) {
    uint32_t t = c->tri[i];
    if (t == UINT32_MAX) {
      c->out[i] = NAN;
      continue;
    }
    const uint32_t *id = c->obj->mesh.indices + 3 * (size_t)t;
    double p[3];
    for (int k = 0; k < 3; k++)
      p[k] = c->bary[3 * i] * P[3 * id[0] + k] + c->bary[3 * i + 1] * P[3 * id[1] + k] +
             c->bary[3 * i + 2] * P[3 * id[2] + k];
    c->out[i] = (float)synth_field_eval(c->field, c->obj, t, p);
  }
}

/* ---- one instance ------------------------------------------------------------------- */
/* nearest-neighbour 4x enlargement of a draft render to the full frame */
static hearth_status enlarge4(const hearth_image *src, size_t W, size_t H, hearth_image *dst,
                              hearth_err *err) {
  hearth_status st = hearth_image_alloc(dst, W, H, src->channels, HEARTH_PIX_U8, err);
  if (st) return st;
  size_t c = (size_t)src->channels;
  const uint8_t *a = src->data;
  uint8_t *b = dst->data;
  for (size_t y = 0; y < H; y++) {
    size_t sy = y / 4 < src->height ? y / 4 : src->height - 1;
    for (size_t x = 0; x < W; x++) {
      size_t sx = x / 4 < src->width ? x / 4 : src->width - 1;
      memcpy(b + (y * W + x) * c, a + (sy * src->width + sx) * c, c);
    }
  }
  return HEARTH_OK;
}

typedef struct render_ctx {
  const hearth_synth_opts *o;
  const hearth_rig *rig;
  const float *thermal_rays, *rgb_rays, *depth_rays;
  /* draft colour (rgb_full_size == 0, for tests): a quarter-size colour
     camera whose renders are enlarged 4x to the full frame */
  const hearth_rig *draft_rig;
  const float *draft_rgb_rays;
  hearth_progress *prog;
  int threads;
  const synth_band *band; /* the camera's band radiance; NULL: the clean rig (ideal) */
} render_ctx;

/* The warm source an instance's glossy surfaces mirror: the operator,
 * standing 0.9 m from the turntable axis at an azimuth drawn per instance
 * (a stream of its own), chest 0.45 m above the turntable top, as a sphere
 * of radius 0.25 m. */
static void warm_source(const synth_instance *inst, double src[4]) {
  hearth_rng r;
  hearth_rng_seed(&r, inst->seed ^ synth_hash("warm source"));
  double az = hearth_rng_range(&r, 0, 2 * PI);
  src[0] = 0.9 * cos(az);
  src[1] = 0.9 * sin(az);
  src[2] = 0.45;
  src[3] = 0.25;
}

/* the state's excess over ambient left at a view's time (Newton cooling) */
static double view_decay(const hearth_synth_effects *fx, const synth_instance *inst, size_t s,
                         const synth_view_def *vd) {
  double t = fx->restore ? vd->time_s - vd->pass_s : vd->time_s;
  double tau = synth_cooling_tau_s(inst->category, inst->states[s]);
  return exp(-fx->cooling * t / tau);
}

static hearth_status write_contact_sheet(const char *path, hearth_image *thumbs,
                                         hearth_image *temps, const synth_view_def *views, size_t n,
                                         hearth_err *err) {
  /* cells: a 256-wide colour thumbnail beside the thermal frame at its size */
  const size_t tw = 256, pad = 6, lab = 18;
  size_t th = n ? temps[0].height : 192, ttw = n ? temps[0].width : 256;
  if (th < 144) th = 144;
  size_t cols = n < 5 ? n : 5, rows = (n + cols - 1) / cols;
  size_t TW = tw + ttw + 3 * pad, TH = th + lab + 2 * pad;
  hearth_image sheet = {0};
  hearth_status st = hearth_image_alloc(&sheet, cols * TW, rows * TH, 3, HEARTH_PIX_U8, err);
  if (st) return st;
  memset(sheet.data, 32, hearth_image_bytes(&sheet));
  const uint8_t white[3] = {235, 235, 235}, nan_rgb[3] = {0, 0, 0};
  for (size_t i = 0; i < n && !st; i++) {
    size_t x0 = (i % cols) * TW, y0 = (i / cols) * TH;
    hearth_image tt = {0};
    st = hearth_turbo_image(&temps[i], 10.0, 60.0, nan_rgb, &tt, err);
    if (st) break;
    hearth_image_blit(&sheet, &thumbs[i], x0 + pad, y0 + pad + (th - thumbs[i].height) / 2);
    hearth_image_blit(&sheet, &tt, x0 + 2 * pad + tw, y0 + pad);
    hearth_image_free(&tt);
    char label[64];
    snprintf(label, sizeof label, "%s  e%d a%d", views[i].name, views[i].elevation_index,
             views[i].azimuth_index);
    hearth_draw_text(&sheet, x0 + pad, y0 + pad + th + 4, label, white, 2);
  }
  if (!st) st = hearth_png_write(path, &sheet, err);
  hearth_image_free(&sheet);
  return st;
}

static hearth_status render_state(const render_ctx *rc, const char *root, synth_instance *inst,
                                  const synth_scene *scene, size_t s, hearth_err *err) {
  const hearth_synth_opts *o = rc->o;
  const char *state = inst->states[s];
  char dir[4096], p[4096];
  snprintf(dir, sizeof dir, "%s/instances/%s/raw/%s", root, inst->id, state);
  hearth_status st;
  if ((st = mkdirf(err, "%s/rgb", dir)) || (st = mkdirf(err, "%s/cutout", dir)) ||
      (st = mkdirf(err, "%s/depth", dir)) || (st = mkdirf(err, "%s/thermal", dir)))
    return st;
  hearth_manifest man = {0};
  snprintf(man.instance, sizeof man.instance, "%s", inst->id);
  snprintf(man.state, sizeof man.state, "%s", state);
  man.n_views = inst->n_views;
  man.views = hearth_calloc_array(inst->n_views, sizeof *man.views);
  hearth_image *thumbs = NULL, *temps = NULL;
  if (o->contact_sheet) {
    thumbs = hearth_calloc_array(inst->n_views, sizeof *thumbs);
    temps = hearth_calloc_array(inst->n_views, sizeof *temps);
  }
  if (!man.views || (o->contact_sheet && (!thumbs || !temps))) {
    free(man.views);
    free(thumbs);
    free(temps);
    return hearth_err_set(err, HEARTH_E_NOMEM, "%s/%s: out of memory", inst->id, state);
  }
  hearth_depth_intrinsics di = {rc->rig->depth, rc->rig->T_depth_from_rgb};
  synth_thermal_fx tfx = {rc->band, &o->effects, inst->ambient_c, {0, 0, 0, 0}, 0, 1};
  warm_source(inst, tfx.source);
  tfx.source_c = inst->ambient_c + o->effects.warm_source_c;
  for (size_t v = 0; v < inst->n_views && !st; v++) {
    const synth_view_def *vd = &inst->views[s][v];
    tfx.decay = view_decay(&o->effects, inst, s, vd);
    synth_view_job job = {scene,
                          &inst->fields[s],
                          rc->rig,
                          rc->thermal_rays,
                          rc->rgb_rays,
                          rc->depth_rays,
                          vd->T_world_from_rgb,
                          inst->seed ^ synth_hash(state) ^ ((uint64_t)vd->index * 0x100000001B3ULL),
                          o->netd_c,
                          rc->threads,
                          rc->band ? &tfx : NULL};
    hearth_view_files *vf = &man.views[v];
    snprintf(vf->view, sizeof vf->view, "%s", vd->name);
    vf->elevation_index = vd->elevation_index;
    vf->azimuth_index = vd->azimuth_index;
    vf->has_turntable = 1;
    vf->turntable_deg = vd->turntable_deg;
    if (rc->band) {
      /* the operator's log: seconds since the state was prepared (or restored) */
      vf->has_time = 1;
      vf->time_s = o->effects.restore ? vd->time_s - vd->pass_s : vd->time_s;
    }
    snprintf(vf->rgb, sizeof vf->rgb, "rgb/%s.jpg", vd->name);
    snprintf(vf->cutout, sizeof vf->cutout, "cutout/%s.png", vd->name);
    snprintf(vf->depth, sizeof vf->depth, "depth/%s.png", vd->name);
    snprintf(vf->depth_intrinsics, sizeof vf->depth_intrinsics, "depth/%s.json", vd->name);
    snprintf(vf->thermal, sizeof vf->thermal, "thermal/%s.csv", vd->name);

    hearth_image th = {0}, rgb = {0}, mask = {0}, depth = {0};
    st = synth_render_thermal(&job, &th, err);
    if (!st) {
      snprintf(p, sizeof p, "%s/%s", dir, vf->thermal);
      st = hearth_thermal_write_csv(p, &th, 2, err);
    }
    if (!st && rc->draft_rig) {
      synth_view_job jd = job;
      jd.rig = rc->draft_rig;
      jd.rgb_rays = rc->draft_rgb_rays;
      hearth_image small = {0}, small_mask = {0};
      st = synth_render_rgb(&jd, &small, &small_mask, err);
      if (!st)
        st = enlarge4(&small, (size_t)rc->rig->rgb.width, (size_t)rc->rig->rgb.height, &rgb, err);
      if (!st)
        st = enlarge4(&small_mask, (size_t)rc->rig->rgb.width, (size_t)rc->rig->rgb.height, &mask,
                      err);
      hearth_image_free(&small);
      hearth_image_free(&small_mask);
    } else if (!st) {
      st = synth_render_rgb(&job, &rgb, &mask, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/%s", dir, vf->rgb);
      st = hearth_jpeg_write(p, &rgb, 92, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/%s", dir, vf->cutout);
      st = hearth_png_write(p, &mask, err);
    }
    if (!st) st = synth_render_depth(&job, &depth, err);
    if (!st) {
      snprintf(p, sizeof p, "%s/%s", dir, vf->depth);
      st = hearth_png_write(p, &depth, err);
    }
    if (!st) {
      snprintf(p, sizeof p, "%s/%s", dir, vf->depth_intrinsics);
      st = hearth_depth_intrinsics_write(p, &di, err);
    }
    if (!st && o->contact_sheet) {
      st = hearth_image_resize(&rgb, 256, 144, &thumbs[v], err);
      temps[v] = th;
      th.data = NULL;
    }
    hearth_image_free(&th);
    hearth_image_free(&rgb);
    hearth_image_free(&mask);
    hearth_image_free(&depth);
    if (st) hearth_err_prefix(err, "%s/%s/%s: ", inst->id, state, vd->name);
    hearth_progress_step(rc->prog, 1);
  }
  if (!st) {
    snprintf(p, sizeof p, "%s/manifest.json", dir);
    st = hearth_manifest_write(p, &man, err);
  }
  if (!st && o->contact_sheet) {
    snprintf(p, sizeof p, "%s/contact_sheet.png", dir);
    st = write_contact_sheet(p, thumbs, temps, inst->views[s], inst->n_views, err);
  }
  if (thumbs)
    for (size_t v = 0; v < inst->n_views; v++) {
      hearth_image_free(&thumbs[v]);
      hearth_image_free(&temps[v]);
    }
  free(thumbs);
  free(temps);
  free(man.views);
  return st;
}

/* poses of all states in the derived (metric) frame, optionally the thermal
 * camera, optionally noisy and divided by the scale (the recon hand-over) */
static hearth_status write_poses(const char *path, const synth_instance *inst,
                                 const hearth_rig *rig, int thermal, int recon, hearth_err *err) {
  hearth_poses ps = {0};
  ps.views = hearth_calloc_array(inst->n_states * inst->n_views, sizeof *ps.views);
  if (!ps.views) return hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory", path);
  hearth_rigid T_rgb_from_th;
  hearth_rigid_inverse(&rig->T_thermal_from_rgb, &T_rgb_from_th);
  hearth_rng base;
  hearth_rng_seed(&base, inst->seed ^ 0x5EC0115EULL);
  for (size_t s = 0; s < inst->n_states; s++)
    for (size_t v = 0; v < inst->n_views; v++) {
      const synth_view_def *vd = &inst->views[s][v];
      hearth_view_pose *vp = &ps.views[ps.n++];
      snprintf(vp->state, sizeof vp->state, "%s", inst->states[s]);
      snprintf(vp->view, sizeof vp->view, "%s", vd->name);
      hearth_rigid T;
      hearth_rigid_compose(&inst->T_derived_from_world, &vd->T_world_from_rgb, &T);
      if (thermal) hearth_rigid_compose(&T, &T_rgb_from_th, &T);
      if (recon) {
        /* the reconstruction's own pose error: ~0.15 deg, ~0.5 mm */
        hearth_rng r;
        hearth_rng_fork(&base, s * 1000 + (uint64_t)vd->index, &r);
        double w[3], dR[9];
        for (int k = 0; k < 3; k++) w[k] = 0.09 * DEG * hearth_rng_normal(&r);
        hearth_rotvec_to_matrix(w, dR);
        hearth_mat3_mul(dR, T.R, T.R);
        for (int k = 0; k < 3; k++)
          T.t[k] = (T.t[k] + 0.0003 * hearth_rng_normal(&r)) / inst->scale;
      }
      vp->T_world_from_cam = T;
    }
  hearth_status st = hearth_poses_write(path, &ps, err);
  free(ps.views);
  return st;
}

/* ---- ground truth of the object effects ---------------------------------------------- */
/* One state's effect maps over texel rows: the normal-incidence apparent
 * temperature at the start of the scan, and per texel what its views saw
 * (conditions.npy, docs/dataset.md): the best viewing cosine of a view
 * that sees it, the share of its views within 60 degrees of the normal in
 * which it mirrors the warm source, and the largest cooling drift of the
 * normal-incidence reading among those views. */
typedef struct fxmap_ctx {
  const render_ctx *rc;
  const synth_instance *inst;
  const synth_scene *scene;
  size_t s;
  const uint32_t *tri;
  const float *bary, *truth;
  size_t R;
  const hearth_rigid *T_th_from_world; /* per view */
  const double *decay;                 /* per view */
  double src[4];
  float *app, *cond;
  int failed;
} fxmap_ctx;

static double normal_reading(const fxmap_ctx *c, const synth_ir *m, double t) {
  const hearth_synth_effects *fx = &c->rc->o->effects;
  const synth_band *b = c->rc->band;
  double amb = c->inst->ambient_c, e = synth_ir_emissivity(m, 1.0, fx->emissivity, fx->grazing);
  double L = e * synth_band_radiance(b, t) + (1.0 - e) * synth_band_radiance(b, amb);
  return synth_camera_reading(b, fx->camera_emissivity, amb, L);
}

static void fxmap_rows(void *vctx, size_t b, size_t e, int ti) {
  fxmap_ctx *c = vctx;
  (void)ti;
  const synth_instance *inst = c->inst;
  const synth_object *obj = &inst->obj;
  const hearth_camera *cam = &c->rc->rig->thermal;
  const size_t R = c->R, nv = inst->n_views;
  const float *P = c->scene->world.positions;
  float *org = hearth_alloc_array(R * nv, 3 * sizeof(float));
  float *dir = hearth_alloc_array(R * nv, 3 * sizeof(float));
  hearth_ray_hit *hits = hearth_alloc_array(R * nv, sizeof *hits);
  double *dist = hearth_alloc_array(R * nv, sizeof(double));
  if (!org || !dir || !hits || !dist) {
    c->failed = 1;
    free(org);
    free(dir);
    free(hits);
    free(dist);
    return;
  }
  for (size_t y = b; y < e; y++) {
    size_t n = 0;
    for (size_t x = 0; x < R; x++) {
      size_t q = y * R + x;
      if (c->tri[q] == UINT32_MAX) continue;
      const uint32_t *id = obj->mesh.indices + 3 * (size_t)c->tri[q];
      double pw[3] = {0, 0, 0};
      for (int v = 0; v < 3; v++)
        for (int k = 0; k < 3; k++) pw[k] += c->bary[3 * q + v] * P[3 * id[v] + k];
      for (size_t v = 0; v < nv; v++, n++) {
        const hearth_rigid *T = &c->T_th_from_world[v];
        double o[3], d[3];
        /* the camera centre: -R^T t */
        for (int k = 0; k < 3; k++)
          o[k] = -(T->R[k] * T->t[0] + T->R[3 + k] * T->t[1] + T->R[6 + k] * T->t[2]);
        for (int k = 0; k < 3; k++) d[k] = pw[k] - o[k];
        double l = hearth_norm3(d);
        dist[n] = l;
        for (int k = 0; k < 3; k++) {
          org[3 * n + k] = (float)o[k];
          dir[3 * n + k] = (float)(d[k] / l);
        }
      }
    }
    if (n) hearth_raycast_batch(c->scene->rc, n, org, dir, 0.0f, 1e4f, hits);
    n = 0;
    for (size_t x = 0; x < R; x++) {
      size_t q = y * R + x;
      float *cd = c->cond + 3 * q;
      if (c->tri[q] == UINT32_MAX) {
        c->app[q] = NAN;
        cd[0] = cd[1] = cd[2] = NAN;
        continue;
      }
      uint32_t t = c->tri[q];
      int style = obj->style_of_tri ? obj->style_of_tri[t] : -1;
      const synth_ir *m = synth_ir_of_style(style);
      double amb = inst->ambient_c, t0 = c->truth[q], a0 = normal_reading(c, m, t0);
      c->app[q] = (float)a0;
      /* the world normal of the texel's triangle */
      const uint32_t *id = obj->mesh.indices + 3 * (size_t)t;
      double u[3], w[3], nrm[3];
      for (int k = 0; k < 3; k++) {
        u[k] = P[3 * id[1] + k] - P[3 * id[0] + k];
        w[k] = P[3 * id[2] + k] - P[3 * id[0] + k];
      }
      hearth_cross3(u, w, nrm);
      double nl = hearth_norm3(nrm);
      if (nl > 0)
        for (int k = 0; k < 3; k++) nrm[k] /= nl;
      double best = 0, drift = 0;
      int usable = 0, mirrored = 0;
      for (size_t v = 0; v < nv; v++, n++) {
        const hearth_ray_hit *h = &hits[n];
        if (h->prim == UINT32_MAX || !(h->prim == t || h->t > dist[n] - 1e-3)) continue;
        double pw[3], pc[3], uv[2], d[3];
        for (int k = 0; k < 3; k++) {
          d[k] = dir[3 * n + k];
          pw[k] = org[3 * n + k] + dist[n] * d[k];
        }
        hearth_rigid_apply(&c->T_th_from_world[v], pw, pc);
        if (!synth_lens_project(cam, pc, uv) || uv[0] < -0.5 || uv[1] < -0.5 ||
            uv[0] > cam->width - 0.5 || uv[1] > cam->height - 0.5)
          continue;
        double dn = hearth_dot3(nrm, d), cs = fabs(dn);
        if (cs > best) best = cs;
        if (cs < 0.5) continue;
        usable++;
        double at = normal_reading(c, m, amb + (t0 - amb) * c->decay[v]);
        if (fabs(at - a0) > drift) drift = fabs(at - a0);
        if (m->glossy && c->rc->o->effects.warm_source_c > 0) {
          double r[3], oc[3];
          for (int k = 0; k < 3; k++) {
            r[k] = d[k] - 2.0 * dn * nrm[k];
            oc[k] = c->src[k] - pw[k];
          }
          double tca = hearth_dot3(oc, r), d2 = hearth_dot3(oc, oc) - tca * tca;
          if (tca > 0 && d2 < c->src[3] * c->src[3]) mirrored++;
        }
      }
      cd[0] = (float)best;
      cd[1] = usable ? (float)mirrored / (float)usable : 0.0f;
      cd[2] = (float)drift;
    }
  }
  free(org);
  free(dir);
  free(hits);
  free(dist);
}

static hearth_status write_effect_maps(const render_ctx *rc, const char *gt,
                                       const synth_instance *inst, const synth_scene *scene,
                                       size_t s, const uint32_t *tri, const float *bary,
                                       const float *truth, hearth_err *err) {
  const size_t R = rc->o->map_resolution ? rc->o->map_resolution : 1024, nv = inst->n_views;
  fxmap_ctx c = {rc, inst, scene, s, tri, bary, truth, R, NULL, NULL, {0}, NULL, NULL, 0};
  hearth_rigid *T = hearth_alloc_array(nv, sizeof *T);
  double *decay = hearth_alloc_array(nv, sizeof *decay);
  c.app = hearth_alloc_array(R * R, sizeof(float));
  c.cond = hearth_alloc_array(R * R, 3 * sizeof(float));
  hearth_status st = HEARTH_OK;
  if (!T || !decay || !c.app || !c.cond)
    st = hearth_err_set(err, HEARTH_E_NOMEM, "%s/%s: effect maps: out of memory", inst->id,
                        inst->states[s]);
  if (!st) {
    for (size_t v = 0; v < nv; v++) {
      const synth_view_def *vd = &inst->views[s][v];
      hearth_rigid T_rgb_from_th, T_world_from_th;
      hearth_rigid_inverse(&rc->rig->T_thermal_from_rgb, &T_rgb_from_th);
      hearth_rigid_compose(&vd->T_world_from_rgb, &T_rgb_from_th, &T_world_from_th);
      hearth_rigid_inverse(&T_world_from_th, &T[v]);
      decay[v] = view_decay(&rc->o->effects, inst, s, vd);
    }
    c.T_th_from_world = T;
    c.decay = decay;
    warm_source(inst, c.src);
    hearth_parallel_for(R, rc->threads, fxmap_rows, &c);
    if (c.failed)
      st = hearth_err_set(err, HEARTH_E_NOMEM, "%s/%s: effect maps: out of memory", inst->id,
                          inst->states[s]);
  }
  char p[4096];
  if (!st) {
    size_t shape[2] = {R, R};
    snprintf(p, sizeof p, "%s/%s/temperature_apparent.npy", gt, inst->states[s]);
    st = hearth_npy_write(p, HEARTH_NPY_F32, 2, shape, c.app, err);
  }
  if (!st) {
    size_t shape[3] = {R, R, 3};
    snprintf(p, sizeof p, "%s/%s/conditions.npy", gt, inst->states[s]);
    st = hearth_npy_write(p, HEARTH_NPY_F32, 3, shape, c.cond, err);
  }
  free(T);
  free(decay);
  free(c.app);
  free(c.cond);
  return st;
}

/* ground_truth/instances/<id>/<state>/: the true temperature per texel at
 * the start of the scan, and with the object effects the normal-incidence
 * apparent temperature and the conditions of the texel's views */
static hearth_status write_truth_maps(const render_ctx *rc, const char *gt, synth_instance *inst,
                                      const synth_scene *scene, hearth_err *err) {
  const hearth_synth_opts *o = rc->o;
  char p[4096];
  hearth_status st = HEARTH_OK;
  /* true temperature per texel */
  size_t R = o->map_resolution ? o->map_resolution : 1024, RR;
  if (!hearth_mul_size(R, R, &RR)) return hearth_err_set(err, HEARTH_E_NOMEM, "map too large");
  uint32_t *tri = hearth_alloc_array(RR, sizeof(uint32_t));
  float *bary = hearth_alloc_array(RR, 3 * sizeof(float));
  float *map = hearth_alloc_array(RR, sizeof(float));
  if (!tri || !bary || !map) st = hearth_err_set(err, HEARTH_E_NOMEM, "map: out of memory");
  if (!st) st = hearth_uv_rasterize(&inst->obj.mesh, R, tri, bary, err);
  /* ground truth without surface would be all NaN: the UVs cover no texel */
  size_t covered = 0;
  for (size_t q = 0; !st && q < RR && !covered; q++) covered = tri[q] != UINT32_MAX;
  if (!st && !covered)
    st = hearth_err_set(err, HEARTH_E_RANGE,
                        "%s/%s: %s: the mesh's UV layout covers no texel of the %zux%zu "
                        "temperature_true map (surface 0 texels): its UVs lie outside [0,1] or "
                        "its UV triangles are too small to hold a texel centre",
                        inst->id, inst->states[0], o->mesh_path ? o->mesh_path : "generated mesh",
                        R, R);
  for (size_t s = 0; s < inst->n_states && !st; s++) {
    tmap_ctx c = {&inst->obj, &inst->fields[s], tri, bary, R, map};
    hearth_parallel_for(R, rc->threads, tmap_rows, &c);
    if ((st = mkdirf(err, "%s/%s", gt, inst->states[s]))) break;
    snprintf(p, sizeof p, "%s/%s/temperature_true.npy", gt, inst->states[s]);
    size_t shape[2] = {R, R};
    st = hearth_npy_write(p, HEARTH_NPY_F32, 2, shape, map, err);
    if (!st && rc->band) st = write_effect_maps(rc, gt, inst, scene, s, tri, bary, map, err);
  }
  free(tri);
  free(bary);
  free(map);
  return st;
}

static hearth_status write_instance(const render_ctx *rc, const char *root, synth_instance *inst,
                                    hearth_err *err) {
  const hearth_synth_opts *o = rc->o;
  char p[4096], gt[4096];
  snprintf(gt, sizeof gt, "%s/ground_truth/instances/%s", root, inst->id);
  hearth_status st;
  if ((st = mkdirf(err, o->no_recon ? "%s/instances/%s" : "%s/instances/%s/recon", root,
                   inst->id)) ||
      (st = hearth_mkdirs(gt, err)))
    return st;

  /* instance.json */
  hearth_instance_doc doc;
  memset(&doc, 0, sizeof doc);
  snprintf(doc.id, sizeof doc.id, "%s", inst->id);
  snprintf(doc.category, sizeof doc.category, "%s", inst->category);
  doc.n_states = inst->n_states;
  for (size_t s = 0; s < inst->n_states; s++)
    snprintf(doc.states[s], HEARTH_NAME_MAX, "%s", inst->states[s]);
  snprintf(doc.notes, sizeof doc.notes, "virtual rig, seed %llu, ambient %.1f C, %zu triangles%s",
           (unsigned long long)o->seed, inst->ambient_c, inst->obj.mesh.n_triangles,
           o->mesh_path ? ", mesh from a given GLB" : "");
  snprintf(p, sizeof p, "%s/instances/%s/instance.json", root, inst->id);
  if ((st = hearth_instance_write(p, &doc, err))) return st;

  /* raw captures */
  synth_scene scene;
  if ((st = synth_scene_init(&scene, &inst->obj, &inst->T_world_from_obj, inst->ambient_c, err)))
    return hearth_err_prefix(err, "%s: ", inst->id);
  scene.backdrop_tilt = o->backdrop_tilt_deg * (3.14159265358979323846 / 180.0);
  for (size_t s = 0; s < inst->n_states && !st; s++)
    st = render_state(rc, root, inst, &scene, s, err);
  if (!st) st = write_truth_maps(rc, gt, inst, &scene, err);
  synth_scene_free(&scene);
  if (st) return st;

  /* recon mesh: x_recon = (R_do x + t_do) / scale */
  hearth_rigid T_do;
  hearth_rigid_compose(&inst->T_derived_from_world, &inst->T_world_from_obj, &T_do);
  hearth_mesh m = {0};
  if ((st = hearth_mesh_copy(&inst->obj.mesh, &m, err))) return st;
  hearth_image_free(&m.texture);
  double t_s[3] = {T_do.t[0] / inst->scale, T_do.t[1] / inst->scale, T_do.t[2] / inst->scale};
  hearth_mesh_transform(&m, 1.0 / inst->scale, T_do.R, t_s);
  m.texture = inst->obj.albedo; /* borrowed for writing */
  snprintf(p, sizeof p, "%s/instances/%s/recon/mesh.glb", root, inst->id);
  st = o->no_recon ? HEARTH_OK : hearth_glb_write(p, &m, err);
  if (!st && !o->no_recon) {
    snprintf(p, sizeof p, "%s/instances/%s/recon/rgb_texture.png", root, inst->id);
    st = hearth_png_write(p, &inst->obj.albedo, err);
  }
  /* ground-truth mesh: the recon mesh brought to metric scale */
  if (!st) {
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, z[3] = {0, 0, 0};
    hearth_mesh_transform(&m, inst->scale, I, z);
    snprintf(p, sizeof p, "%s/mesh.glb", gt);
    st = hearth_glb_write(p, &m, err);
  }
  memset(&m.texture, 0, sizeof m.texture);
  hearth_mesh_free(&m);
  if (st) return st;

  snprintf(p, sizeof p, "%s/instances/%s/recon/poses_rgb.json", root, inst->id);
  if (!o->no_recon && (st = write_poses(p, inst, rc->rig, 0, 1, err))) return st;
  snprintf(p, sizeof p, "%s/poses_rgb.json", gt);
  if ((st = write_poses(p, inst, rc->rig, 0, 0, err))) return st;
  snprintf(p, sizeof p, "%s/poses_thermal.json", gt);
  if ((st = write_poses(p, inst, rc->rig, 1, 0, err))) return st;
  hearth_scale_doc sd = {inst->scale, (int)(inst->n_views * inst->n_states), 0.0};
  snprintf(p, sizeof p, "%s/scale.json", gt);
  if ((st = hearth_scale_doc_write(p, &sd, err))) return st;

  return HEARTH_OK;
}

/* ---- the release ----------------------------------------------------------------------- */
static int dir_is_empty(const char *path) {
  DIR *d = opendir(path);
  if (!d) return 0;
  struct dirent *e;
  int empty = 1;
  while ((e = readdir(d)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
      empty = 0;
      break;
    }
  closedir(d);
  return empty;
}

static hearth_status check_opts(const hearth_synth_opts *o, hearth_err *err) {
  if (!o->out_root || !*o->out_root)
    return hearth_err_set(err, HEARTH_E_ARG, "synth: no output directory given");
  if (o->n_views < 0 || o->n_views > 30)
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: views must be 1..30, got %d", o->n_views);
  if (o->instances_per_category < 0 || o->instances_per_category > 99)
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: instances must be 1..99, got %d",
                          o->instances_per_category);
  if (o->n_categories > HEARTH_SYNTH_MAX_ITEMS || o->n_states > HEARTH_MAX_STATES)
    return hearth_err_set(err, HEARTH_E_LIMIT, "synth: too many categories or states");
  if (o->texture_size && (o->texture_size < 16 || o->texture_size > 8192))
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: texture size must be 16..8192, got %zu",
                          o->texture_size);
  if (o->map_resolution && (o->map_resolution < 8 || o->map_resolution > 8192))
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: map resolution must be 8..8192, got %zu",
                          o->map_resolution);
  if (o->triangles && (o->triangles < 100 || o->triangles > 5000000))
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: triangles must be 100..5000000, got %zu",
                          o->triangles);
  if (o->calibration && (o->n_thermal_frames < 0 || o->n_thermal_frames > 999 ||
                         o->n_stereo_pairs < 0 || o->n_stereo_pairs > 999))
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: calibration frame counts must be 0..999");
  if (!(o->netd_c >= 0 && o->netd_c <= 5))
    return hearth_err_set(err, HEARTH_E_RANGE, "synth: NETD must be 0..5 degC");
  if ((o->thermal_width || o->thermal_height) &&
      (o->thermal_width < 64 || o->thermal_width > 1280 || o->thermal_height < 48 ||
       o->thermal_height > 1024))
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "synth: thermal size %zux%zu: expected 64..1280 x 48..1024",
                          o->thermal_width, o->thermal_height);
  if (o->target.rows) {
    hearth_status ts = hearth_target_check(&o->target, "synth: target", err);
    if (ts) return ts;
  }
  for (size_t i = 0; i < o->n_categories; i++)
    if (!o->categories[i] || !hearth_category_valid(o->categories[i]))
      return hearth_err_set(err, HEARTH_E_ARG, "synth: unknown category '%s'",
                            o->categories[i] ? o->categories[i] : "(null)");
  for (size_t i = 0; i < o->n_states; i++)
    if (!o->states[i] || !hearth_state_valid(o->states[i]))
      return hearth_err_set(err, HEARTH_E_ARG, "synth: unknown state '%s'",
                            o->states[i] ? o->states[i] : "(null)");
  if (o->mesh_path && o->mesh_category && !hearth_category_valid(o->mesh_category))
    return hearth_err_set(err, HEARTH_E_ARG, "synth: unknown mesh category '%s'", o->mesh_category);
  return HEARTH_OK;
}

static hearth_status build_tree(const hearth_synth_opts *o, const char *root, hearth_err *err) {
  hearth_rig rig;
  synth_rig_draw_thermal(o->seed, o->thermal_width ? (int)o->thermal_width : 256,
                         o->thermal_height ? (int)o->thermal_height : 192, o->thermal_wide, &rig);
  int threads = o->threads > 0 ? o->threads : hearth_default_threads();
  hearth_status st;
  if ((st = mkdirf(err, "%s/calibration", root)) || (st = mkdirf(err, "%s/ground_truth", root)) ||
      (st = mkdirf(err, "%s/instances", root)))
    return st;
  char p[4096];
  snprintf(p, sizeof p, "%s/ground_truth/rig.json", root);
  if ((st = hearth_rig_write(p, &rig, err))) return st;
  if ((st = write_factory(root, &rig, err))) return st;

  float *trays = synth_ray_table(&rig.thermal, 4, threads);
  float *crays = synth_ray_table(&rig.rgb, 1, threads);
  float *drays = synth_ray_table(&rig.depth, 1, threads);
  float *draft_rays = NULL;
  hearth_mesh given = {0};
  const char *defaults[64];
  const char *const *cats = o->categories;
  size_t ncat = o->n_categories;
  if (!trays || !crays || !drays) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "synth: ray tables: out of memory");
    goto done;
  }
  hearth_rng base, r;
  hearth_rng_seed(&base, o->seed);
  hearth_rng_fork(&base, synth_hash("calibration"), &r);
  if (o->calibration && o->target.rows) {
    snprintf(p, sizeof p, "%s/calibration/target.json", root);
    if ((st = hearth_target_write(p, &o->target, err))) goto done;
  }
  if (o->calibration) {
    st = synth_calibration_write(root, &rig, o, hearth_rng_u64(&r), trays, crays,
                                 hearth_rng_range(&r, 21.0, 23.0), err);
    if (st) goto done;
  }
  if (o->mesh_path) {
    hearth_glb_read_opts ro = {1, 1, 0};
    if ((st = hearth_glb_read(o->mesh_path, &ro, &given, err))) goto done;
    defaults[0] = o->mesh_category ? o->mesh_category : "cup";
    cats = defaults;
    ncat = 1;
  } else if (!ncat) {
    ncat = synth_object_categories(defaults, 64);
    cats = defaults;
  }
  int per = o->mesh_path ? 1 : (o->instances_per_category > 0 ? o->instances_per_category : 1);
  size_t total_views = 0;
  hearth_release_doc rel;
  memset(&rel, 0, sizeof rel);
  snprintf(rel.name, sizeof rel.name, "hearth virtual rig, seed %llu", (unsigned long long)o->seed);
  snprintf(rel.version, sizeof rel.version, "1.0");
  snprintf(rel.software_version, sizeof rel.software_version, "%s", HEARTH_VERSION);
  rel.instances = hearth_calloc_array(ncat * (size_t)per, HEARTH_NAME_MAX);
  if (!rel.instances) {
    st = hearth_err_set(err, HEARTH_E_NOMEM, "synth: out of memory");
    goto done;
  }
  {
    int nv = o->n_views <= 0 || o->n_views > 30 ? 30 : o->n_views;
    for (size_t ci = 0; ci < ncat; ci++) {
      const char *sn[HEARTH_MAX_STATES];
      size_t nst =
          o->n_states ? o->n_states : synth_category_states(cats[ci], sn, HEARTH_MAX_STATES);
      total_views += (size_t)per * nst * (size_t)nv;
    }
  }
  hearth_progress prog;
  hearth_progress_begin(&prog, "rendering views", total_views, o->quiet);
  synth_band *band = NULL;
  if (!o->ideal) {
    band = malloc(sizeof *band);
    if (!band) {
      st = hearth_err_set(err, HEARTH_E_NOMEM, "synth: out of memory");
      hearth_progress_end(&prog);
      hearth_release_free(&rel);
      goto done;
    }
    synth_band_init(band);
  }
  render_ctx rc = {o, &rig, trays, crays, drays, NULL, NULL, &prog, threads, band};
  hearth_rig draft_rig = rig;
  if (!o->rgb_full_size) {
    hearth_camera *dc = &draft_rig.rgb;
    dc->width /= 4;
    dc->height /= 4;
    dc->fx /= 4.0;
    dc->fy /= 4.0;
    dc->cx = (dc->cx + 0.5) / 4.0 - 0.5;
    dc->cy = (dc->cy + 0.5) / 4.0 - 0.5;
    draft_rays = synth_ray_table(dc, 1, threads);
    if (!draft_rays) {
      st = hearth_err_set(err, HEARTH_E_NOMEM, "synth: ray tables: out of memory");
      goto done;
    }
    rc.draft_rig = &draft_rig;
    rc.draft_rgb_rays = draft_rays;
  }
  for (size_t ci = 0; ci < ncat && !st; ci++)
    for (int k = 0; k < per && !st; k++) {
      synth_instance *inst = malloc(sizeof *inst);
      if (!inst) {
        st = hearth_err_set(err, HEARTH_E_NOMEM, "synth: out of memory");
        break;
      }
      st = synth_instance_make(o, &rig, cats[ci], k, o->mesh_path ? &given : NULL, inst, err);
      if (!st) {
        st = write_instance(&rc, root, inst, err);
        snprintf(rel.instances[rel.n_instances++], HEARTH_NAME_MAX, "%s", inst->id);
        synth_instance_free(inst);
      }
      free(inst);
    }
  hearth_progress_end(&prog);
  if (!st) {
    snprintf(p, sizeof p, "%s/release.json", root);
    st = hearth_release_write(p, &rel, err);
  }
  hearth_release_free(&rel);
  free(band);
done:
  hearth_mesh_free(&given);
  free(trays);
  free(crays);
  free(drays);
  free(draft_rays);
  return st;
}

hearth_status hearth_synth_release(const hearth_synth_opts *o, hearth_err *err) {
  hearth_status st = check_opts(o, err);
  if (st) return st;
  char root[4096], tmp[4200];
  size_t n = strlen(o->out_root);
  if (n >= sizeof root) return hearth_err_set(err, HEARTH_E_LIMIT, "synth: output path too long");
  memcpy(root, o->out_root, n + 1);
  while (n > 1 && root[n - 1] == '/') root[--n] = 0;
  struct stat sb;
  int existed = 0;
  if (stat(root, &sb) == 0) {
    if (!S_ISDIR(sb.st_mode) || !dir_is_empty(root))
      return hearth_err_set(err, HEARTH_E_ARG,
                            "%s: output exists and is not an empty directory; refusing to "
                            "overwrite",
                            root);
    existed = 1;
  }
  /* built beside root under the temporary pattern (core.h); trees that
   * killed earlier runs left there go first */
  if ((st = hearth_sweep_temps_of(root, NULL, err))) return st;
  if ((st = hearth_temp_dir(root, tmp, sizeof tmp, err))) return st;
  st = build_tree(o, tmp, err);
  if (!st) {
    if (existed && rmdir(root) != 0)
      st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot replace the empty directory: %s", root,
                          strerror(errno));
    else if (rename(tmp, root) != 0)
      st = hearth_err_set(err, HEARTH_E_IO, "%s: cannot rename %s into place: %s", root, tmp,
                          strerror(errno));
  }
  if (st) hearth_remove_tree(tmp, NULL);
  return st;
}
