/* The PNG writer's DEFLATE encoder, checked by zlib's inflate (an
 * independent decoder): pieces of every kind (empty, one byte, long runs,
 * incompressible noise that must fall back to stored blocks, skewed counts
 * that force the 15-bit length limit, sizes around the stored blocks'
 * 65535) decode to their input, alone and concatenated through sync
 * flushes, and compress where they should. */
#include <stdint.h>
#include <zlib.h>
#include "io/io_deflate.h"
#include "test_util.h"

/* a small deterministic generator, independent of the library */
static uint32_t next_u32(uint64_t *s) {
  *s = *s * 6364136223846793005ull + 1442695040888963407ull;
  return (uint32_t)(*s >> 33);
}

/* pieces deflated one after another (all but the last with a sync flush),
   inflated as one raw stream; returns 1 if the output equals the input */
static int round_trip(const uint8_t *in, const size_t *cut, size_t n_pieces, size_t *packed) {
  size_t total = cut[n_pieces], cap = 0;
  for (size_t k = 0; k < n_pieces; k++) cap += hearth_deflate_bound(cut[k + 1] - cut[k]);
  uint8_t *z = malloc(cap ? cap : 1), *back = malloc(total + 16);
  size_t nz = 0;
  int ok = z && back;
  for (size_t k = 0; ok && k < n_pieces; k++) {
    size_t len = 0, m = cut[k + 1] - cut[k];
    ok = hearth_deflate_rle(in + cut[k], m, k + 1 == n_pieces, z + nz, &len);
    ok = ok && len <= hearth_deflate_bound(m);
    nz += len;
  }
  if (ok) {
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    ok = inflateInit2(&zs, -15) == Z_OK;
    zs.next_in = z;
    zs.avail_in = (uInt)nz;
    zs.next_out = back;
    zs.avail_out = (uInt)(total + 16);
    int rc = ok ? inflate(&zs, Z_FINISH) : Z_DATA_ERROR;
    ok = ok && rc == Z_STREAM_END && zs.total_out == total && zs.avail_in == 0;
    if (rc != Z_STREAM_END) fprintf(stderr, "inflate: %d (%s)\n", rc, zs.msg ? zs.msg : "");
    inflateEnd(&zs);
    ok = ok && (total == 0 || memcmp(back, in, total) == 0);
  }
  if (packed) *packed = nz;
  free(z);
  free(back);
  return ok;
}

static int one_piece(const uint8_t *in, size_t n, size_t *packed) {
  size_t cut[2] = {0, n};
  return round_trip(in, cut, 1, packed);
}

int main(void) {
  enum { N = 300000 };
  uint8_t *buf = calloc(N, 1);
  uint64_t seed = 12345;
  size_t packed = 0;

  /* empty and tiny pieces */
  CHECK(one_piece(buf, 0, &packed));
  buf[0] = 7;
  CHECK(one_piece(buf, 1, &packed));
  memset(buf, 9, 3);
  CHECK(one_piece(buf, 3, &packed));

  /* a long run: matches of 258, a few bytes for 200 kB */
  memset(buf, 0, N);
  CHECK(one_piece(buf, 200000, &packed));
  CHECK_MSG(packed < 2000, "200000 zero bytes packed into %zu", packed);

  /* noise: Huffman cannot gain, stored blocks (around 65535 too) */
  for (size_t i = 0; i < N; i++) buf[i] = (uint8_t)next_u32(&seed);
  size_t sizes[] = {2, 100, 65534, 65535, 65536, 131071, 131070, 200000};
  for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
    CHECK_MSG(one_piece(buf, sizes[k], &packed), "noise of %zu bytes", sizes[k]);
    CHECK_MSG(packed <= sizes[k] + 5 * (sizes[k] / 65535 + 1), "noise of %zu bytes packed into %zu",
              sizes[k], packed);
  }

  /* skewed counts (doubling frequencies over 24 symbols): an unlimited
     Huffman code would need 23 bits, the limit of 15 must hold */
  size_t at = 0;
  for (int s = 0; s < 24 && at < N; s++)
    for (size_t r = 0; r < ((size_t)1 << (s < 17 ? s : 17)) && at < N; r++)
      buf[at++] = (uint8_t)(3 * s + 1);
  for (size_t i = 0; i + 1 < at; i += 2) { /* break the runs: literals, not matches */
    size_t j = next_u32(&seed) % at;
    uint8_t t = buf[i];
    buf[i] = buf[j];
    buf[j] = t;
  }
  CHECK(one_piece(buf, at, &packed));
  CHECK_MSG(packed < at, "skewed bytes %zu packed into %zu", at, packed);

  /* image-like rows: runs and small differences, in pieces of every size
     concatenated through sync flushes */
  for (size_t i = 0; i < N; i++) {
    size_t x = i % 3073;
    buf[i] = x == 0                ? 1
             : (i / 3073) % 3 == 0 ? 0
                                   : (uint8_t)((x / 97) % 5 + (next_u32(&seed) % 3 == 0));
  }
  CHECK(one_piece(buf, N, &packed));
  CHECK_MSG(packed < N / 3, "image-like %d bytes packed into %zu", (int)N, packed);
  size_t cut[6] = {0, 1, 4, 70000, 70000, N};
  CHECK(round_trip(buf, cut, 5, NULL));
  size_t bands[11];
  for (int k = 0; k <= 10; k++) bands[k] = (size_t)k * N / 10;
  CHECK(round_trip(buf, bands, 10, NULL));

  /* every short size, of two-valued bytes (runs of every length start and
     end at every offset, also within the last 18 bytes, where the search
     for matches goes byte by byte) */
  for (size_t n = 1; n <= 80; n++) {
    for (size_t i = 0; i < n; i++) buf[i] = (uint8_t)(next_u32(&seed) % 2);
    CHECK_MSG(one_piece(buf, n, NULL), "%zu two-valued bytes", n);
  }

  /* random pieces of random mixtures */
  for (int trial = 0; trial < 40; trial++) {
    size_t n = 1 + next_u32(&seed) % 20000;
    int kind = trial % 4;
    for (size_t i = 0; i < n; i++) {
      uint32_t r = next_u32(&seed);
      buf[i] = kind == 0   ? (uint8_t)r
               : kind == 1 ? (uint8_t)(r % 3)
               : kind == 2 ? (uint8_t)(i / 300)
                           : (uint8_t)(r % 200 < 190 ? 0 : r);
    }
    size_t c[4] = {0, next_u32(&seed) % (n + 1), 0, n};
    c[2] = c[1] + next_u32(&seed) % (n - c[1] + 1);
    CHECK_MSG(round_trip(buf, c, 3, NULL), "trial %d: %zu bytes of kind %d", trial, n, kind);
  }
  free(buf);
  TEST_MAIN_END();
}
