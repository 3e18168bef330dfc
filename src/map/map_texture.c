/* Texture images from fused maps: Turbo for temperatures, colour as is, with
 * a few texels of padding around islands for clean bilinear lookups. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/map.h"

/* the 4-neighbours of texel q inside the R x R map; returns their count */
static int neighbours4(size_t q, size_t R, size_t nb[4]) {
  /* 32-bit division where the map allows (always, for R <= 16384): the
     64-bit one costs several times more */
  size_t x, y;
  if (R <= UINT16_MAX) {
    x = (uint32_t)q % (uint32_t)R;
    y = (uint32_t)q / (uint32_t)R;
  } else {
    x = q % R;
    y = q / R;
  }
  int k = 0;
  if (x > 0) nb[k++] = q - 1;
  if (x + 1 < R) nb[k++] = q + 1;
  if (y > 0) nb[k++] = q - R;
  if (y + 1 < R) nb[k++] = q + R;
  return k;
}

/* the colours of observed and filled texels, nan_rgb elsewhere; rows in
   parallel (each texel from its own value). state[q]: TEX_NONE, TEX_COLOUR
   (a value or padding), or TEX_LISTED (a padding candidate, no colour yet) */
enum { TEX_NONE = 0, TEX_COLOUR = 1, TEX_LISTED = 2 };
typedef struct colour_job {
  const hearth_map_result *r;
  uint8_t *px, *have;
  uint32_t *cand; /* the frontier pass: each row chunk's candidates at its first texel */
  size_t *n_cand; /* per row chunk (FRONTIER_ROWS rows) */
  const uint8_t (*lut)[3];
  int lut_n;
  double lo, scale;
  const uint8_t *nan_rgb;
} colour_job;

static void colour_rows(void *ctx, size_t b, size_t e, int t) {
  const colour_job *j = ctx;
  const hearth_map_result *r = j->r;
  size_t R = r->R;
  int C = r->channels;
  (void)t;
  for (size_t q = b * R; q < e * R; q++) {
    uint8_t *p = j->px + 3 * q;
    if (r->mask[q] == HEARTH_TEXEL_OBSERVED || r->mask[q] == HEARTH_TEXEL_FILLED) {
      if (C == 1) {
        double u = ((double)r->filled[q] - j->lo) * j->scale;
        int k = !(u > 0) ? 0 : u >= j->lut_n - 1 ? j->lut_n - 1 : (int)(u + 0.5);
        memcpy(p, j->lut[k], 3);
      } else {
        for (int c = 0; c < 3; c++) {
          double v = r->filled[q * (size_t)C + (size_t)c];
          p[c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : lround(v));
        }
      }
      j->have[q] = TEX_COLOUR;
    } else {
      memcpy(p, j->nan_rgb, 3);
      j->have[q] = TEX_NONE;
    }
  }
}

/* padding round 0's candidates, by rows: the uncoloured texels next to a
   coloured one, in texel order within each chunk of rows */
#define FRONTIER_ROWS 32
static void frontier_rows(void *ctx, size_t b, size_t e, int t) {
  const colour_job *j = ctx;
  const size_t R = j->r->R;
  const uint8_t *have = j->have;
  (void)t;
  for (size_t chunk = b; chunk < e; chunk++) {
    size_t y0 = chunk * FRONTIER_ROWS, y1 = y0 + FRONTIER_ROWS < R ? y0 + FRONTIER_ROWS : R, n = 0;
    uint32_t *out = j->cand + y0 * R;
    for (size_t y = y0; y < y1; y++)
      for (size_t x = 0, q = y * R; x < R; x++, q++) {
        if (have[q] == TEX_COLOUR) continue;
        if ((x > 0 && have[q - 1] == TEX_COLOUR) || (x + 1 < R && have[q + 1] == TEX_COLOUR) ||
            (y > 0 && have[q - R] == TEX_COLOUR) || (y + 1 < R && have[q + R] == TEX_COLOUR))
          out[n++] = (uint32_t)q;
      }
    j->n_cand[chunk] = n;
  }
}

