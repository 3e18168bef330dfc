/* Locale-independent decimal parsing/formatting and a portable RNG. */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "hearth/core.h"

/* Exact powers of ten representable in a double. */
static const double k_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                   1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                   1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

int hearth_parse_double(const char *s, size_t len, int decimal_comma, double *out) {
  size_t i = 0;
  int neg = 0;
  if (i < len && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
  uint64_t mant = 0;
  int digits = 0, sig = 0, exp10 = 0, any = 0;
  while (i < len && s[i] >= '0' && s[i] <= '9') {
    any = 1;
    if (sig < 19) {
      mant = mant * 10 + (uint64_t)(s[i] - '0');
      if (mant) sig++;
    } else {
      exp10++;
    }
    i++;
    digits++;
  }
  char dp = decimal_comma ? ',' : '.';
  if (i < len && s[i] == dp) {
    i++;
    while (i < len && s[i] >= '0' && s[i] <= '9') {
      any = 1;
      if (sig < 19) {
        mant = mant * 10 + (uint64_t)(s[i] - '0');
        if (mant) sig++;
        exp10--;
      }
      i++;
    }
  }
  if (!any) return -1;
  if (i < len && (s[i] == 'e' || s[i] == 'E')) {
    i++;
    int eneg = 0, e = 0, edig = 0;
    if (i < len && (s[i] == '+' || s[i] == '-')) eneg = s[i++] == '-';
    while (i < len && s[i] >= '0' && s[i] <= '9') {
      if (e < 10000) e = e * 10 + (s[i] - '0');
      i++;
      edig++;
    }
    if (!edig) return -1;
    exp10 += eneg ? -e : e;
  }
  if (i != len) return -1;
  double v;
  if (mant == 0) {
    v = 0.0;
  } else if (mant < (1ULL << 53) && exp10 >= -22 && exp10 <= 22) {
    /* one correctly rounded operation on exact operands */
    v = exp10 < 0 ? (double)mant / k_pow10[-exp10] : (double)mant * k_pow10[exp10];
  } else {
    v = (double)mant * pow(10.0, exp10);
  }
  if (!isfinite(v)) return -1;
  *out = neg ? -v : v;
  (void)digits;
  return 0;
}

int hearth_format_fixed(char *buf, size_t bufsz, double x, int decimals) {
  if (!isfinite(x) || decimals < 0 || decimals > 9 || bufsz < 2) return -1;
  double scale = k_pow10[decimals];
  double r = nearbyint(fabs(x) * scale);
  if (r > 9.0e15) return -1;
  uint64_t v = (uint64_t)r;
  int neg = x < 0 && v != 0;
  char tmp[48];
  int n = 0;
  /* digits in reverse */
  for (int d = 0; d < decimals; d++) {
    tmp[n++] = (char)('0' + v % 10);
    v /= 10;
  }
  if (decimals) tmp[n++] = '.';
  do {
    tmp[n++] = (char)('0' + v % 10);
    v /= 10;
  } while (v);
  if (neg) tmp[n++] = '-';
  if ((size_t)n + 1 > bufsz) return -1;
  for (int k = 0; k < n; k++) buf[k] = tmp[n - 1 - k];
  buf[n] = 0;
  return n;
}

static uint64_t splitmix64(uint64_t *x) {
  uint64_t z = (*x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

void hearth_rng_seed(hearth_rng *r, uint64_t seed) {
  uint64_t x = seed;
  for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&x);
}

void hearth_rng_fork(const hearth_rng *parent, uint64_t stream, hearth_rng *child) {
  uint64_t x = parent->s[0] ^ (parent->s[1] * 0x9E3779B97F4A7C15ULL) ^
               (stream * 0xD1B54A32D192ED03ULL) ^ parent->s[3];
  for (int i = 0; i < 4; i++) child->s[i] = splitmix64(&x);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t hearth_rng_u64(hearth_rng *r) {
  uint64_t *s = r->s;
  uint64_t result = rotl(s[1] * 5, 7) * 9;
  uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = rotl(s[3], 45);
  return result;
}

double hearth_rng_uniform(hearth_rng *r) {
  return (double)(hearth_rng_u64(r) >> 11) * (1.0 / 9007199254740992.0);
}

double hearth_rng_range(hearth_rng *r, double lo, double hi) {
  return lo + (hi - lo) * hearth_rng_uniform(r);
}

double hearth_rng_normal(hearth_rng *r) {
  /* Box-Muller; uses two uniforms per call so the stream stays simple */
  double u1 = hearth_rng_uniform(r), u2 = hearth_rng_uniform(r);
  if (u1 < 1e-300) u1 = 1e-300;
  return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}
