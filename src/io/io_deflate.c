/* Raw DEFLATE with run-length matching and one dynamic-Huffman block (see
 * io_deflate.h).
 *
 * A piece is first cut into tokens: a byte equal to the one before it,
 * repeated three times or more, becomes one match of distance 1 (lengths 3
 * to 258); every other byte is a literal. Their counts give the literal /
 * length code (at most 15 bits), the only distance code (distance 1) gets
 * one bit, and the block is written behind its header: the two codes'
 * lengths, run-length coded with symbols 16-18 and themselves Huffman coded
 * (at most 7 bits). The block's size in bits follows from the counts and
 * the code lengths, so where it would be larger than the stored form
 * the piece is stored without being coded. Bits go out least significant
 * first through a 64-bit buffer, whole bytes at a time.
 *
 * Cutting into tokens looks, sixteen bytes at a time where SSE2 is there,
 * for the next byte that starts a match (it, the byte before it and the two
 * after it all equal); the bytes before it are literals. */
#include "io_deflate.h"

#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* RFC 1951: match lengths 3..258 by length code 257..285 */
static const uint16_t k_len_base[29] = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                        15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                        67, 83, 99, 115, 131, 163, 195, 227, 258};
static const uint8_t k_len_extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                        2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
/* the order in which the code-length code's lengths are sent */
static const uint8_t k_cl_order[19] = {16, 17, 18, 0, 8,  7, 9,  6, 10, 5,
                                       11, 4,  12, 3, 13, 2, 14, 1, 15};

enum { N_LL = 286, N_CL = 19, END_OF_BLOCK = 256, MIN_RUN = 3, MAX_RUN = 258 };

size_t hearth_deflate_bound(size_t n) {
  /* stored blocks (5 bytes per 65535) or the Huffman block, whichever is
     written, plus a sync flush; the Huffman block is kept only when it is
     no larger than the stored form */
  return n + 5 * (n / 65535 + 1) + 16;
}

/* ---- bits ---------------------------------------------------------------------- */

/* The output is sized beforehand (the block's exact size plus 8 bytes), so
 * the writer never checks for room: after every bits_flush fewer than 8
 * bits wait in buf, so up to 56 more can be put before the next flush. */
typedef struct bit_out {
  uint8_t *p;
  uint64_t buf;
  unsigned n; /* bits in buf */
} bit_out;

static inline void put_bits(bit_out *w, uint64_t v, unsigned nb) {
  w->buf |= v << w->n;
  w->n += nb;
}

/* the whole bytes of buf out (all 8 bytes are stored; p moves past the
   whole ones) */
static inline void bits_flush(bit_out *w) {
  uint64_t b = w->buf;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  memcpy(w->p, &b, 8); /* least significant byte first, as below */
#else
  for (int k = 0; k < 8; k++) w->p[k] = (uint8_t)(b >> (8 * k));
#endif
  w->p += w->n >> 3;
  w->buf >>= w->n & ~7u;
  w->n &= 7u;
}

/* ---- Huffman codes ------------------------------------------------------------- */

typedef struct leaf {
  uint32_t w;
  uint16_t sym;
} leaf;

static int cmp_leaf(const void *a, const void *b) {
  const leaf *x = a, *y = b;
  if (x->w != y->w) return x->w < y->w ? -1 : 1;
  return (x->sym > y->sym) - (x->sym < y->sym);
}

/* Huffman code lengths of n (<= N_LL) symbols with counts freq (0: not
 * used, length 0), none longer than limit: the tree of the two lightest
 * (leaves sorted, internal nodes made in order of weight: two queues); if
 * too deep, the counts are halved (never below 1) and the tree made again,
 * which flattens it. One used symbol gets length 1. */
