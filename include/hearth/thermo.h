/* hearth/thermo.h - area thermo (src/thermo/): a lumped (reduced-order)
 * thermal network per asset, so that an asset's temperatures can change
 * over a simulated episode. Model and parameters: docs/thermal-model.md.
 *
 * A network has n <= HEARTH_THERMO_MAX_REGIONS regions (body, handle, lid,
 * liquid...), each with a heat capacity C_i (J/K) and a temperature T_i
 * (degC). Regions exchange heat through symmetric conductances G_ij (W/K),
 * with the air at T_air through convection h_i*A_i plus radiation
 * eps_i*sigma*A_i*(T_i^4 - T_air^4), and with contact links the caller sets
 * each step (a table, gripper fingers, another network's region).
 *
 * Integration is backward Euler, stable for any step: each step solves
 *   (C/dt + L + D) dT = -(L + D) T + D T_air + sum_c G_c T_c + P
 * (L: the conductance Laplacian, D: the diagonal of air and contact
 * conductances), a small dense solve. Radiation enters D through its secant
 * conductance eps*sigma*A*(T^2 + Ta^2)(T + Ta) (kelvin) evaluated at the
 * step's start, so every step is linear with a non-negative conductance
 * matrix: the system is an M-matrix, temperatures obey a maximum principle
 * (no overshoot past the hottest and coldest of T, T_air and the contact
 * temperatures) and, with no air, contacts or sources, sum C_i T_i is
 * conserved to rounding at any dt. */
#ifndef HEARTH_THERMO_H
#define HEARTH_THERMO_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HEARTH_THERMO_MAX_REGIONS 16
#define HEARTH_THERMO_MAX_CONTACTS 32
/* networks one coupled step may join */
#define HEARTH_THERMO_MAX_NETS 8
#define HEARTH_THERMO_MAX_CLUSTERS 6
#define HEARTH_THERMO_SIGMA 5.670374419e-8 /* Stefan-Boltzmann, W/(m^2 K^4) */
#define HEARTH_THERMO_NAME_MAX 32
/* a region that owns no texels of the texture (e.g. the liquid) */
#define HEARTH_THERMO_NO_LABEL 255

typedef struct hearth_thermo_region {
  char name[HEARTH_THERMO_NAME_MAX]; /* 1..31 of [A-Za-z0-9_-] */
  double C;                          /* heat capacity, J/K, > 0 */
  double T;                          /* temperature, degC */
  double area;                       /* area exposed to the air, m^2, >= 0 */
  double h_conv;                     /* convection coefficient, W/(m^2 K), >= 0 */
  double emissivity;                 /* 0..1 */
  double power;                      /* heat put in by the caller, W (a heater; 0 by default) */
  int label;                         /* texture region label (0..5), or -1: owns no texels */
} hearth_thermo_region;

/* A contact link of region `region` to a body at a fixed temperature (the
 * table, a finger) for the next step: conductance G = h_contact * area. */
typedef struct hearth_thermo_contact {
  size_t region;
  double G;       /* W/K, >= 0 */
  double T_other; /* degC */
} hearth_thermo_contact;

typedef struct hearth_thermo_net {
  size_t n;
  hearth_thermo_region region[HEARTH_THERMO_MAX_REGIONS];
  double G[HEARTH_THERMO_MAX_REGIONS][HEARTH_THERMO_MAX_REGIONS]; /* symmetric, zero diagonal */
  double T_air;                                                   /* degC */
  size_t n_contacts;
  hearth_thermo_contact contact[HEARTH_THERMO_MAX_CONTACTS];
} hearth_thermo_net;

/* an empty network (n = 0, T_air = 20 degC) */
void hearth_thermo_net_init(hearth_thermo_net *net);
/* append a region; its index in *index (may be NULL) */
hearth_status hearth_thermo_add_region(hearth_thermo_net *net, const hearth_thermo_region *r,
                                       size_t *index, hearth_err *err);
/* set G_ij = G_ji = g (W/K, >= 0; 0 removes the link) */
hearth_status hearth_thermo_set_conductance(hearth_thermo_net *net, size_t i, size_t j, double g,
                                            hearth_err *err);
/* contact links to external bodies at a fixed temperature, set per step */
hearth_status hearth_thermo_add_contact(hearth_thermo_net *net, size_t region, double G,
                                        double T_other, hearth_err *err);
void hearth_thermo_clear_contacts(hearth_thermo_net *net);
/* region index by name, or HEARTH_E_NOT_FOUND */
hearth_status hearth_thermo_find(const hearth_thermo_net *net, const char *name, size_t *index,
                                 hearth_err *err);
/* check every field (finite, in range, G symmetric); names the bad field */
hearth_status hearth_thermo_net_check(const hearth_thermo_net *net, hearth_err *err);

/* total energy sum C_i T_i (J, relative to 0 degC) */
double hearth_thermo_energy(const hearth_thermo_net *net);
/* the heat-capacity weighted mean temperature (degC); NAN for a network
 * without heat capacity */
double hearth_thermo_mean_temperature(const hearth_thermo_net *net);
/* One backward Euler step of dt seconds (> 0; any size is stable).
 * heat_in (may be NULL) receives the heat taken from outside during the
 * step (J: air, contacts and power), so that the energy after the step is
 * the energy before plus *heat_in, to rounding. */
