/* thermo_net.c - the lumped thermal network: building it and the backward
 * Euler step (include/hearth/thermo.h). */
#include <math.h>
#include <string.h>

#include "hearth/thermo.h"

#define KELVIN 273.15
#define MAX_N (HEARTH_THERMO_MAX_REGIONS * HEARTH_THERMO_MAX_NETS)

void hearth_thermo_net_init(hearth_thermo_net *net) {
  memset(net, 0, sizeof *net);
  net->T_air = 20.0;
}

static int name_ok(const char *s) {
  size_t n = strnlen(s, HEARTH_THERMO_NAME_MAX);
  if (n == 0 || n >= HEARTH_THERMO_NAME_MAX) return 0;
  for (size_t i = 0; i < n; i++) {
    char c = s[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
          c == '-'))
      return 0;
  }
  return 1;
}

static hearth_status region_check(const hearth_thermo_region *r, size_t i, hearth_err *err) {
  if (!name_ok(r->name))
    return hearth_err_set(err, HEARTH_E_ARG, "region %zu: name must be 1..31 of [A-Za-z0-9_-]", i);
  if (!isfinite(r->C) || r->C <= 0)
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: C = %g J/K, expected > 0", r->name,
                          r->C);
  if (!isfinite(r->T) || r->T <= -KELVIN)
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: T = %g degC, expected > -273.15",
                          r->name, r->T);
  if (!isfinite(r->area) || r->area < 0)
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: area = %g m^2, expected >= 0", r->name,
                          r->area);
  if (!isfinite(r->h_conv) || r->h_conv < 0)
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: h_conv = %g, expected >= 0", r->name,
                          r->h_conv);
  if (!isfinite(r->emissivity) || r->emissivity < 0 || r->emissivity > 1)
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: emissivity = %g, expected 0..1", r->name,
                          r->emissivity);
  if (!isfinite(r->power))
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: power is not finite", r->name);
  if (r->label < -1 || r->label >= HEARTH_THERMO_MAX_CLUSTERS)
    return hearth_err_set(err, HEARTH_E_RANGE, "region %s: label = %d, expected -1..%d", r->name,
                          r->label, HEARTH_THERMO_MAX_CLUSTERS - 1);
  return HEARTH_OK;
}

hearth_status hearth_thermo_add_region(hearth_thermo_net *net, const hearth_thermo_region *r,
                                       size_t *index, hearth_err *err) {
  if (net->n >= HEARTH_THERMO_MAX_REGIONS)
    return hearth_err_set(err, HEARTH_E_LIMIT, "a network holds at most %d regions",
                          HEARTH_THERMO_MAX_REGIONS);
  hearth_status s = region_check(r, net->n, err);
  if (s != HEARTH_OK) return s;
  for (size_t i = 0; i < net->n; i++)
    if (strcmp(net->region[i].name, r->name) == 0)
      return hearth_err_set(err, HEARTH_E_INCONSISTENT, "region %s: name already used", r->name);
  net->region[net->n] = *r;
  if (index) *index = net->n;
  net->n++;
  return HEARTH_OK;
}

hearth_status hearth_thermo_set_conductance(hearth_thermo_net *net, size_t i, size_t j, double g,
                                            hearth_err *err) {
  if (i >= net->n || j >= net->n || i == j)
    return hearth_err_set(err, HEARTH_E_ARG,
                          "conductance %zu-%zu: needs two distinct regions of %zu", i, j, net->n);
  if (!isfinite(g) || g < 0)
    return hearth_err_set(err, HEARTH_E_RANGE, "conductance %s-%s = %g W/K, expected >= 0",
                          net->region[i].name, net->region[j].name, g);
  net->G[i][j] = net->G[j][i] = g;
  return HEARTH_OK;
}

hearth_status hearth_thermo_add_contact(hearth_thermo_net *net, size_t region, double G,
                                        double T_other, hearth_err *err) {
  if (region >= net->n)
    return hearth_err_set(err, HEARTH_E_ARG, "contact: region %zu of %zu", region, net->n);
  if (net->n_contacts >= HEARTH_THERMO_MAX_CONTACTS)
    return hearth_err_set(err, HEARTH_E_LIMIT, "a network holds at most %d contacts",
                          HEARTH_THERMO_MAX_CONTACTS);
  if (!isfinite(G) || G < 0 || !isfinite(T_other) || T_other <= -KELVIN)
    return hearth_err_set(err, HEARTH_E_RANGE, "contact on %s: G = %g W/K, T = %g degC",
                          net->region[region].name, G, T_other);
  net->contact[net->n_contacts++] = (hearth_thermo_contact){region, G, T_other};
  return HEARTH_OK;
}

void hearth_thermo_clear_contacts(hearth_thermo_net *net) { net->n_contacts = 0; }

