/* The rig's radiometry against independent references: band radiance
 * ratios of Planck's law over 8-14 um integrated with numpy (trapezoid,
 * 200001 points, CODATA 2018 constants), the camera reading's round trip,
 * Fresnel's equations worked by hand for n = 1.5, and the shapes the
 * physics requires (metals' emissivity rising towards grazing, every
 * dielectric's falling to 0). */
#include <math.h>
#include <stdlib.h>
#include "synth/synth_category.h"
#include "synth/synth_radiometry.h"
#include "test_util.h"

int main(void) {
  synth_band *b = malloc(sizeof *b);
  CHECK(b != NULL);
  if (!b) TEST_MAIN_END();
  synth_band_init(b);
  /* numpy: L(100 C) / L(20 C) = 2.770312328, L(0 C) / L(20 C) = 0.711968827,
     L(60 C) / L(20 C) = 1.760723915 */
  double l20 = synth_band_radiance(b, 20.0);
  CHECK_NEAR(synth_band_radiance(b, 100.0) / l20, 2.770312328, 2e-5);
  CHECK_NEAR(synth_band_radiance(b, 0.0) / l20, 0.711968827, 2e-5);
  CHECK_NEAR(synth_band_radiance(b, 60.0) / l20, 1.760723915, 2e-5);
  /* inverse and camera reading: a surface read as t through the camera's
     setting is read back as t, for any setting */
  for (double t = -20.0; t <= 150.0; t += 7.3) {
    CHECK_NEAR(synth_band_temperature(b, synth_band_radiance(b, t)), t, 1e-3);
    double L = synth_camera_radiance(b, 0.95, 22.0, t);
    CHECK_NEAR(synth_camera_reading(b, 0.95, 22.0, L), t, 1e-3);
  }
  /* a black body at 60 C read with the 0.95 setting shows more than 60 C */
  CHECK(synth_camera_reading(b, 0.95, 22.0, synth_band_radiance(b, 60.0)) > 60.5);

  /* dielectric with e_n = 0.96: n = 1.5; by hand R(60 deg) = 0.089186 */
  synth_ir d = {0.96, IR_DIELECTRIC, 1};
  CHECK_NEAR(synth_ir_emissivity(&d, 1.0, 1.0, 1.0), 0.96, 1e-9);
  CHECK_NEAR(synth_ir_emissivity(&d, 0.5, 1.0, 1.0), 1.0 - 0.089186, 1e-5);
  CHECK(synth_ir_emissivity(&d, 0.001, 1.0, 1.0) < 0.02);
  /* the switches: no fall-off, no emissivity below 1 */
  CHECK_NEAR(synth_ir_emissivity(&d, 0.1, 1.0, 0.0), 0.96, 1e-12);
  CHECK_NEAR(synth_ir_emissivity(&d, 0.1, 0.0, 1.0), 1.0, 1e-12);
  /* a metal: e_n at the normal, higher towards grazing, then 0 */
  synth_ir m = {0.07, IR_METAL, 1};
  CHECK_NEAR(synth_ir_emissivity(&m, 1.0, 1.0, 1.0), 0.07, 1e-6);
  double peak = 0;
  for (double c = 0.02; c <= 1.0; c += 0.01) {
    double e = synth_ir_emissivity(&m, c, 1.0, 1.0);
    peak = e > peak ? e : peak;
  }
  CHECK(peak > 0.15);
  CHECK(synth_ir_emissivity(&m, 1e-5, 1.0, 1.0) < 0.01);
  /* every material of the table: 0 < e_n <= 1, monotone for dielectrics */
  for (int s = 0; s < S_COUNT; s++) {
    const synth_ir *ir = synth_ir_of_style(s);
    CHECK_MSG(ir->eps_n > 0 && ir->eps_n <= 1, "style %d: e_n %g", s, ir->eps_n);
    if (ir->kind == IR_DIELECTRIC)
      CHECK_MSG(synth_ir_emissivity(ir, 0.3, 1.0, 1.0) < synth_ir_emissivity(ir, 0.9, 1.0, 1.0),
                "style %d: no fall-off", s);
  }
  /* cooling: tabulated and the fallback */
  CHECK(synth_cooling_tau_s("cup", "hot") == 1800.0);
  CHECK(synth_cooling_tau_s("pillow", "warm") > 0);
  free(b);
  TEST_MAIN_END();
}
