/* Temperature fields of the virtual rig: apparent surface temperature as a
 * smooth function of the object-frame position and the part of the surface.
 *
 * synth_field_make draws the state's temperatures from the seed and caches
 * what the evaluation needs in f->params (layout below), so that
 * synth_field_eval is a pure function: deterministic and thread-safe. The
 * shapes follow the paper's examples: a hot cup whose body is hottest below
 * the liquid line, with a cooler rim and handle; an iced can colder at the
 * bottom; a phone warm over its battery; an orange close to ambient. */
#include <math.h>
#include <string.h>

#include "synth/synth_category.h"
#include "synth/synth_noise.h"
#include "synth/synth_object.h"

/* params layout */
enum {
  P_MODEL,
  P_STATE,
  P_H,
  P_ZF,
  P_RB,
  P_RMAX,
  P_NAMP,
  P_GRAD,
  P_T0 = 8,   /* P_T0..P_T0+7: temps */
  P_ROLE = 16 /* role of part k at P_ROLE + k */
};

enum { ST_NEUTRAL, ST_HOT, ST_WARM, ST_ICED, ST_USED };
static const char *const k_states[] = {"neutral", "hot", "warm", "iced", "used"};

enum {
  R_BODY,
  R_BOTTOM,
  R_RIM,
  R_INNER,
  R_HANDLE,
  R_TOP,
  R_NECK,
  R_CAP,
  R_BACK,
  R_FRAME,
  R_SCREEN,
  R_FOAM,
  R_PAD,
  R_BASE,
  R_LID,
  R_SPOUT,
  R_CUSHION,
  R_BAND,
  R_SHELL
};

static int role_of(const char *name) {
  static const struct {
    const char *n;
    int r;
  } t[] = {{"body", R_BODY},     {"bottom", R_BOTTOM},   {"rim", R_RIM},      {"inner", R_INNER},
           {"handle", R_HANDLE}, {"top", R_TOP},         {"stem_end", R_TOP}, {"neck", R_NECK},
           {"cap", R_CAP},       {"back", R_BACK},       {"frame", R_FRAME},  {"screen", R_SCREEN},
           {"foam", R_FOAM},     {"pad", R_PAD},         {"base", R_BASE},    {"lid", R_LID},
           {"spout", R_SPOUT},   {"cushion", R_CUSHION}, {"band", R_BAND},    {"shell", R_SHELL},
           {"side", R_SHELL},    {"cup", R_SHELL}};
  if (!name) return R_BODY;
  for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
    if (strcmp(name, t[i].n) == 0) return t[i].r;
  return R_BODY;
}

/* ---- shaping ------------------------------------------------------------ */

static double sstep(double t) {
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return t * t * (3 - 2 * t);
}

static double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }
static double logistic(double x) { return 1.0 / (1.0 + exp(-x)); }

/* a soft rectangle: ~1 inside |x-cx| < ax, |y-cy| < ay, falling over w */
static double soft_rect(double x, double y, double cx, double cy, double ax, double ay, double w) {
  return logistic((ax - fabs(x - cx)) / w) * logistic((ay - fabs(y - cy)) / w);
}

static double gauss2(double x, double y, double cx, double cy, double sg) {
  double dx = x - cx, dy = y - cy;
  return exp(-(dx * dx + dy * dy) / (2 * sg * sg));
}

/* ---- make ---------------------------------------------------------------- */