hearth_status hearth_thermo_find(const hearth_thermo_net *net, const char *name, size_t *index,
                                 hearth_err *err) {
  for (size_t i = 0; i < net->n; i++)
    if (strcmp(net->region[i].name, name) == 0) {
      *index = i;
      return HEARTH_OK;
    }
  return hearth_err_set(err, HEARTH_E_NOT_FOUND, "no region named \"%s\"", name);
}

hearth_status hearth_thermo_net_check(const hearth_thermo_net *net, hearth_err *err) {
  if (net->n > HEARTH_THERMO_MAX_REGIONS || net->n_contacts > HEARTH_THERMO_MAX_CONTACTS)
    return hearth_err_set(err, HEARTH_E_LIMIT, "network: %zu regions, %zu contacts", net->n,
                          net->n_contacts);
  if (!isfinite(net->T_air) || net->T_air <= -KELVIN)
    return hearth_err_set(err, HEARTH_E_RANGE, "T_air = %g degC", net->T_air);
  for (size_t i = 0; i < net->n; i++) {
    hearth_status s = region_check(&net->region[i], i, err);
    if (s != HEARTH_OK) return s;
    for (size_t j = 0; j < net->n; j++) {
      double g = net->G[i][j];
      if (!isfinite(g) || g < 0 || g != net->G[j][i] || (i == j && g != 0))
        return hearth_err_set(err, HEARTH_E_INCONSISTENT,
                              "conductance %zu-%zu: must be finite, >= 0, symmetric, 0 on the "
                              "diagonal",
                              i, j);
    }
  }
  for (size_t c = 0; c < net->n_contacts; c++) {
    const hearth_thermo_contact *k = &net->contact[c];
    if (k->region >= net->n || !isfinite(k->G) || k->G < 0 || !isfinite(k->T_other))
      return hearth_err_set(err, HEARTH_E_RANGE, "contact %zu: bad region, G or T", c);
  }
  return HEARTH_OK;
}

double hearth_thermo_energy(const hearth_thermo_net *net) {
  double e = 0;
  for (size_t i = 0; i < net->n; i++) e += net->region[i].C * net->region[i].T;
  return e;
}

double hearth_thermo_mean_temperature(const hearth_thermo_net *net) {
  double c = 0;
  for (size_t i = 0; i < net->n; i++) c += net->region[i].C;
  return c > 0 ? hearth_thermo_energy(net) / c : NAN;
}

/* conductance of region r to the air: convection plus the secant of the
 * T^4 law at r's current temperature */
static double air_conductance(const hearth_thermo_region *r, double T_air) {
  double a = r->T + KELVIN, b = T_air + KELVIN;
  double h_rad = r->emissivity * HEARTH_THERMO_SIGMA * (a * a + b * b) * (a + b);
  return (r->h_conv + h_rad) * r->area;
}

/* Solve A x = b in place (n x n, row stride MAX_N) by Gaussian elimination
 * with partial pivoting. A is a strictly diagonally dominant M-matrix here,
 * so no pivot vanishes; a non-positive pivot is reported as numeric. */
static int solve_dense(double (*A)[MAX_N], double *b, size_t n) {
  for (size_t k = 0; k < n; k++) {
    size_t p = k;
    for (size_t i = k + 1; i < n; i++)
      if (fabs(A[i][k]) > fabs(A[p][k])) p = i;
    if (!(fabs(A[p][k]) > 0)) return -1;
    if (p != k) {
      for (size_t j = 0; j < n; j++) {
        double t = A[k][j];
        A[k][j] = A[p][j];
        A[p][j] = t;
      }
      double t = b[k];
      b[k] = b[p];
      b[p] = t;
    }
    for (size_t i = k + 1; i < n; i++) {
      double f = A[i][k] / A[k][k];
      if (f == 0) continue;
      for (size_t j = k; j < n; j++) A[i][j] -= f * A[k][j];
      b[i] -= f * b[k];
    }
  }
  for (size_t k = n; k-- > 0;) {
    double s = b[k];
    for (size_t j = k + 1; j < n; j++) s -= A[k][j] * b[j];
    b[k] = s / A[k][k];
  }
  return 0;
}

/* the scratch of one coupled step: the joint system over all regions */
typedef struct step_ws {
  double A[MAX_N][MAX_N];
  double rhs[MAX_N];
  double d_ext[MAX_N]; /* air + contact conductance of each unknown */
  double q_ext[MAX_N]; /* sum G_c T_c + power of each unknown */
  size_t base[HEARTH_THERMO_MAX_NETS];
} step_ws;

