/* hearth/synth.h - area synth (src/synth/): the virtual capture rig, a
 * digital twin of the paper's RGB-thermal-depth rig that writes a release
 * tree with ground truth.
 *
 * It is an independent forward model (scene -> sensor): thermal pixels
 * integrate the scene over their footprint through the distorting lens, then
 * optical blur and sensor noise are applied. It never runs a pipeline stage
 * backwards. Same options and seed, same bytes, for any thread count. What
 * it models, what it writes and every option: docs/virtual-rig.md. */
#ifndef HEARTH_SYNTH_H
#define HEARTH_SYNTH_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"
#include "hearth/camera.h"
#include "hearth/dataset.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_SYNTH_MAX_ITEMS 32

/* The physics of the object captures that make the rig as hard as a real
 * bench (docs/virtual-rig.md, "Object physics", gives the physics and the
 * source of every default). Each magnitude of 0 turns its effect off. */
typedef struct hearth_synth_effects {
  double emissivity;        /* scale of each material's (1 - normal emissivity); default 1,
                               0: black bodies */
  double grazing;           /* the Fresnel fall-off of emissivity towards grazing, blended in;
                               default 1, 0: the normal emissivity at every angle */
  double warm_source_c;     /* excess over ambient (degC) of a warm source (the operator)
                               mirrored by glossy surfaces; default 12, 0: none */
  double cooling;           /* scale of the Newton cooling rates (1 / tau); default 1, 0: the
                               state holds during the scan */
  double scan_s;            /* duration of a state's scan (s), three passes (elevations) of
                               equal length; default 300 */
  int restore;              /* 1: the state is restored before each pass (its time restarts);
                               default 0 */
  double camera_emissivity; /* the thermal camera's emissivity setting; default 0.95 */
  /* the calibration bench (docs/virtual-rig.md, "Calibration physics") */
  double plate_thickness_m; /* plate thickness; < 0 (default -1): drawn per seed in 3..6 mm;
                               0: an infinitely thin plate */
  double lamp;              /* scale of the lamp's uneven heating of the backing (a hot spot
                               and a gradient); default 1 */
  double plate_warming_c;   /* the plate's warming over the whole capture (degC); default 1.5 */
  double vignetting;        /* blend of a cos^4 fall-off of thermal contrast; default 0.3 */
  double fpn_offset_c;      /* fixed-pattern offset per thermal pixel (1 sigma, degC);
                               default 0.05 */
  double fpn_gain;          /* fixed-pattern gain per thermal pixel (1 sigma); default 0.01 */
  double motion_blur_px;    /* longest linear motion blur of a colour frame (px); default 2 */
  int jpeg_quality;         /* quality of the colour calibration JPEGs; default 90 (ideal: 92) */
  double trigger_ms;        /* longest trigger offset between the two cameras (ms); default 2 */
  double hand_speed_m_s;    /* speed of the hand-held plate (m/s); default 0.05 */
  double hand_turn_rad_s;   /* turn rate of the hand-held plate (rad/s); default 0.1 */
  double rs_readout_ms;     /* the colour camera's rolling-shutter readout of a full frame
                               (ms), rows exposed in turn while the plate moves; default 20 */
  double plate_bow_m;       /* largest bow of the plate (its centre against its corners, m),
                               drawn per seed in 0.5..1 of it, either sign; default 5e-5 */
  double plate_flex_m;      /* the hand-held plate's flex: each frame's bow changes by
                               U(-1, 1) of it (m); default 2e-4 */
  double plate_twist_m;     /* the hand-held plate's twist: each frame's corners rise and
                               fall by U(-1, 1) of it (a saddle, m); default 0 */
  double hole_burr_m;       /* irregularity of each hole's rim (burrs, drill wander): 1 sigma
                               of the first three Fourier terms of its radius (m); default 0 */
  double hole_position_m;   /* each hole's drilled position off its nominal one in the plate
                               plane: 1 sigma per axis (m), cut at 3 sigma, one draw per hole
                               and seed; the pipeline is given the nominal lattice; default
                               4e-5 */
  double plate_roll_deg;    /* the plate's turn in its own plane in each calibration frame,
                               drawn in -it..it degrees (the paper's plate only; other targets
                               and the ideal bench: 12); default 180 */
  double lens_residual_px;  /* the thermal lens's departure from its 5-parameter model in the
                               calibration captures: rms per axis (px) of a smooth field of
                               2.5..6 cycles across the image; default 0 */
  double rgb_residual_px;   /* the same for the colour camera against its factory model;
                               default 0 */
  double backing_texture;   /* the warm backing's mm-scale non-uniformity (heater traces,
                               paint): rms fraction of the hole contrast, waves of 6..15 mm;
                               default 0 */
} hearth_synth_effects;