hearth_status synth_field_make(const synth_object *obj, const char *state, uint64_t seed,
                               double ambient_c, synth_field *f, hearth_err *err) {
  if (!obj || !f) return hearth_err_set(err, HEARTH_E_ARG, "synth_field_make: NULL argument");
  int st = -1;
  for (int i = 0; i < 5; i++)
    if (state && strcmp(state, k_states[i]) == 0) st = i;
  if (st < 0)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "synth_field_make(%s): unknown state '%s': expected "
                          "neutral|hot|warm|iced|used",
                          obj->category, state ? state : "(null)");
  if (!(ambient_c > -40 && ambient_c < 60))
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "synth_field_make(%s): ambient %g degC: expected -40..60", obj->category,
                          ambient_c);
  if (obj->n_parts < 0 || obj->n_parts > SYNTH_MAX_PARTS)
    return hearth_err_set(err, HEARTH_E_RANGE, "synth_field_make(%s): %d parts: expected <= %d",
                          obj->category, obj->n_parts, SYNTH_MAX_PARTS);
  memset(f, 0, sizeof *f);
  snprintf(f->state, sizeof f->state, "%s", k_states[st]);
  f->ambient_c = ambient_c;
  f->seed = seed;
  double *P = f->params;
  const synth_category *cat = synth_category_find(obj->category);
  const synth_field_spec *spec = cat ? &cat->field : &synth_field_other;
  const synth_temps *temps = st == ST_HOT    ? &spec->hot
                             : st == ST_WARM ? &spec->warm
                             : st == ST_ICED ? &spec->iced
                             : st == ST_USED ? &spec->used
                                             : NULL;
  P[P_MODEL] = temps ? temps->model : FIELD_MODELS; /* neutral: none */
  P[P_STATE] = st;
  for (int k = 0; k < obj->n_parts; k++) P[P_ROLE + k] = role_of(obj->part_names[k]);

  /* geometry the fields need: height, liquid line, body radius (without
   * handles and spouts), overall radius */
  const hearth_mesh *m = &obj->mesh;
  double H = obj->height > 0 ? obj->height : 0.1, rb = 0, rmax = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    int part = obj->part_of_tri && obj->part_of_tri[t] < obj->n_parts ? obj->part_of_tri[t] : 0;
    int role = (int)P[P_ROLE + part];
    for (int k = 0; k < 3; k++) {
      const float *p = m->positions + 3 * (size_t)m->indices[3 * t + k];
      double r = hypot(p[0], p[1]);
      if (r > rmax) rmax = r;
      if (role != R_HANDLE && role != R_SPOUT && r > rb) rb = r;
    }
  }
  if (rmax <= rb) rmax = rb + 1e-3;
  P[P_H] = H;
  /* half extents in x and y (the phone's screen and battery layout) */
  double ax = 1e-3, by = 1e-3;
  for (size_t v = 0; v < m->n_vertices; v++) {
    ax = fmax(ax, fabs(m->positions[3 * v]));
    by = fmax(by, fabs(m->positions[3 * v + 1]));
  }
  P[P_ZF] = (obj->fill_level > 0 ? obj->fill_level : 0.8) * H;
  P[P_RB] = rb;
  P[P_RMAX] = rmax;

  hearth_rng root, r;
  hearth_rng_seed(&root, seed);
  hearth_rng_fork(&root, 0x6669656c64ULL + (uint64_t)st * 131 + (uint64_t)spec->stream, &r);
  P[P_NAMP] = hearth_rng_range(&r, 0.15, 0.3);
  P[P_GRAD] = hearth_rng_range(&r, -0.15, 0.15);
  double *T = P + P_T0;
  for (int k = 0; temps && k < temps->n && k < SYNTH_MAX_TEMPS; k++)
    T[k] = hearth_rng_range(&r, temps->range[k][0], temps->range[k][1]);
  if (temps && temps->model == FIELD_PHONE) {
    T[4] = ax;
    T[5] = by;
  }
  return HEARTH_OK;
}

/* ---- eval ---------------------------------------------------------------- */

/* temperature above a liquid line: hot below, cooling towards `top` at the
 * top, joined by a logistic of width w */
static double liquid_line(double z, double zf, double H, double hot, double top, double w) {
  double above = top + (hot - 4 - top) * (1 - clamp01((z - zf) / fmax(H - zf, 1e-3)));
  double s = logistic((zf - z) / w);
  return s * hot + (1 - s) * above;
}

/* a handle from T2 where it leaves the body to T3 at its far end */
static double handle_temp(const double *T, double r, double rb, double rmax) {
  return T[2] + (T[3] - T[2]) * sstep(clamp01((r - rb) / (rmax - rb)));
}

