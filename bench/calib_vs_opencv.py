#!/usr/bin/python3
"""Calibration check: hearth detect + calibrate against the virtual rig's
ground truth and against OpenCV (cv2.calibrateCamera / cv2.stereoCalibrate)
on the same detected points, with the time ratio.

usage: /usr/bin/python3 bench/calib_vs_opencv.py ROOT [--hearth PATH] [--centres PATH]
       [--runs N]

ROOT is a release with calibration/captures and calibration/factory.json
(a virtual-rig release also has ground_truth/). The script runs
`hearth detect ROOT --no-overlays` and `hearth calibrate ROOT`, so it
rewrites calibration/detections.json, rig.json, rig_opencv.yaml and
calibration_report.json (the default calibration is left in place at the
end). The OpenCV comparison runs hearth with --no-perspective-correction so
both solvers see exactly the same points and frames. Exit status 1 if a
Done-means figure fails.

The hole centres against the rig's truth: on a root of `hearth synth
--ideal` the detected centroids themselves (detections.json); on a root
with the bench's physics (the default synth: a thick plate whose walls
hide part of each hole, blur, ...) the centroids are biased by design and
the check is on the centres calibrate solves from instead, the centroids
corrected for the walls and the perspective (build/bench_calib_centres,
--centres names it; compared on either rig).
"""
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np
import cv2

PITCH, ROW = 0.012, 0.0103923


def plate_points():
    pts = []
    for r in range(8):
        for c in range(11 if r % 2 == 0 else 10):
            pts.append([PITCH * c + (PITCH / 2 if r % 2 else 0.0), ROW * r, 0.0])
    return np.array(pts, dtype=np.float32)


def cam(block):
    return np.array(block["K"], dtype=np.float64), np.array(block["dist"], dtype=np.float64)


def rot_angle_deg(Ra, Rb):
    c = (np.trace(Ra.T @ Rb) - 1) / 2
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def root_ideal(root):
    """(ideal, why): whether ROOT is a `hearth synth --ideal` release, from
    its files: the bench's physics writes each view's time_s into the
    state manifests (the scan's cooling clock) and the plate's thickness_m
    into calibration/target.json; the ideal rig writes neither"""
    inst = os.path.join(root, "instances")
    for dirpath, _, files in sorted(os.walk(inst)) if os.path.isdir(inst) else []:
        if "manifest.json" in files:
            m = json.load(open(os.path.join(dirpath, "manifest.json")))
            if any("time_s" in v for v in m.get("views", [])):
                return False, "manifest time_s (%s)" % os.path.relpath(dirpath, root)
    tp = os.path.join(root, "calibration", "target.json")
    if os.path.exists(tp) and json.load(open(tp)).get("thickness_m", 0) > 0:
        return False, "calibration/target.json thickness_m"
    return True, "no manifest time_s, no plate thickness"


def centre_errors(found, src):
    """squared centre errors per camera of the frames found (truth frames)
    against src[(frame, camera)]["centres"]; and the count of mis-ordered
    frames (a centre nearer another hole's truth than its own)"""
    err = {"thermal": [], "rgb": []}
    misordered = 0
    for f in found:
        a = np.array(src[(f["frame"], f["camera"])]["centres"])
        b = np.array(f["centres"])
        d = np.linalg.norm(a - b, axis=1)
        nn = np.argmin(np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2), axis=1)
        if np.any(nn != np.arange(len(b))):
            misordered += 1
            continue
        err[f["camera"]].extend((d ** 2).tolist())
    rms = {c: math.sqrt(np.mean(e)) if e else float("nan") for c, e in err.items()}
    return rms, misordered


LAST_CPU = [0.0]


def run(cmd):
    """wall seconds of cmd; its CPU seconds (user + sys, all threads) go to
    LAST_CPU[0]: on a shared, loaded machine wall time mostly measures the
    wait for a core"""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    LAST_CPU[0] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if p.returncode != 0:
        sys.stderr.write(p.stdout + p.stderr)
        sys.exit("command failed: " + " ".join(cmd))
    return dt


def timed(cmd, runs):
    """best wall time and best CPU time over runs"""
    walls, cpus = [], []
    for _ in range(runs):
        walls.append(run(cmd))
        cpus.append(LAST_CPU[0])
    return min(walls), min(cpus)


