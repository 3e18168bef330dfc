/* Dynamic temperatures: a lumped thermal network per object (thermo.h),
 * built from the object's temperature map and its category's materials,
 * integrated once per control step with heat exchanged with the air, the
 * table, the finger pads and the other objects through MuJoCo's contacts
 * (touching objects' networks are solved as one system), and the thermal
 * texture re-composed from the region temperatures plus the map's offset
 * field. Model, parameters and sources: docs/simulation.md, "Dynamic
 * temperatures". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/image.h"
#include "hearth/map.h"
#include "hearth/npy.h"
#include "sim/sim_env.h"

/* texture clusters (k-means over the map's temperatures) per object */
#define SIM_TH_CLUSTERS 3
/* contact patch areas, m^2: a finger pad pressed on a curved surface (a
 * 1 cm x 1 cm patch of the 2 cm pad) and the rim or foot an object stands
 * on (a tenth of its footprint) */
#define SIM_TH_FINGER_AREA 1.0e-4
#define SIM_TH_TABLE_FRACTION 0.1
/* the table top: wood (Incropera Table A.3, oak across the grain,
 * 0.17 W/(m K)), 22 degC far from the objects. Heat leaves a patch of area
 * A into it through the contact's h_c A in series with the spreading
 * conductance of an isothermal disc of diameter D on a half-space, S k
 * with S = 2 D (Incropera Table 4.1), D the disc of area A */
#define SIM_TH_TABLE_K 0.17
/* the patch of two objects touching: two rigid curved surfaces, taken as
 * the finger pad's 1 cm^2 */
#define SIM_TH_OBJECT_AREA 1.0e-4

int hearth_sim_thermal_parse(const char *s) {
  if (!s) return -1;
  if (strcmp(s, "static") == 0) return HEARTH_SIM_THERMAL_STATIC;
  if (strcmp(s, "dynamic") == 0) return HEARTH_SIM_THERMAL_DYNAMIC;
  return -1;
}

/* per simulated category: the shell's material, its conduction thickness
 * (wall of a hollow object, half the smallest extent of a solid one) and
 * the thermo template that adds a liquid region (cup, can) */
typedef struct th_category {
  const char *name, *material;
  double thickness;   /* m */
  const char *thermo; /* hearth_thermo_category_net name, or NULL */
} th_category;

static const th_category k_th_cats[] = {
    {"cup", "ceramic", 0.005, "cup"},
    {"canned_drink", "aluminium_painted", 0.0001, "can"},
    {"electric_kettle", "stainless_steel", 0.001, NULL},
    {"eraser", "rubber", 0.01, NULL},
    {"orange", "water", 0.035, NULL}, /* a water-rich fruit */
    {"smartphone", "glass", 0.004, NULL},
    {"sponge", "urethane_foam", 0.01, NULL},
};

static const th_category *th_category_find(const char *name) {
  for (size_t i = 0; i < sizeof k_th_cats / sizeof k_th_cats[0]; i++)
    if (strcmp(k_th_cats[i].name, name) == 0) return &k_th_cats[i];
  return NULL;
}

static double mesh_area(const hearth_mesh *m) {
  double a = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    const float *p0 = m->positions + 3 * m->indices[3 * t],
                *p1 = m->positions + 3 * m->indices[3 * t + 1],
                *p2 = m->positions + 3 * m->indices[3 * t + 2];
    double u[3], v[3];
    for (int i = 0; i < 3; i++) u[i] = p1[i] - p0[i], v[i] = p2[i] - p0[i];
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    a += 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  }
  return a;
}

/* an object's temperature map as hearth_thermo_regions_from_map takes it:
 * a derived asset's mask.npy, temperature_observed.npy and
 * temperature_filled.npy (docs/dataset.md; the Turbo image would clamp at
 * 10..60 degC and colour texels without surface), else the asset's
 * temperatures (the true map) observed wherever they are finite */
typedef struct th_map {
  size_t R;
  uint8_t *mask;
  const float *observed, *filled;
  hearth_npy npy[3];
} th_map;

static void th_map_free(th_map *mp) {
  if (!mp->npy[0].data) free(mp->mask);
  for (int i = 0; i < 3; i++) hearth_npy_free(&mp->npy[i]);
  memset(mp, 0, sizeof *mp);
}

