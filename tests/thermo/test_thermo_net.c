/* The network's step against analytic solutions: a single region cooling to
 * the air, two regions equalising in isolation, energy balance on random
 * networks at any step size, coupled networks. */
#include <string.h>

#include "hearth/thermo.h"
#include "test_util.h"

static hearth_thermo_region region(const char *name, double C, double T, double area, double h,
                                   double eps) {
  hearth_thermo_region r = {0};
  strcpy(r.name, name);
  r.C = C;
  r.T = T;
  r.area = area;
  r.h_conv = h;
  r.emissivity = eps;
  r.label = -1;
  return r;
}

/* (a) T(t) = Ta + (T0 - Ta) exp(-t/tau), tau = C / (h A) (no radiation) */
static void test_single_cooling(void) {
  hearth_err err;
  const double C = 1000, h = 10, A = 0.05, T0 = 80, Ta = 20, tau = C / (h * A);
  const double dts[] = {0.01 * tau, 1e-3 * tau};
  const double tols[] = {0.2,
                         0.02}; /* backward Euler error ~ dt/(2 tau) * (T0-Ta) * t/tau e^-t/tau */
  for (int d = 0; d < 2; d++) {
    hearth_thermo_net net;
    hearth_thermo_net_init(&net);
    net.T_air = Ta;
    hearth_thermo_region r = region("body", C, T0, A, h, 0);
    CHECK_OK(hearth_thermo_add_region(&net, &r, NULL, &err), &err);
    double t = 0, worst = 0;
    while (t < 5 * tau) {
      CHECK_OK(hearth_thermo_step(&net, dts[d], NULL, &err), &err);
      t += dts[d];
      double ref = Ta + (T0 - Ta) * exp(-t / tau);
      if (fabs(net.region[0].T - ref) > worst) worst = fabs(net.region[0].T - ref);
    }
    CHECK_MSG(worst < tols[d], "dt = %g tau: worst error %g K", dts[d] / tau, worst);
  }
  /* dt >> tau: monotone, never below the air (and with radiation too) */
  const double big[] = {10 * tau, 1e3 * tau, 1e6 * tau};
  for (int d = 0; d < 3; d++)
    for (int rad = 0; rad < 2; rad++) {
      hearth_thermo_net net;
      hearth_thermo_net_init(&net);
      net.T_air = Ta;
      hearth_thermo_region r = region("body", C, T0, A, h, rad ? 0.9 : 0);
      CHECK_OK(hearth_thermo_add_region(&net, &r, NULL, &err), &err);
      double prev = T0;
      for (int i = 0; i < 20; i++) {
        CHECK_OK(hearth_thermo_step(&net, big[d], NULL, &err), &err);
        CHECK(net.region[0].T <= prev);
        CHECK(net.region[0].T >= Ta);
        prev = net.region[0].T;
      }
      CHECK_NEAR(prev, Ta, 1e-3 * (T0 - Ta));
    }
  /* a cold body warms toward the air without passing it */
  hearth_thermo_net net;
  hearth_thermo_net_init(&net);
  net.T_air = Ta;
  hearth_thermo_region r = region("body", C, -10, A, h, 0.9);
  CHECK_OK(hearth_thermo_add_region(&net, &r, NULL, &err), &err);
  for (int i = 0; i < 10; i++) {
    double prev = net.region[0].T;
    CHECK_OK(hearth_thermo_step(&net, 1e5, NULL, &err), &err);
    CHECK(net.region[0].T >= prev && net.region[0].T <= Ta);
  }
}