def main():
    args = sys.argv[1:]
    if not args or args[0] in ("-h", "--help"):
        print(__doc__)
        return 0
    root = args[0]
    exe = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "hearth")
    runs = 3
    centres_exe = None
    i = 1
    while i < len(args):
        if args[i] == "--hearth":
            exe = args[i + 1]
            i += 2
        elif args[i] == "--centres":
            centres_exe = args[i + 1]
            i += 2
        elif args[i] == "--runs":
            runs = int(args[i + 1])
            i += 2
        else:
            sys.exit("unknown option " + args[i])
    if not os.access(exe, os.X_OK):
        sys.exit("no hearth executable at %s (use --hearth PATH)" % exe)
    if centres_exe is None:
        centres_exe = os.path.join(os.path.dirname(exe), "bench_calib_centres")
    ok = True

    # ---- hearth: detection + calibration, timed (best of runs) ----
    t_det, c_det = timed([exe, "detect", root, "--no-overlays", "--quiet"], runs)
    t_cal, c_cal = timed([exe, "calibrate", root, "--quiet"], runs)
    # the same work in one process (calibrate --detect)
    t_one, c_one = timed([exe, "calibrate", root, "--detect", "--no-overlays", "--quiet"], runs)
    cal = os.path.join(root, "calibration")
    det = json.load(open(os.path.join(cal, "detections.json")))
    rig = json.load(open(os.path.join(cal, "rig.json")))
    fac = json.load(open(os.path.join(cal, "factory.json")))
    rep = json.load(open(os.path.join(cal, "calibration_report.json")))
    fs = cv2.FileStorage(os.path.join(cal, "rig_opencv.yaml"), cv2.FILE_STORAGE_READ)
    yK = fs.getNode("thermal_K").mat()
    fs.release()
    Kt, Dt = cam(rig["thermal"])
    print("rig_opencv.yaml: cv2.FileStorage reads thermal_K, max diff vs rig.json %.2e"
          % np.abs(yK - Kt).max())
    ok &= bool(np.abs(yK - Kt).max() < 1e-9)
    frames = {(f["frame"], f["camera"]): f for f in det["frames"]}

    # ---- against ground truth ----
    gt_path = os.path.join(root, "ground_truth", "calibration", "detections.json")
    if os.path.exists(gt_path):
        gt = json.load(open(gt_path))
        full = [f for f in gt["frames"] if f["found"]]
        found = [f for f in full if frames.get((f["frame"], f["camera"]), {}).get("found")]
        false_pos = [f for f in gt["frames"] if not f["found"]
                     and frames.get((f["frame"], f["camera"]), {}).get("found")]
        ideal, why = root_ideal(root)
        raw, misordered = centre_errors(found, frames)
        rate = len(found) / max(1, len(full))
        print("detection: %d of %d full-view frames found (%.1f%%), %d partial frames accepted, "
              "%d mis-ordered" % (len(found), len(full), 100 * rate, len(false_pos), misordered))
        print("rig: %s (%s)" % ("ideal" if ideal else "the bench's physics", why))
        print("centre error vs truth, detected centroids: thermal %.4f px RMS, colour %.4f px RMS"
              % (raw["thermal"], raw["rgb"]))
        ok &= rate >= 0.98 and misordered == 0
        if ideal:
            # the clean rig: a thin plate, no blur: the centroid is the
            # centre up to its perspective bias (0.028 and 0.067 px on seed 1);
            # with the physics it is off by design (0.87-1.20 px thermal,
            # 3.4-4.7 px colour: the walls hide part of each hole at a tilt)
            ok &= raw["thermal"] <= 0.05 and raw["rgb"] <= 0.1
        if not os.access(centres_exe, os.X_OK):
            print("no %s: the corrected centres are not compared" % centres_exe)
            ok &= ideal
        else:
            p = subprocess.run([centres_exe, root], capture_output=True, text=True)
            if p.returncode != 0:
                sys.stderr.write(p.stderr)
                sys.exit("command failed: %s %s" % (centres_exe, root))
            cor_frames = {(f["frame"], f["camera"]): f for f in json.loads(p.stdout)["frames"]}
            cor, mis_c = centre_errors(found, cor_frames)
            print("centre error vs truth, corrected centres (calibrate's): thermal %.4f px RMS, "
                  "colour %.4f px RMS" % (cor["thermal"], cor["rgb"]))
            # the ideal rig's bounds on either rig: measured 0.023-0.029 px
            # (thermal) and 0.048-0.061 px (colour) with the physics over
            # seeds 1-4 and 7, 0.022 and 0.025 px on the ideal rig (seed 1;
            # bench/README.md)
            ok &= mis_c == 0 and cor["thermal"] <= 0.05 and cor["rgb"] <= 0.1
        ok &= len(false_pos) == 0
        grig = json.load(open(os.path.join(root, "ground_truth", "rig.json")))
        Kg, Dg = cam(grig["thermal"])
        efx = abs(Kt[0, 0] / Kg[0, 0] - 1) * 100
        efy = abs(Kt[1, 1] / Kg[1, 1] - 1) * 100
        ecx, ecy = abs(Kt[0, 2] - Kg[0, 2]), abs(Kt[1, 2] - Kg[1, 2])
        print("thermal intrinsics vs truth: fx %.3f%%, fy %.3f%%, cx %.3f px, cy %.3f px"
              % (efx, efy, ecx, ecy))
        ok &= efx <= 0.2 and efy <= 0.2 and ecx <= 0.5 and ecy <= 0.5
        Rg = np.array(grig["T_thermal_from_rgb"]["R"])
        tg = np.array(grig["T_thermal_from_rgb"]["t"])
        R = np.array(rig["T_thermal_from_rgb"]["R"])
        t = np.array(rig["T_thermal_from_rgb"]["t"])
        ang = rot_angle_deg(R, Rg)
        dt = np.linalg.norm(t - tg) * 1000
        print("stereo vs truth: rotation %.4f deg, translation %.3f mm; stereo RMS %.4f px, "
              "thermal RMS %.4f px" % (ang, dt, rig["stereo_rms_px"], rig["thermal_rms_px"]))
        ok &= ang <= 0.05 and dt <= 0.5 and rig["stereo_rms_px"] <= 0.3

    # ---- OpenCV on the same points: hearth without its perspective
    # correction and rolling-shutter model (OpenCV has neither), same frames
    # and pairs, and with the thermal intrinsics held in the stereo solve as
    # cv2.stereoCalibrate's CALIB_FIX_INTRINSIC holds them (hearth's default
    # refines them) ----
    run([exe, "calibrate", root, "--quiet", "--no-perspective-correction",
         "--no-rolling-shutter", "--fixed-intrinsics"])
    rig = json.load(open(os.path.join(cal, "rig.json")))
    rep = json.load(open(os.path.join(cal, "calibration_report.json")))
    Kt, Dt = cam(rig["thermal"])
    obj = plate_points()
    used_t = [f["frame"] for f in rep["thermal_frames"] if f["used"]]
    used_p = [f["frame"] for f in rep["stereo_pairs"] if f["used"]]
    ipts = [np.array(frames[(n, "thermal")]["centres"], dtype=np.float32).reshape(-1, 1, 2)
            for n in used_t]
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-15)
    Ka, Da = cam(fac["rgb"])
    pa = [np.array(frames[(n, "rgb")]["centres"], dtype=np.float32).reshape(-1, 1, 2)
          for n in used_p]
    pb = [np.array(frames[(n, "thermal")]["centres"], dtype=np.float32).reshape(-1, 1, 2)
          for n in used_p]

    def opencv_all():
        rms, K, D, _, _ = cv2.calibrateCamera([obj] * len(ipts), ipts, (256, 192), None, None,
                                              flags=0, criteria=crit)
        srms, _, _, _, _, R, T, _, _ = cv2.stereoCalibrate(
            [obj] * len(pa), pa, pb, Ka, Da, Kt, Dt, (1920, 1080),
            flags=cv2.CALIB_FIX_INTRINSIC, criteria=crit)
        return rms, K, D, srms, R, T

    times, cpus = [], []
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        rms, K, D, srms, R, T = opencv_all()
        times.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    t_cv, c_cv = min(times), min(cpus)
    d_rms = abs(rms - rig["thermal_rms_px"])
    d_srms = abs(srms - rig["stereo_rms_px"])
    d_K = np.abs(K - Kt).max()
    print("OpenCV calibrateCamera (%d frames): RMS %.6f vs hearth %.6f (diff %.2e px); "
          "max |K diff| %.2e px; max |dist diff| %.2e"
          % (len(ipts), rms, rig["thermal_rms_px"], d_rms, d_K, np.abs(D.ravel() - Dt).max()))
    tR = np.array(rig["T_thermal_from_rgb"]["R"])
    tT = np.array(rig["T_thermal_from_rgb"]["t"])
    print("OpenCV stereoCalibrate (%d pairs, intrinsics fixed): RMS %.6f vs hearth %.6f "
          "(diff %.2e px); R %.2e deg, T %.2e mm apart"
          % (len(pa), srms, rig["stereo_rms_px"], d_srms, rot_angle_deg(R, tR),
             np.linalg.norm(T.ravel() - tT) * 1000))
    ok &= d_rms <= 1e-3 and d_srms <= 1e-3 and d_K <= 1e-2
    print("time: hearth detect %.3f s + calibrate %.3f s = %.3f s; OpenCV calibration alone "
          "%.3f s; ratio hearth/OpenCV %.2f (best of %d)"
          % (t_det, t_cal, t_det + t_cal, t_cv, (t_det + t_cal) / t_cv, runs))
    print("cpu: hearth detect %.3f s + calibrate %.3f s = %.3f s; OpenCV %.3f s; ratio %.2f "
          "(user + sys over all threads, best of %d)"
          % (c_det, c_cal, c_det + c_cal, c_cv, (c_det + c_cal) / c_cv, runs))
    print("one process (hearth calibrate --detect): wall %.3f s, ratio to OpenCV %.2f; "
          "cpu %.3f s, ratio %.2f"
          % (t_one, t_one / t_cv, c_one, c_one / c_cv))
    # leave the default calibration in place
    run([exe, "calibrate", root, "--quiet"])
    print("RESULT:", "PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
