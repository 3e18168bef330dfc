/* private to the release area */
#ifndef HEARTH_RELEASE_INTERNAL_H
#define HEARTH_RELEASE_INTERNAL_H

#include "hearth/release.h"

/* Fill stages[] (at most max) with the calibration stages that apply to
 * root: detect + calibrate when calibration/captures/ exists; returns how
 * many. overlays: detection writes its overlay pictures. */
size_t hb_calib_stages(const char *root, int overlays, hearth_build_stage *stages, size_t max);

#endif
