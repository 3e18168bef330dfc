#!/usr/bin/env bash
# The whole job against its core: `hearth build -j2` of a 2-instance
# virtual-rig release (cup + canned_drink, 2 states each, 30 views,
# calibration captures) per stage, against `hearth map` of all its states in
# the same run (the target: the build at most 12x the mapping); then
# `hearth demo` followed by `hearth build` of its release, which must run no
# stage; then the peak memory of the colour bake (as `hearth map --rgb`
# reports it) and of the whole `hearth map --rgb` beside plain `hearth map`.
# Times are wall clock and CPU (user + sys) on a possibly shared machine:
# compare the ratios, not the seconds, across machines.
#   bench/bench_build.sh [BUILD_DIR] [WORK_DIR]
# HEARTH_BENCH_DEMO=0 leaves out the demo part (it takes most of the run's
# time and does not enter the ratio).
# The synthetic release is made once in WORK_DIR/pristine and reused.
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
work=${2:-/tmp/hearth_bench_build}
h="$build/hearth"
mkdir -p "$work"
now() { date +%s.%N; }
# run a command, leave its wall and CPU seconds in $wall and $cpu
timed() {
  local t0 t1
  t0=$(now)
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f "%U %S %M" -o "$work/time.txt" "$@"
    cpu=$(awk '{printf "%.2f", $1 + $2}' "$work/time.txt")
  else
    "$@"
    cpu=nan
  fi
  t1=$(now)
  wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.2f", b - a}')
}

if [ ! -f "$work/pristine/release.json" ]; then
  rm -rf "$work/pristine"
  echo "making the release (once): hearth synth --categories cup,canned_drink"
  "$h" synth --out "$work/pristine" --categories cup,canned_drink --quiet
fi
rm -rf "$work/rel"
cp -a "$work/pristine" "$work/rel"