/* Strings are borrowed: they must stay valid during hearth_synth_release. */
typedef struct hearth_synth_opts {
  uint64_t seed;        /* default 1 */
  const char *out_root; /* release root to create (must not exist, or be empty) */
  /* categories to make (hearth_synth_opts_default: one, "cup"); 0 = every
     procedural category */
  size_t n_categories;
  const char *categories[HEARTH_SYNTH_MAX_ITEMS];
  int instances_per_category; /* default 1 */
  /* states per instance; 0 = the category's defaults (neutral + its second state) */
  size_t n_states;
  const char *states[8];
  int n_views;           /* views per state, <= 30; default 30 (3 x 10) */
  size_t triangles;      /* target mesh detail; default 20000 (100..5000000) */
  size_t texture_size;   /* RGB texture side; default 1024 */
  size_t map_resolution; /* R of ground-truth temperature maps; default 1024 */
  int calibration;       /* write calibration/ captures; default 1 */
  int n_thermal_frames;  /* default 27 */
  int n_stereo_pairs;    /* default 24 */
  int rgb_full_size;     /* 1 (default): object colour views rendered at full size;
                                    0: draft, rendered at a quarter of the size and enlarged 4x to
                                    the full 1920x1080 frame (for tests only) */
  /* put a given UV-mapped GLB on the turntable instead of a procedural object */
  const char *mesh_path;
  double mesh_size_m;        /* largest extent after scaling; default 0.12 */
  const char *mesh_category; /* whose states to use; default "cup" */
  int contact_sheet;         /* write instances/<id>/raw/<state>/contact_sheet.png */
  int no_recon;              /* 1: no recon/ stand-in (a release for `hearth recon`);
                                ground_truth/ is written as always */
  double backdrop_tilt_deg;  /* the backdrop behind the turntable (a plane facing each
                                camera, 0.45 m behind the axis) leans back by this much,
                                its top away from the camera; default 0 (vertical) */
  double netd_c;             /* thermal noise, default 0.05 degC */
  /* the calibration target; zeroed (the default): the paper's plate and no
     calibration/target.json; set: that target, written to target.json */
  hearth_target target;
  size_t thermal_width, thermal_height; /* thermal sensor; 0 (default): 256 x 192 */
  int thermal_wide;                     /* a ~90 degree thermal lens, strong barrel distortion */
  /* calibration captures made to look like real ones (all 0 by default):
     clutter behind the plate (a window grid, a desk edge, a warm person in
     thermal), low contrast (holes a few degC / grey levels off the plate),
     inverted polarity (holes cooler in thermal, brighter in colour) */
  int calib_clutter, calib_low_contrast, calib_invert;
  int threads; /* 0 = hearth_default_threads() */
  int quiet;   /* no progress output */
  /* 1: the clean rig, every effect off (black bodies, no reflections, nothing
     cools; no view times in the manifests, no temperature_apparent.npy): the
     bytes of the rig before the effects, for closed-form tests. Default 0. */
  int ideal;
  hearth_synth_effects effects; /* used unless ideal */
} hearth_synth_opts;

void hearth_synth_opts_default(hearth_synth_opts *o);
/* The small clean release the simulator's commands make when given no
 * release: the eight categories tasks H1-H6 draw from, states neutral, hot
 * and iced, 6 views, 4000 triangles, 256-texel textures and maps, no
 * calibration, draft raw colour, quiet. out_root is left NULL. */
void hearth_synth_opts_sim_assets(hearth_synth_opts *o);
/* the default magnitudes of every effect */
void hearth_synth_effects_default(hearth_synth_effects *e);
/* Write a complete release tree (atomically: built under a temporary name
 * beside out_root, renamed at the end; removed on failure). */
hearth_status hearth_synth_release(const hearth_synth_opts *o, hearth_err *err);

/* A thermal-only calibration root (docs/dataset.md, "Thermal-only
 * calibration"): out_root/calibration/captures/thermal/IR_NNNN.<ext> and
 * ground_truth/rig.json (thermal-only, the true camera) and
 * ground_truth/calibration/detections.json (true centres). Written under a
 * temporary name and renamed; out_root must not exist. */
typedef struct hearth_synth_thermal_opts {
  uint64_t seed;        /* default 1 */
  const char *out_root; /* borrowed */
  int n_frames;         /* default 18 */
  int width, height;    /* default 256 x 192 */
  /* 0: the rig's drawn thermal lens (5-parameter); 1: a ~100 degree lens
   * with strong barrel distortion in OpenCV's rational model */
  int wide_angle;
  /* frame formats, used in turn: csv (degC), png8 (tone-mapped over the
   * frame's range), png8-dark (the same inverted: holes dark), png16 (raw
   * centikelvin counts), png-rgb (8-bit grey as RGB), tiff8, tiff16,
   * tiff-lzw (16-bit), tiff-deflate (8-bit), tiff-packbits (8-bit); comma
   * separated; default "csv,png8,png16,tiff8,tiff16" */
  const char *formats;
  double netd_c; /* default 0.05 degC */
  int threads;   /* 0 = hearth_default_threads() */
} hearth_synth_thermal_opts;
void hearth_synth_thermal_opts_default(hearth_synth_thermal_opts *o);
hearth_status hearth_synth_thermal_only(const hearth_synth_thermal_opts *o, hearth_err *err);
/* The true camera hearth_synth_thermal_only renders with. */
void hearth_synth_thermal_camera(const hearth_synth_thermal_opts *o, hearth_camera *c);

/* Names of the procedural categories available (static strings) into
 * names[0..max); returns how many there are (18), which may exceed max. */
size_t hearth_synth_categories(const char **names, size_t max);

#ifdef __cplusplus
}
#endif
#endif
