#!/usr/bin/python3
"""Plots the mug curve of docs/simulation.md ("The mug curve"): the coupled
simulator's cup against the published cooling measurements, from the CSV
that tests/sim/test_sim_thermal_mug.c writes (source, minute, model,
published), as a PNG drawn with OpenCV:

  build/sim_test_sim_thermal_mug OUT.csv
  /usr/bin/python3 bench/mug_curve.py OUT.csv OUT.png

Lines: the model's liquid temperature each minute; dots: the published
points; bars: the test's +-2 degC."""
import csv
import sys

import cv2
import numpy as np

COLOURS = {"wagon": ((200, 60, 0), "Portmann & Wagon 2005, minutes 10..20 of the record"),
           "stratigrafia": ((0, 120, 220), "stratigrafia.org 2012, ceramic mug (0 and 13 min)")}


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    with open(argv[0]) as f:
        rows = list(csv.DictReader(f))
    w, h, left, right, top, bottom = 900, 580, 80, 30, 40, 90
    img = np.full((h, w, 3), 255, np.uint8)
    t_max, lo, hi = 13, 62, 84

    def px(t, v):
        return (int(left + t / t_max * (w - left - right)), int(top + (hi - v) / (hi - lo) * (h - top - bottom)))

    font, ink = cv2.FONT_HERSHEY_SIMPLEX, (0, 0, 0)
    for v in range(lo, hi + 1, 2):
        cv2.line(img, px(0, v), px(t_max, v), (230, 230, 230), 1)
        cv2.putText(img, str(v), (left - 35, px(0, v)[1] + 5), font, 0.45, ink, 1, cv2.LINE_AA)
    for t in range(t_max + 1):
        cv2.putText(img, str(t), (px(t, lo)[0] - 6, h - bottom + 20), font, 0.45, ink, 1, cv2.LINE_AA)
    cv2.rectangle(img, px(0, hi), px(t_max, lo), ink, 1)
    cv2.putText(img, "liquid, degC", (left, top - 12), font, 0.5, ink, 1, cv2.LINE_AA)
    cv2.putText(img, "minutes left alone", (w // 2 - 80, h - bottom + 45), font, 0.55, ink, 1, cv2.LINE_AA)
    cv2.putText(img, "lines: coupled simulator (H1's cup on the table, dt 3 s); dots: published; bars: +-2 degC",
                (left, h - 15), font, 0.45, ink, 1, cv2.LINE_AA)
    for k, (source, (colour, label)) in enumerate(COLOURS.items()):
        pts = [(float(r["minute"]), float(r["model"])) for r in rows if r["source"] == source]
        for a, b in zip(pts, pts[1:]):
            cv2.line(img, px(*a), px(*b), colour, 2, cv2.LINE_AA)
        for r in rows:
            if r["source"] == source and r["published"]:
                t, v = float(r["minute"]), float(r["published"])
                cv2.circle(img, px(t, v), 5, colour, -1, cv2.LINE_AA)
                cv2.line(img, px(t, v - 2), px(t, v + 2), colour, 1, cv2.LINE_AA)
        cv2.putText(img, label, (left + 300, top + 25 + 25 * k), font, 0.5, colour, 1, cv2.LINE_AA)
    return 0 if cv2.imwrite(argv[1], img) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