static hearth_status th_map_load(sim_asset *a, th_map *mp, hearth_err *err) {
  memset(mp, 0, sizeof *mp);
  if (!a->map_dir[0]) {
    hearth_status st = sim_asset_temperatures(a, err);
    if (st) return st;
    size_t n = a->temp_R * a->temp_R;
    mp->R = a->temp_R;
    mp->mask = malloc(n ? n : 1);
    if (!mp->mask) return hearth_err_set(err, HEARTH_E_NOMEM, "sim thermal: out of memory");
    for (size_t i = 0; i < n; i++)
      mp->mask[i] = isfinite(a->temp[i]) ? HEARTH_TEXEL_OBSERVED : HEARTH_TEXEL_NONE;
    mp->observed = mp->filled = a->temp;
    return HEARTH_OK;
  }
  static const char *files[3] = {"mask.npy", "temperature_observed.npy", "temperature_filled.npy"};
  size_t R = a->thermal.width;
  for (int i = 0; i < 3; i++) {
    char p[4200];
    snprintf(p, sizeof p, "%s/%s", a->map_dir, files[i]);
    hearth_status st = hearth_npy_read(p, &mp->npy[i], err);
    const hearth_npy *q = &mp->npy[i];
    if (!st && (q->dtype != (i ? HEARTH_NPY_F32 : HEARTH_NPY_U8) || q->ndim != 2 ||
                q->shape[0] != R || q->shape[1] != R))
      st = hearth_err_set(err, HEARTH_E_SIZE, "%s: expected %s [%zu][%zu] beside thermal_turbo.png",
                          p, i ? "float32" : "uint8", R, R);
    if (st) {
      th_map_free(mp);
      return st;
    }
  }
  mp->R = R;
  mp->mask = mp->npy[0].data;
  mp->observed = mp->npy[1].data, mp->filled = mp->npy[2].data;
  return HEARTH_OK;
}

/* one object's network from its map: the shell split over the texture
 * regions (C and area by their share of the texels with a value),
 * conductances between regions that share texel edges (k t L / d), and the
 * template's liquid */
