/* thermo_regions.c - texel regions of a temperature map: 1-D k-means on the
 * observed temperatures, optional UV-island majority labels, region means
 * and the offset field that keeps the texture's detail. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/map.h"
#include "hearth/thermo.h"

#define KMEANS_ITERS 50

void hearth_thermo_regions_free(hearth_thermo_regions *r) {
  if (!r) return;
  free(r->label);
  free(r->offset);
  memset(r, 0, sizeof *r);
}

static int cmp_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

static int cmp_u32(const void *a, const void *b) {
  uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return (x > y) - (x < y);
}

static size_t nearest(const double *centre, size_t k, double v) {
  size_t best = 0;
  for (size_t c = 1; c < k; c++)
    if (fabs(v - centre[c]) < fabs(v - centre[best])) best = c;
  return best;
}

/* Lloyd's iterations from the k quantile centres of the sorted values */
static size_t kmeans_1d(const float *sorted, size_t n, size_t k, double *centre) {
  for (size_t c = 0; c < k; c++) centre[c] = sorted[(size_t)((2 * c + 1) * n / (2 * k))];
  for (int it = 0; it < KMEANS_ITERS; it++) {
    double sum[HEARTH_THERMO_MAX_CLUSTERS] = {0};
    size_t cnt[HEARTH_THERMO_MAX_CLUSTERS] = {0};
    for (size_t i = 0; i < n; i++) {
      size_t c = nearest(centre, k, sorted[i]);
      sum[c] += sorted[i];
      cnt[c]++;
    }
    int moved = 0;
    for (size_t c = 0; c < k; c++)
      if (cnt[c] && sum[c] / cnt[c] != centre[c]) {
        centre[c] = sum[c] / cnt[c];
        moved = 1;
      }
    if (!moved) break;
  }
  /* drop duplicate centres (equal quantiles), keep ascending order */
  size_t m = 0;
  for (size_t c = 0; c < k; c++)
    if (m == 0 || centre[c] != centre[m - 1]) centre[m++] = centre[c];
  return m;
}

