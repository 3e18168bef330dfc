/* Private to the virtual rig: its cameras, its own lens model and the
 * renderers (synth_rig.c, synth_render.c, synth_plate.c, synth_release.c).
 *
 * The lens functions here are deliberately written apart from
 * hearth_camera_project/undistort: the rig is the test oracle of the
 * pipeline, so a mistake shared by both must not cancel out. */
#ifndef HEARTH_SYNTH_RIG_H
#define HEARTH_SYNTH_RIG_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/image.h"
#include "hearth/mesh.h"
#include "hearth/dataset.h"
#include "hearth/synth.h"
#include "synth/synth_object.h"
#include "synth/synth_radiometry.h"

/* ---- lens (synth_rig.c) --------------------------------------------------- */
/* Brown-Conrady [k1 k2 p1 p2 k3] on normalised coordinates. */
void synth_lens_distort(const double dist[5], double x, double y, double *xd, double *yd);
/* The camera's own model: the above, or OpenCV's rational model. */
void synth_lens_distort_cam(const hearth_camera *c, double x, double y, double *xd, double *yd);
/* Camera-frame point -> pixel; 0 if behind the camera. */
int synth_lens_project(const hearth_camera *c, const double Xc[3], double uv[2]);
/* Pixel -> ideal normalised (x, y); returns the residual in pixels. */
double synth_lens_unproject(const hearth_camera *c, double u, double v, double xy[2]);
/* Unit ray (camera frame) through pixel (u, v). */
void synth_lens_ray(const hearth_camera *c, double u, double v, double dir[3]);
/* Table of unit camera-frame rays for ss x ss sub-samples per pixel: entry
 * ((y * W + x) * ss * ss + j * ss + i) * 3 is the ray through
 * (x + (i + 0.5) / ss - 0.5, y + (j + 0.5) / ss - 0.5). malloc'ed. */
float *synth_ray_table(const hearth_camera *c, int ss, int threads);
/* The same table for a lens whose pixel (u, v) shows what c's model shows
 * at warp(warp_ctx, u, v) (a lens that departs from its model). */
typedef void (*synth_pixel_warp)(const void *warp_ctx, double u, double v, double q[2]);
float *synth_ray_table_warped(const hearth_camera *c, int ss, int threads, synth_pixel_warp warp,
                              const void *warp_ctx);

/* The rig drawn from a seed (realistic Femto Bolt + Mini2 ranges). */
void synth_rig_draw(uint64_t seed, hearth_rig *rig);
/* The same with a thermal sensor of thermal_w x thermal_h pixels and, if
 * wide, a ~90 degree lens with strong barrel distortion; 256, 192, 0 give
 * synth_rig_draw's rig exactly. */
void synth_rig_draw_thermal(uint64_t seed, int thermal_w, int thermal_h, int wide, hearth_rig *rig);
/* OpenCV-axes camera at eye looking at target, world z up. */
void synth_look_at(const double eye[3], const double target[3], hearth_rigid *T_world_from_cam);
/* Cheap approximately normal noise (sum of four 16-bit uniforms, unit
 * variance, tails cut at ~3.5 sigma) for the millions of pixel samples of
 * sensor noise where Box-Muller would dominate the run time. */
static inline double synth_fast_normal(hearth_rng *r) {
  uint64_t u = hearth_rng_u64(r);
  double s = (double)(u & 0xFFFF) + (double)((u >> 16) & 0xFFFF) + (double)((u >> 32) & 0xFFFF) +
             (double)(u >> 48);
  return (s - 131070.0) * (1.0 / 37837.23);
}
/* A 64-bit stream id for a name (FNV-1a). */
uint64_t synth_hash(const char *s);

/* ---- scene and renderers (synth_render.c) ----------------------------------- */
typedef struct synth_scene {
  const synth_object *obj;
  hearth_rigid T_world_from_obj;
  hearth_mesh world; /* object mesh placed in the world (no texture) */
  float *normals;    /* per-vertex normals, world, 3 per vertex */
  hearth_raycaster *rc;
  double centre[3], radius; /* bounding sphere of the object, world */
  double turntable_radius;
  double ambient_c;
  double backdrop_tilt; /* radians, the backdrop leaning back (0: vertical) */
} synth_scene;

