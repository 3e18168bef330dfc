/* Locale-free number parsing/formatting, RNG determinism, parallel-for. */
#include <locale.h>
#include <stdatomic.h>
#include "hearth/core.h"
#include "test_util.h"

typedef struct chunk_seen {
  _Atomic int hits[1000];
  _Atomic int bad;
  size_t chunk;
  int nt;
} chunk_seen;

static void chunk_range(void *ctx, size_t b, size_t e, int t) {
  chunk_seen *cs = ctx;
  if (t < 0 || t >= cs->nt || b >= e || b % cs->chunk || (e - b != cs->chunk && e != 1000))
    atomic_store(&cs->bad, 1);
  for (size_t i = b; i < e && i < 1000; i++) atomic_fetch_add(&cs->hits[i], 1);
}

static void sum_range(void *ctx, size_t b, size_t e, int t) {
  double *out = ctx;
  for (size_t i = b; i < e; i++) out[i] = (double)i * 0.5;
}

int main(void) {
  double v;
  CHECK(hearth_parse_double("21.37", 5, 0, &v) == 0 && v == 21.37);
  CHECK(hearth_parse_double("-0.05", 5, 0, &v) == 0 && v == -0.05);
  CHECK(hearth_parse_double("21,37", 5, 1, &v) == 0 && v == 21.37);
  CHECK(hearth_parse_double("21,37", 5, 0, &v) != 0);
  CHECK(hearth_parse_double("1e3", 3, 0, &v) == 0 && v == 1000.0);
  CHECK(hearth_parse_double("2.5E-2", 6, 0, &v) == 0 && v == 0.025);
  CHECK(hearth_parse_double("nan", 3, 0, &v) != 0);
  CHECK(hearth_parse_double("inf", 3, 0, &v) != 0);
  CHECK(hearth_parse_double("", 0, 0, &v) != 0);
  CHECK(hearth_parse_double("-", 1, 0, &v) != 0);
  CHECK(hearth_parse_double("1.2.3", 5, 0, &v) != 0);
  CHECK(hearth_parse_double("1e", 2, 0, &v) != 0);
  CHECK(hearth_parse_double("1e999", 5, 0, &v) != 0);
  CHECK(hearth_parse_double(".5", 2, 0, &v) == 0 && v == 0.5);
  /* every 2-decimal temperature parses to the same double as the C library */
  for (int i = -5000; i <= 65000; i += 7) {
    char buf[32];
    int n = hearth_format_fixed(buf, sizeof buf, i / 100.0, 2);
    CHECK(n > 0);
    CHECK(hearth_parse_double(buf, (size_t)n, 0, &v) == 0 && v == strtod(buf, NULL));
  }
  char buf[32];
  CHECK(hearth_format_fixed(buf, sizeof buf, -0.004, 2) > 0 && !strcmp(buf, "0.00"));
  CHECK(hearth_format_fixed(buf, sizeof buf, -1.25, 1) > 0 && !strcmp(buf, "-1.2"));
  CHECK(hearth_format_fixed(buf, sizeof buf, 22.0, 3) > 0 && !strcmp(buf, "22.000"));
  /* a comma-decimal locale must not change anything */
  if (setlocale(LC_NUMERIC, "de_DE.UTF-8")) {
    CHECK(hearth_parse_double("21.37", 5, 0, &v) == 0 && v == 21.37);
    CHECK(hearth_format_fixed(buf, sizeof buf, 21.37, 2) > 0 && !strcmp(buf, "21.37"));
    setlocale(LC_NUMERIC, "C");
  }
  /* rng: same seed, same stream; forks differ */
  hearth_rng a, b, c;
  hearth_rng_seed(&a, 42);
  hearth_rng_seed(&b, 42);
  for (int i = 0; i < 100; i++) CHECK(hearth_rng_u64(&a) == hearth_rng_u64(&b));
  hearth_rng_fork(&a, 1, &b);
  hearth_rng_fork(&a, 2, &c);
  CHECK(hearth_rng_u64(&b) != hearth_rng_u64(&c));
  double mean = 0, var = 0;
  for (int i = 0; i < 100000; i++) {
    double x = hearth_rng_normal(&a);
    mean += x;
    var += x * x;
  }
  mean /= 100000;
  var = var / 100000 - mean * mean;
  CHECK_NEAR(mean, 0.0, 0.02);
  CHECK_NEAR(var, 1.0, 0.02);
  /* parallel_for covers every index once for any thread count */
  for (int nt = 1; nt <= 7; nt++) {
    double out[1000];
    memset(out, 0, sizeof out);
    hearth_parallel_for(1000, nt, sum_range, out);
    for (int i = 0; i < 1000; i++) CHECK(out[i] == i * 0.5);
  }
  /* parallel_chunks: every index exactly once, in chunks of the asked size
     (the last shorter), each chunk on a worker below the thread count */
  for (int nt = 1; nt <= 5; nt++)
    for (size_t chunk = 1; chunk <= 300; chunk += 37) {
      chunk_seen cs;
      memset(&cs, 0, sizeof cs);
      cs.chunk = chunk;
      cs.nt = nt;
      hearth_parallel_chunks(1000, chunk, nt, chunk_range, &cs);
      int ok = !atomic_load(&cs.bad);
      for (int i = 0; i < 1000; i++) ok &= atomic_load(&cs.hits[i]) == 1;
      CHECK_MSG(ok, "parallel_chunks: %d threads, chunk %zu", nt, chunk);
    }
  {
    chunk_seen cs;
    memset(&cs, 0, sizeof cs);
    cs.chunk = 1;
    cs.nt = 3;
    hearth_parallel_chunks(0, 1, 3, chunk_range, &cs); /* nothing to do */
    CHECK(!atomic_load(&cs.bad));
  }
  size_t m;
  CHECK(!hearth_mul_size(SIZE_MAX / 2, 3, &m));
  CHECK(hearth_mul_size(1000, 1000, &m) && m == 1000000);
  TEST_MAIN_END();
}
