#!/bin/sh
# Simulator speed against physics-only stepping, in one run: for each task
# and image size, `hearth sim collect` with --renderer none (physics,
# control and the scripted expert; no images), soft (hearth's software
# rasteriser, the default) and gl (MuJoCo's OpenGL renderer on OSMesa),
# run back to back so that the three see the same machine. Prints env
# steps/s by wall clock and by the process's CPU time (user + sys, which
# other jobs on a shared machine disturb less), the ratio of each renderer
# to physics-only, and the projected wall time of the paper's collection
# (200 layouts x 2 instructions x 3 tasks = 1,200 demos) on 2 cores: one
# task process per core, i.e. (sum of the three tasks' CPU times) / 2,
# extrapolated linearly from the N-layout subset. With OUT_DIR, also
# writes side-by-side pictures GL | soft | 3 x |difference| of each task's
# three views (OUT_DIR/compare_<size>.png, needs python3 with OpenCV).
# Usage: bench/sim_speed.sh BUILD_DIR [N=2] [M=1] [OUT_DIR]
#   N layouts per task at 128 px, M at 256 px
set -eu
BUILD=${1:-build}
N=${2:-2}
M=${3:-1}
KEEP=${4:-}
HEARTH="$BUILD/hearth"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

"$HEARTH" synth --out "$OUT/rel" --categories cup,canned_drink,electric_kettle,eraser,orange,smartphone,sponge \
  --states neutral,hot,iced --views 6 --triangles 4000 --texture 256 --map-res 256 --no-calibration \
  --draft-rgb --quiet

# one collection: "<task> <size> <renderer> <steps> <wall s> <cpu s>"
run() {
  T=$1 S=$2 R=$3 L=$4
  /usr/bin/time -f "%U %S" -o "$OUT/time" "$HEARTH" sim collect --task "$T" --layouts "$L" --size "$S" \
    --renderer "$R" --release "$OUT/rel" --ground-truth --out "$OUT/$T-$S-$R.hdf5" --quiet > "$OUT/log"
  steps=$(sed -n 's/.* replaced, \([0-9]*\) steps, \([0-9.]*\) s .*/\1/p' "$OUT/log")
  wall=$(sed -n 's/.* replaced, \([0-9]*\) steps, \([0-9.]*\) s .*/\2/p' "$OUT/log")
  cpu=$(awk '{ print $1 + $2 }' "$OUT/time")
  echo "$T $S $R $steps $wall $cpu" >> "$OUT/runs"
}

: > "$OUT/runs"
for S in 128 256; do
  L=$N
  [ "$S" = 256 ] && L=$M
  for T in H1 H2 H3; do
    for R in none soft gl; do run "$T" "$S" "$R" "$L"; done
  done
done

awk -v n128="$N" -v n256="$M" '
  { key = $2 " " $3; st[key] += $4; wall[key] += $5; cpu[key] += $6 }
  END {
    for (s = 128; s <= 256; s += 128) {
      n = s == 128 ? n128 : n256
      printf "%d px (%d layouts x 2 instructions per task, H1-H3):\n", s, n
      split("none soft gl", rs, " ")
      for (i = 1; i <= 3; i++) {
        k = s " " rs[i]; k0 = s " none"
        ws = st[k] / wall[k]; cs = st[k] / cpu[k]
        printf "  %-4s %6.1f steps/s wall, %6.1f steps/s CPU", rs[i], ws, cs
        if (i > 1) printf "; of physics-only: %.2f wall, %.2f CPU", ws / (st[k0] / wall[k0]), cs / (st[k0] / cpu[k0])
        # the expert reads the state, not the images: every renderer runs
        # the same episodes, step for step
        full = cpu[k] / n * 200 / 2
        printf "; 1,200 demos on 2 cores: %.0f s (%.1f min)\n", full, full / 60
      }
    }
  }' "$OUT/runs"

if [ -n "$KEEP" ]; then
  mkdir -p "$KEEP"
  for S in 128 256; do
    for R in gl soft; do
      "$HEARTH" sim render --renderer "$R" --size "$S" --release "$OUT/rel" --ground-truth \
        --out "$OUT/img-$S-$R" > /dev/null
    done
    /usr/bin/python3 - "$OUT/img-$S-gl" "$OUT/img-$S-soft" "$KEEP/compare_$S.png" <<'EOF'
import sys
import cv2
import numpy as np
gl, soft, out = sys.argv[1:4]
rows = []
for t in ("H1", "H2", "H3"):
    row = []
    for v in ("rgb", "thermal", "wrist"):
        a = cv2.imread(f"{gl}/{t}_{v}.png")
        b = cv2.imread(f"{soft}/{t}_{v}.png")
        d = np.abs(a.astype(int) - b.astype(int))
        print(f"{t} {v:7s} gl vs soft: mean |d| {d.mean():.2f}, pixels off by > 24: {(d.max(2) > 24).mean():.4f}")
        row.append(np.hstack([a, b, np.clip(3 * d, 0, 255).astype(np.uint8)]))
    rows.append(np.hstack(row))
cv2.imwrite(out, np.vstack(rows))
print(out)
EOF
  done
fi
