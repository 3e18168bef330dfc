/* The truth read at a matched surface point (hb_truth_sample), in closed
 * form: a 32 x 32 map whose left half is one island, a 32 mm plate with 1 mm
 * texels carrying a linear field (1.3 degC/mm, the hot cup rim's gradient),
 * and whose right half is another island far away at 90 degC. Bilinear
 * reading must return the linear field exactly where the four texel centres
 * around the point are the plate's; beside the other island it must keep to
 * the plate's own texels; texels without surface never count. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "release/release_internal.h"
#include "test_util.h"

#define RG 32
#define N (RG * RG)
#define L 0.032 /* metres across the map: 1 mm a texel */

static double field(double x, double y) { return 20.0 + 1300.0 * x + 400.0 * y; }

/* the plate's point at uv (both islands share the UV-to-plane map; the
   second lies 0.1 m above the plate) */
static void plate_point(double u, double v, double p[3]) {
  p[0] = u * L;
  p[1] = v * L;
  p[2] = 0;
}

static double frand(unsigned *s) {
  *s = *s * 1103515245u + 12345u;
  return (double)((*s >> 8) & 0xffffff) / (double)0x1000000;
}

/* a random point of the plate at texel coordinates x0 + dx U(0,1),
   y0 + dy U(0,1): its uv, its place q and the field there */
static double plate_draw(unsigned *seed, double x0, double dx, double y0, double dy, double uv[2],
                         double q[3]) {
  double x = x0 + dx * frand(seed), y = y0 + dy * frand(seed);
  uv[0] = x / RG;
  uv[1] = y / RG;
  plate_point(uv[0], uv[1], q);
  return field(q[0], q[1]);
}

int main(void) {
  static float map[N], pos[3 * N], map3[3 * N];
  for (int r = 0; r < RG; r++)
    for (int c = 0; c < RG; c++) {
      const int t = r * RG + c;
      double p[3];
      plate_point((c + 0.5) / RG, (r + 0.5) / RG, p);
      if (r == 0) { /* the first row holds no surface */
        map[t] = NAN;
        pos[3 * t] = pos[3 * t + 1] = pos[3 * t + 2] = NAN;
      } else if (c < RG / 2) {
        map[t] = (float)field(p[0], p[1]);
        for (int a = 0; a < 3; a++) pos[3 * t + a] = (float)p[a];
      } else {
        map[t] = 90.0f;
        pos[3 * t] = (float)p[0], pos[3 * t + 1] = (float)p[1], pos[3 * t + 2] = 0.1f;
      }
      map3[3 * t] = -5.0f, map3[3 * t + 1] = map[t], map3[3 * t + 2] = 77.0f;
    }
  const double reach = 2.0 * L / RG; /* 2 texels, as truth_reach gives a plate */

  /* inside the plate's island: exact, where the nearest texel is not */
  unsigned seed = 7;
  double worst_bil = 0, worst_near = 0;
  for (int i = 0; i < 2000; i++) {
    /* between the texel centres of rows 1..31, columns 0..15 */
    double uv[2], q[3], exact = plate_draw(&seed, 0.5, 15.0, 1.5, 30.0, uv, q);
    double got = hb_truth_sample(map, RG, 1, 0, pos, q, uv, reach);
    double got3 = hb_truth_sample(map3, RG, 3, 1, pos, q, uv, reach);
    CHECK_MSG(got == got3, "channel 1 of a 3-channel map: %g against %g", got3, got);
    worst_bil = fmax(worst_bil, fabs(got - exact));
    long c = (long)floor(uv[0] * RG), r = (long)floor(uv[1] * RG);
    worst_near = fmax(worst_near, fabs(map[r * RG + c] - exact));
  }
  printf("inside: bilinear worst %.2e degC, nearest texel worst %.3f degC\n", worst_bil,
         worst_near);
  CHECK_MSG(worst_bil < 1e-4, "bilinear off by %g degC on a linear field", worst_bil);
  /* the ruler the bilinear read replaces: half a texel of 1.3 and 0.4 degC/mm */
  CHECK_MSG(worst_near > 0.6, "nearest texel only %g off", worst_near);

  /* beside the other island (columns 15 | 16): only the plate's texels,
     so within a texel's change of the field, and never pulled to 90 */
  double worst_seam = 0, worst_ungated = 0;
  for (int i = 0; i < 500; i++) {
    double uv[2], q[3], exact = plate_draw(&seed, 15.0, 0.999, 1.5, 30.0, uv, q);
    double got = hb_truth_sample(map, RG, 1, 0, pos, q, uv, reach);
    double ungated = hb_truth_sample(map, RG, 1, 0, pos, q, uv, 1e9);
    worst_seam = fmax(worst_seam, fabs(got - exact));
    worst_ungated = fmax(worst_ungated, fabs(ungated - exact));
  }
  printf("seam: worst %.3f degC, without the reach %.1f degC\n", worst_seam, worst_ungated);
  CHECK_MSG(worst_seam <= 1.3 + 1e-4, "beside the other island: %g degC off", worst_seam);
  CHECK_MSG(worst_ungated > 10, "the other island did not bleed in without the reach (%g)",
            worst_ungated);

  /* at the edge of surface (row 0 has none): the rows below only */
  {
    double uv[2] = {4.2 / RG, 0.9 / RG}, q[3];
    plate_point(uv[0], uv[1], q);
    double got = hb_truth_sample(map, RG, 1, 0, pos, q, uv, reach);
    CHECK_MSG(isfinite(got) && fabs(got - field(q[0], q[1])) < 0.4 + 1e-4,
              "beside texels without surface: %g against %g", got, field(q[0], q[1]));
  }
  /* no counting texel: NaN (between row 0, without surface, and the row
     above the map; a point off the map) */
  {
    double uv[2] = {4.2 / RG, 0.2 / RG}, q[3];
    plate_point(uv[0], uv[1], q);
    CHECK(isnan(hb_truth_sample(map, RG, 1, 0, pos, q, uv, reach)));
    double off[2] = {-0.1, 0.5};
    CHECK(isnan(hb_truth_sample(map, RG, 1, 0, pos, q, off, reach)));
  }
  return g_test_failures != 0;
}