hearth_status hearth_thermo_step_coupled_each(hearth_thermo_net *const *nets, size_t n_nets,
                                              const hearth_thermo_link *links, size_t n_links,
                                              double dt, double *heat_in, hearth_err *err) {
  if (heat_in)
    for (size_t a = 0; a < n_nets && a < HEARTH_THERMO_MAX_NETS; a++) heat_in[a] = 0;
  if (!(dt > 0) || !isfinite(dt))
    return hearth_err_set(err, HEARTH_E_ARG, "thermal step: dt = %g s, expected > 0", dt);
  if (n_nets == 0 || n_nets > HEARTH_THERMO_MAX_NETS)
    return hearth_err_set(err, HEARTH_E_ARG, "thermal step: %zu networks, expected 1..%d", n_nets,
                          HEARTH_THERMO_MAX_NETS);
  step_ws ws;
  size_t n = 0;
  for (size_t a = 0; a < n_nets; a++) {
    hearth_status s = hearth_thermo_net_check(nets[a], err);
    if (s != HEARTH_OK) {
      hearth_err_prefix(err, "network %zu", a);
      return s;
    }
    ws.base[a] = n;
    n += nets[a]->n;
  }
  for (size_t l = 0; l < n_links; l++) {
    const hearth_thermo_link *k = &links[l];
    if (k->a >= n_nets || k->b >= n_nets || k->ra >= nets[k->a]->n || k->rb >= nets[k->b]->n ||
        (k->a == k->b && k->ra == k->rb) || !isfinite(k->G) || k->G < 0)
      return hearth_err_set(err, HEARTH_E_ARG, "thermal link %zu: bad networks, regions or G", l);
  }
  if (n == 0) return HEARTH_OK;

  for (size_t i = 0; i < n; i++) {
    memset(ws.A[i], 0, n * sizeof ws.A[i][0]);
    ws.d_ext[i] = ws.q_ext[i] = 0;
  }
  /* conductances within each network and to its air and contacts */
  for (size_t a = 0; a < n_nets; a++) {
    const hearth_thermo_net *net = nets[a];
    size_t o = ws.base[a];
    for (size_t i = 0; i < net->n; i++) {
      for (size_t j = 0; j < net->n; j++)
        if (j != i && net->G[i][j] > 0) {
          ws.A[o + i][o + j] -= net->G[i][j];
          ws.A[o + i][o + i] += net->G[i][j];
        }
      double g = air_conductance(&net->region[i], net->T_air);
      ws.d_ext[o + i] += g;
      ws.q_ext[o + i] += g * net->T_air + net->region[i].power;
    }
    for (size_t c = 0; c < net->n_contacts; c++) {
      const hearth_thermo_contact *k = &net->contact[c];
      ws.d_ext[o + k->region] += k->G;
      ws.q_ext[o + k->region] += k->G * k->T_other;
    }
  }
  for (size_t l = 0; l < n_links; l++) {
    size_t i = ws.base[links[l].a] + links[l].ra, j = ws.base[links[l].b] + links[l].rb;
    ws.A[i][j] -= links[l].G;
    ws.A[j][i] -= links[l].G;
    ws.A[i][i] += links[l].G;
    ws.A[j][j] += links[l].G;
  }
  /* rhs = -(L + D) T + q; then A = C/dt + L + D, solved for the increment */
  double T[MAX_N], C[MAX_N];
  for (size_t a = 0; a < n_nets; a++)
    for (size_t i = 0; i < nets[a]->n; i++) {
      T[ws.base[a] + i] = nets[a]->region[i].T;
      C[ws.base[a] + i] = nets[a]->region[i].C;
    }
  for (size_t i = 0; i < n; i++) {
    double s = ws.q_ext[i] - ws.d_ext[i] * T[i];
    for (size_t j = 0; j < n; j++) s -= ws.A[i][j] * T[j];
    ws.rhs[i] = s;
  }
  for (size_t i = 0; i < n; i++) ws.A[i][i] += C[i] / dt + ws.d_ext[i];
  if (solve_dense(ws.A, ws.rhs, n) != 0)
    return hearth_err_set(err, HEARTH_E_NUMERIC, "thermal step: singular system");
  for (size_t a = 0; a < n_nets; a++) {
    double in = 0;
    for (size_t i = 0; i < nets[a]->n; i++) {
      size_t u = ws.base[a] + i;
      double Tn = T[u] + ws.rhs[u];
      in += dt * (ws.q_ext[u] - ws.d_ext[u] * Tn);
      nets[a]->region[i].T = Tn;
    }
    if (heat_in) heat_in[a] = in;
  }
  return HEARTH_OK;
}

hearth_status hearth_thermo_step_coupled(hearth_thermo_net *const *nets, size_t n_nets,
                                         const hearth_thermo_link *links, size_t n_links, double dt,
                                         double *heat_in, hearth_err *err) {
  double each[HEARTH_THERMO_MAX_NETS];
  hearth_status s = hearth_thermo_step_coupled_each(nets, n_nets, links, n_links, dt, each, err);
  if (heat_in) {
    *heat_in = 0;
    for (size_t a = 0; s == HEARTH_OK && a < n_nets; a++) *heat_in += each[a];
  }
  return s;
}

hearth_status hearth_thermo_step(hearth_thermo_net *net, double dt, double *heat_in,
                                 hearth_err *err) {
  hearth_thermo_net *one[1] = {net};
  return hearth_thermo_step_coupled(one, 1, NULL, 0, dt, heat_in, err);
}
