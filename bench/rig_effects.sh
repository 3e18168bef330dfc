#!/bin/sh
# The pipeline against the virtual rig with every object effect on
# (docs/virtual-rig.md, "Object physics"): synth with the defaults for cup,
# canned_drink, smartphone and electric_kettle, each in the states neutral,
# hot, iced and warm, a full build with the paper's max fusion, then the maps again with
# the corrected fusion, and for each the error table of
# bench/rig_effects_eval.py (median and p95 of |error| in degC on texels seen
# within 60 degrees of the normal, against the normal-incidence apparent
# temperature and the true surface temperature).
#
# usage: bench/rig_effects.sh BUILD_DIR WORK_DIR [RES] [VIEWS] [FAST]
#   RES: map side (default 1024); VIEWS: views per state (default 30);
#   STATES (environment): the states synthesised (default neutral,hot,iced,warm;
#   empty: each category's own); FAST=1: no calibration captures (the true rig is put in calibration/:
#   a test of the fusion only), draft colour, small meshes.
# Exit status 0; the table goes to stdout.
set -eu
B=$1
W=$2
RES=${3:-1024}
VIEWS=${4:-30}
FAST=${5:-0}
STATES=${STATES-neutral,hot,iced,warm}  # empty: each category's own states
HERE=$(cd "$(dirname "$0")" && pwd)
H="$B/hearth"
rm -rf "$W"
mkdir -p "$W"
if [ "$FAST" = 1 ]; then
  "$H" synth --out "$W/rel" --categories cup,canned_drink,smartphone,electric_kettle \
    ${STATES:+--states "$STATES"} --views "$VIEWS" --map-res "$RES" --triangles 6000 --texture 256 --draft-rgb \
    --no-calibration --quiet
  cp "$W/rel/ground_truth/rig.json" "$W/rel/calibration/rig.json"
else
  "$H" synth --out "$W/rel" --categories cup,canned_drink,smartphone,electric_kettle \
    ${STATES:+--states "$STATES"} --views "$VIEWS" --map-res "$RES" --quiet
fi
"$H" build "$W/rel" --resolution "$RES" --fusion max --no-bake --quiet >/dev/null
echo "fusion     instance             state     texels  med|app|  p95|app| med|true| p95|true|"
/usr/bin/python3 "$HERE/rig_effects_eval.py" "$W/rel" max
"$H" map "$W/rel" --resolution "$RES" --fusion corrected >/dev/null
/usr/bin/python3 "$HERE/rig_effects_eval.py" "$W/rel" corrected
