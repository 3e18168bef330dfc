#!/usr/bin/env bash
# The whole build on virtual releases with other thermal cameras and other
# targets beside the paper's configuration: per configuration, `hearth
# synth` (one or two categories, a few views, calibration captures), `hearth
# build`, `hearth validate`, then bench/calib_accuracy.py: thermal
# intrinsics and RGB-thermal transform against ground_truth/rig.json and the
# temperature maps against the ground-truth maps.
#   bench/target_sizes.sh [BUILD_DIR] [WORK_DIR] [VIEWS=6] [CATEGORIES=cup,canned_drink]
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
work=${2:-/tmp/hearth_target_sizes}
views=${3:-6}
cats=${4:-cup,canned_drink}
h="$build/hearth"
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
run() {
  local tag=$1
  shift
  rm -rf "$work/$tag"
  "$h" synth --out "$work/$tag" --categories "$cats" --views "$views" --triangles 6000 \
    --texture 256 --map-res 128 --thermal-frames 18 --stereo-pairs 12 --draft-rgb --seed 5 \
    --quiet "$@"
  "$h" build "$work/$tag" --resolution 128 --quiet >"$work/$tag.build.log" 2>&1 ||
    { echo "$tag: build failed"; tail -5 "$work/$tag.build.log"; return; }
  "$h" validate "$work/$tag" >/dev/null || echo "$tag: validate found problems"
  /usr/bin/python3 "$here/calib_accuracy.py" "$work/$tag" "$tag"
}
run paper-256x192
run paper-160x120 --thermal-size 160x120
run paper-640x512 --thermal-size 640x512
run grid7x7-256x192 --target grid
run hex6x8-256x192 --target hex
run grid7x7-160x120 --target grid --thermal-size 160x120
run hex6x8-640x512 --target hex --thermal-size 640x512