hearth_status synth_scene_init(synth_scene *s, const synth_object *obj,
                               const hearth_rigid *T_world_from_obj, double ambient_c,
                               hearth_err *err);
void synth_scene_free(synth_scene *s);

/* The object effects of one thermal view (NULL in a job: the clean rig). */
typedef struct synth_thermal_fx {
  const synth_band *band;
  const hearth_synth_effects *fx;
  double ambient_c; /* the room, and the camera's reflected-temperature setting */
  double source[4]; /* the warm source: a sphere, centre (world) and radius (m) */
  double source_c;  /* its temperature */
  double decay;     /* the state's excess over ambient left at the view's time, exp(-t / tau) */
} synth_thermal_fx;

/* Everything a view render needs. Tables come from synth_ray_table:
 * thermal with ss = 4, rgb and depth with ss = 1. */
typedef struct synth_view_job {
  const synth_scene *scene;
  const synth_field *field;
  const hearth_rig *rig;
  const float *thermal_rays, *rgb_rays, *depth_rays;
  hearth_rigid T_world_from_rgb;
  uint64_t noise_seed; /* per view */
  double netd_c;
  int threads;
  const synth_thermal_fx *tfx; /* the object effects; NULL: none */
} synth_view_job;

/* Outputs: thermal 1-channel F32 (degC), rgb 3-channel U8, mask 1-channel
 * U8 (255 object, 0 background), depth 1-channel U16 (mm). */
hearth_status synth_render_thermal(const synth_view_job *job, hearth_image *out, hearth_err *err);
hearth_status synth_render_rgb(const synth_view_job *job, hearth_image *rgb, hearth_image *mask,
                               hearth_err *err);
hearth_status synth_render_depth(const synth_view_job *job, hearth_image *out, hearth_err *err);

/* Separable Gaussian blur of a 1-channel F32 image (edge clamped). */
hearth_status synth_blur_f32(hearth_image *img, double sigma, hearth_err *err);

/* ---- calibration captures (synth_plate.c) ------------------------------------ */
/* The target as the renderer uses it: hole centres in plate coordinates,
 * row starts, the pattern's extent and centre, the plate's half size. */
typedef struct synth_plate_geom {
  hearth_target t;
  size_t n;
  double step, r; /* row step, hole radius */
  int row_start[65];
  double holes[HEARTH_TARGET_MAX_HOLES][2];
  double ext_x, ext_y, cx, cy, half_w, half_h;
  /* the plate's bow: its front face at plate z = bow (1 - rho^2), rho^2 the
   * squared distance from the centre over half_w^2 + half_h^2 (0: flat) */
  double bow;
  /* the plate's twist: its front face adds twist (x - cx)(y - cy) / (half_w
   * half_h) (a saddle, corners +-twist; 0: none) */
  double twist;
  /* each hole's rim irregularity: radius r + sum_k a_k cos(k phi) + b_k
   * sin(k phi), k = 1..3, as {a1, b1, a2, b2, a3, b3}; burr_max bounds the
   * sum (0: round holes, burr unused) */
  double burr_max;
  float burr[HEARTH_TARGET_MAX_HOLES][6];
  /* the largest distance of a hole centre from its lattice position (holes
   * drilled off nominal; 0: exact) */
  double pos_max;
} synth_plate_geom;
/* target may be NULL or zeroed (the paper's plate, 200 x 150 mm). */
void synth_plate_geom_init(synth_plate_geom *g, const hearth_target *target);
/* Plate coordinates of the pattern centre (metres). */
void synth_plate_centre(const synth_plate_geom *g, double c[3]);

/* How real a calibration frame looks (all 0: the virtual rig's clean plate). */
typedef struct synth_plate_look {
  int clutter;      /* a window of panes, a desk edge, a person, hole-sized spots */
  int low_contrast; /* holes 2-4 degC above the plate; colour contrast ~0.2 */
  int invert;       /* holes cooler than the plate (thermal), brighter (colour) */
} synth_plate_look;

/* Write calibration/captures/... and ground_truth/calibration/detections.json
 * under root for the rig. */
