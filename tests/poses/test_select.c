/* Order statistics by selection (rf_select, rf_quantile) against qsort's
 * sorted copy (an independent order): every k of small arrays, and for
 * arrays large enough for the sampled path, ranks at both ends and in the
 * middle of random, sorted, reversed, few-valued and all-equal data, plus
 * an array with a NaN (the quickselect path). The k-th value must be the
 * sorted one and the array partitioned around it, and still hold the same
 * values (same sorted copy). */
#include <math.h>
#include <stdint.h>
#include "poses/poses_internal.h"
#include "test_util.h"

static uint32_t next_u32(uint64_t *s) {
  *s = *s * 6364136223846793005ull + 1442695040888963407ull;
  return (uint32_t)(*s >> 33);
}

static int cmp_d(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* rf_select(v, n, k) on a copy of v: the sorted value, partitioned, a
   permutation */
static int check_k(const double *v, const double *sorted, size_t n, size_t k, double *w,
                   double *w2) {
  memcpy(w, v, n * sizeof *w);
  double got = rf_select(w, n, k);
  if (got != sorted[k]) return 0;
  for (size_t i = 0; i < n; i++)
    if ((i < k && !(w[i] <= got)) || (i > k && !(w[i] >= got))) return 0;
  if (w[k] != got) return 0;
  memcpy(w2, w, n * sizeof *w2);
  qsort(w2, n, sizeof *w2, cmp_d);
  return memcmp(w2, sorted, n * sizeof *w2) == 0;
}

int main(void) {
  enum { N = 60000 };
  double *v = malloc(N * sizeof *v), *sorted = malloc(N * sizeof *v), *w = malloc(N * sizeof *v),
         *w2 = malloc(N * sizeof *v);
  CHECK(v && sorted && w && w2);
  uint64_t seed = 99;
  const size_t sizes[] = {1, 2, 7, 100, 4095, 4096, 5000, N};
  for (int kind = 0; kind < 5; kind++)
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++) {
      size_t n = sizes[si];
      for (size_t i = 0; i < n; i++) {
        uint32_t r = next_u32(&seed);
        v[i] = kind == 0   ? (double)r / 4294967296.0 - 0.3
               : kind == 1 ? (double)i
               : kind == 2 ? (double)(n - i)
               : kind == 3 ? (double)(r % 3)
                           : 2.5;
      }
      memcpy(sorted, v, n * sizeof *v);
      qsort(sorted, n, sizeof *sorted, cmp_d);
      size_t ks[] = {0, 1, n / 50, n / 2, n - 1 - n / 50, n - 2, n - 1};
      for (size_t j = 0; j < sizeof ks / sizeof *ks; j++) {
        size_t k = ks[j] < n ? ks[j] : n - 1;
        CHECK_MSG(check_k(v, sorted, n, k, w, w2), "kind %d, n %zu, k %zu", kind, n, k);
      }
      if (n <= 100)
        for (size_t k = 0; k < n; k++)
          CHECK_MSG(check_k(v, sorted, n, k, w, w2), "kind %d, n %zu, k %zu", kind, n, k);
      /* the quantile interpolates between the sorted neighbours */
      memcpy(w, v, n * sizeof *w);
      double pos = 0.9 * (double)(n - 1), want = sorted[(size_t)pos];
      if ((size_t)pos + 1 < n)
        want += (pos - floor(pos)) * (sorted[(size_t)pos + 1] - sorted[(size_t)pos]);
      CHECK_MSG(fabs(rf_quantile(w, n, 0.9) - want) <= 1e-12 * (1 + fabs(want)),
                "kind %d, n %zu: 0.9 quantile", kind, n);
    }
  /* a NaN among many values: the result is still one of the values and
     the call returns */
  for (size_t i = 0; i < N; i++) v[i] = (double)(next_u32(&seed) % 1000);
  v[N / 3] = NAN;
  memcpy(w, v, N * sizeof *w);
  double got = rf_select(w, N, N / 2);
  CHECK(got >= 0.0 && got < 1000.0);
  free(v);
  free(sorted);
  free(w);
  free(w2);
  TEST_MAIN_END();
}
