#!/usr/bin/python3
"""hearth detect against OpenCV's findCirclesGrid on the same real-looking
calibration frames of a virtual-rig release (bench/detect_vs_opencv.sh makes
them), judged by the rig's true hole centres.

  detect_vs_opencv.py prepare ROOT OUT   copy ROOT to OUT with every thermal
        capture tone-mapped to 8 bits (min..max, gamma 1/1.4, as a camera
        without a radiometric export saves it): OUT/.../fNNN.png for OpenCV
        and the same 0..255 values as fNNN.csv for hearth
  detect_vs_opencv.py judge OUT HEARTH   run OpenCV on OUT's frames, read
        OUT/calibration/detections.json (hearth detect) and
        OUT/calibration/rig.json (hearth calibrate); print both

Counts are over frames whose whole target is in view (ground truth found),
and separately over partial frames (a detector must refuse them).
"Mis-ordered": a found frame whose centres are not the true ones in an
order the target's symmetry allows (hearth: its documented order exactly;
OpenCV: any rotation of the target, since OpenCV numbers a symmetric grid
from the image; a mirrored order counts as mis-ordered). Calibration: the
thermal intrinsics from the thermal-only frames (fNNN) each method found,
OpenCV's cv2.calibrateCamera with the same 5-parameter model against
hearth calibrate, both against ground_truth/rig.json.
"""
import glob
import json
import math
import os
import shutil
import sys

import cv2
import numpy as np


def tone_map(T):
    lo, hi = float(T.min()), float(T.max())
    span = hi - lo if hi > lo else 1.0
    return np.rint(255.0 * ((T - lo) / span) ** (1 / 1.4)).astype(np.uint8)


def prepare(root, out):
    if os.path.exists(out):
        shutil.rmtree(out)
    shutil.copytree(root, out)
    for sub in ("thermal", "stereo"):
        for csv in glob.glob(os.path.join(out, "calibration/captures", sub, "*.csv")):
            T = np.loadtxt(csv, delimiter=",", dtype=np.float64)
            g = tone_map(T)
            cv2.imwrite(csv[:-4] + ".png", g)
            np.savetxt(csv, g, fmt="%d", delimiter=",")
    # detections and calibration are remade by hearth on the 8-bit frames
    for f in ("detections.json", "rig.json", "calibration_report.json", "rig_opencv.yaml"):
        p = os.path.join(out, "calibration", f)
        if os.path.exists(p):
            os.remove(p)


def target_of(root):
    p = os.path.join(root, "calibration/target.json")
    if not os.path.exists(p):
        return {"lattice": "hex-alternating", "rows": 8, "cols": 11, "pitch_m": 0.012,
                "hole_diameter_m": 0.008}
    return json.load(open(p))


def target_points(t):
    P, R, C = t["pitch_m"], t["rows"], t["cols"]
    step = P if t["lattice"] == "grid" else round(P * math.sqrt(3) / 2 * 1e7) / 1e7
    pts = []
    for r in range(R):
        n = C - 1 if (t["lattice"] == "hex-alternating" and r % 2) else C
        off = 0.5 * P if (t["lattice"] != "grid" and r % 2) else 0.0
        for c in range(n):
            pts.append((P * c + off, step * r, 0.0))
    return np.array(pts, np.float64)


def symmetries(t, n):
    """index permutations of the target's orientation-preserving symmetries"""
    R, C, L = t["rows"], t["cols"], t["lattice"]
    ident = list(range(n))
    perms = [ident]
    half = list(range(n))[::-1]
    if L == "grid" or (L == "hex" and R % 2 == 0) or (L == "hex-alternating" and R % 2 == 1):
        perms.append(half)
    if L == "grid" and R == C:
        q = [0] * n  # quarter turn: (r, c) -> (c, R-1-r)
        for r in range(R):
            for c in range(C):
                q[r * C + c] = c * C + (R - 1 - r)
        q3 = [q[q[q[i]]] for i in range(n)]
        perms += [q, q3]
    return perms


def blob_detector(hole_px):
    p = cv2.SimpleBlobDetector_Params()
    a = math.pi * hole_px * hole_px
    p.filterByArea = True
    p.minArea = max(4.0, 0.25 * a)
    p.maxArea = 4.0 * a
    p.filterByColor = True
    p.blobColor = 0
    p.filterByCircularity = False
    p.filterByConvexity = False
    p.filterByInertia = True
    p.minInertiaRatio = 0.2
    p.minThreshold = 5
    p.maxThreshold = 250
    p.thresholdStep = 5
    p.minDistBetweenBlobs = 0.5 * hole_px
    return cv2.SimpleBlobDetector_create(p)


def opencv_find(gray, t, hole_px):
    """findCirclesGrid on the image and on its inverse (holes may be bright);
    the centres in OpenCV's order, or None"""
    if t["lattice"] == "grid":
        flags, size = cv2.CALIB_CB_SYMMETRIC_GRID, (t["cols"], t["rows"])
    elif t["lattice"] == "hex":
        flags, size = cv2.CALIB_CB_ASYMMETRIC_GRID, (t["cols"], t["rows"])
    else:
        return None  # rows of 11 and 10: no OpenCV pattern
    det = blob_detector(hole_px)
    for img in (gray, 255 - gray):
        ok, c = cv2.findCirclesGrid(img, size, flags=flags, blobDetector=det)
        if ok:
            return c.reshape(-1, 2).astype(np.float64)
    return None


