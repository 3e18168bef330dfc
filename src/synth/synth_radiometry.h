/* Private to the virtual rig: the thermal camera's radiometry and the
 * objects' infrared surface properties (synth_radiometry.c), used by the
 * thermal renderer and the ground-truth writer when the object effects of
 * hearth_synth_effects are on. Physics and the source of every number:
 * docs/virtual-rig.md, "Object physics".
 *
 * Radiances are the band radiance of a black body over the camera's 8-14 um
 * band (Planck's law integrated), in arbitrary but consistent units. The
 * camera turns a radiance L into the temperature it shows as a radiometric
 * camera does: T such that eps_set B(T) + (1 - eps_set) B(T_refl) = L. */
#ifndef HEARTH_SYNTH_RADIOMETRY_H
#define HEARTH_SYNTH_RADIOMETRY_H

#include <stddef.h>
#include <stdint.h>

/* tabulated band radiance, -60..260 degC every 0.05 degC */
#define SYNTH_BAND_LO_C (-60.0)
#define SYNTH_BAND_STEP_C 0.05
#define SYNTH_BAND_N 6401

typedef struct synth_band {
  double L[SYNTH_BAND_N];
} synth_band;

/* Fill the table (Simpson's rule over 8-14 um). */
void synth_band_init(synth_band *b);
/* band radiance of a black body at t_c (clamped to the table) */
double synth_band_radiance(const synth_band *b, double t_c);
/* the black-body temperature of band radiance L (clamped to the table) */
double synth_band_temperature(const synth_band *b, double L);

/* The camera: the radiance of a surface it reads as t_app (degC), and
 * the temperature it shows for band radiance L, with its emissivity
 * setting eps_set and reflected temperature refl_c. */
double synth_camera_radiance(const synth_band *b, double eps_set, double refl_c, double t_app);
double synth_camera_reading(const synth_band *b, double eps_set, double refl_c, double L);

/* How a surface emits and reflects in the long-wave infrared. */
typedef enum synth_ir_kind {
  IR_DIELECTRIC, /* paint, glaze, plastic, glass, peel: Fresnel with a real index */
  IR_METAL       /* bare metal: Fresnel with a complex index n (1 + i) (Hagen-Rubens) */
} synth_ir_kind;

typedef struct synth_ir {
  double eps_n;       /* normal emissivity, 8-14 um */
  synth_ir_kind kind; /* how it falls off towards grazing */
  int glossy;         /* 1: reflects the surroundings specularly; 0: diffusely */
} synth_ir;

/* the infrared properties of albedo style s (synth_category.h's S_*) */
const synth_ir *synth_ir_of_style(int style);

/* Directional emissivity of m at |cos| of the angle from the normal,
 * with (1 - eps_n) scaled by eps_scale (0: a black body) and the fall-off
 * towards grazing blended in by grazing (0: eps_n at every angle). */
double synth_ir_emissivity(const synth_ir *m, double cos_theta, double eps_scale, double grazing);

/* The surface time constant (s) of Newton cooling towards ambient of a
 * category in a state (hot, warm, iced, used, neutral); categories outside
 * the table get the "others" row. */
double synth_cooling_tau_s(const char *category, const char *state);

#endif
