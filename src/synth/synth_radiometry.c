/* The thermal camera's band radiance and the objects' infrared surface
 * properties (see synth_radiometry.h; physics and sources in
 * docs/virtual-rig.md, "Object physics"). */
#include "synth/synth_radiometry.h"

#include <complex.h>
#include <math.h>
#include <string.h>

#include "synth/synth_category.h"

/* ---- band radiance -------------------------------------------------------- */

/* Planck's spectral radiance up to a constant factor: lambda in um, T in K
   (second radiation constant c2 = 14387.77 um K, CODATA 2018) */
static double planck(double lambda_um, double t_k) {
  const double c2 = 14387.77;
  double l5 = lambda_um * lambda_um * lambda_um * lambda_um * lambda_um;
  return 1.0e4 / (l5 * expm1(c2 / (lambda_um * t_k)));
}

void synth_band_init(synth_band *b) {
  const int n = 120; /* Simpson intervals over 8..14 um (0.05 um) */
  const double lo = 8.0, hi = 14.0, h = (hi - lo) / n;
  for (int i = 0; i < SYNTH_BAND_N; i++) {
    double t_k = SYNTH_BAND_LO_C + SYNTH_BAND_STEP_C * i + 273.15, s = 0;
    for (int k = 0; k <= n; k++) {
      double w = (k == 0 || k == n) ? 1.0 : (k & 1) ? 4.0 : 2.0;
      s += w * planck(lo + h * k, t_k);
    }
    b->L[i] = s * h / 3.0;
  }
}

double synth_band_radiance(const synth_band *b, double t_c) {
  double x = (t_c - SYNTH_BAND_LO_C) / SYNTH_BAND_STEP_C;
  if (!(x > 0)) return b->L[0];
  if (x >= SYNTH_BAND_N - 1) return b->L[SYNTH_BAND_N - 1];
  size_t i = (size_t)x;
  double f = x - (double)i;
  return b->L[i] + f * (b->L[i + 1] - b->L[i]);
}

double synth_band_temperature(const synth_band *b, double L) {
  if (!(L > b->L[0])) return SYNTH_BAND_LO_C;
  if (L >= b->L[SYNTH_BAND_N - 1]) return SYNTH_BAND_LO_C + SYNTH_BAND_STEP_C * (SYNTH_BAND_N - 1);
  size_t lo = 0, hi = SYNTH_BAND_N - 1; /* L[lo] <= L < L[hi] */
  while (hi - lo > 1) {
    size_t mid = lo + (hi - lo) / 2;
    if (b->L[mid] <= L) lo = mid;
    else hi = mid;
  }
  double f = (L - b->L[lo]) / (b->L[hi] - b->L[lo]);
  return SYNTH_BAND_LO_C + SYNTH_BAND_STEP_C * ((double)lo + f);
}

double synth_camera_radiance(const synth_band *b, double eps_set, double refl_c, double t_app) {
  return eps_set * synth_band_radiance(b, t_app) + (1.0 - eps_set) * synth_band_radiance(b, refl_c);
}

double synth_camera_reading(const synth_band *b, double eps_set, double refl_c, double L) {
  return synth_band_temperature(b,
                                (L - (1.0 - eps_set) * synth_band_radiance(b, refl_c)) / eps_set);
}

/* ---- surfaces ---------------------------------------------------------------- */

/* normal emissivities in 8-14 um; sources per row in docs/virtual-rig.md */
#define PAINT(e) \
  { e, IR_DIELECTRIC, 1 }
#define MATTE(e) \
  { e, IR_DIELECTRIC, 0 }
#define GLOSS(e) \
  { e, IR_DIELECTRIC, 1 }
#define METAL(e) \
  { e, IR_METAL, 1 }