def judge_order(found, truth, perms, spacing):
    """(matched, perm index): matched if some permutation lands every centre
    within a quarter spacing of its true hole"""
    for k, p in enumerate(perms):
        if np.max(np.hypot(*(found - truth[p]).T)) < 0.25 * spacing:
            return True, k
    return False, -1


def load_gray(path):
    if path.endswith(".csv"):
        return None
    return cv2.imread(path, cv2.IMREAD_GRAYSCALE)


def main_judge(out, hearth_exe):
    t = target_of(out)
    obj = target_points(t)
    n = len(obj)
    perms = symmetries(t, n)
    gt = json.load(open(os.path.join(out, "ground_truth/calibration/detections.json")))
    hd = json.load(open(os.path.join(out, "calibration/detections.json")))
    hmap = {(f["frame"], f["camera"]): f for f in hd["frames"]}
    rig = json.load(open(os.path.join(out, "ground_truth/rig.json")))
    stats = {m: {"full": 0, "found": 0, "mis": 0, "partial": 0, "partial_found": 0}
             for m in ("hearth", "opencv")}
    ocv_thermal = []  # (frame, centres in OpenCV order)
    ocv_pairs = {}
    for f in gt["frames"]:
        cam = f["camera"]
        name = f["frame"]
        if cam == "thermal":
            sub = "thermal" if name[0] == "f" else "stereo"
            path = os.path.join(out, "calibration/captures", sub,
                                name + ("" if name[0] == "f" else "_thermal") + ".png")
            K = rig["thermal"]["K"]
        else:
            path = os.path.join(out, "calibration/captures/stereo", name + "_rgb.jpg")
            K = rig["rgb"]["K"]
        gray = load_gray(path)
        full = f["found"]
        truth = np.array(f["centres"]) if full else None
        # hole radius in pixels at a typical distance: spacing * diameter / pitch / 2
        h = hmap[(name, cam)]
        spacing = None
        if full:
            spacing = float(np.median(np.hypot(*(truth[1:] - truth[:-1]).T)))
        res = {}
        res["hearth"] = np.array(h["centres"]) if h["found"] else None
        est_sp = spacing if spacing else K[0][0] * t["pitch_m"] / 0.35
        hole_px = 0.5 * est_sp * t["hole_diameter_m"] / t["pitch_m"]
        res["opencv"] = opencv_find(gray, t, hole_px) if gray is not None else None
        for m in ("hearth", "opencv"):
            s = stats[m]
            c = res[m]
            if not full:
                s["partial"] += 1
                s["partial_found"] += c is not None
                continue
            s["full"] += 1
            if c is None:
                continue
            s["found"] += 1
            ok, k = judge_order(c, truth, perms if m == "opencv" else perms[:1], spacing)
            if not ok:
                s["mis"] += 1
            elif m == "opencv":
                if cam == "thermal" and name[0] == "f":
                    ocv_thermal.append(c)
                if name[0] == "p":
                    ocv_pairs.setdefault(name, {})[cam] = k
    # colour and thermal of one pair numbered alike
    pair_disagree = sum(1 for v in ocv_pairs.values() if len(v) == 2 and v["rgb"] != v["thermal"])
    print("target %s %dx%d (%d holes)" % (t["lattice"], t["rows"], t["cols"], n))
    for m in ("hearth", "opencv"):
        s = stats[m]
        if m == "opencv" and t["lattice"] == "hex-alternating":
            print("  opencv: no findCirclesGrid pattern for rows of C and C-1 holes")
            continue
        print("  %-7s found %3d/%3d whole-target frames (%.0f%%), mis-ordered %d, partial found %d/%d"
              % (m, s["found"], s["full"], 100.0 * s["found"] / max(1, s["full"]), s["mis"],
                 s["partial_found"], s["partial"]))
    if t["lattice"] != "hex-alternating":
        print("  opencv  stereo pairs numbered differently in the two cameras: %d" % pair_disagree)
    tk = np.array(rig["thermal"]["K"])
    W, H = rig["thermal"]["width"], rig["thermal"]["height"]

    def errs(K):
        return (100 * abs(K[0][0] / tk[0, 0] - 1), 100 * abs(K[1][1] / tk[1, 1] - 1),
                abs(K[0][2] - tk[0, 2]), abs(K[1][2] - tk[1, 2]))
    p = os.path.join(out, "calibration/rig.json")
    if os.path.exists(p):
        est = json.load(open(p))
        e = errs(est["thermal"]["K"])
        print("  hearth  calibrate: fx %.3f%% fy %.3f%% cx %.2f px cy %.2f px (RMS %.3f px)"
              % (e + (est["thermal_rms_px"],)))
    if len(ocv_thermal) >= 3 and t["lattice"] != "hex-alternating":
        o = obj.astype(np.float32)
        if t["lattice"] == "hex":
            # OpenCV's asymmetric order: the same row-by-row numbering
            pass
        objs = [o] * len(ocv_thermal)
        imgs = [c.astype(np.float32).reshape(-1, 1, 2) for c in ocv_thermal]
        rms, K, dist, _, _ = cv2.calibrateCamera(objs, imgs, (W, H), None, None)
        e = errs(K)
        print("  opencv  calibrateCamera on %d frames: fx %.3f%% fy %.3f%% cx %.2f px cy %.2f px "
              "(RMS %.3f px)" % ((len(ocv_thermal),) + e + (rms,)))


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "prepare":
        prepare(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 4 and sys.argv[1] == "judge":
        main_judge(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