hearth_status hearth_thermo_regions_from_map(size_t R, const uint8_t *mask, const float *observed,
                                             const float *filled, const uint32_t *island, size_t k,
                                             hearth_thermo_regions *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  if (k == 0 || k > HEARTH_THERMO_MAX_CLUSTERS)
    return hearth_err_set(err, HEARTH_E_ARG, "regions: k = %zu, expected 1..%d", k,
                          HEARTH_THERMO_MAX_CLUSTERS);
  if (R == 0 || R > 65536 || !mask || !observed || !filled)
    return hearth_err_set(err, HEARTH_E_ARG, "regions: needs an R x R map with mask and values");
  size_t n = R * R, n_obs = 0;
  for (size_t t = 0; t < n; t++)
    if (mask[t] == HEARTH_TEXEL_OBSERVED && isfinite(observed[t])) n_obs++;
  if (n_obs == 0)
    return hearth_err_set(err, HEARTH_E_INCONSISTENT, "regions: the map has no observed texel");
  float *vals = malloc(n_obs * sizeof *vals);
  out->label = malloc(n);
  out->offset = malloc(n * sizeof *out->offset);
  if (!vals || !out->label || !out->offset) {
    free(vals);
    hearth_thermo_regions_free(out);
    return hearth_err_set(err, HEARTH_E_NOMEM, "regions: %zu texels", n);
  }
  out->R = R;
  size_t m = 0;
  for (size_t t = 0; t < n; t++)
    if (mask[t] == HEARTH_TEXEL_OBSERVED && isfinite(observed[t])) vals[m++] = observed[t];
  qsort(vals, n_obs, sizeof *vals, cmp_float);
  double centre[HEARTH_THERMO_MAX_CLUSTERS];
  size_t kc = kmeans_1d(vals, n_obs, k < n_obs ? k : n_obs, centre);
  free(vals);

  /* label every texel with a value by its nearest centre */
  for (size_t t = 0; t < n; t++) {
    float v = mask[t] == HEARTH_TEXEL_OBSERVED ? observed[t] : filled[t];
    out->label[t] =
        (mask[t] == HEARTH_TEXEL_OBSERVED || mask[t] == HEARTH_TEXEL_FILLED) && isfinite(v)
            ? (uint8_t)nearest(centre, kc, v)
            : HEARTH_THERMO_NO_LABEL;
  }
  /* islands: every island takes the label most of its observed texels have
   * (ties to the lower label); island ids are found in a sorted id list */
  if (island) {
    uint32_t *ids = malloc(n * sizeof *ids);
    size_t n_ids = 0;
    if (!ids) {
      hearth_thermo_regions_free(out);
      return hearth_err_set(err, HEARTH_E_NOMEM, "regions: island table");
    }
    for (size_t t = 0; t < n; t++)
      if (out->label[t] != HEARTH_THERMO_NO_LABEL) ids[n_ids++] = island[t];
    qsort(ids, n_ids, sizeof *ids, cmp_u32);
    size_t u = 0;
    for (size_t i = 0; i < n_ids; i++)
      if (u == 0 || ids[i] != ids[u - 1]) ids[u++] = ids[i];
    size_t(*votes)[HEARTH_THERMO_MAX_CLUSTERS] = calloc(u ? u : 1, sizeof *votes);
    if (!votes) {
      free(ids);
      hearth_thermo_regions_free(out);
      return hearth_err_set(err, HEARTH_E_NOMEM, "regions: island votes");
    }
    for (size_t t = 0; t < n; t++)
      if (mask[t] == HEARTH_TEXEL_OBSERVED && out->label[t] != HEARTH_THERMO_NO_LABEL) {
        const uint32_t *p = bsearch(&island[t], ids, u, sizeof *ids, cmp_u32);
        votes[p - ids][out->label[t]]++;
      }
    for (size_t t = 0; t < n; t++) {
      if (out->label[t] == HEARTH_THERMO_NO_LABEL) continue;
      const uint32_t *p = bsearch(&island[t], ids, u, sizeof *ids, cmp_u32);
      const size_t *v = votes[p - ids];
      size_t best = 0, total = 0;
      for (size_t c = 0; c < kc; c++) {
        total += v[c];
        if (v[c] > v[best]) best = c;
      }
      if (total) out->label[t] = (uint8_t)best; /* an island never observed keeps its own */
    }
    free(votes);
    free(ids);
  }

  /* region means over observed texels; empty regions dropped */
  double sum[HEARTH_THERMO_MAX_CLUSTERS] = {0};
  size_t cnt[HEARTH_THERMO_MAX_CLUSTERS] = {0}, all[HEARTH_THERMO_MAX_CLUSTERS] = {0};
  for (size_t t = 0; t < n; t++) {
    if (out->label[t] == HEARTH_THERMO_NO_LABEL) continue;
    all[out->label[t]]++;
    if (mask[t] == HEARTH_TEXEL_OBSERVED) {
      sum[out->label[t]] += observed[t];
      cnt[out->label[t]]++;
    }
  }
  uint8_t remap[HEARTH_THERMO_MAX_CLUSTERS];
  size_t kk = 0, largest = 0;
  for (size_t c = 0; c < kc; c++) {
    remap[c] = HEARTH_THERMO_NO_LABEL;
    if (cnt[c] == 0) continue;
    remap[c] = (uint8_t)kk;
    out->mean[kk] = sum[c] / (double)cnt[c];
    out->n_observed[kk] = cnt[c];
    out->n_texels[kk] = all[c];
    if (all[c] > out->n_texels[largest]) largest = kk;
    kk++;
  }
  out->k = kk;
  /* a region without observed texels (only filled texels chose it) is
   * merged into the nearest kept region by mean */
  for (size_t c = 0; c < kc; c++)
    if (remap[c] == HEARTH_THERMO_NO_LABEL) {
      size_t best = 0;
      for (size_t d = 1; d < kk; d++)
        if (fabs(out->mean[d] - centre[c]) < fabs(out->mean[best] - centre[c])) best = d;
      remap[c] = (uint8_t)best;
    }
  memset(out->n_texels, 0, sizeof out->n_texels);
  for (size_t t = 0; t < n; t++) {
    if (out->label[t] != HEARTH_THERMO_NO_LABEL) {
      uint8_t l = remap[out->label[t]];
      float v = mask[t] == HEARTH_TEXEL_OBSERVED ? observed[t] : filled[t];
      out->n_texels[l]++;
      out->label[t] = l;
      out->offset[t] = (float)((double)v - out->mean[l]);
    } else if (mask[t] == HEARTH_TEXEL_UNOBSERVED) {
      out->label[t] = (uint8_t)largest;
      out->offset[t] = 0.0f;
      out->n_texels[largest]++;
    } else {
      out->offset[t] = 0.0f;
    }
  }
  return HEARTH_OK;
}

void hearth_thermo_regions_texture(const hearth_thermo_regions *r, const double *T_label,
                                   float *out) {
  size_t n = r->R * r->R;
  for (size_t t = 0; t < n; t++)
    out[t] =
        r->label[t] == HEARTH_THERMO_NO_LABEL ? NAN : (float)(T_label[r->label[t]] + r->offset[t]);
}
