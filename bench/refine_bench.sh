#!/bin/sh
# Scale + refinement on a small virtual-rig release: scale error vs truth,
# reprojection error of perturbed thermal poses before/after refinement, and
# the time per view on 2 threads. Wall time on a shared machine is noisy, so
# the CPU time of the refinement alone is also printed: CPU of a run minus
# that of the same run with --no-auto (loading, reprojection checks).
# usage: bench/refine_bench.sh [HEARTH_EXE] [WORKDIR] [CATEGORIES] [VIEWS]
set -e
EXE=${1:-build/hearth}
W=${2:-/tmp/hearth_refine_bench}
CATS=${3:-cup,canned_drink,smartphone}
VIEWS=${4:-10}
rm -rf "$W"
"$EXE" synth --out "$W" --categories "$CATS" --views "$VIEWS" --triangles 4000 \
  --texture 256 --map-res 256 --no-calibration --quiet
for ID in $(ls "$W/instances"); do
  G="$W/ground_truth/instances/$ID"
  "$EXE" scale "$W" --instance "$ID" --threads 2
  python3 -c "import json; a=json.load(open('$W/instances/$ID/derived/scale.json'))['scale']; b=json.load(open('$G/scale.json'))['scale']; print('$ID: scale rel error %.4f %%' % (100*abs(a/b-1)))"
  cpu() { /usr/bin/time -f "%U %S" -o "$W/cpu.txt" "$@" >"$W/out.txt" && awk '{print $1 + $2}' "$W/cpu.txt"; }
  set -- refine "$W" --instance "$ID" --rig "$W/ground_truth/rig.json" --mesh "$G/mesh.glb" \
    --start "$G/poses_thermal.json" --perturb 1,5 --truth "$G/poses_thermal.json" --threads 2
  c0=$(cpu "$EXE" "$@" --no-auto)
  c1=$(cpu "$EXE" "$@")
  cat "$W/out.txt"
  n=$(python3 -c "import json; print(len(json.load(open('$W/instances/$ID/derived/refine_report.json'))['views']))")
  python3 -c "print('$ID: refinement CPU %.1f ms per view (%d views; run %.2f s CPU, without refinement %.2f s)' % (1e3*($c1-$c0)/$n, $n, $c1, $c0))"
  python3 - "$W/instances/$ID/derived/refine_report.json" <<'EOF'
import json, sys, collections
by = collections.defaultdict(list)
for v in json.load(open(sys.argv[1]))['views']:
    by[v['state']].append(v)
for s, vs in by.items():
    a = [v['reproj_vs_truth_start_px'] for v in vs]
    b = [v['reproj_vs_truth_final_px'] for v in vs]
    print('  %-8s reprojection %.3f -> %.3f px (worst %.3f), %d/%d refined, %d worse' % (
        s, sum(a) / len(a), sum(b) / len(b), max(b), sum(v['refined'] for v in vs), len(vs),
        sum(y > x + 1e-9 for x, y in zip(a, b))))
EOF
done