hearth_status synth_calibration_write(const char *root, const hearth_rig *rig,
                                      const hearth_synth_opts *o, uint64_t seed,
                                      const float *thermal_rays, const float *rgb_rays,
                                      double ambient_c, hearth_err *err);
/* True centres of the target's holes in camera c for T_cam_from_plate into
 * centres[0..g->n); returns how many are wholly inside the image. */
int synth_plate_truth(const hearth_camera *c, const synth_plate_geom *g,
                      const hearth_rigid *T_cam_from_plate, double (*centres)[2]);
/* A plausible plate pose: pattern centre at distance d and normalised
 * offset (ox, oy), tilted 5..40 degrees, rolled up to 12. */
void synth_plate_pose(const synth_plate_geom *g, hearth_rng *r, double d, double ox, double oy,
                      hearth_rigid *T_cam_from_plate);
/* The same with the roll drawn in -roll_deg..roll_deg. */
void synth_plate_pose_rolled(const synth_plate_geom *g, hearth_rng *r, double d, double ox,
                             double oy, double roll_deg, hearth_rigid *T_cam_from_plate);
/* One calibration frame of the target at pose T in camera cam: thermal (F32
 * degC, 0.05 degC noise) or colour (U8 RGB), with the look (NULL: clean),
 * deterministic in seed. out is allocated (hearth_image_free). */
hearth_status synth_plate_frame(const hearth_camera *cam, const synth_plate_geom *g,
                                const hearth_rigid *T, int thermal, const synth_plate_look *look,
                                uint64_t seed, int threads, hearth_image *out, hearth_err *err);
/* A thermal frame as an 8-bit tone-mapped image (min..max, gamma 1/1.4),
 * the way cameras without a radiometric export save it. */
hearth_status synth_tone_map8(const hearth_image *temps, hearth_image *out, hearth_err *err);

/* One thermal-only frame of the target g at T_cam_from_plate (1-channel F32,
 * degC): plate ambient + plate_dt, holes ambient + hole_dt, Gaussian blur,
 * noise netd (seeded by noise_seed); rays from synth_ray_table(cam, 4). */
hearth_status synth_plate_thermal_frame(const hearth_camera *cam, const synth_plate_geom *g,
                                        const hearth_rigid *T, const float *rays, double ambient,
                                        double plate_dt, double hole_dt, double blur, double netd,
                                        uint64_t noise_seed, int threads, hearth_image *out,
                                        hearth_err *err);

/* ---- instances (synth_release.c) ---------------------------------------------- */
/* One instance as the rig captures it; shared with the tests so they can
 * check the files against the scene they came from. */
typedef struct synth_view_def {
  char name[8]; /* "v07" */
  int index, elevation_index, azimuth_index;
  hearth_rigid T_world_from_rgb;
  double time_s;        /* from the start of the state's scan: its pass (elevation) starts at
                    elevation_index * scan / 3, views every scan / 30 */
  double pass_s;        /* the start of its pass */
  double turntable_deg; /* the encoder's reading: the view's azimuth from the
                           instance's start, with a 0.05-degree (sigma) error */
} synth_view_def;

typedef struct synth_instance {
  char id[HEARTH_NAME_MAX];
  char category[HEARTH_NAME_MAX];
  uint64_t seed;
  synth_object obj;
  hearth_rigid T_world_from_obj;
  double ambient_c;
  size_t n_states;
  char states[HEARTH_MAX_STATES][HEARTH_NAME_MAX];
  synth_field fields[HEARTH_MAX_STATES];
  size_t n_views;
  synth_view_def views[HEARTH_MAX_STATES][30];
  /* recon frame: x_derived = T_derived_from_world x_world, x_recon = x_derived / scale */
  hearth_rigid T_derived_from_world;
  double scale;
} synth_instance;

/* Build instance k (0-based) of category for the options (object, fields,
 * placement, views, recon similarity), deterministic in (o->seed, category,
 * k). mesh may be NULL (procedural). */
hearth_status synth_instance_make(const hearth_synth_opts *o, const hearth_rig *rig,
                                  const char *category, int k, const hearth_mesh *mesh,
                                  synth_instance *inst, hearth_err *err);
void synth_instance_free(synth_instance *inst);

#endif
