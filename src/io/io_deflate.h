/* A fast raw DEFLATE (RFC 1951) compressor for PNG rows (internal to the io
 * library): run-length matching only (distance 1, as zlib's Z_RLE) and one
 * dynamic-Huffman block per call. */
#ifndef HEARTH_IO_DEFLATE_H
#define HEARTH_IO_DEFLATE_H

#include <stddef.h>
#include <stdint.h>

/* The most bytes hearth_deflate_rle writes for n input bytes. */
size_t hearth_deflate_bound(size_t n);

/* Compress in[0..n) into out (hearth_deflate_bound(n) bytes), *out_len set
 * to the bytes written. final: the block is the stream's last (BFINAL);
 * otherwise the output ends with an empty stored block, byte-aligned (a
 * "sync flush"), so the outputs of consecutive pieces, concatenated, are
 * one stream (each piece refers to no byte of another). Where Huffman
 * coding would not gain, the piece is stored. Returns 0 when out of memory,
 * 1 otherwise. */
int hearth_deflate_rle(const uint8_t *in, size_t n, int final, uint8_t *out, size_t *out_len);

/* in[0..n) as stored (uncompressed) blocks of up to 65535 bytes, the last
 * marked final when final is set (else followed by a sync flush), into out
 * (hearth_deflate_bound(n) bytes); returns the bytes written. n == 0 gives
 * one empty block. */
size_t hearth_deflate_stored(const uint8_t *in, size_t n, int final, uint8_t *out);

#endif
