/* Private to the io area: checks shared by the image readers. */
#ifndef HEARTH_IO_INTERNAL_H
#define HEARTH_IO_INTERNAL_H

#include "hearth/image.h"

/* Check a file's declared size and channels (from its header, before any
 * pixels are allocated) against what the caller expects (NULL: anything).
 * HEARTH_OK, or the status with a message (without the file's name) in
 * msg. */
/* HEARTH_E_LIMIT (with msg) when a w x h image of channels samples of
 * sample_bytes each exceeds HEARTH_IMAGE_MAX_BYTES */
hearth_status hearth_image_bytes_check(size_t w, size_t h, int channels, int sample_bytes,
                                       char *msg, size_t msgsz);
hearth_status hearth_image_expect_check(const hearth_image_expect *want, size_t w, size_t h,
                                        int channels, char *msg, size_t msgsz);

#endif
