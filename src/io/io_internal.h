/* Private to the io area: checks shared by the image readers. */
#ifndef HEARTH_IO_INTERNAL_H
#define HEARTH_IO_INTERNAL_H

#include "hearth/image.h"

/* Check a file's declared size and channels (from its header, before any
 * pixels are allocated) against what the caller expects (NULL: anything).
 * HEARTH_OK, or the status with a message (without the file's name) in
 * msg. */
hearth_status hearth_image_expect_check(const hearth_image_expect *want, size_t w, size_t h,
                                        int channels, char *msg, size_t msgsz);

#endif