/* (b) two regions in contact, isolated */
static void test_two_isolated(void) {
  hearth_err err;
  const double dts[] = {1e-3, 1, 1e3, 1e6};
  for (int d = 0; d < 4; d++) {
    hearth_thermo_net net;
    hearth_thermo_net_init(&net);
    hearth_thermo_region a = region("a", 300, 90, 0, 0, 0), b = region("b", 1250, 15, 0, 0, 0);
    CHECK_OK(hearth_thermo_add_region(&net, &a, NULL, &err), &err);
    CHECK_OK(hearth_thermo_add_region(&net, &b, NULL, &err), &err);
    CHECK_OK(hearth_thermo_set_conductance(&net, 0, 1, 2.0, &err), &err);
    const double E0 = hearth_thermo_energy(&net), Teq = E0 / (300 + 1250);
    /* tau of the pair: C1 C2 / (G (C1 + C2)) = 121 s; run 20 tau or 50 steps */
    size_t steps = (size_t)fmin(50 + 2420.0 / dts[d], 3e6);
    double worst = 0;
    for (size_t i = 0; i < steps; i++) {
      double heat;
      CHECK_OK(hearth_thermo_step(&net, dts[d], &heat, &err), &err);
      double e = fabs(hearth_thermo_energy(&net) - E0);
      if (e > worst) worst = e;
      if (heat != 0) {
        CHECK(heat == 0);
        break;
      }
      if (net.region[0].T < Teq - 1e-9 || net.region[1].T > Teq + 1e-9) {
        CHECK_MSG(0, "dt %g: overshoot past the equilibrium", dts[d]);
        break;
      }
    }
    CHECK_MSG(worst <= 1e-12 * E0 * 64, "dt %g: energy drift %g J of %g", dts[d], worst, E0);
    CHECK_NEAR(net.region[0].T, Teq, 1e-6);
    CHECK_NEAR(net.region[1].T, Teq, 1e-6);
  }
}

static double urand(hearth_rng *rng) { return hearth_rng_uniform(rng); }

/* (c) random networks: energy after = energy before + heat in, every step;
 * with the air colder than every region, energy never rises */
static void test_random_networks(void) {
  hearth_err err;
  hearth_rng rng;
  hearth_rng_seed(&rng, 12345);
  for (int trial = 0; trial < 200; trial++) {
    hearth_thermo_net net;
    hearth_thermo_net_init(&net);
    net.T_air = 10 + 20 * urand(&rng);
    size_t n = 1 + (size_t)(urand(&rng) * HEARTH_THERMO_MAX_REGIONS);
    if (n > HEARTH_THERMO_MAX_REGIONS) n = HEARTH_THERMO_MAX_REGIONS;
    for (size_t i = 0; i < n; i++) {
      char name[16];
      snprintf(name, sizeof name, "r%zu", i);
      hearth_thermo_region r =
          region(name, pow(10, 6 * urand(&rng) - 1), net.T_air + 100 * urand(&rng),
                 urand(&rng) < 0.5 ? 0 : 0.1 * urand(&rng), 20 * urand(&rng), urand(&rng));
      CHECK_OK(hearth_thermo_add_region(&net, &r, NULL, &err), &err);
    }
    for (size_t i = 0; i < n; i++)
      for (size_t j = i + 1; j < n; j++)
        if (urand(&rng) < 0.4)
          hearth_thermo_set_conductance(&net, i, j, pow(10, 6 * urand(&rng) - 3), &err);
    int contact = urand(&rng) < 0.3;
    if (contact) hearth_thermo_add_contact(&net, 0, urand(&rng), net.T_air - 5, &err);
    double lo = contact ? net.T_air - 5 : net.T_air, hi = -1e9;
    for (size_t i = 0; i < n; i++) hi = fmax(hi, net.region[i].T);
    double dt = pow(10, 12 * urand(&rng) - 4);
    /* rounding of the balance: the energies, and the heat flows over dt
     * (each at most G_ext * 400 K; radiation's secant below 15 W/(m^2 K)) */
    double E = hearth_thermo_energy(&net), scale = 0;
    for (size_t i = 0; i < n; i++) {
      const hearth_thermo_region *r = &net.region[i];
      scale += r->C * (fabs(r->T) + 300) + dt * (r->h_conv + 15) * r->area * 400;
    }
    if (contact) scale += dt * net.contact[0].G * 400;
    for (int s = 0; s < 20; s++) {
      double heat;
      CHECK_OK(hearth_thermo_step(&net, dt, &heat, &err), &err);
      double E1 = hearth_thermo_energy(&net);
      CHECK_MSG(fabs(E1 - (E + heat)) <= 1e-12 * scale, "trial %d: E %.17g -> %.17g, heat %g",
                trial, E, E1, heat);
      /* everything outside is colder than every region: energy only falls */
      if (!contact)
        CHECK_MSG(heat <= 1e-12 * scale && E1 <= E + 1e-12 * scale, "trial %d: energy rose", trial);
      for (size_t i = 0; i < n; i++)
        CHECK_MSG(net.region[i].T >= lo - 1e-9 && net.region[i].T <= hi + 1e-9,
                  "trial %d: region %zu at %g outside [%g, %g]", trial, i, net.region[i].T, lo, hi);
      E = E1;
    }
  }
}

