/* PNG chunk writing shared by the PNG and APNG encoders (internal to the
 * io library; io_png.c). */
#ifndef HEARTH_IO_PNG_H
#define HEARTH_IO_PNG_H

#include <stddef.h>
#include <stdint.h>

/* v big-endian into p[0..4). */
void hearth_png_put32(uint8_t *p, uint32_t v);
/* One chunk at o: length, type, the data of up to three pieces a, b, c
 * (NULL with length 0 where absent) and the CRC-32 of type and data.
 * o must hold 12 + na + nb + nc bytes; returns the end of the chunk. */
uint8_t *hearth_png_put_chunk(uint8_t *o, const char type[4], const uint8_t *a, size_t na,
                              const uint8_t *b, size_t nb, const uint8_t *c, size_t nc);

#endif
