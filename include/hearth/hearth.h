/* hearth/hearth.h - every area's public header in one include, in pipeline
 * order: core (core.h, geom.h, camera.h), io (image.h, thermal.h, npy.h,
 * parquet.h), dataset, net (msgpack.h, ws.h), mesh, synth, calib, poses, map,
 * release, then the simulation areas sim, export and eval.
 *
 * Link the pipeline areas with `pkg-config --cflags --libs hearth`; sim.h,
 * export.h and eval.h need a build with HEARTH_SIM and `pkg-config --libs
 * hearth-sim` (MuJoCo, OSMesa, HDF5). */
#ifndef HEARTH_HEARTH_H
#define HEARTH_HEARTH_H
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/camera.h"
#include "hearth/image.h"
#include "hearth/thermal.h"
#include "hearth/npy.h"
#include "hearth/parquet.h"
#include "hearth/dataset.h"
#include "hearth/msgpack.h"
#include "hearth/ws.h"
#include "hearth/mesh.h"
#include "hearth/thermo.h"
#include "hearth/recon.h"
#include "hearth/recon_geom.h"
#include "hearth/synth.h"
#include "hearth/calib.h"
#include "hearth/poses.h"
#include "hearth/map.h"
#include "hearth/release.h"
#include "hearth/sim.h"
#include "hearth/export.h"
#include "hearth/eval.h"
#endif