/* two networks joined by a link conserve the energy they exchange */
static void test_coupled(void) {
  hearth_err err;
  hearth_thermo_net a, b;
  hearth_thermo_net_init(&a);
  hearth_thermo_net_init(&b);
  hearth_thermo_region ra = region("cup", 500, 70, 0, 0, 0), rb = region("finger", 50, 30, 0, 0, 0);
  CHECK_OK(hearth_thermo_add_region(&a, &ra, NULL, &err), &err);
  CHECK_OK(hearth_thermo_add_region(&b, &rb, NULL, &err), &err);
  hearth_thermo_net *nets[2] = {&a, &b};
  hearth_thermo_link link = {0, 0, 1, 0, 0.5};
  double E0 = hearth_thermo_energy(&a) + hearth_thermo_energy(&b);
  for (int i = 0; i < 300; i++) {
    double heat;
    CHECK_OK(hearth_thermo_step_coupled(nets, 2, &link, 1, 10.0, &heat, &err), &err);
    CHECK(heat == 0);
  }
  CHECK_NEAR(hearth_thermo_energy(&a) + hearth_thermo_energy(&b), E0, 1e-9 * E0);
  CHECK_NEAR(a.region[0].T, b.region[0].T, 1e-3);
  /* with air on both (convection only): each network's booked heat is
   * dt h A (T_air - T') at its new temperature, and what the link carried,
   * dt G (T_b' - T_a') by backward Euler, is each one's energy change
   * beyond that, equal and opposite */
  a.region[0].T = 80, b.region[0].T = 10;
  a.region[0].area = 0.02, b.region[0].area = 0.001;
  a.region[0].h_conv = 7, b.region[0].h_conv = 20;
  a.T_air = b.T_air = 22;
  for (int i = 0; i < 50; i++) {
    double Ea = hearth_thermo_energy(&a), Eb = hearth_thermo_energy(&b), each[2],
           dt = 5.0 * (i + 1);
    CHECK_OK(hearth_thermo_step_coupled_each(nets, 2, &link, 1, dt, each, &err), &err);
    double Ta = a.region[0].T, Tb = b.region[0].T, q = dt * link.G * (Tb - Ta);
    CHECK_NEAR(each[0], dt * 7 * 0.02 * (22 - Ta), 1e-9 * fabs(each[0]) + 1e-12);
    CHECK_NEAR(each[1], dt * 20 * 0.001 * (22 - Tb), 1e-9 * fabs(each[1]) + 1e-12);
    CHECK_NEAR(hearth_thermo_energy(&a) - Ea - each[0], q, 1e-9 * Ea);
    CHECK_NEAR(hearth_thermo_energy(&b) - Eb - each[1], -q, 1e-9 * Ea);
  }
  /* bad input is refused with a message */
  CHECK(hearth_thermo_step(&a, 0, NULL, &err) == HEARTH_E_ARG);
  CHECK(hearth_thermo_step(&a, NAN, NULL, &err) == HEARTH_E_ARG);
  hearth_thermo_link bad = {0, 3, 1, 0, 1};
  CHECK(hearth_thermo_step_coupled(nets, 2, &bad, 1, 1, NULL, &err) == HEARTH_E_ARG);
  hearth_thermo_region neg = region("neg", -1, 20, 0, 0, 0);
  CHECK(hearth_thermo_add_region(&a, &neg, NULL, &err) == HEARTH_E_RANGE);
  CHECK(strstr(err.msg, "neg") != NULL);
}

int main(void) {
  test_single_cooling();
  test_two_isolated();
  test_random_networks();
  test_coupled();
  return g_test_failures;
}
