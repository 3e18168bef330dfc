#!/bin/sh
# The embedded pose route on a virtual-rig release: turntable geometry and
# joint point-to-plane ICP per instance, against the rig's true colour
# poses after the best similarity (rotation and camera-centre errors, the
# largest tilt error), then the mesh fused from the depth maps with those
# poses against the true mesh (RMS in both directions, in the truth's frame
# through the same similarity; true->recon also over the true vertices some
# true depth camera sees, by ray casting, tests/recon/true_visibility.h).
# The manifests' turntable_deg (the encoder) holds the angles unless
# RECON_TT_NO_ENCODER=1; RECON_TT_COLOUR=W turns the photometric term on;
# RECON_TT_AIM=W sets the aim term's weight (0: off, the route before it).
# usage: bench/recon_turntable.sh [BUILD_DIR] [WORKDIR] [CATEGORIES] [VIEWS] [VOXEL_M]
set -e
B=${1:-build}
W=${2:-/tmp/hearth_recon_turntable_bench}
CATS=${3:-cup,canned_drink,smartphone,electric_kettle}
VIEWS=${4:-30}
VOXEL=${5:-0.0015}
if [ ! -f "$W/release.json" ]; then
  rm -rf "$W"
  "$B/hearth" synth --out "$W" --categories "$CATS" --views "$VIEWS" \
    --no-calibration --texture 256 --map-res 64 --quiet
fi
for ID in $(ls "$W/instances"); do
  RECON_TT_VOXEL=$VOXEL "$B/recon_test_turntable" "$W" "$ID" mesh
done
