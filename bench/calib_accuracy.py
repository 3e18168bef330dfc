#!/usr/bin/python3
"""Accuracy of a built virtual-rig release against its ground truth:
thermal intrinsics (calibration/rig.json vs ground_truth/rig.json), the
RGB-thermal transform, and the temperature maps (derived/<state>/
temperature_observed.npy where mask == 1, and temperature_filled.npy where
mask is 1 or 2, vs ground_truth/instances/<id>/<state>/temperature_true.npy).
  bench/calib_accuracy.py ROOT [LABEL]   -> one line of figures (and JSON with --json)
"""
import glob
import json
import math
import os
import sys

import numpy as np


def rot_angle_deg(Ra, Rb):
    R = np.asarray(Ra) @ np.asarray(Rb).T
    c = max(-1.0, min(1.0, (np.trace(R) - 1) / 2))
    return math.degrees(math.acos(c))


def main():
    root = sys.argv[1]
    label = sys.argv[2] if len(sys.argv) > 2 and not sys.argv[2].startswith("--") else root
    est = json.load(open(os.path.join(root, "calibration/rig.json")))
    tru = json.load(open(os.path.join(root, "ground_truth/rig.json")))
    Ke, Kt = np.array(est["thermal"]["K"]), np.array(tru["thermal"]["K"])
    w, h = est["thermal"]["width"], est["thermal"]["height"]
    out = {"label": label, "thermal_size": f"{w}x{h}",
           "fx_rel_pct": 100 * abs(Ke[0, 0] - Kt[0, 0]) / Kt[0, 0],
           "fy_rel_pct": 100 * abs(Ke[1, 1] - Kt[1, 1]) / Kt[1, 1],
           "cx_px": abs(Ke[0, 2] - Kt[0, 2]), "cy_px": abs(Ke[1, 2] - Kt[1, 2]),
           "thermal_rms_px": est["thermal_rms_px"], "stereo_rms_px": est["stereo_rms_px"]}
    # distortion: the largest displacement difference over the image (px)
    de, dt = np.array(est["thermal"]["dist"]), np.array(tru["thermal"]["dist"])
    ys, xs = np.mgrid[0:h:8, 0:w:8]
    x = (xs - Kt[0, 2]) / Kt[0, 0]
    y = (ys - Kt[1, 2]) / Kt[1, 1]

    def distort(d):
        r2 = x * x + y * y
        rad = 1 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 ** 3
        return (x * rad + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x),
                y * rad + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y)
    xe, ye = distort(de)
    xt, yt = distort(dt)
    out["dist_max_px"] = float(np.max(np.hypot((xe - xt) * Kt[0, 0], (ye - yt) * Kt[1, 1])))
    Te, Tt = est["T_thermal_from_rgb"], tru["T_thermal_from_rgb"]
    out["stereo_rot_deg"] = rot_angle_deg(Te["R"], Tt["R"])
    out["stereo_t_mm"] = 1000 * float(np.linalg.norm(np.array(Te["t"]) - np.array(Tt["t"])))
    obs_err, fill_err = [], []
    for truth in sorted(glob.glob(os.path.join(root, "ground_truth/instances/*/*/temperature_true.npy"))):
        state = os.path.basename(os.path.dirname(truth))
        inst = os.path.basename(os.path.dirname(os.path.dirname(truth)))
        d = os.path.join(root, "instances", inst, "derived", state)
        if not os.path.exists(os.path.join(d, "mask.npy")):
            continue
        T = np.load(truth)
        m = np.load(os.path.join(d, "mask.npy"))
        o = np.load(os.path.join(d, "temperature_observed.npy"))
        f = np.load(os.path.join(d, "temperature_filled.npy"))
        if T.shape != o.shape:
            continue
        sel = (m == 1) & np.isfinite(T)
        obs_err.append(np.abs(o[sel] - T[sel]))
        sel = ((m == 1) | (m == 2)) & np.isfinite(T)
        fill_err.append(np.abs(f[sel] - T[sel]))
    if obs_err:
        e = np.concatenate(obs_err)
        out["map_observed_median_c"] = float(np.median(e))
        out["map_observed_p95_c"] = float(np.percentile(e, 95))
        e = np.concatenate(fill_err)
        out["map_filled_median_c"] = float(np.median(e))
    if "--json" in sys.argv:
        print(json.dumps(out))
    else:
        print(("%-28s %-8s fx %.3f%% fy %.3f%% cx %.2f cy %.2f px dist %.2f px | stereo %.3f deg "
               "%.2f mm | map median %.3f p95 %.3f C") %
              (label, out["thermal_size"], out["fx_rel_pct"], out["fy_rel_pct"], out["cx_px"],
               out["cy_px"], out["dist_max_px"], out["stereo_rot_deg"], out["stereo_t_mm"],
               out.get("map_observed_median_c", float("nan")),
               out.get("map_observed_p95_c", float("nan"))))


if __name__ == "__main__":
    main()