static hearth_status build_object(hearth_sim_env *e, int k, hearth_err *err) {
  sim_asset *a = &e->assets[k];
  sim_thermal_obj *o = &e->th[k];
  const th_category *tc = th_category_find(a->category);
  if (!tc)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "sim thermal: no parameters for '%s'",
                          a->category);
  const hearth_thermo_material *mat = hearth_thermo_material_find(tc->material);
  if (!mat)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "sim thermal: no material '%s'", tc->material);
  th_map mp;
  hearth_status st = th_map_load(a, &mp, err);
  if (st) return st;
  size_t R = mp.R, n = R * R;
  hearth_thermo_regions reg = {0};
  st = hearth_thermo_regions_from_map(R, mp.mask, mp.observed, mp.filled, NULL, SIM_TH_CLUSTERS,
                                      &reg, err);
  /* each region's share of the shell: of the texels with a value (observed
   * or filled; an unobserved island's temperature is unknown, so it takes
   * none), else of all texels */
  double share[HEARTH_THERMO_MAX_CLUSTERS] = {0};
  size_t valued[HEARTH_THERMO_MAX_CLUSTERS] = {0}, n_valued = 0, total = 0;
  for (size_t i = 0; !st && i < n; i++)
    if (reg.label[i] != HEARTH_THERMO_NO_LABEL &&
        (mp.mask[i] == HEARTH_TEXEL_OBSERVED || mp.mask[i] == HEARTH_TEXEL_FILLED))
      valued[reg.label[i]]++, n_valued++;
  th_map_free(&mp);
  if (st) return hearth_err_prefix(err, "sim thermal %s/%s: ", a->category, a->state);
  for (size_t l = 0; l < reg.k; l++) total += reg.n_texels[l];
  for (size_t l = 0; l < reg.k; l++)
    share[l] = n_valued ? (double)valued[l] / (double)n_valued
               : total  ? (double)reg.n_texels[l] / (double)total
                        : 0.0;
  /* the shell: the template's body region, else the category's mass */
  hearth_thermo_net tpl;
  double C_body = a->mass * mat->c, h_body = HEARTH_THERMO_H_NATURAL, G_liquid = 0;
  const hearth_thermo_region *liquid = NULL;
  if (tc->thermo) {
    st = hearth_thermo_category_net(tc->thermo, SIM_ROOM_C, HEARTH_SIM_THERMAL_ROOM, &tpl, err);
    if (st) {
      hearth_thermo_regions_free(&reg);
      return st;
    }
    size_t ib = 0, il = 0;
    if (hearth_thermo_find(&tpl, "body", &ib, NULL) == HEARTH_OK)
      C_body = tpl.region[ib].C, h_body = tpl.region[ib].h_conv;
    if (hearth_thermo_find(&tpl, "liquid", &il, NULL) == HEARTH_OK)
      liquid = &tpl.region[il], G_liquid = tpl.G[ib][il];
  }
  double A_body = mesh_area(&a->mesh);
  hearth_thermo_net_init(&o->net);
  o->net.T_air = HEARTH_SIM_THERMAL_ROOM;
  double mean_T = 0;
  for (size_t l = 0; l < reg.k && !st; l++) {
    double f = share[l];
    hearth_thermo_region r = {0};
    snprintf(r.name, sizeof r.name, "shell%zu", l);
    r.C = C_body * (f > 0 ? f : 1e-6);
    r.T = reg.mean[l];
    r.area = A_body * f;
    r.h_conv = h_body;
    r.emissivity = mat->emissivity;
    r.label = (int)l;
    mean_T += f * reg.mean[l];
    st = hearth_thermo_add_region(&o->net, &r, NULL, err);
  }
  /* region-region conductances over shared texel edges */
  double texel = total ? sqrt(A_body / (double)total) : 0;
  size_t edges[SIM_TH_CLUSTERS][SIM_TH_CLUSTERS] = {{0}};
  for (size_t y = 0; y < R; y++)
    for (size_t x = 0; x < R; x++) {
      uint8_t l0 = reg.label[y * R + x];
      if (l0 == HEARTH_THERMO_NO_LABEL) continue;
      uint8_t nb[2] = {x + 1 < R ? reg.label[y * R + x + 1] : HEARTH_THERMO_NO_LABEL,
                       y + 1 < R ? reg.label[(y + 1) * R + x] : HEARTH_THERMO_NO_LABEL};
      for (int j = 0; j < 2; j++)
        if (nb[j] != HEARTH_THERMO_NO_LABEL && nb[j] != l0) edges[l0][nb[j]]++, edges[nb[j]][l0]++;
    }
  for (size_t i = 0; i < reg.k && !st; i++)
    for (size_t j = i + 1; j < reg.k && !st; j++) {
      if (!edges[i][j]) continue;
      double L = (double)edges[i][j] * texel;
      double d = 0.5 * (sqrt(o->net.region[i].area) + sqrt(o->net.region[j].area));
      if (d > 0)
        st = hearth_thermo_set_conductance(&o->net, i, j, mat->k * tc->thickness * L / d, err);
    }
  if (!st && liquid) {
    hearth_thermo_region r = *liquid;
    r.T = mean_T;
    r.label = -1;
    size_t il = 0;
    st = hearth_thermo_add_region(&o->net, &r, &il, err);
    for (size_t l = 0; l < reg.k && !st; l++) {
      double f = share[l];
      if (f > 0) st = hearth_thermo_set_conductance(&o->net, l, il, G_liquid * f, err);
    }
  }
  if (!st) st = hearth_thermo_net_check(&o->net, err);
  if (st) {
    hearth_thermo_regions_free(&reg);
    return hearth_err_prefix(err, "sim thermal %s/%s: ", a->category, a->state);
  }
  for (size_t i = 0; i < o->net.n; i++) o->T0[i] = o->net.region[i].T;
  /* texels: the regions' labels grown 4 texels into the seams (as the
   * static texture's colours are), each grown texel's temperature the mean
   * of its labelled neighbours' */
  o->R = R;
  o->label = reg.label, o->offset = reg.offset;
  reg.label = NULL, reg.offset = NULL;
  float *F = malloc(n * sizeof(float));
  uint8_t *nl = malloc(n);
  if (!F || !nl) {
    free(F), free(nl);
    hearth_thermo_regions_free(&reg);
    return hearth_err_set(err, HEARTH_E_NOMEM, "sim thermal: out of memory");
  }
  for (size_t i = 0; i < n; i++)
    F[i] = o->label[i] != HEARTH_THERMO_NO_LABEL ? (float)reg.mean[o->label[i]] + o->offset[i] : 0;
  for (int it = 0; it < 4; it++) {
    memcpy(nl, o->label, n);
    for (size_t y = 0; y < R; y++)
      for (size_t x = 0; x < R; x++) {
        if (o->label[y * R + x] != HEARTH_THERMO_NO_LABEL) continue;
        double acc = 0;
        int cnt = 0;
        uint8_t first = HEARTH_THERMO_NO_LABEL;
        for (int dy = -1; dy <= 1; dy++)
          for (int dx = -1; dx <= 1; dx++) {
            long yy = (long)y + dy, xx = (long)x + dx;
            if (yy < 0 || xx < 0 || yy >= (long)R || xx >= (long)R) continue;
            uint8_t l = o->label[yy * R + xx];
            if (l == HEARTH_THERMO_NO_LABEL) continue;
            if (first == HEARTH_THERMO_NO_LABEL) first = l;
            acc += F[yy * R + xx], cnt++;
          }
        if (cnt) {
          nl[y * R + x] = first;
          F[y * R + x] = (float)(acc / cnt);
          o->offset[y * R + x] = (float)(acc / cnt - reg.mean[first]);
        }
      }
    memcpy(o->label, nl, n);
  }
  free(F), free(nl);
  /* each mesh vertex's region: the label at its UV, else the largest region */
  size_t big = 0;
  for (size_t l = 1; l < reg.k; l++)
    if (reg.n_texels[l] > reg.n_texels[big]) big = l;
  hearth_thermo_regions_free(&reg);
  const hearth_mesh *me = &a->mesh;
  o->vregion = malloc(me->n_vertices ? me->n_vertices : 1);
  if (!o->vregion) return hearth_err_set(err, HEARTH_E_NOMEM, "sim thermal: out of memory");
  for (size_t i = 0; i < me->n_vertices; i++) {
    double u = me->uvs[2 * i], v = me->uvs[2 * i + 1];
    long c = (long)floor(u * (double)R), r = (long)floor(v * (double)R);
    c = c < 0 ? 0 : c >= (long)R ? (long)R - 1 : c;
    r = r < 0 ? 0 : r >= (long)R ? (long)R - 1 : r;
    uint8_t l = o->label[(size_t)r * R + (size_t)c];
    o->vregion[i] = l != HEARTH_THERMO_NO_LABEL ? l : (uint8_t)big;
  }
  return HEARTH_OK;
}

