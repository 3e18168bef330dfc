/* thermo_params.c - material properties and the typical network of each
 * object category. Every number's source is in docs/thermal-model.md under
 * the key given in `source`. */
#include <math.h>
#include <string.h>

#include "hearth/thermo.h"

static const hearth_thermo_material k_materials[] = {
    /* name               c (J/kg K)  k (W/m K)  emissivity  source */
    {"ceramic", 920.0, 1.3, 0.90, "ETB-c, OMEGA-eps"},
    {"water", 4179.0, 0.613, 0.96, "INC-A6, IDEAL-eps"},
    {"aluminium", 903.0, 237.0, 0.09, "INC-A1, FLIR-eps"},
    {"aluminium_painted", 903.0, 237.0, 0.94, "INC-A1, IDEAL-eps"},
    {"glass", 840.0, 1.4, 0.94, "ETB-c, INC-A3, IDEAL-eps"},
    {"stainless_steel", 477.0, 14.9, 0.16, "INC-A1, IDEAL-eps"},
    {"rubber", 2010.0, 0.13, 0.90, "INC-A3"},
    {"urethane_foam", 1045.0, 0.026, 0.90, "INC-A3"},
};

const hearth_thermo_material *hearth_thermo_material_find(const char *name) {
  for (size_t i = 0; i < sizeof k_materials / sizeof k_materials[0]; i++)
    if (strcmp(k_materials[i].name, name) == 0) return &k_materials[i];
  return NULL;
}

/* One region of a category's typical object: its material, mass, area in
 * the air, convection (the free liquid surface adds the heat carried by
 * evaporation as an equivalent coefficient) and texture label. */
typedef struct region_tpl {
  const char *name;
  const char *material;
  double mass; /* kg */
  double area; /* m^2 */
  double h;    /* W/(m^2 K) */
  int label;
} region_tpl;

/* a conductance between two regions of the template, W/K */
typedef struct link_tpl {
  const char *a, *b;
  double G;
} link_tpl;

typedef struct category_tpl {
  const char *name;
  region_tpl regions[4];
  size_t n_regions;
  link_tpl links[4];
  size_t n_links;
} category_tpl;

/* free water surface: natural convection plus evaporation, as an equivalent
 * coefficient (docs/thermal-model.md, "liquid surface") */
#define H_LIQUID_SURFACE 40.0

/* Geometry: a 300 ml mug 8 cm across, 9.5 cm tall, 5 mm wall, 0.35 kg; a
 * 330 ml can 6.6 cm across, 11.5 cm tall, 15 g; a 26 cm plate, 0.6 kg.
 * Wall conductances: k * wetted area / wall thickness in series with the
 * liquid's inner natural convection (about 300 W/(m^2 K) on 0.02 m^2). */
static const category_tpl k_categories[] = {
    {"cup",
     {{"body", "ceramic", 0.35, 0.027, HEARTH_THERMO_H_NATURAL, 0},
      {"liquid", "water", 0.30, 0.0043, H_LIQUID_SURFACE, -1}},
     2,
     {{"body", "liquid", 3.0}},
     1},
    {"can",
     {{"body", "aluminium_painted", 0.015, 0.027, HEARTH_THERMO_H_NATURAL, 0},
      {"liquid", "water", 0.33, 0.0, 0.0, -1}},
     2,
     {{"body", "liquid", 6.0}},
     1},
    {"plate",
     {{"body", "ceramic", 0.60, 0.106, HEARTH_THERMO_H_NATURAL, 0}},
     1,
     {{NULL, NULL, 0}},
     0},
};

hearth_status hearth_thermo_category_net(const char *category, double T0, double T_air,
                                         hearth_thermo_net *net, hearth_err *err) {
  const category_tpl *c = NULL;
  for (size_t i = 0; i < sizeof k_categories / sizeof k_categories[0]; i++)
    if (strcmp(k_categories[i].name, category) == 0) c = &k_categories[i];
  if (!c)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "no thermal parameters for category \"%s\"",
                          category);
  hearth_thermo_net_init(net);
  net->T_air = T_air;
  for (size_t i = 0; i < c->n_regions; i++) {
    const region_tpl *t = &c->regions[i];
    const hearth_thermo_material *m = hearth_thermo_material_find(t->material);
    hearth_thermo_region r = {0};
    strcpy(r.name, t->name);
    r.C = t->mass * m->c;
    r.T = T0;
    r.area = t->area;
    r.h_conv = t->h;
    r.emissivity = m->emissivity;
    r.label = t->label;
    hearth_status s = hearth_thermo_add_region(net, &r, NULL, err);
    if (s != HEARTH_OK) return s;
  }
  for (size_t l = 0; l < c->n_links; l++) {
    size_t a, b;
    hearth_status s = hearth_thermo_find(net, c->links[l].a, &a, err);
    if (s == HEARTH_OK) s = hearth_thermo_find(net, c->links[l].b, &b, err);
    if (s == HEARTH_OK) s = hearth_thermo_set_conductance(net, a, b, c->links[l].G, err);
    if (s != HEARTH_OK) return s;
  }
  return hearth_thermo_net_check(net, err);
}
