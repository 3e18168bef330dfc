/* Order statistics by selection (poses_internal.h). */
#include "poses/poses_internal.h"

static void swap_d(double *a, double *b) {
  double t = *a;
  *a = *b;
  *b = t;
}

double rf_select(double *v, size_t n, size_t k) {
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