echo "== hearth build -j2 (fresh)"
timed "$h" build "$work/rel" -j2 > "$work/build.log"
build_wall=$wall build_cpu=$cpu
# per stage: the sum over instances/states of each stage run's own seconds
awk '
  /^build: [a-z]+: done \(/ { n = $2; sub(":", "", n); s = $0; sub(/.*\(/, "", s); t[n] += s + 0; c[n]++ }
  /^build \[[0-9]+\/[0-9]+\] .*: done \(/ {
    split($0, a, "] "); split(a[2], w, " "); n = w[2]; sub(":", "", n)
    s = $0; sub(/.*\(/, "", s); t[n] += s + 0; c[n]++ }
  END {
    split("detect calibrate recon scale bake transfer refine map overlay", order, " ")
    for (i = 1; i <= 9; i++) if (order[i] in t)
      printf "  %-10s %3d run(s) %7.2f s\n", order[i], c[order[i]], t[order[i]]
  }' "$work/build.log"
grep "^build summary" "$work/build.log" | sed 's/^/  /'

echo "== hearth map (every state, all threads)"
timed "$h" map "$work/rel" > "$work/map.log"
map_wall=$wall map_cpu=$cpu
echo "  $(grep -c '^map ' "$work/map.log") state(s)"

echo "== each stage alone, one thread (CPU s; ratio: to hearth map of all states, one thread)"
# on a copy of the built release, each stage's command as the build runs it
# (overlay at the build's zoom 2; bake = map --rgb less the maps it also does)
rm -rf "$work/stages"
cp -a "$work/rel" "$work/stages"
st="$work/stages"
stage_cpu() { HEARTH_THREADS=1 timed "$@" > /dev/null; echo "$cpu"; }
insts=$(ls "$st/instances")
c_map1=$(stage_cpu "$h" map "$st")
c_detect=$(stage_cpu "$h" detect "$st")
c_calib=$(stage_cpu "$h" calibrate "$st")
c_scale=0 c_refine=0 c_bake=0
for i in $insts; do
  c_scale=$(awk -v a="$c_scale" -v b="$(stage_cpu "$h" scale "$st" --instance "$i")" 'BEGIN{print a + b}')
  c_refine=$(awk -v a="$c_refine" -v b="$(stage_cpu "$h" refine "$st" --instance "$i")" 'BEGIN{print a + b}')
  rgb=$(stage_cpu "$h" map "$st" --instance "$i" --rgb)
  m=$(stage_cpu "$h" map "$st" --instance "$i")
  c_bake=$(awk -v a="$c_bake" -v b="$rgb" -v c="$m" 'BEGIN{print a + b - c}')
done
c_overlay=$(stage_cpu "$h" overlay "$st" --zoom 2)
stages_table=$(awk -v m="$c_map1" -v d="$c_detect" -v ca="$c_calib" -v sc="$c_scale" \
  -v r="$c_refine" -v b="$c_bake" -v o="$c_overlay" 'BEGIN {
  n = split("detect calibrate scale bake refine map overlay", k, " ")
  v["detect"] = d; v["calibrate"] = ca; v["scale"] = sc; v["bake"] = b
  v["refine"] = r; v["map"] = m; v["overlay"] = o
  for (i = 1; i <= n; i++) { t += v[k[i]]
    printf "  %-10s %6.2f s CPU %5.1fx\n", k[i], v[k[i]], (m > 0 ? v[k[i]] / m : 0) }
  printf "  %-10s %6.2f s CPU %5.1fx\n", "all", t, (m > 0 ? t / m : 0) }')
echo "$stages_table"

demo=${HEARTH_BENCH_DEMO:-1}
if [ "$demo" != 0 ]; then
  echo "== hearth demo, then hearth build of its release"
  rm -rf "$work/demo"
  "$h" demo "$work/demo" --quiet > "$work/demo.log" 2>&1 || { cat "$work/demo.log"; exit 1; }
  timed "$h" build "$work/demo/release" > "$work/rebuild.log"
  rebuild_runs=$(sed -n 's/.* \([0-9]*\) stage(s) run.*/\1/p' "$work/rebuild.log")
  echo "  $(grep '^build summary' "$work/rebuild.log")"
fi

echo "== peak memory (cup_01, first state)"
state=$(sed -n 's/.*"states": *\["\([^"]*\)".*/\1/p' "$work/rel/instances/cup_01/instance.json")
rss() { if [ -x /usr/bin/time ]; then /usr/bin/time -f "%M" -o "$work/rss.txt" "$@" > /dev/null && cat "$work/rss.txt"; else echo 0; fi; }
rss_map=$(rss "$h" map "$work/rel" --instance cup_01 --state "$state")
rss_rgb=$(rss "$h" map "$work/rel" --instance cup_01 --state "$state" --rgb)
# the bake runs first in map --rgb and reports the process's peak when it
# ends: the bake's own peak (MiB)
"$h" map "$work/rel" --instance cup_01 --state "$state" --rgb > "$work/rgb.log"
rss_bake=$(sed -n 's/.*colour texture baked (.*peak memory so far \([0-9.]*\) MiB).*/\1/p' "$work/rgb.log")

echo
printf "build -j2      %7.2f s wall %7.2f s CPU\n" "$build_wall" "$build_cpu"
printf "map, 4 states  %7.2f s wall %7.2f s CPU\n" "$map_wall" "$map_cpu"
awk -v a="$build_wall" -v b="$map_wall" -v c="$build_cpu" -v d="$map_cpu" 'BEGIN {
  printf "ratio build / map: %.1fx wall, %.1fx CPU (target: at most 12x)\n", a / b, (d > 0 ? c / d : 0) }'
[ "$demo" = 0 ] || printf "build after demo: %s stage(s) run (must be 0)\n" "${rebuild_runs:-?}"
awk -v a="$rss_map" -v b="$rss_rgb" -v c="${rss_bake:-0}" 'BEGIN {
  printf "peak RSS: map %.1f MiB; the bake %.1f MiB (%.2fx the map, target: at most 1x); map --rgb as a whole %.1f MiB (%.2fx)\n",
    a / 1024, c, (a > 0 ? c * 1024 / a : 0), b / 1024, (a > 0 ? b / a : 0) }'
[ "$demo" = 0 ] || [ "${rebuild_runs:-1}" = 0 ]
