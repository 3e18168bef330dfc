/* hearth_map_texture against an independent reference: Turbo colours of
 * observed and filled texels (through hearth_turbo, within one 8-bit step
 * of the table the texture uses), the NaN colour elsewhere, and island
 * padding that equals the rule applied by brute force: each round, every
 * uncoloured texel with coloured 4-neighbours (as of the previous round)
 * takes their rounded mean. Random masks, several sizes and pad widths. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/hearth.h"
#include "test_util.h"

/* the padding rule, scanning every texel every round */
static void reference_pad(size_t R, uint8_t *px, uint8_t *have, int pad) {
  size_t N = R * R;
  uint8_t *nh = malloc(N), *np = malloc(3 * N);
  for (int round = 0; round < pad; round++) {
    memcpy(nh, have, N);
    memcpy(np, px, 3 * N);
    for (size_t y = 0; y < R; y++)
      for (size_t x = 0; x < R; x++) {
        size_t q = y * R + x;
        if (have[q]) continue;
        int acc[3] = {0, 0, 0}, n = 0;
        long dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
        for (int k = 0; k < 4; k++) {
          long nx = (long)x + dx[k], ny = (long)y + dy[k];
          if (nx < 0 || ny < 0 || nx >= (long)R || ny >= (long)R) continue;
          size_t nq = (size_t)ny * R + (size_t)nx;
          if (!have[nq]) continue;
          for (int c = 0; c < 3; c++) acc[c] += px[3 * nq + c];
          n++;
        }
        if (!n) continue;
        for (int c = 0; c < 3; c++) np[3 * q + c] = (uint8_t)((acc[c] + n / 2) / n);
        nh[q] = 1;
      }
    memcpy(have, nh, N);
    memcpy(px, np, 3 * N);
  }
  free(nh);
  free(np);
}

int main(void) {
  hearth_rng rng;
  hearth_rng_seed(&rng, 7);
  const size_t sizes[] = {1, 2, 17, 64};
  const int pads[] = {0, 1, 4, 9};
  const uint8_t nan_rgb[3] = {10, 20, 30};
  for (size_t si = 0; si < 4; si++)
    for (int pi = 0; pi < 4; pi++) {
      size_t R = sizes[si], N = R * R;
      int pad = pads[pi];
      hearth_map_result r = {0};
      r.R = R;
      r.channels = 1;
      r.mask = malloc(N);
      r.filled = malloc(N * sizeof(float));
      /* blobs of surface: a few random discs, observed or filled */
      for (size_t q = 0; q < N; q++) r.mask[q] = HEARTH_TEXEL_NONE, r.filled[q] = NAN;
      for (int b = 0; b < 3; b++) {
        double cx = hearth_rng_uniform(&rng) * R, cy = hearth_rng_uniform(&rng) * R;
        double rad = 0.5 + hearth_rng_uniform(&rng) * R / 4.0;
        for (size_t y = 0; y < R; y++)
          for (size_t x = 0; x < R; x++) {
            double d = hypot(x + 0.5 - cx, y + 0.5 - cy);
            if (d > rad) continue;
            size_t q = y * R + x;
            double u = hearth_rng_uniform(&rng);
            r.mask[q] = u < 0.6   ? HEARTH_TEXEL_OBSERVED
                        : u < 0.9 ? HEARTH_TEXEL_FILLED
                                  : HEARTH_TEXEL_UNOBSERVED;
            if (r.mask[q] != HEARTH_TEXEL_UNOBSERVED)
              r.filled[q] = (float)(0 + 70 * hearth_rng_uniform(&rng));
          }
      }
      hearth_image tex = {0};
      hearth_err err = {0};
      CHECK_OK(hearth_map_texture(&r, 10.0, 60.0, pad, nan_rgb, &tex, &err), &err);
      uint8_t *px = malloc(3 * N), *have = calloc(N, 1);
      int worst = 0;
      for (size_t q = 0; q < N; q++) {
        if (r.mask[q] == HEARTH_TEXEL_OBSERVED || r.mask[q] == HEARTH_TEXEL_FILLED) {
          hearth_turbo((r.filled[q] - 10.0) / 50.0, px + 3 * q);
          have[q] = 1;
        } else {
          memcpy(px + 3 * q, nan_rgb, 3);
        }
      }
      /* the table may differ from the polynomial by one step: compare the
       * coloured texels first, then pad from the texture's own colours */
      const uint8_t *tp = tex.data;
      for (size_t q = 0; q < N; q++)
        if (have[q])
          for (int c = 0; c < 3; c++) {
            int d = abs((int)tp[3 * q + c] - (int)px[3 * q + c]);
            if (d > worst) worst = d;
          }
      CHECK_MSG(worst <= 1, "R=%zu: Turbo colours off by %d", R, worst);
      for (size_t q = 0; q < N; q++)
        if (have[q]) memcpy(px + 3 * q, tp + 3 * q, 3);
      reference_pad(R, px, have, pad);
      size_t diff = 0;
      for (size_t i = 0; i < 3 * N; i++) diff += px[i] != tp[i];
      CHECK_MSG(diff == 0, "R=%zu pad=%d: %zu bytes differ from the reference padding", R, pad,
                diff);
      free(px);
      free(have);
      hearth_image_free(&tex);
      free(r.mask);
      free(r.filled);
    }
  TEST_MAIN_END();
}