hearth_status sim_thermal_init(hearth_sim_env *e, hearth_err *err) {
  if (e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return HEARTH_OK;
  const mjModel *m = e->m;
  for (int i = 0; i < SIM_TH_LUT; i++) hearth_turbo((double)i / (SIM_TH_LUT - 1), e->th_lut[i]);
  for (int k = 0; k < SIM_NOBJ; k++) {
    hearth_status st = build_object(e, k, err);
    if (st) return st;
    sim_thermal_obj *o = &e->th[k];
    int g = e->obj_geom_th[k];
    o->texid = g >= 0 && m->geom_matid[g] >= 0 ? m->mat_texid[m->geom_matid[g]] : -1;
    const hearth_image *img = &e->assets[k].thermal;
    size_t R = o->R;
    if (o->texid < 0 || m->tex_width[o->texid] != (int)R || m->tex_height[o->texid] != (int)R ||
        img->width != R)
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                            "sim thermal: object %d's thermal texture is not its %zux%zu map", k, R,
                            R);
    /* which row order MuJoCo keeps the texture in */
    const uint8_t *tx = m->tex_rgb + m->tex_adr[o->texid], *px = img->data;
    if (memcmp(tx, px, 3 * R) == 0 &&
        memcmp(tx + 3 * R * (R - 1), px + 3 * R * (R - 1), 3 * R) == 0)
      o->flip = 0;
    else if (memcmp(tx, px + 3 * R * (R - 1), 3 * R) == 0) o->flip = 1;
    else
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                            "sim thermal: object %d's model texture is not its thermal image", k);
  }
  sim_thermal_reset(e);
  return HEARTH_OK;
}

