/* Order statistics by selection (poses_internal.h).
 *
 * Large arrays: two values bracketing the k-th are picked from an evenly
 * spaced sample (its order statistics around k's rank), one pass counts the
 * values below and above them, and if the k-th lies between (almost always)
 * a second pass moves the three groups into place through a scratch array
 * without a branch per value; quickselect then only sees the middle group,
 * a tenth of the array. Otherwise (and for arrays with NaN, small arrays or
 * no scratch) quickselect runs on the whole array. Either way the k-th
 * smallest is the same value and v ends partitioned around it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "poses/poses_internal.h"

#define SEL_MIN 4096    /* fewer values: quickselect alone */
#define SEL_SAMPLE 1024 /* sample size */
#define SEL_SPAN 48     /* sample ranks on each side of k's */

static void swap_d(double *a, double *b) {
  double t = *a;
  *a = *b;
  *b = t;
}

static double quickselect(double *v, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  /* invariant: v[0..lo) <= v[lo..hi] <= v(hi..n), and lo <= k <= hi */
  while (lo < hi) {
    /* median of the first, middle and last values as the pivot */
    double a = v[lo], b = v[lo + (hi - lo) / 2], c = v[hi];
    double piv = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
    /* three-way partition: [lo, lt) < piv, [lt, gt) == piv, [gt, hi] > piv;
     * the middle part holds the pivot itself, so each round shrinks the range */
    size_t lt = lo, i = lo, gt = hi + 1;
    while (i < gt) {
      if (v[i] < piv) swap_d(&v[lt++], &v[i++]);
      else if (v[i] > piv) swap_d(&v[i], &v[--gt]);
      else i++;
    }
    if (k < lt) hi = lt - 1;
    else if (k >= gt) lo = gt;
    else return piv;
  }
  return v[k];
}

double rf_select(double *v, size_t n, size_t k) {
  if (n < SEL_MIN) return quickselect(v, n, k);
  double smp[SEL_SAMPLE];
  for (size_t j = 0; j < SEL_SAMPLE; j++) smp[j] = v[j * (n / SEL_SAMPLE)];
  size_t r = (size_t)((double)k / (double)n * SEL_SAMPLE);
  if (r >= SEL_SAMPLE) r = SEL_SAMPLE - 1;
  size_t rlo = r > SEL_SPAN ? r - SEL_SPAN : 0;
  size_t rhi = r + SEL_SPAN < SEL_SAMPLE ? r + SEL_SPAN : SEL_SAMPLE - 1;
  /* the ends of the sample stand for no bound */
  double lo = rlo > 0 ? quickselect(smp, SEL_SAMPLE, rlo) : -INFINITY;
  double hi = rhi < SEL_SAMPLE - 1 ? quickselect(smp, SEL_SAMPLE, rhi) : INFINITY;
  size_t n_lt = 0, n_gt = 0, n_nan = 0;
  for (size_t i = 0; i < n; i++) {
    n_lt += v[i] < lo;
    n_gt += v[i] > hi;
    n_nan += v[i] != v[i];
  }
  double *tmp = NULL;
  if (n_nan || !(lo <= hi) || k < n_lt || k >= n - n_gt ||
      !(tmp = hearth_alloc_array(n, sizeof *tmp)))
    return quickselect(v, n, k);
  /* below lo from 0, between from n_lt, above hi from n - n_gt */
  size_t at[3] = {0, n_lt, n - n_gt};
  for (size_t i = 0; i < n; i++) {
    const double x = v[i];
    const int g = 1 + (x > hi) - (x < lo);
    tmp[at[g]++] = x;
  }
  memcpy(v, tmp, n * sizeof *v);
  free(tmp);
  return quickselect(v + n_lt, n - n_lt - n_gt, k - n_lt);
}

double rf_quantile(double *v, size_t n, double q) {
  if (!n) return 0.0;
  double pos = q * (double)(n - 1);
  size_t i = (size_t)pos;
  if (i + 1 >= n) return rf_select(v, n, n - 1);
  double a = rf_select(v, n, i), b = v[i + 1];
  /* the next order statistic: the smallest value above position i */
  for (size_t j = i + 2; j < n; j++)
    if (v[j] < b) b = v[j];
  return a + (pos - (double)i) * (b - a);
}
