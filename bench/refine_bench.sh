#!/bin/sh
# Scale + refinement on a small virtual-rig release: scale error vs truth,
# reprojection error of perturbed thermal poses before/after refinement, and
# the time per view on 2 threads.
# usage: bench/refine_bench.sh [HEARTH_EXE] [WORKDIR] [CATEGORY] [STATES]
set -e
EXE=${1:-build/hearth}
W=${2:-/tmp/hearth_refine_bench}
CAT=${3:-cup}
STATES=${4:-neutral,hot}
rm -rf "$W"
"$EXE" synth --out "$W" --categories "$CAT" --states "$STATES" --views 8 --triangles 5000 \
  --texture 256 --map-res 256 --no-calibration --quiet
ID=$(ls "$W/instances")
G="$W/ground_truth/instances/$ID"
"$EXE" scale "$W" --threads 2
python3 -c "import json,sys; a=json.load(open('$W/instances/$ID/derived/scale.json'))['scale']; b=json.load(open('$G/scale.json'))['scale']; print('scale rel error %.4f %%' % (100*abs(a/b-1)))"
"$EXE" refine "$W" --rig "$W/ground_truth/rig.json" --start "$G/poses_thermal.json" --perturb 1,5 \
  --truth "$G/poses_thermal.json" --threads 2