static const synth_ir k_ir[S_COUNT] = {
    [S_PLAIN] = PAINT(0.93),        /* kettle: painted / enamelled shell */
    [S_GLAZE] = GLOSS(0.92),        /* glazed ceramic (porcelain, glazed) */
    [S_GLAZE_BAND] = GLOSS(0.92),   /* glazed ceramic */
    [S_UNGLAZED] = MATTE(0.90),     /* fired clay, unglazed foot ring */
    [S_CAN_LABEL] = PAINT(0.90),    /* lacquered print on aluminium */
    [S_ALU] = METAL(0.07),          /* bare aluminium, rolled and not polished */
    [S_ALU_TOP] = METAL(0.07),      /* bare aluminium */
    [S_CLEAR] = GLOSS(0.92),        /* glass / PET wall, opaque at 8-14 um */
    [S_BOTTLE_LABEL] = MATTE(0.92), /* printed paper or film label */
    [S_CAP] = MATTE(0.94),          /* moulded plastic */
    [S_PEEL] = MATTE(0.95),         /* orange peel */
    [S_PEEL_TOP] = MATTE(0.95),     /* orange peel, stem end */
    [S_SCREEN] = GLOSS(0.92),       /* cover glass */
    [S_FRAME] = GLOSS(0.77),        /* anodised aluminium frame */
    [S_PHONE_BACK] = GLOSS(0.92),   /* glass back */
    [S_FOAM] = MATTE(0.95),         /* wet foam */
    [S_PAD] = MATTE(0.95),          /* scouring pad */
    [S_STEEL] = METAL(0.16),        /* stainless steel, brushed */
    [S_STEEL_DARK] = METAL(0.28),   /* stainless steel, used and scratched */
    [S_BLACK] = MATTE(0.95),        /* black plastic */
    [S_MOUSE_TOP] = MATTE(0.94),    /* plastic */
    [S_RUBBER] = MATTE(0.93),       /* rubber */
    [S_SLEEVE] = MATTE(0.95),       /* fabric / cardboard sleeve */
    [S_LAPTOP_LID] = MATTE(0.77),   /* anodised aluminium */
    [S_LAPTOP_BASE] = MATTE(0.77),  /* anodised aluminium */
    [S_LEATHER] = MATTE(0.95),      /* leather */
    [S_TISSUE_BOX] = MATTE(0.93),   /* printed cardboard */
    [S_TISSUE_TOP] = MATTE(0.93),   /* paper */
    [S_CASE] = MATTE(0.94),         /* plastic */
    [S_FABRIC] = MATTE(0.95),       /* woven fabric */
    [S_FABRIC_CHECK] = MATTE(0.95), /* woven fabric */
    [S_BAG] = MATTE(0.92),          /* nylon */
    [S_BAG_ZIP] = MATTE(0.93),      /* plastic zip */
    [S_CUSHION_PAD] = MATTE(0.95),  /* fabric */
};

const synth_ir *synth_ir_of_style(int style) {
  static const synth_ir k_default = MATTE(0.95);
  if (style < 0 || style >= S_COUNT || k_ir[style].eps_n <= 0) return &k_default;
  return &k_ir[style];
}

/* unpolarised Fresnel reflectance of a dielectric of real index n */
static double fresnel_real(double n, double c) {
  double s2 = 1.0 - c * c, ct = sqrt(fmax(0.0, 1.0 - s2 / (n * n)));
  double rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
  return 0.5 * (rs * rs + rp * rp);
}

/* unpolarised Fresnel reflectance of an absorbing medium of index N */
static double fresnel_complex(double complex N, double c) {
  double s2 = 1.0 - c * c;
  double complex ct = csqrt(1.0 - s2 / (N * N));
  double complex rs = (c - N * ct) / (c + N * ct), rp = (N * c - ct) / (N * c + ct);
  double as = cabs(rs), ap = cabs(rp);
  return 0.5 * (as * as + ap * ap);
}

double synth_ir_emissivity(const synth_ir *m, double cos_theta, double eps_scale, double grazing) {
  double e = 1.0 - eps_scale * (1.0 - m->eps_n);
  if (e > 1.0) e = 1.0;
  if (e < 0.01) e = 0.01;
  if (grazing <= 0.0 || e >= 0.9999) return e;
  double c = fabs(cos_theta);
  if (c > 1.0) c = 1.0;
  if (c < 1e-6) c = 1e-6;
  double ed;
  if (m->kind == IR_METAL && e < 0.5) {
    /* N = n (1 + i): 1 - R(0) = 4n / (2n^2 + 2n + 1) = e, the larger root */
    double a = 2.0 * e, bq = 2.0 * e - 4.0, disc = bq * bq - 4.0 * a * e;
    double n = (-bq + sqrt(fmax(disc, 0.0))) / (2.0 * a);
    ed = 1.0 - fresnel_complex(n + n * I, c);
  } else {
    /* 1 - R(0) = e: n = (1 + sqrt(R0)) / (1 - sqrt(R0)) */
    double r0 = sqrt(1.0 - e), n = (1.0 + r0) / (1.0 - r0);
    ed = 1.0 - fresnel_real(n, c);
  }
  double g = grazing > 1.0 ? 1.0 : grazing;
  return (1.0 - g) * e + g * ed;
}

/* ---- cooling ------------------------------------------------------------------ */

/* lumped-capacitance time constants tau = m c / (h A) (derivation and the
   masses, heat capacities, areas and film coefficients assumed:
   docs/virtual-rig.md) */
static const struct {
  const char *category;
  double tau_s;
} k_tau[] = {
    {"cup", 1800},          {"electric_kettle", 4500}, {"pot", 5000},     {"sponge", 400},
    {"canned_drink", 4000}, {"bottled_drink", 5000},   {"orange", 3000},  {"smartphone", 800},
    {"laptop", 900},        {"mouse", 1000},           {"headset", 1000},
};

double synth_cooling_tau_s(const char *category, const char *state) {
  (void)state;
  for (size_t i = 0; category && i < sizeof k_tau / sizeof k_tau[0]; i++)
    if (strcmp(category, k_tau[i].category) == 0) return k_tau[i].tau_s;
  return 1200.0;
}
