#!/bin/sh
# The paper's full demonstration set, timed: `hearth sim collect` for H1, H2
# and H3 with every default (200 layouts x 2 instructions = 400 demos per
# task, 256 px, assets made by the virtual rig), the three processes started
# together on this machine (2 cores on the reference machine), so the wall
# time is that of the whole 1,200-demo collection. Reports each task's
# expert success per instruction, replaced layouts, steps and time, the
# total wall and CPU time, and checks every file with h5py.
# Usage: bench/sim_full.sh BUILD_DIR OUT_DIR [LAYOUTS=200] [SIZE=256]
#   SIZE: the stored image side (--size), 128 for the speed issue's views
set -eu
BUILD=${1:-build}
OUT=${2:?usage: sim_full.sh BUILD_DIR OUT_DIR [LAYOUTS] [SIZE]}
L=${3:-200}
S=${4:-256}
HEARTH="$BUILD/hearth"
mkdir -p "$OUT"
now() { date +%s.%N; }
echo "cores: $(nproc), layouts per task: $L, image side: $S px, started $(date -u +%FT%TZ)"
t0=$(now)
for T in H1 H2 H3; do
  # progress goes to the .err file (tail -f it to watch)
  ( /usr/bin/time -f "%U %S" -o "$OUT/$T.cpu" "$HEARTH" sim collect --task "$T" --layouts "$L" --size "$S" \
      --out "$OUT/$T.hdf5" > "$OUT/$T.log" 2> "$OUT/$T.err"; echo $? > "$OUT/$T.rc" ) &
done
wait
t1=$(now)
fail=0
for T in H1 H2 H3; do
  rc=$(cat "$OUT/$T.rc")
  [ "$rc" = 0 ] || { echo "$T: exit $rc"; tail -3 "$OUT/$T.err"; fail=1; }
  sed "s/^/$T: /" "$OUT/$T.log"
done
cpu=$(cat "$OUT"/H1.cpu "$OUT"/H2.cpu "$OUT"/H3.cpu | awk '{ s += $1 + $2 } END { printf "%.0f", s }')
echo "wall time of the whole collection: $(echo "$t1 - $t0" | bc | xargs printf '%.0f') s; CPU time (user+sys, all three): $cpu s"
du -ch "$OUT"/H1.hdf5 "$OUT"/H2.hdf5 "$OUT"/H3.hdf5 | tail -1 | sed 's/^/files: /'
if /usr/bin/python3 -c 'import h5py' 2>/dev/null; then
  /usr/bin/python3 "$(dirname "$0")/sim_check_hdf5.py" "$OUT"/H1.hdf5 "$OUT"/H2.hdf5 "$OUT"/H3.hdf5
fi
exit $fail
