"""OpenCV's side of the thermal-only calibration test (run by
tests/calib/test_thermal_only.c with /usr/bin/python3).

  thermal_only_cv.py POINTS YAML UNDIST FX FY CX CY

POINTS: "m n rational", n plate points (x y), then m * n detected centres
(u v). cv2.calibrateCamera on them with the model's flags must reach the
focal length and principal point hearth's own solve of the same points
reached (FX FY CX CY). YAML: hearth's rig_opencv.yaml, read with
cv2.FileStorage; cv2.undistortPointsIter with its camera_matrix and
distortion_coefficients must agree with hearth's undistortion in UNDIST
(lines "u v x y") wherever OpenCV's iteration converged.
Exit 0 on agreement, 1 otherwise."""
import sys

import cv2
import numpy as np


def main():
    pts_path, yaml_path, und_path = sys.argv[1:4]
    fx, fy, cx, cy = (float(a) for a in sys.argv[4:8])
    with open(pts_path) as f:
        m, n, rational = (int(t) for t in f.readline().split())
        rows = np.loadtxt(f)
    obj = np.zeros((n, 3), np.float32)
    obj[:, :2] = rows[:n]
    img = rows[n:].reshape(m, n, 2).astype(np.float32)
    flags = cv2.CALIB_RATIONAL_MODEL if rational else 0
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 2000, 1e-15)
    rms, K, D, _, _ = cv2.calibrateCamera([obj] * m, list(img), (256, 192), None, None,
                                          flags=flags, criteria=crit)
    ok = True
    got = (K[0, 0], K[1, 1], K[0, 2], K[1, 2])
    want = (fx, fy, cx, cy)
    print("opencv: rms %.5f px, fx fy cx cy %s; hearth %s; dist %s" %
          (rms, " ".join("%.4f" % g for g in got), " ".join("%.4f" % w for w in want),
           np.array2string(D.ravel(), precision=5)))
    tol = 0.05 if rational else 0.01
    for name, g, w in zip(("fx", "fy", "cx", "cy"), got, want):
        if abs(g - w) > tol:
            print("opencv and hearth differ in %s: %.6f vs %.6f (tolerance %g px)" % (name, g, w, tol))
            ok = False
    if D.size != (8 if rational else 5) and not (rational and D.size >= 8):
        print("opencv returned %d coefficients" % D.size)
        ok = False

    fs = cv2.FileStorage(yaml_path, cv2.FILE_STORAGE_READ)
    Ky = fs.getNode("camera_matrix").mat()
    Dy = fs.getNode("distortion_coefficients").mat()
    w = int(fs.getNode("image_width").real())
    h = int(fs.getNode("image_height").real())
    model = fs.getNode("lens_model").string()
    fs.release()
    if Ky is None or Dy is None or Ky.shape != (3, 3) or Dy.shape not in ((1, 5), (1, 8)):
        print("%s: camera_matrix / distortion_coefficients unreadable" % yaml_path)
        return 1
    if (Dy.shape[1] == 8) != (model == "rational8") or (w, h) != (256, 192):
        print("%s: lens_model %s with %d coefficients, %dx%d" % (yaml_path, model, Dy.shape[1], w, h))
        ok = False
    und = np.loadtxt(und_path)
    uv = und[:, :2].reshape(-1, 1, 2).astype(np.float64)
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 500, 1e-15)
    xy = cv2.undistortPointsIter(uv, Ky, Dy, None, None, crit).reshape(-1, 2)
    # where OpenCV's fixed-point iteration converged: its point reprojects
    # onto the pixel
    pts3 = np.hstack([xy, np.ones((len(xy), 1))])
    back, _ = cv2.projectPoints(pts3, np.zeros(3), np.zeros(3), Ky, Dy)
    conv = np.linalg.norm(back.reshape(-1, 2) - und[:, :2], axis=1) < 1e-6
    diff = np.abs(xy - und[:, 2:4]).max(axis=1)
    worst = diff[conv].max() if conv.any() else np.inf
    print("undistortPointsIter: %d of %d pixels converged, worst difference from hearth %.3g "
          "(normalised)" % (conv.sum(), len(conv), worst))
    if conv.sum() < 0.8 * len(conv) or not worst < 1e-7:
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
