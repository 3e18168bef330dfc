/* Texture regions: k-means on a two-temperature map, island majority
 * labels, means over observed texels, offsets that rebuild the texture. */
#include <stdint.h>

#include "hearth/map.h"
#include "hearth/thermo.h"
#include "test_util.h"

#define R 32

int main(void) {
  hearth_err err;
  static uint8_t mask[R * R];
  static float obs[R * R], fil[R * R], tex[R * R];
  static uint32_t island[R * R];
  /* left half: a hot body (60 degC with a +-1 pattern), right half: a cool
   * handle (30 degC); row 0 has no surface, row 1 is filled, the last row
   * is an island never observed */
  for (int y = 0; y < R; y++)
    for (int x = 0; x < R; x++) {
      size_t t = (size_t)y * R + x;
      double v = (x < R / 2 ? 60.0 : 30.0) + ((x + y) % 2 ? 1.0 : -1.0);
      island[t] = x < R / 2 ? 7 : 3;
      obs[t] = fil[t] = NAN;
      if (y == 0) {
        mask[t] = HEARTH_TEXEL_NONE;
      } else if (y == R - 1) {
        mask[t] = HEARTH_TEXEL_UNOBSERVED;
        island[t] = 99;
      } else if (y == 1) {
        mask[t] = HEARTH_TEXEL_FILLED;
        fil[t] = (float)v;
      } else {
        mask[t] = HEARTH_TEXEL_OBSERVED;
        obs[t] = fil[t] = (float)v;
      }
    }
  /* one stray hot texel on the handle's island: the island vote keeps it
   * in the handle's region */
  obs[5 * R + R - 1] = fil[5 * R + R - 1] = 61.0f;

  hearth_thermo_regions rg;
  CHECK_OK(hearth_thermo_regions_from_map(R, mask, obs, fil, island, 4, &rg, &err), &err);
  CHECK(rg.k == 2);
  if (rg.k == 2) {
    /* centres ascend: label 0 the handle, 1 the body */
    CHECK_NEAR(rg.mean[1], 60.0, 0.05);
    CHECK(rg.label[5 * R + R - 1] == 0);
    CHECK(rg.label[0] == HEARTH_THERMO_NO_LABEL);
    CHECK(rg.label[(R - 1) * R] != HEARTH_THERMO_NO_LABEL);
    CHECK(rg.n_texels[0] + rg.n_texels[1] == (size_t)(R - 1) * R);
    /* texture at the map's own temperatures = the map */
    hearth_thermo_regions_texture(&rg, rg.mean, tex);
    int same = 1;
    for (size_t t = 0; t < (size_t)R * R; t++)
      if ((mask[t] == HEARTH_TEXEL_OBSERVED || mask[t] == HEARTH_TEXEL_FILLED) &&
          fabsf(tex[t] - fil[t]) > 1e-4f)
        same = 0;
    CHECK(same);
    CHECK(isnan(tex[0]));
    /* the body cools by 20 K: its texels follow, the pattern stays */
    double T[2] = {rg.mean[0], rg.mean[1] - 20.0};
    hearth_thermo_regions_texture(&rg, T, tex);
    CHECK_NEAR(tex[10 * R + 3], fil[10 * R + 3] - 20.0, 1e-4);
    CHECK_NEAR(tex[10 * R + R - 3], fil[10 * R + R - 3], 1e-4);
  }
  hearth_thermo_regions_free(&rg);
  /* without islands the stray texel joins the hot cluster */
  CHECK_OK(hearth_thermo_regions_from_map(R, mask, obs, fil, NULL, 2, &rg, &err), &err);
  CHECK(rg.k == 2 && rg.label[5 * R + R - 1] == 1);
  hearth_thermo_regions_free(&rg);
  /* a uniform map gives one region; bad k is refused */
  for (size_t t = 0; t < (size_t)R * R; t++)
    if (mask[t] == HEARTH_TEXEL_OBSERVED) obs[t] = 25.0f;
  CHECK_OK(hearth_thermo_regions_from_map(R, mask, obs, fil, NULL, 6, &rg, &err), &err);
  CHECK(rg.k == 1);
  hearth_thermo_regions_free(&rg);
  CHECK(hearth_thermo_regions_from_map(R, mask, obs, fil, NULL, 7, &rg, &err) == HEARTH_E_ARG);
  hearth_thermo_regions_free(&rg);
  return g_test_failures;
}
