#!/bin/sh
# sim benchmark: environment steps per second with all three views rendered
# (collect at 128 px renders front RGB, front thermal and wrist RGB every
# step), and the projected wall time of the paper's full 1,200 demos on 2
# cores (two task processes at a time). Usage: bench/sim_bench.sh BUILD_DIR [LAYOUTS]
set -eu
BUILD=${1:-build-sim}
N=${2:-5}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for T in H1 H2 H3; do
  start=$(date +%s.%N)
  "$BUILD/hearth" sim collect --task "$T" --layouts "$N" --out "$OUT/$T.hdf5" --quiet | tee "$OUT/$T.log"
  end=$(date +%s.%N)
  echo "$T: $(echo "$end - $start" | bc) s wall for $N layouts (includes making assets)"
done
# verify the files open in h5py with LIBERO's keys
/usr/bin/python3 "$(dirname "$0")/sim_check_hdf5.py" "$OUT"/H1.hdf5 "$OUT"/H2.hdf5 "$OUT"/H3.hdf5
# projection: steps/s from the logs; 200 layouts x 2 instructions per task,
# 3 tasks on 2 cores (one process per core)
awk -v n="$N" '/steps\/s/ { s += $3; t += $5 } END {
  sps = s / t; total = s / n * 200;
  printf "all views rendered: %.1f env steps/s per core\n", sps;
  printf "full collection (1,200 demos, %d steps): %.0f s on 1 core, %.0f s on 2 cores\n", total, total / sps, total / sps / 2 * 1.0 }' "$OUT"/H1.log "$OUT"/H2.log "$OUT"/H3.log