static void huff_lengths(const uint32_t *freq, int n, int limit, uint8_t *len) {
  leaf lv[N_LL];
  uint32_t w[2 * N_LL];
  int parent[2 * N_LL], depth[2 * N_LL];
  int m = 0;
  memset(len, 0, (size_t)n);
  for (int i = 0; i < n; i++)
    if (freq[i]) lv[m++] = (leaf){freq[i], (uint16_t)i};
  if (m == 0) return;
  if (m == 1) {
    len[lv[0].sym] = 1;
    return;
  }
  for (;;) {
    qsort(lv, (size_t)m, sizeof *lv, cmp_leaf);
    for (int i = 0; i < m; i++) w[i] = lv[i].w;
    /* nodes 0..m-1 are the leaves (sorted), m.. the internal ones */
    int li = 0, ii = m, nn = m;
    for (int k = 0; k < m - 1; k++) {
      int pick[2];
      for (int s = 0; s < 2; s++) {
        /* the lighter head of the two queues; ties to the leaf */
        if (li < m && (ii >= nn || w[li] <= w[ii])) pick[s] = li++;
        else pick[s] = ii++;
      }
      w[nn] = w[pick[0]] + w[pick[1]];
      parent[pick[0]] = parent[pick[1]] = nn;
      nn++;
    }
    depth[nn - 1] = 0;
    int maxd = 0;
    for (int i = nn - 2; i >= 0; i--) {
      depth[i] = depth[parent[i]] + 1;
      if (i < m && depth[i] > maxd) maxd = depth[i];
    }
    if (maxd <= limit) {
      for (int i = 0; i < m; i++) len[lv[i].sym] = (uint8_t)depth[i];
      return;
    }
    for (int i = 0; i < m; i++) lv[i].w = (lv[i].w + 1) / 2;
  }
}

/* canonical codes (RFC 1951 3.2.2) from lengths, bit-reversed for sending
   least significant bit first */
static void huff_codes(const uint8_t *len, int n, uint16_t *code) {
  int count[16] = {0}, next[16] = {0};
  for (int i = 0; i < n; i++) count[len[i]]++;
  count[0] = 0;
  for (int b = 1, c = 0; b < 16; b++) {
    c = (c + count[b - 1]) << 1;
    next[b] = c;
  }
  for (int i = 0; i < n; i++) {
    code[i] = 0;
    if (!len[i]) continue;
    unsigned c = (unsigned)next[len[i]]++, r = 0;
    for (int b = 0; b < len[i]; b++, c >>= 1) r = (r << 1) | (c & 1u);
    code[i] = (uint16_t)r;
  }
}

/* ---- blocks -------------------------------------------------------------------- */

/* stored blocks of in[0..n): the fallback where coding would not gain */
static size_t write_stored(const uint8_t *in, size_t n, int final, uint8_t *out) {
  uint8_t *o = out;
  size_t at = 0;
  do {
    size_t k = n - at < 65535 ? n - at : 65535;
    int last = final && at + k == n;
    *o++ = (uint8_t)last; /* BFINAL, BTYPE 00, then up to the byte boundary */
    o[0] = (uint8_t)k;
    o[1] = (uint8_t)(k >> 8);
    o[2] = (uint8_t)~k;
    o[3] = (uint8_t)(~k >> 8);
    o += 4;
    memcpy(o, in + at, k);
    o += k;
    at += k;
  } while (at < n);
  if (!final) {
    /* the sync flush: an empty stored block */
    static const uint8_t sync[5] = {0, 0, 0, 0xff, 0xff};
    memcpy(o, sync, 5);
    o += 5;
  }
  return (size_t)(o - out);
}

/* the tokens of in[0..n) into tok (n + 16 entries: the vector path
   stores 16 at a time), their literal / length symbol counts into freq;
   returns the number of tokens */
static size_t tokenize(const uint8_t *in, size_t n, const uint8_t *len_sym, uint16_t *tok,
                       uint32_t *freq) {
  size_t nt = 0;
#if defined(__SSE2__)
  /* the vector path's literal counts in four tables, so that equal bytes in
     a row do not wait on each other's increments */
  uint32_t lit[4][256];
  memset(lit, 0, sizeof lit);
#endif
  for (size_t i = 0; i < n;) {
#if defined(__SSE2__)
    /* sixteen positions at a time while in[i - 1 .. i + 17] can be read:
       the first that starts a match ends the literals */
    unsigned m = 0;
    while (i >= 1 && i + 18 <= n) {
      const __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(in + i - 1)),
                    b = _mm_loadu_si128((const __m128i *)(const void *)(in + i)),
                    c = _mm_loadu_si128((const __m128i *)(const void *)(in + i + 1)),
                    d = _mm_loadu_si128((const __m128i *)(const void *)(in + i + 2));
      const __m128i e = _mm_and_si128(_mm_and_si128(_mm_cmpeq_epi8(a, b), _mm_cmpeq_epi8(b, c)),
                                      _mm_cmpeq_epi8(c, d));
      m = (unsigned)_mm_movemask_epi8(e);
      const unsigned k = m ? (unsigned)__builtin_ctz(m) : 16u;
      const __m128i z = _mm_setzero_si128();
      _mm_storeu_si128((__m128i *)(void *)(tok + nt), _mm_unpacklo_epi8(b, z));
      _mm_storeu_si128((__m128i *)(void *)(tok + nt + 8), _mm_unpackhi_epi8(b, z));
      if (k == 16) {
        for (unsigned j = 0; j < 16; j += 4) {
          lit[0][in[i + j]]++;
          lit[1][in[i + j + 1]]++;
          lit[2][in[i + j + 2]]++;
          lit[3][in[i + j + 3]]++;
        }
      } else {
        for (unsigned j = 0; j < k; j++) lit[j & 3][in[i + j]]++;
      }
      nt += k;
      i += k;
      if (m) break;
    }
    if (i >= n) break;
#endif
    if (i > 0 && in[i] == in[i - 1]) {
      const uint8_t b = in[i - 1];
      size_t L = 1, lim = n - i < MAX_RUN ? n - i : MAX_RUN;
      /* eight bytes at a time through long runs (the background) */
      const uint64_t pat = 0x0101010101010101ull * b;
      for (uint64_t x; L + 8 <= lim; L += 8) {
        memcpy(&x, in + i + L, 8);
        if (x != pat) break;
      }
      while (L < lim && in[i + L] == b) L++;
      if (L >= MIN_RUN) {
        tok[nt++] = (uint16_t)(256 + L);
        freq[257 + len_sym[L]]++;
        i += L;
        continue;
      }
    }
    tok[nt++] = in[i];
    freq[in[i]]++;
    i++;
  }
