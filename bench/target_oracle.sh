#!/usr/bin/env bash
# Oracle experiments on the drilling tolerance (issue 20): which part of the
# holes' offsets from the nominal lattice moves the calibration. Builds a
# scratch copy of HEAD with bench/target_oracle.patch (two diagnostic hooks,
# never in the product: the synth writes the drilled hole positions to
# $HEARTH_ORACLE_HOLES_OUT, calibrate takes the target's points from
# $HEARTH_ORACLE_HOLES_IN), then per seed synthesises the default bench
# with --hole-position M, detects, and calibrates with the target taken as
#   nominal  the lattice of target.json (what a drawing gives),
#   true     the drilled positions,
#   nosim    the drilled positions less their best-fit similarity (the best
#            a refinement gauge-fixed on the similarity part can reach),
#   noaff    the drilled positions less their best-fit affine part (the
#            best a refinement gauge-fixed on the affine part can reach),
#   noproj   less their best-fit affine and first-order projective part
#            (8 modes: x, y, 1 per axis, (x^2, xy) and (xy, y^2)),
#   affonly  the nominal lattice plus the affine part (the target error is
#            then the non-affine part alone),
# and once more with --refine-target against the nominal lattice:
#   bench/target_oracle.sh WORK_DIR [M] [SEEDS...]   (default 4e-5; 1 2)
# SYNTH_ARGS (environment) adds synth options. One line per seed and case:
# stereo RMS, thermal RMS, fx / fy error (%), cx / cy error (px), rotation
# (deg) and translation (mm) of T_thermal_from_rgb against
# ground_truth/rig.json.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/.." && pwd)
work=$(mkdir -p "$1" && cd "$1" && pwd)
m=${2:-4e-5}
shift $(($# >= 2 ? 2 : 1))
seeds=${*:-1 2}
if [ ! -x "$work/build/hearth" ]; then
  rm -rf "$work/src"
  mkdir -p "$work/src"
  git -C "$repo" archive HEAD | tar -x -C "$work/src"
  patch -s -d "$work/src" -p1 <"$here/target_oracle.patch"
  cmake -S "$work/src" -B "$work/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  cmake --build "$work/build" -j2 --target hearth >/dev/null
fi
h="$work/build/hearth"
py=/usr/bin/python3
for s in $seeds; do
  r="$work/seed$s"
  rm -rf "$r"
  HEARTH_ORACLE_HOLES_OUT="$r.holes" "$h" synth --out "$r" --categories cup --states neutral \
    --views 1 --seed "$s" --quiet --hole-position "$m" ${SYNTH_ARGS:-} >/dev/null
  mv "$r.holes" "$r/holes_true.txt"
  "$h" detect "$r" >/dev/null
  "$py" - "$r" "$s" <<'PY'
import sys, numpy as np
r = sys.argv[1]
T = np.loadtxt(f"{r}/holes_true.txt")
import json
t = json.load(open(f"{r}/calibration/target.json"))
pitch, rows, cols = t["pitch_m"], t["rows"], t["cols"]
step = round(pitch * np.sqrt(3) / 2 * 1e7) / 1e7
N = np.array([(pitch * c + (0.5 * pitch if q & 1 else 0.0), step * q)
              for q in range(rows) for c in range(cols - (q & 1))])
O = (T - N).ravel()
x, y, one = N[:, 0], N[:, 1], np.ones(len(N))
def modes(proj, sim=False):
    cols_ = []
    if sim:
        for f in ((one, 0 * x), (0 * x, one), (x, y), (-y, x)):
            v = np.zeros(O.size); v[0::2] = f[0]; v[1::2] = f[1]; cols_.append(v)
        return np.array(cols_).T
    for k in range(2):
        for f in (x, y, one):
            v = np.zeros(O.size); v[k::2] = f; cols_.append(v)
    if proj:
        v = np.zeros(O.size); v[0::2] = x * x; v[1::2] = x * y; cols_.append(v)
        v = np.zeros(O.size); v[0::2] = x * y; v[1::2] = y * y; cols_.append(v)
    return np.array(cols_).T
A = modes(False); a = A @ np.linalg.lstsq(A, O, rcond=None)[0]
P = modes(True); p = P @ np.linalg.lstsq(P, O, rcond=None)[0]
S = modes(False, True); q = S @ np.linalg.lstsq(S, O, rcond=None)[0]
um = lambda v: 1e6 * np.sqrt((v ** 2).mean() * 2)
print(f"seed {sys.argv[2]}: offsets {um(O):.1f} um rms length, affine part {um(a):.1f} um, "
      f"affine + projective part {um(p):.1f} um")
for name, v in (("nominal", 0 * O), ("nosim", O - q), ("noaff", O - a), ("noproj", O - p),
                ("affonly", a)):
    np.savetxt(f"{r}/holes_{name}.txt", N + v.reshape(-1, 2), fmt="%.17g")
PY
  for c in nominal true nosim noaff noproj affonly refine; do
    f="$r/holes_$c.txt"
    a=""
    [ $c = refine ] && f="" && a=--refine-target
    HEARTH_ORACLE_HOLES_IN=$f "$h" calibrate "$r" --quiet $a >/dev/null
    "$py" - "$r" "$s" "$c" <<'PY'
import json, math, sys
import numpy as np
r, s, c = sys.argv[1:4]
e = json.load(open(f"{r}/calibration/rig.json"))
t = json.load(open(f"{r}/ground_truth/rig.json"))
Ke, Kt = np.array(e["thermal"]["K"]), np.array(t["thermal"]["K"])
Re, Rt = np.array(e["T_thermal_from_rgb"]["R"]), np.array(t["T_thermal_from_rgb"]["R"])
cs = max(-1.0, min(1.0, (np.trace(Re @ Rt.T) - 1) / 2))
dt = 1000 * np.linalg.norm(np.array(e["T_thermal_from_rgb"]["t"]) - np.array(t["T_thermal_from_rgb"]["t"]))
print(f"seed {s} {c:8s} stereo_rms {e['stereo_rms_px']:.3f} px  thermal_rms {e['thermal_rms_px']:.4f} px  "
      f"fx {100*(Ke[0,0]-Kt[0,0])/Kt[0,0]:+.3f} %  fy {100*(Ke[1,1]-Kt[1,1])/Kt[1,1]:+.3f} %  "
      f"cx {Ke[0,2]-Kt[0,2]:+.2f} px  cy {Ke[1,2]-Kt[1,2]:+.2f} px  "
      f"rot {math.degrees(math.acos(cs)):.4f} deg  t {dt:.3f} mm")
PY
  done
done
