/* Raw DEFLATE with run-length matching and one dynamic-Huffman block (see
 * io_deflate.h).
 *
 * A piece is first cut into tokens: a byte equal to the one before it,
 * repeated three times or more, becomes one match of distance 1 (lengths 3
 * to 258); every other byte is a literal. Their counts give the literal /
 * length code (at most 15 bits), the only distance code (distance 1) gets
 * one bit, and the block is written behind its header: the two codes'
 * lengths, run-length coded with symbols 16-18 and themselves Huffman coded
 * (at most 7 bits). Bits go out least significant first through a 64-bit
 * buffer. */
#include "io_deflate.h"

#include <stdlib.h>
#include <string.h>

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

typedef struct bit_out {
  uint8_t *p, *end;
  uint64_t buf;
  int n;       /* bits in buf, < 32 between calls */
  int overrun; /* the output would pass end */
} bit_out;

static inline void put_bits(bit_out *w, uint32_t v, int nb) {
  w->buf |= (uint64_t)v << w->n;
  w->n += nb;
  if (w->n >= 32) {
    if (w->end - w->p >= 4) {
      w->p[0] = (uint8_t)w->buf;
      w->p[1] = (uint8_t)(w->buf >> 8);
      w->p[2] = (uint8_t)(w->buf >> 16);
      w->p[3] = (uint8_t)(w->buf >> 24);
      w->p += 4;
    } else {
      w->overrun = 1;
    }
    w->buf >>= 32;
    w->n -= 32;
  }
}

/* out to the next byte boundary */
static void flush_bits(bit_out *w) {
  while (w->n > 0) {
    if (w->p < w->end) *w->p++ = (uint8_t)w->buf;
    else w->overrun = 1;
    w->buf >>= 8;
    w->n = w->n > 8 ? w->n - 8 : 0;
  }
  w->buf = 0;
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

int hearth_deflate_rle(const uint8_t *in, size_t n, int final, uint8_t *out, size_t *out_len) {
  *out_len = 0;
  /* tokens: a literal byte b as b, a match of length L as 256 + L */
  uint16_t *tok = malloc((n ? n : 1) * sizeof *tok);
  if (!tok) return 0;
  uint8_t len_sym[MAX_RUN + 1]; /* match length -> index of its length code */
  for (int c = 0, L = MIN_RUN; L <= MAX_RUN; L++) {
    while (c < 28 && L >= k_len_base[c + 1]) c++;
    len_sym[L] = (uint8_t)c;
  }
  uint32_t freq[N_LL] = {0};
  size_t nt = 0;
  for (size_t i = 0; i < n;) {
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

  /* the block, into out as far as the stored form's size (it is kept only
     if smaller) */
  size_t stored = n + 5 * (n / 65535 + 1) + (final ? 0 : 5);
  bit_out w = {out, out + stored, 0, 0, 0};
  put_bits(&w, final ? 1u : 0u, 1);
  put_bits(&w, 2, 2); /* dynamic Huffman */
  put_bits(&w, (uint32_t)(hlit - 257), 5);
  put_bits(&w, 0, 5); /* one distance code */
  put_bits(&w, (uint32_t)(hclen - 4), 4);
  for (int i = 0; i < hclen; i++) put_bits(&w, cl_len[k_cl_order[i]], 3);
  static const uint8_t cl_extra_bits[3] = {2, 3, 7};
  for (int i = 0; i < ncl; i++) {
    int s = cl_sym[i];
    put_bits(&w, cl_code[s], cl_len[s]);
    if (s >= 16) put_bits(&w, cl_extra[i], cl_extra_bits[s - 16]);
  }
  for (size_t i = 0; i < nt && !w.overrun; i++) {
    unsigned t = tok[i];
    if (t < 256) {
      put_bits(&w, ll_code[t], ll_len[t]);
    } else {
      unsigned L = t - 256, c = len_sym[L], s = 257 + c;
      /* the length code, its extra bits and the distance code (0, one bit) */
      put_bits(&w, ll_code[s] | (uint32_t)(L - k_len_base[c]) << ll_len[s],
               ll_len[s] + k_len_extra[c] + 1);
    }
  }
  put_bits(&w, ll_code[END_OF_BLOCK], ll_len[END_OF_BLOCK]);
  if (!final) put_bits(&w, 0, 3); /* the sync flush: an empty stored block */
  flush_bits(&w);
  if (!final && !w.overrun) {
    if (w.end - w.p >= 4) {
      memcpy(w.p, "\x00\x00\xff\xff", 4);
      w.p += 4;
    } else {
      w.overrun = 1;
    }
  }
  free(tok);
  if (w.overrun) *out_len = write_stored(in, n, final, out);
  else *out_len = (size_t)(w.p - out);
  return 1;
}

size_t hearth_deflate_stored(const uint8_t *in, size_t n, int final, uint8_t *out) {
  return write_stored(in, n, final, out);
}
