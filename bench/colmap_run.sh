#!/bin/sh
# hearth recon --poses colmap on a small virtual-rig instance: how many of
# its views COLMAP registers and the pose error after the best similarity
# against ground_truth/instances/<id>/poses_rgb.json. Slow (COLMAP's CPU
# SIFT on 1920x1080 views), so not a ctest. Needs Debian's colmap on PATH.
# usage: bench/colmap_run.sh [BUILD_DIR] [WORKDIR] [CATEGORY] [VIEWS] [-- recon options]
#   e.g. bench/colmap_run.sh build /tmp/hearth_colmap_bench cup 30 -- --intrinsics estimate
set -e
B=${1:-build}
W=${2:-/tmp/hearth_colmap_bench}
CAT=${3:-cup}
VIEWS=${4:-30}
shift $(( $# < 4 ? $# : 4 ))
[ "$1" = "--" ] && shift
command -v colmap >/dev/null || { echo "colmap not on PATH (Debian: apt-get install colmap)" >&2; exit 2; }
rm -rf "$W"
mkdir -p "$W"
"$B/hearth" synth --out "$W/R" --categories "$CAT" --views "$VIEWS" --no-calibration --quiet
for ID in $(ls "$W/R/instances"); do
  t0=$(date +%s)
  # the synthetic release has the reconstruction stand-in's poses: replaced
  "$B/hearth" recon "$W/R" --instance "$ID" --poses colmap --work "$W/work_$ID" --force "$@" ||
    { echo "$ID: hearth recon failed (logs in $W/work_$ID/logs)"; continue; }
  echo "$ID: recon took $(( $(date +%s) - t0 )) s"
  "$B/bench_pose_error" "$W/R/instances/$ID/recon/poses_rgb.json" \
    "$W/R/ground_truth/instances/$ID/poses_rgb.json" || true
done
