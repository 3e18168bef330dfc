#!/bin/sh
# The UV atlas (hearth_mesh_atlas) on the fused meshes of a reconstructed
# release: for every instance's recon/mesh_geometry.glb one line with the
# charts, the L2 stretch (mesh, worst triangle, worst chart), the area and
# angle distortion, the packing efficiency and the charts merged, and its
# wall time. The release is one `hearth recon` (or `hearth build`) has run
# on, e.g. bench/recon_turntable.sh's or `hearth demo`'s.
# usage: bench/recon_atlas.sh [BUILD_DIR] RELEASE_ROOT
set -e
B=${1:-build}
R=${2:?usage: bench/recon_atlas.sh [BUILD_DIR] RELEASE_ROOT}
for M in "$R"/instances/*/recon/mesh_geometry.glb; do
  [ -f "$M" ] || continue
  T0=$(date +%s.%N)
  "$B/recon_test_atlas" "$M"
  T1=$(date +%s.%N)
  echo "  $(echo "$T1 - $T0" | bc) s"
done