double synth_field_eval(const synth_field *f, const synth_object *obj, uint32_t tri,
                        const double p[3]) {
  const double *P = f->params, *T = P + P_T0;
  int part = (obj && obj->part_of_tri && tri < obj->mesh.n_triangles) ? obj->part_of_tri[tri] : 0;
  if (part >= SYNTH_MAX_PARTS) part = 0;
  int role = (int)P[P_ROLE + part];
  int st = (int)P[P_STATE];
  double amb = f->ambient_c, H = P[P_H], zf = P[P_ZF], rb = P[P_RB], rmax = P[P_RMAX];
  double x = p[0], y = p[1], z = p[2], r = hypot(x, y);
  double nz = synth_smooth_noise3(f->seed, x / 0.05, y / 0.05, z / 0.05);
  double small = P[P_NAMP] * nz;
  double zr = clamp01(z / H);

  if (st == ST_NEUTRAL) return amb + small + P[P_GRAD] * (zr - 0.5);

  switch ((synth_field_model)P[P_MODEL]) {
    case FIELD_TOP_COOLER: return T[0] - T[1] * zr + 0.5 * small;
    case FIELD_CUP: {
      double hot = T[0], rim = T[1], w = T[4];
      switch (role) {
        case R_HANDLE: return handle_temp(T, r, rb, rmax) + 0.3 * small;
        case R_RIM: return rim + 0.3 * small;
        case R_INNER: return liquid_line(z, zf, H, hot + 1.5, rim + 3, w) + 0.3 * small;
        case R_BOTTOM: return hot - T[5] * (1 - sstep(r / rb)) + 0.3 * small;
        default: return liquid_line(z, zf, H, hot, rim, w) + 0.3 * small;
      }
    }
    case FIELD_KETTLE:
      switch (role) {
        case R_HANDLE: return T[3] + 0.5 * small;
        case R_BASE: return T[4] + 2 * clamp01(z / 0.02) + 0.3 * small;
        case R_LID: /* the plastic knob is cooler than the lid */
          return T[2] + (amb + 12 - T[2]) * sstep((0.02 - r) / 0.008) + 0.5 * small;
        case R_SPOUT: return T[5] + 0.5 * small;
        default: return liquid_line(z, zf, H, T[0], T[1], T[6]) + 0.4 * small;
      }
    case FIELD_POT:
      switch (role) {
        case R_HANDLE: return handle_temp(T, r, rb, rmax) + 0.3 * small;
        case R_LID: return T[4] + (amb + 15 - T[4]) * sstep((0.021 - r) / 0.008) + 0.5 * small;
        case R_RIM: return T[1] + 0.3 * small;
        case R_INNER: return liquid_line(z, zf, H, T[0] + 2, T[1] + 3, T[5]) + 0.3 * small;
        default: return liquid_line(z, zf, H, T[0], T[1], T[5]) + 0.4 * small;
      }
    case FIELD_SPONGE: {
      double wet = synth_smooth_noise3(f->seed + 17, x / 0.03, y / 0.03, z / 0.03);
      double t = T[0] - T[1] * sstep((wet - 0.05) / 0.5);
      if (role == R_PAD) t -= T[2];
      return t + 0.2 * small;
    }
    case FIELD_PHONE: {
      /* long axis along y, screen on top (+z) */
      double edge = T[0], bat = T[1], soc = T[2], scr = T[3];
      double ax = T[4], by = T[5];
      double g_bat = soft_rect(x, y, 0, -0.1 * by, 0.7 * ax, 0.45 * by, 0.006);
      double g_soc = gauss2(x, y, 0.25 * ax, 0.55 * by, 0.015);
      double g_in = soft_rect(x, y, 0, 0, 0.8 * ax, 0.88 * by, 0.006);
      switch (role) {
        case R_BACK:
          return edge + (bat - edge) * g_bat + (soc - edge) * 0.7 * g_soc * (1 - g_bat) +
                 0.2 * small;
        case R_SCREEN: return edge + (scr - edge) * g_in + (soc - scr) * g_soc * g_in + 0.2 * small;
        default: return edge + 1.5 * g_soc + 0.2 * small;
      }
    }
    case FIELD_CHILLED: {
      double t = T[0] + (T[1] - T[0]) * pow(zr, 0.8);
      if (role == R_TOP) t += 0.5;
      if (role == R_CAP) t += 2.0;
      if (role == R_NECK) t += 1.0;
      return t + 0.2 * small;
    }
    case FIELD_CHILLED_FRUIT: return T[0] + T[1] * zr + 0.4 * small;
    case FIELD_WARM: return amb + T[0] * (0.8 + 0.2 * (1 - zr)) + 0.4 * small;
    case FIELD_LAPTOP:
      if (role == R_LID) return amb + T[2] + 0.3 * small;
      return amb + T[1] + T[0] * gauss2(x, y, 0.04, 0.03, 0.05) + 0.3 * small;
    case FIELD_USED_CUSHION:
      if (role == R_CUSHION) return amb + T[1] + 0.3 * small;
      break;
    case FIELD_USED_GRIP:
      if (role == R_SHELL || role == R_TOP)
        return amb + T[0] + (T[1] - T[0]) * sstep(-y / 0.05 + 0.2) + 0.3 * small;
      break;
    case FIELD_USED:
    case FIELD_MODELS: break;
  }
  /* used: mild warmth, more where hands, palms or heads were */
  double blob = sstep(0.5 + 0.8 * synth_smooth_noise3(f->seed + 29, x / 0.04, y / 0.04, z / 0.04));
  return amb + T[0] * (0.4 + 0.6 * blob) + 0.3 * small;
}