void sim_thermal_free(hearth_sim_env *e) {
  for (int k = 0; k < SIM_NOBJ; k++) {
    free(e->th[k].label), free(e->th[k].offset), free(e->th[k].vregion);
    e->th[k].label = NULL, e->th[k].offset = NULL, e->th[k].vregion = NULL;
  }
}

void sim_thermal_reset(hearth_sim_env *e) {
  if (e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return;
  for (int k = 0; k < SIM_NOBJ; k++) {
    sim_thermal_obj *o = &e->th[k];
    for (size_t i = 0; i < o->net.n; i++) o->net.region[i].T = o->T0[i];
    hearth_thermo_clear_contacts(&o->net);
    o->heat_in = o->heat_link = 0;
  }
  e->n_th_links = 0;
  e->thermal_dirty = 1;
}

/* the region of object k nearest to world point p (its nearest vertex's) */
static size_t contact_region(const hearth_sim_env *e, int k, const mjtNum p[3]) {
  const mjtNum *bp = e->d->xpos + 3 * e->obj_body[k], *R = e->d->xmat + 9 * e->obj_body[k];
  double d[3] = {p[0] - bp[0], p[1] - bp[1], p[2] - bp[2]}, l[3];
  for (int i = 0; i < 3; i++) l[i] = R[i] * d[0] + R[3 + i] * d[1] + R[6 + i] * d[2];
  const hearth_mesh *me = &e->assets[k].mesh;
  size_t best = 0;
  double bd = INFINITY;
  for (size_t v = 0; v < me->n_vertices; v++) {
    const float *q = me->positions + 3 * v;
    double dx = q[0] - l[0], dy = q[1] - l[1], dz = q[2] - l[2], dd = dx * dx + dy * dy + dz * dz;
    if (dd < bd) bd = dd, best = v;
  }
  return me->n_vertices ? e->th[k].vregion[best] : 0;
}

/* which fixed-temperature body geom g is: 0 table or mat, 1 + s finger s,
 * -1 neither (the floor, another object) */
static int contact_kind(const hearth_sim_env *e, int g) {
  if (g == e->table_geom || g == e->mat_geom) return 0;
  int b = e->m->geom_bodyid[g];
  for (int s = 0; s < 2; s++)
    if (e->pad_geom[s] >= 0 && b == e->m->geom_bodyid[e->pad_geom[s]]) return 1 + s;
  return -1;
}

/* the object (0..3) geom g belongs to, or -1 */
static int contact_object(const hearth_sim_env *e, int g) {
  int b = e->m->geom_bodyid[g];
  for (int k = 0; k < SIM_NOBJ; k++)
    if (e->obj_body[k] == b) return k;
  return -1;
}

/* the links of objects touching each other: one patch of h A per pair,
 * shared equally by the pair's contact points, each point linking the
 * regions of both objects nearest to it (one link per pair of regions) */
static void object_links(hearth_sim_env *e) {
  const mjData *d = e->d;
  e->n_th_links = 0;
  if (!(e->h_object > 0)) return;
  int count[SIM_NOBJ][SIM_NOBJ] = {{0}};
  for (int i = 0; i < d->ncon; i++) {
    int a = contact_object(e, d->contact[i].geom1), b = contact_object(e, d->contact[i].geom2);
    if (a >= 0 && b >= 0 && a != b) count[a < b ? a : b][a < b ? b : a]++;
  }
  for (int i = 0; i < d->ncon; i++) {
    int a = contact_object(e, d->contact[i].geom1), b = contact_object(e, d->contact[i].geom2);
    if (a < 0 || b < 0 || a == b) continue;
    if (a > b) {
      int t = a;
      a = b, b = t;
    }
    size_t ra = contact_region(e, a, d->contact[i].pos),
           rb = contact_region(e, b, d->contact[i].pos);
    double G = e->h_object * SIM_TH_OBJECT_AREA / (double)count[a][b];
    size_t l = 0;
    while (l < e->n_th_links && !(e->th_links[l].a == (size_t)a && e->th_links[l].b == (size_t)b &&
                                  e->th_links[l].ra == ra && e->th_links[l].rb == rb))
      l++;
    if (l == e->n_th_links) /* at most SIM_TH_MAX_LINKS distinct (a, ra, b, rb) */
      e->th_links[e->n_th_links++] = (hearth_thermo_link){(size_t)a, ra, (size_t)b, rb, 0};
    e->th_links[l].G += G;
  }
}

hearth_status sim_thermal_step(hearth_sim_env *e, double dt, hearth_err *err) {
  if (e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return HEARTH_OK;
  const mjModel *m = e->m;
  const mjData *d = e->d;
  for (int k = 0; k < SIM_NOBJ; k++) {
    sim_thermal_obj *o = &e->th[k];
    hearth_thermo_clear_contacts(&o->net);
    /* MuJoCo's contact points of each (object, kind) pair share one patch */
    int count[3] = {0, 0, 0};
    for (int i = 0; i < d->ncon; i++) {
      int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2, other = -1;
      if (m->geom_bodyid[g1] == e->obj_body[k]) other = g2;
      else if (m->geom_bodyid[g2] == e->obj_body[k]) other = g1;
      int kind = other >= 0 ? contact_kind(e, other) : -1;
      if (kind >= 0) count[kind]++;
    }
    if (!count[0] && !count[1] && !count[2]) continue;
    const double *sz = e->assets[k].size;
    double A_table = SIM_TH_TABLE_FRACTION * sz[0] * sz[1], Gc = e->h_table * A_table,
           Gs = SIM_TH_TABLE_K * 4.0 * sqrt(A_table / M_PI);
    double GA[3] = {Gc > 0 ? Gc * Gs / (Gc + Gs) : 0, e->h_finger * SIM_TH_FINGER_AREA,
                    e->h_finger * SIM_TH_FINGER_AREA};
    double G[HEARTH_THERMO_MAX_REGIONS][3] = {{0}};
    for (int i = 0; i < d->ncon; i++) {
      int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2, other = -1;
      if (m->geom_bodyid[g1] == e->obj_body[k]) other = g2;
      else if (m->geom_bodyid[g2] == e->obj_body[k]) other = g1;
      int kind = other >= 0 ? contact_kind(e, other) : -1;
      if (kind < 0) continue;
      /* each contact point carries its patch's share */
      size_t r = contact_region(e, k, d->contact[i].pos);
      G[r][kind] += GA[kind] / (double)count[kind];
    }
    for (size_t r = 0; r < o->net.n; r++)
      for (int kind = 0; kind < 3; kind++)
        if (G[r][kind] > 0) {
          hearth_status st =
              hearth_thermo_add_contact(&o->net, r, G[r][kind], HEARTH_SIM_THERMAL_ROOM, err);
          if (st) return st;
        }
  }
  object_links(e);
  if (!e->n_th_links) {
    for (int k = 0; k < SIM_NOBJ; k++) {
      double q = 0;
      hearth_status st = hearth_thermo_step(&e->th[k].net, dt, &q, err);
      if (st) return hearth_err_prefix(err, "sim thermal object %d: ", k);
      e->th[k].heat_in += q;
    }
  } else {
    /* touching objects: all four networks as one system */
    hearth_thermo_net *nets[SIM_NOBJ];
    for (int k = 0; k < SIM_NOBJ; k++) nets[k] = &e->th[k].net;
    double q[SIM_NOBJ];
    hearth_status st =
        hearth_thermo_step_coupled_each(nets, SIM_NOBJ, e->th_links, e->n_th_links, dt, q, err);
    if (st) return hearth_err_prefix(err, "sim thermal: ");
    for (int k = 0; k < SIM_NOBJ; k++) e->th[k].heat_in += q[k];
    /* what each link carried over the step (backward Euler: at the new
     * temperatures), given to b's side and taken from a's */
    for (size_t l = 0; l < e->n_th_links; l++) {
      const hearth_thermo_link *k = &e->th_links[l];
      double h = dt * k->G * (nets[k->a]->region[k->ra].T - nets[k->b]->region[k->rb].T);
      e->th[k->b].heat_link += h;
      e->th[k->a].heat_link -= h;
    }
  }
  e->thermal_dirty = 1;
  return HEARTH_OK;
}

void sim_thermal_update_textures(hearth_sim_env *e) {
  if (e->thermal != HEARTH_SIM_THERMAL_DYNAMIC || !e->thermal_dirty) return;
  const double scale = (SIM_TH_LUT - 1) / (SIM_THI - SIM_TLO);
  for (int k = 0; k < SIM_NOBJ; k++) {
    sim_thermal_obj *o = &e->th[k];
    size_t R = o->R;
    float Tl[HEARTH_THERMO_MAX_REGIONS];
    for (size_t i = 0; i < o->net.n; i++) Tl[i] = (float)o->net.region[i].T;
    uint8_t *tx = e->m->tex_rgb + e->m->tex_adr[o->texid];
    for (size_t y = 0; y < R; y++) {
      uint8_t *row = tx + 3 * R * (o->flip ? R - 1 - y : y);
      const uint8_t *lab = o->label + y * R;
      const float *off = o->offset + y * R;
      for (size_t x = 0; x < R; x++) {
        if (lab[x] == HEARTH_THERMO_NO_LABEL) continue;
        double t = ((double)(Tl[lab[x]] + off[x]) - SIM_TLO) * scale + 0.5;
        int i = !(t >= 0) ? 0 : t >= SIM_TH_LUT - 1 ? SIM_TH_LUT - 1 : (int)t;
        memcpy(row + 3 * x, e->th_lut[i], 3);
      }
    }
    sim_render_texture_changed(e, o->texid);
  }
  e->thermal_dirty = 0;
}

/* ---- public accessors ---------------------------------------------------------- */
const hearth_thermo_net *hearth_sim_thermal_net(const hearth_sim_env *e, int k) {
  if (!e || e->thermal != HEARTH_SIM_THERMAL_DYNAMIC || k < 0 || k >= SIM_NOBJ) return NULL;
  return &e->th[k].net;
}

double hearth_sim_thermal_heat_in(const hearth_sim_env *e, int k) {
  if (!e || e->thermal != HEARTH_SIM_THERMAL_DYNAMIC || k < 0 || k >= SIM_NOBJ) return 0;
  return e->th[k].heat_in;
}

hearth_status hearth_sim_thermal_set(hearth_sim_env *e, int k, size_t region, double T,
                                     hearth_err *err) {
  if (!e || e->thermal != HEARTH_SIM_THERMAL_DYNAMIC || k < 0 || k >= SIM_NOBJ ||
      region >= e->th[k].net.n)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "sim thermal: no region %zu of object %d (dynamic temperatures only)",
                          region, k);
  if (!isfinite(T) || T <= -273.15)
    return hearth_err_set(err, HEARTH_E_RANGE, "sim thermal: T = %g degC", T);
  e->th[k].net.region[region].T = T;
  for (int j = 0; j < SIM_NOBJ; j++) e->th[j].heat_in = e->th[j].heat_link = 0;
  e->thermal_dirty = 1;
  return HEARTH_OK;
}

double hearth_sim_thermal_heat_exchanged(const hearth_sim_env *e, int k) {
  if (!e || e->thermal != HEARTH_SIM_THERMAL_DYNAMIC || k < 0 || k >= SIM_NOBJ) return 0;
  return e->th[k].heat_link;
}

size_t hearth_sim_thermal_links(const hearth_sim_env *e, hearth_thermo_link *links, size_t max) {
  if (!e || e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return 0;
  for (size_t l = 0; links && l < e->n_th_links && l < max; l++) links[l] = e->th_links[l];
  return e->n_th_links;
}

size_t hearth_sim_thermal_state(const hearth_sim_env *e, float *T, size_t max) {
  if (!e || e->thermal != HEARTH_SIM_THERMAL_DYNAMIC) return 0;
  size_t n = 0;
  for (int k = 0; k < SIM_NOBJ; k++) n += e->th[k].net.n;
  if (T && max >= n) {
    size_t j = 0;
    for (int k = 0; k < SIM_NOBJ; k++)
      for (size_t i = 0; i < e->th[k].net.n; i++) T[j++] = (float)e->th[k].net.region[i].T;
  }
  return n;
}
