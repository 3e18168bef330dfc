/* hearth/hearth.h - everything. */
#ifndef HEARTH_HEARTH_H
#define HEARTH_HEARTH_H
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/camera.h"
#include "hearth/image.h"
#include "hearth/thermal.h"
#include "hearth/npy.h"
#include "hearth/mesh.h"
#include "hearth/dataset.h"
#include "hearth/synth.h"
#include "hearth/calib.h"
#include "hearth/map.h"
#include "hearth/release.h"
#include "hearth/poses.h"
#include "hearth/sim.h"
#include "hearth/eval.h"
#include "hearth/msgpack.h"
#include "hearth/ws.h"
#endif