hearth_status hearth_map_texture(const hearth_map_result *r, double lo, double hi, int pad,
                                 const uint8_t nan_rgb[3], hearth_image *out, hearth_err *err) {
  size_t R = r->R, N = R * R;
  int C = r->channels;
  hearth_status s = hearth_image_alloc(out, R, R, 3, HEARTH_PIX_U8, err);
  if (s) return s;
  uint8_t *px = out->data;
  /* have[q]: the texel's state (TEX_*); cand / fresh: this and the next
   * round's candidates, rgb their new colours. Turbo goes through a
   * 4096-entry table (0.012 degC steps over 10-60 degC, finer than the 8-bit
   * colours resolve). */
  enum { LUT_N = 4096 };
  const size_t n_chunks = (R + FRONTIER_ROWS - 1) / FRONTIER_ROWS;
  uint8_t *have = hearth_alloc_array(N, 1);
  uint8_t(*lut)[3] = C == 1 ? malloc(sizeof(uint8_t[LUT_N][3])) : NULL;
  uint32_t *cand = hearth_alloc_array(N, sizeof *cand),
           *fresh = hearth_alloc_array(N, sizeof *fresh);
  uint8_t *rgb = hearth_alloc_array(N, 3);
  size_t *n_cand = calloc(n_chunks, sizeof *n_cand);
  if (!have || (C == 1 && !lut) || !cand || !fresh || !rgb || !n_cand) {
    hearth_image_free(out);
    s = hearth_err_set(err, HEARTH_E_NOMEM, "texture: out of memory");
    goto done;
  }
  for (int i = 0; C == 1 && i < LUT_N; i++) hearth_turbo((double)i / (LUT_N - 1), lut[i]);
  colour_job cj = {r,      px,     have,
                   cand,   n_cand, (const uint8_t(*)[3])lut,
                   LUT_N,  lo,     (LUT_N - 1) / (hi - lo),
                   nan_rgb};
  hearth_parallel_chunks(R, 32, 0, colour_rows, &cj);
  /* padding: each round, a texel without colour takes the mean of its
     coloured 4-neighbours (deterministic: reads the previous round only).
     Only the frontier is visited: round 0's candidates are the uncoloured
     texels next to a coloured one (found by row chunks in parallel, then
     gathered in texel order), and each later round's are the uncoloured
     neighbours of the texels the previous round coloured */
  size_t nc = 0;
  if (pad > 0) {
    hearth_parallel_chunks(n_chunks, 1, 0, frontier_rows, &cj);
    for (size_t chunk = 0; chunk < n_chunks; chunk++) {
      memmove(cand + nc, cand + chunk * FRONTIER_ROWS * R, n_cand[chunk] * sizeof *cand);
      nc += n_cand[chunk];
    }
    for (size_t i = 0; i < nc; i++) have[cand[i]] = TEX_LISTED;
  }
  for (int round = 0; round < pad && nc; round++) {
    for (size_t i = 0; i < nc; i++) {
      size_t q = cand[i], nb[4];
      int acc[3] = {0, 0, 0}, n = 0, k = neighbours4(q, R, nb);
      for (int j = 0; j < k; j++)
        if (have[nb[j]] == TEX_COLOUR) {
          for (int c = 0; c < 3; c++) acc[c] += px[3 * nb[j] + (size_t)c];
          n++;
        }
      for (int c = 0; c < 3; c++)
        rgb[3 * i + (size_t)c] = (uint8_t)((acc[c] + n / 2) / (n ? n : 1));
    }
    for (size_t i = 0; i < nc; i++) {
      memcpy(px + 3 * (size_t)cand[i], rgb + 3 * i, 3);
      have[cand[i]] = TEX_COLOUR;
    }
    size_t nf = 0;
    for (size_t i = 0; i < nc && round + 1 < pad; i++) {
      size_t nb[4];
      int k = neighbours4(cand[i], R, nb);
      for (int j = 0; j < k; j++)
        if (have[nb[j]] == TEX_NONE) {
          have[nb[j]] = TEX_LISTED;
          fresh[nf++] = (uint32_t)nb[j];
        }
    }
    uint32_t *t = cand;
    cand = fresh;
    fresh = t;
    nc = nf;
  }
done:
  free(cand);
  free(fresh);
  free(rgb);
  free(have);
  free(n_cand);
  free(lut);
  return s;
}
