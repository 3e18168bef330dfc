#!/bin/sh
# Geometry from depth on a virtual-rig release: TSDF fusion of every view's
# masked depth with the true metric poses, marching tetrahedra, cleaning
# and simplification, then the surface RMS in both directions against
# ground_truth/.../mesh.glb (recon vertices to the true triangles, true
# vertices to the recon triangles, also over only the true vertices some
# true depth camera sees) and the wall time of the reconstruction.
# usage: bench/recon_tsdf.sh [BUILD_DIR] [WORKDIR] [CATEGORIES] [VIEWS] [VOXEL_M] [TRIANGLES]
set -e
B=${1:-build}
W=${2:-/tmp/hearth_recon_tsdf_bench}
CATS=${3:-cup,canned_drink,smartphone,electric_kettle}
VIEWS=${4:-30}
VOXEL=${5:-0.0015}
TRIS=${6:-40000}
if [ ! -f "$W/release.json" ]; then
  rm -rf "$W"
  "$B/hearth" synth --out "$W" --categories "$CATS" --views "$VIEWS" --states neutral \
    --no-calibration --draft-rgb --texture 256 --map-res 64 --quiet
fi
for ID in $(ls "$W/instances"); do
  "$B/recon_test_tsdf" "$W" "$ID" "$VOXEL" "$TRIS"
done
