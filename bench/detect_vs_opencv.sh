#!/usr/bin/env bash
# hearth detect + calibrate against OpenCV's findCirclesGrid + calibrateCamera
# on calibration frames made to look like real ones: a room behind the plate
# (window grid, desk edge, a warm person, hole-sized spots), a ~90 degree
# thermal lens with strong barrel distortion, and, in the second look, low
# contrast and inverted polarity; every thermal frame tone-mapped to 8 bits.
# Per target (the paper's plate, a 7x7 grid, a 6x8 hex) and look: found
# counts, mis-orders, partial frames refused, and the thermal intrinsics each
# calibration gives against the rig's truth.
#   bench/detect_vs_opencv.sh [BUILD_DIR] [WORK_DIR] [FRAMES=36] [PAIRS=12]
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
work=${2:-/tmp/hearth_detect_vs_opencv}
frames=${3:-36}
pairs=${4:-12}
h="$build/hearth"
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
for target in hex-alternating grid hex; do
  for look in "clutter" "clutter,low-contrast,invert"; do
    flags="--calib-clutter"
    case "$look" in *low-contrast*) flags="$flags --calib-low-contrast --calib-invert" ;; esac
    tag="$target-${look//,/-}"
    echo "== $target, $look, wide thermal lens, 8-bit thermal frames"
    rm -rf "$work/$tag" "$work/$tag-8bit"
    "$h" synth --out "$work/$tag" --target "$target" --thermal-wide $flags \
      --categories cup --states neutral --views 1 --triangles 600 --texture 64 --map-res 16 \
      --draft-rgb --thermal-frames "$frames" --stereo-pairs "$pairs" --seed 21 --quiet
    /usr/bin/python3 "$here/detect_vs_opencv.py" prepare "$work/$tag" "$work/$tag-8bit"
    "$h" detect "$work/$tag-8bit" --no-overlays >/dev/null
    "$h" calibrate "$work/$tag-8bit" >/dev/null || echo "  hearth calibrate failed"
    /usr/bin/python3 "$here/detect_vs_opencv.py" judge "$work/$tag-8bit" "$h"
  done
done
