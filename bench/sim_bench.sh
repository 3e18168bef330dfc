#!/bin/sh
# sim benchmark. Makes the CLI's default virtual-rig assets once (timed on
# their own), then collects N layouts x 2 instructions per task with every
# view rendered each step (front RGB, front thermal, wrist RGB) at 128 px
# (LIBERO's size, the collect default) and M layouts at 256 px, and reports
# env steps/s per process and the projected wall time of the paper's full
# collection (200 layouts x 2 instructions x 3 tasks = 1,200 demos) on 2
# cores: one task process per core, i.e. (sum of the three tasks' times) / 2,
# extrapolated linearly from the N-layout subset.
# Usage: bench/sim_bench.sh BUILD_DIR [N=10] [M=2]
set -eu
BUILD=${1:-build}
N=${2:-10}
M=${3:-2}
HEARTH="$BUILD/hearth"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
now() { date +%s.%N; }

t0=$(now)
"$HEARTH" synth --out "$OUT/rel" --categories cup,canned_drink,electric_kettle,eraser,orange,smartphone,sponge \
  --states neutral,hot,iced --views 6 --triangles 4000 --texture 256 --map-res 256 --no-calibration \
  --draft-rgb --quiet
t1=$(now)
echo "assets (virtual rig, 7 categories x 3 states): $(echo "$t1 - $t0" | bc) s"

for S in 128 256; do
  L=$N
  [ "$S" = 256 ] && L=$M
  for T in H1 H2 H3; do
    "$HEARTH" sim collect --task "$T" --layouts "$L" --size "$S" --release "$OUT/rel" --ground-truth \
      --out "$OUT/$T-$S.hdf5" --quiet > "$OUT/$T-$S.log"
    sed "s/^/$T $S px: /" "$OUT/$T-$S.log"
  done
done

# the files open in h5py with LIBERO's keys (Debian python3-h5py)
if /usr/bin/python3 -c 'import h5py' 2>/dev/null; then
  /usr/bin/python3 "$(dirname "$0")/sim_check_hdf5.py" "$OUT"/H1-128.hdf5 "$OUT"/H2-128.hdf5 "$OUT"/H3-128.hdf5
fi

# "D demos, R layouts replaced, S steps, T s (...)"
for S in 128 256; do
  L=$N
  [ "$S" = 256 ] && L=$M
  cat "$OUT"/H1-$S.log "$OUT"/H2-$S.log "$OUT"/H3-$S.log | awk -v n="$L" -v size="$S" '
    / demos, / { for (i = 1; i <= NF; i++) { if ($i == "steps,") st += $(i - 1); if ($i == "s") { sec += $(i - 1); break } } }
    END {
      printf "%s px, all three views rendered: %.1f env steps/s per process (%d steps in %.1f s)\n", size, st / sec, st, sec;
      if (size == 128) {
        full = sec / n * 200;
        printf "projected full collection (1,200 demos at 128 px, linear from %d layouts/task): %.0f s on 1 core, %.0f s (%.1f h) on 2 cores (one task per core)\n", n, full, full / 2, full / 2 / 3600;
      }
    }'
done
