#!/usr/bin/env bash
# Calibration accuracy on the virtual rig with the bench's physics on (the
# default synth: thick plate, lamp-heated backing, warming plate, vignetting,
# fixed-pattern noise, colour motion blur and JPEG, trigger offset, holes
# drilled off the nominal lattice, the plate turned every way round), over
# seeds, with the wall-corrected hole centres and the rolling-shutter stereo
# and the thermal intrinsics refined in the stereo stage (the defaults), with
# the naive centroid (--no-wall-correction), with a rigid plate per pair
# (--no-rolling-shutter), with the thermal intrinsics held fixed in the
# stereo (--fixed-intrinsics) and with the holes' positions estimated
# (--refine-target), against ground_truth/rig.json:
#   bench/calib_physics.sh BUILD_DIR OUT_DIR [SEEDS...]   (default seeds 1 2 3 4)
# SYNTH_ARGS (environment) adds synth options, e.g. SYNTH_ARGS="--plate-bow 0"
# to see one effect's share; ESTIMATORS (environment) picks estimators from
# "wall naive rigid fixed target ntarget" (default: all but ntarget, which is
# --refine-target with the naive centroid).
# One line per seed and estimator: stereo RMS (px; "nominal" against the
# target as drawn, from calibration_report.json), thermal fx error (%),
# rotation (deg) and translation (mm) of T_thermal_from_rgb.
set -euo pipefail
build=$(cd "$1" && pwd)
out=$2
shift 2
seeds=${*:-1 2 3 4}
here=$(cd "$(dirname "$0")" && pwd)
h="$build/hearth"
mkdir -p "$out"
for s in $seeds; do
  r="$out/seed$s"
  rm -rf "$r"
  "$h" synth --out "$r" --categories cup --states neutral --views 1 --seed "$s" --quiet \
    ${SYNTH_ARGS:-} >/dev/null
  "$h" detect "$r" >/dev/null
  for est in ${ESTIMATORS:-wall naive rigid fixed target}; do
    case $est in
      wall) "$h" calibrate "$r" --quiet >/dev/null ;;
      naive) "$h" calibrate "$r" --quiet --no-wall-correction >/dev/null ;;
      rigid) "$h" calibrate "$r" --quiet --no-rolling-shutter >/dev/null ;;
      fixed) "$h" calibrate "$r" --quiet --fixed-intrinsics >/dev/null ;;
      target) "$h" calibrate "$r" --quiet --refine-target >/dev/null ;;
      ntarget) "$h" calibrate "$r" --quiet --refine-target --no-wall-correction >/dev/null ;;
    esac
    /usr/bin/python3 - "$r" "$s" "$est" <<'PY'
import json, math, sys
import numpy as np
r, s, est = sys.argv[1:4]
e = json.load(open(f"{r}/calibration/rig.json"))
t = json.load(open(f"{r}/ground_truth/rig.json"))
import os
tp = f"{r}/calibration/target.json"
th = json.load(open(tp)).get("thickness_m", 0) if os.path.exists(tp) else 0
Ke, Kt = np.array(e["thermal"]["K"]), np.array(t["thermal"]["K"])
Re, Rt = np.array(e["T_thermal_from_rgb"]["R"]), np.array(t["T_thermal_from_rgb"]["R"])
c = max(-1.0, min(1.0, (np.trace(Re @ Rt.T) - 1) / 2))
dt = 1000 * np.linalg.norm(np.array(e["T_thermal_from_rgb"]["t"]) - np.array(t["T_thermal_from_rgb"]["t"]))
rep = json.load(open(f"{r}/calibration/calibration_report.json"))
nom = rep.get("stereo_rms_nominal_px", e["stereo_rms_px"])
print(f"seed {s} {est:7s} thickness {1000*th:.2f} mm  stereo_rms {e['stereo_rms_px']:.3f} px  "
      f"nominal {nom:.3f} px  "
      f"thermal_rms {e['thermal_rms_px']:.4f} px  fx {100*abs(Ke[0,0]-Kt[0,0])/Kt[0,0]:.3f} %  "
      f"fy {100*abs(Ke[1,1]-Kt[1,1])/Kt[1,1]:.3f} %  cx {abs(Ke[0,2]-Kt[0,2]):.2f} px  "
      f"cy {abs(Ke[1,2]-Kt[1,2]):.2f} px  rot {math.degrees(math.acos(c)):.4f} deg  t {dt:.3f} mm")
PY
  done
done