#if defined(__SSE2__)
  for (int b = 0; b < 256; b++) freq[b] += lit[0][b] + lit[1][b] + lit[2][b] + lit[3][b];
#endif
  return nt;
}

int hearth_deflate_rle(const uint8_t *in, size_t n, int final, uint8_t *out, size_t *out_len) {
  *out_len = 0;
  /* tokens: a literal byte b as b, a match of length L as 256 + L */
  uint16_t *tok = malloc((n + 16) * sizeof *tok);
  if (!tok) return 0;
  uint8_t len_sym[MAX_RUN + 1]; /* match length -> index of its length code */
  for (int c = 0, L = MIN_RUN; L <= MAX_RUN; L++) {
    while (c < 28 && L >= k_len_base[c + 1]) c++;
    len_sym[L] = (uint8_t)c;
  }
  uint32_t freq[N_LL] = {0};
  size_t nt = tokenize(in, n, len_sym, tok, freq);
  freq[END_OF_BLOCK] = 1;
  if (!nt) freq[0] = 1; /* an unused literal: two codes, a complete code */

  uint8_t ll_len[N_LL], dist_len[1] = {1}; /* the one distance code: 1 bit */
  uint16_t ll_code[N_LL];
  huff_lengths(freq, N_LL, 15, ll_len);
  huff_codes(ll_len, N_LL, ll_code);
  int hlit = N_LL;
  while (hlit > 257 && !ll_len[hlit - 1]) hlit--;

  /* the lengths of both codes as one sequence, run-length coded: 16 (the
     last length again 3-6 times), 17 (3-10 zeros), 18 (11-138 zeros) */
  uint8_t seq[N_LL + 1], cl_sym[N_LL + 1], cl_extra[N_LL + 1];
  int ns = 0, ncl = 0;
  memcpy(seq, ll_len, (size_t)hlit);
  seq[hlit] = dist_len[0];
  ns = hlit + 1;
  uint32_t cl_freq[N_CL] = {0};
  for (int i = 0; i < ns;) {
    int v = seq[i], r = 1;
    while (i + r < ns && seq[i + r] == v) r++;
    i += r;
    if (v == 0) {
      while (r >= 11) {
        int k = r < 138 ? r : 138;
        cl_sym[ncl] = 18, cl_extra[ncl++] = (uint8_t)(k - 11);
        r -= k;
      }
      if (r >= 3) {
        cl_sym[ncl] = 17, cl_extra[ncl++] = (uint8_t)(r - 3);
        r = 0;
      }
    } else {
      cl_sym[ncl] = (uint8_t)v, cl_extra[ncl++] = 0;
      r--;
      while (r >= 3) {
        int k = r < 6 ? r : 6;
        cl_sym[ncl] = 16, cl_extra[ncl++] = (uint8_t)(k - 3);
        r -= k;
      }
    }
    while (r-- > 0) cl_sym[ncl] = (uint8_t)v, cl_extra[ncl++] = 0;
  }
  for (int i = 0; i < ncl; i++) cl_freq[cl_sym[i]]++;
  /* a code-length code must be complete (RFC 1951 decoders reject one
     code of one bit here): a second, unused symbol where only one is used */
  int used = 0;
  for (int i = 0; i < N_CL; i++) used += cl_freq[i] > 0;
  if (used < 2) cl_freq[cl_freq[0] ? 1 : 0] = 1;
  uint8_t cl_len[N_CL];
  uint16_t cl_code[N_CL];
  huff_lengths(cl_freq, N_CL, 7, cl_len);
  huff_codes(cl_len, N_CL, cl_code);
  int hclen = N_CL;
  while (hclen > 4 && !cl_len[k_cl_order[hclen - 1]]) hclen--;

  /* the block's size: header, the two codes' lengths, the tokens (a match
     also sends its extra bits and the one-bit distance code), the end of
     block and, unless final, the empty stored block's 3 header bits; then
     the sync flush's 4 bytes. It is coded only if no larger than the
     stored form. */
  static const uint8_t cl_extra_bits[3] = {2, 3, 7};
  uint64_t bits = 3 + 5 + 5 + 4 + 3 * (uint64_t)hclen;
  for (int i = 0; i < ncl; i++)
    bits += cl_len[cl_sym[i]] + (cl_sym[i] >= 16 ? cl_extra_bits[cl_sym[i] - 16] : 0);
  if (nt)
    for (int sym = 0; sym < 256; sym++) bits += (uint64_t)freq[sym] * ll_len[sym];
  for (int c = 0; c < 29; c++)
    bits += (uint64_t)freq[257 + c] * (ll_len[257 + c] + k_len_extra[c] + 1u);
  bits += ll_len[END_OF_BLOCK] + (final ? 0 : 3);
  size_t coded = (size_t)((bits + 7) / 8) + (final ? 0 : 4);
  size_t stored = n + 5 * (n / 65535 + 1) + (final ? 0 : 5);
  if (coded > stored) {
    free(tok);
    *out_len = write_stored(in, n, final, out);
    return 1;
  }

  /* every token's bits as one value: the code, and for a match its extra
     bits and the distance code (0, one bit) */
  uint32_t tcode[256 + MAX_RUN + 1];
  uint8_t tlen[256 + MAX_RUN + 1];
  for (int t = 0; t < 256; t++) tcode[t] = ll_code[t], tlen[t] = ll_len[t];
  for (int L = MIN_RUN; L <= MAX_RUN; L++) {
    int c = len_sym[L], sym = 257 + c;
    tcode[256 + L] = ll_code[sym] | (uint32_t)(L - k_len_base[c]) << ll_len[sym];
    tlen[256 + L] = (uint8_t)(ll_len[sym] + k_len_extra[c] + 1);
  }
  /* room: the block's bytes plus the 8 that the last flush stores
     (hearth_deflate_bound leaves 11 beyond the stored form) */
  bit_out w = {out, 0, 0};
  put_bits(&w, final ? 1u : 0u, 1);
  put_bits(&w, 2, 2); /* dynamic Huffman */
  put_bits(&w, (uint32_t)(hlit - 257), 5);
  put_bits(&w, 0, 5); /* one distance code */
  put_bits(&w, (uint32_t)(hclen - 4), 4);
  bits_flush(&w);
  for (int i = 0; i < hclen; i++) {
    put_bits(&w, cl_len[k_cl_order[i]], 3);
    bits_flush(&w);
  }
  for (int i = 0; i < ncl; i++) {
    int sy = cl_sym[i];
    put_bits(&w, cl_code[sy], cl_len[sy]);
    if (sy >= 16) put_bits(&w, cl_extra[i], cl_extra_bits[sy - 16]);
    bits_flush(&w);
  }
  /* two tokens (at most 21 bits each) per flush */
  size_t i = 0;
  for (; i + 2 <= nt; i += 2) {
    unsigned t0 = tok[i], t1 = tok[i + 1];
    put_bits(&w, tcode[t0], tlen[t0]);
    put_bits(&w, tcode[t1], tlen[t1]);
    bits_flush(&w);
  }
  if (i < nt) {
    put_bits(&w, tcode[tok[i]], tlen[tok[i]]);
    bits_flush(&w);
  }
  put_bits(&w, ll_code[END_OF_BLOCK], ll_len[END_OF_BLOCK]);
  if (!final) put_bits(&w, 0, 3); /* the sync flush: an empty stored block */
  bits_flush(&w);
  /* the last partial byte (zero-padded) is already stored */
  if (w.n) w.p++;
  if (!final) {
    memcpy(w.p, "\x00\x00\xff\xff", 4);
    w.p += 4;
  }
  free(tok);
  *out_len = (size_t)(w.p - out);
  return 1;
}

size_t hearth_deflate_stored(const uint8_t *in, size_t n, int final, uint8_t *out) {
  return write_stored(in, n, final, out);
}
