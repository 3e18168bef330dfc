/* Release-level build stages that live outside the map area (detection and
 * calibration): the executable links every area, so they are assembled here
 * and handed to hearth_build_release. */
#ifndef HEARTH_CLI_BUILD_H
#define HEARTH_CLI_BUILD_H

#include "hearth/release_tools.h"

/* Fill stages[] (at most max) with the release-level stages that apply to
 * root: detect + calibrate when calibration/captures/ exists. */
size_t cli_release_stages(const char *root, int overlays, hearth_build_stage *stages, size_t max);

#endif