hearth_status hearth_thermo_step(hearth_thermo_net *net, double dt, double *heat_in,
                                 hearth_err *err);

/* A contact link between region ra of nets[a] and region rb of nets[b]
 * (two objects touching): the coupled step conserves the energy they
 * exchange. */
typedef struct hearth_thermo_link {
  size_t a, ra, b, rb;
  double G; /* W/K, >= 0 */
} hearth_thermo_link;
/* One backward Euler step of all nets together (n_nets <= HEARTH_THERMO_MAX_NETS),
 * joined by links. */
hearth_status hearth_thermo_step_coupled(hearth_thermo_net *const *nets, size_t n_nets,
                                         const hearth_thermo_link *links, size_t n_links, double dt,
                                         double *heat_in, hearth_err *err);
/* The same step with heat_in (may be NULL) an array of n_nets: each
 * network's heat from outside the joined system (its air, contacts and
 * power, J). The heat a network got through links is its energy change
 * minus its heat_in; over all networks those sum to zero, to rounding. */
hearth_status hearth_thermo_step_coupled_each(hearth_thermo_net *const *nets, size_t n_nets,
                                              const hearth_thermo_link *links, size_t n_links,
                                              double dt, double *heat_in, hearth_err *err);

/* ---- regions over a texture ---------------------------------------------- */
/* Texel regions from a temperature map (hearth_map_result's R, mask,
 * observed and filled arrays; include/hearth/map.h): k-means (k <= 6) on
 * the observed texels' temperatures and, where island (R*R UV island ids,
 * may be NULL) is given, every island's texels take the label most of its
 * observed texels have. mean[l] is the mean observed temperature of region
 * l; offset[t] = filled[t] - mean[label[t]] keeps the texture's detail, so
 * the texture at any time is T[label] + offset. Texels without a value
 * (mask NONE or UNOBSERVED) have label HEARTH_THERMO_NO_LABEL (NONE) or the
 * largest region (UNOBSERVED) and offset 0. Empty clusters are dropped
 * (k_out <= k). Deterministic. */
typedef struct hearth_thermo_regions {
  size_t R;
  size_t k;                                /* regions found */
  uint8_t *label;                          /* R*R */
  float *offset;                           /* R*R, degC */
  double mean[HEARTH_THERMO_MAX_CLUSTERS]; /* degC */
  size_t n_observed[HEARTH_THERMO_MAX_CLUSTERS];
  size_t n_texels[HEARTH_THERMO_MAX_CLUSTERS];
} hearth_thermo_regions;
hearth_status hearth_thermo_regions_from_map(size_t R, const uint8_t *mask, const float *observed,
                                             const float *filled, const uint32_t *island, size_t k,
                                             hearth_thermo_regions *out, hearth_err *err);
/* frees the arrays and zeroes r; accepts a zeroed struct */
void hearth_thermo_regions_free(hearth_thermo_regions *r);
/* out[t] = T_label[label[t]] + offset[t] (R*R floats; NaN where label is
 * HEARTH_THERMO_NO_LABEL) */
void hearth_thermo_regions_texture(const hearth_thermo_regions *r, const double *T_label,
                                   float *out);

/* ---- parameters per category (docs/thermal-model.md has the sources) ------- */
typedef struct hearth_thermo_material {
  const char *name;
  double c; /* specific heat, J/(kg K) */
  double k; /* conductivity, W/(m K) */
  double emissivity;
  const char *source; /* short reference key of docs/thermal-model.md */
} hearth_thermo_material;
/* the material table entry or NULL */
const hearth_thermo_material *hearth_thermo_material_find(const char *name);
/* natural convection in still air for small objects, W/(m^2 K) */
#define HEARTH_THERMO_H_NATURAL 7.0

/* The network of a category's typical object (regions, C from mass and c,
 * areas, emissivities, conductances between regions) at temperature T0 in
 * air at T_air. Categories: "cup" (ceramic body + 0.30 kg of liquid),
 * "can" (painted aluminium + 0.33 kg of liquid), "plate" (ceramic). */
hearth_status hearth_thermo_category_net(const char *category, double T0, double T_air,
                                         hearth_thermo_net *net, hearth_err *err);

/* ---- thermal_model.json (schema: docs/thermal-model.md) ---------------------- */
typedef struct hearth_thermo_model {
  char category[HEARTH_THERMO_NAME_MAX];
  hearth_thermo_net net; /* contacts are never stored */
  char offsets[256];     /* texture offsets file relative to the document, or "" */
} hearth_thermo_model;
/* strict: unknown keys, wrong types, bad ranges and unknown region names
 * are errors naming `name` and the JSON path */
hearth_status hearth_thermo_model_parse(const char *text, size_t len, const char *name,
                                        hearth_thermo_model *out, hearth_err *err);
hearth_status hearth_thermo_model_read(const char *path, hearth_thermo_model *out, hearth_err *err);
/* written atomically, deterministic text, validated by the parser first */
hearth_status hearth_thermo_model_write(const char *path, const hearth_thermo_model *m,
                                        hearth_err *err);

#ifdef __cplusplus
}
#endif

#endif
