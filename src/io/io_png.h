/* PNG chunk writing shared by the PNG and APNG encoders (internal to the
 * io library; io_png.c). */
#ifndef HEARTH_IO_PNG_H
#define HEARTH_IO_PNG_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/image.h"

/* v big-endian into p[0..4). */
void hearth_png_put32(uint8_t *p, uint32_t v);
/* One chunk at o: length, type, the data of up to three pieces a, b, c
 * (NULL with length 0 where absent) and the CRC-32 of type and data.
 * o must hold 12 + na + nb + nc bytes; returns the end of the chunk. */
uint8_t *hearth_png_put_chunk(uint8_t *o, const char type[4], const uint8_t *a, size_t na,
                              const uint8_t *b, size_t nb, const uint8_t *c, size_t nc);

/* The PNG reader's libpng route alone (hearth_png_read_mem takes its own
 * faster path where the file allows): the reference the fast path is
 * checked against. want may be NULL (any image). */
hearth_status hearth_png_read_mem_libpng(const void *data, size_t size, const char *name,
                                         const hearth_image_expect *want, hearth_image *img,
                                         hearth_err *err);

#endif
