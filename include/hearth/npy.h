/* hearth/npy.h - area io (src/io/io_npy.c): NumPy .npy arrays (format
 * 1.0/2.0), the float maps and masks of a release. Reads and writes
 * little-endian float32 ('<f4') and uint8 ('|u1'), C order, any rank up to
 * 4. */
#ifndef HEARTH_NPY_H
#define HEARTH_NPY_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum hearth_npy_dtype { HEARTH_NPY_F32 = 1, HEARTH_NPY_U8 = 2 } hearth_npy_dtype;

typedef struct hearth_npy {
  hearth_npy_dtype dtype;
  int ndim;
  size_t shape[4];
  void *data; /* owned, C order */
} hearth_npy;

/* Number of elements (product of the shape). */
size_t hearth_npy_count(const hearth_npy *a);
/* Frees data and zeroes a; accepts a zeroed array. */
void hearth_npy_free(hearth_npy *a);
/* Read a file or parse data[0..size) into out, whose data is a new copy
 * (the caller frees it with hearth_npy_free); `name` names the input in
 * messages. */
hearth_status hearth_npy_read(const char *path, hearth_npy *out, hearth_err *err);
hearth_status hearth_npy_parse(const void *data, size_t size, const char *name, hearth_npy *out,
                               hearth_err *err);
/* Write ndim dimensions shape[0..ndim) of data (C order, native floats or
 * bytes) atomically. */
hearth_status hearth_npy_write(const char *path, hearth_npy_dtype dtype, int ndim,
                               const size_t *shape, const void *data, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
