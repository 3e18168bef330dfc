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
#include "hearth/release.h"
#include "hearth/synth.h"
#include "hearth/calib.h"
#include "hearth/map.h"
#include "hearth/pipeline.h"
#include "hearth/release_tools.h"
#include "hearth/refine.h"
#include "hearth/sim.h"
#include "hearth/eval.h"
#include "hearth/msgpack.h"
#include "hearth/ws.h"
#endif
