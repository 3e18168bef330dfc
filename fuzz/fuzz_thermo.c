/* Fuzz target for thermal_model.json: the parser must fail cleanly, and a
 * model it accepts must pass the network check and take a step at any dt
 * without leaving the range of its temperatures. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "hearth/thermo.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  hearth_err err;
  hearth_thermo_model m;
  if (hearth_thermo_model_parse((const char *)data, size, "fuzz", &m, &err) != HEARTH_OK) return 0;
  if (hearth_thermo_net_check(&m.net, &err) != HEARTH_OK) abort();
  double lo = m.net.T_air, hi = m.net.T_air;
  for (size_t i = 0; i < m.net.n; i++) {
    lo = fmin(lo, m.net.region[i].T);
    hi = fmax(hi, m.net.region[i].T);
  }
  const double dts[] = {1e-3, 1.0, 1e6};
  for (int d = 0; d < 3; d++) {
    if (hearth_thermo_step(&m.net, dts[d], NULL, &err) != HEARTH_OK) abort();
    for (size_t i = 0; i < m.net.n; i++) {
      double T = m.net.region[i].T, tol = 1e-9 * (fabs(lo) + fabs(hi) + 1);
      if (!(T >= lo - tol && T <= hi + tol)) abort();
    }
  }
  return 0;
}
