#!/usr/bin/python3
"""Accuracy of a built release of the virtual rig with its object effects on,
against both truths of ground_truth/ (docs/virtual-rig.md, "Object physics"):
per instance and state, median and p95 of |observed - truth| over observed
texels seen away from grazing (best viewing cosine >= 0.5 in conditions.npy),
against the normal-incidence apparent temperature and the true surface
temperature at the start of the scan.

usage: rig_effects_eval.py ROOT LABEL [STATE ...]   (prints one row per state)
"""
import json
import os
import sys

import numpy as np


def rows(root, states):
    rel = json.load(open(os.path.join(root, "release.json")))
    for inst in rel["instances"]:
        doc = json.load(open(os.path.join(root, "instances", inst, "instance.json")))
        for st in doc["states"]:
            if states and st not in states:
                continue
            gt = os.path.join(root, "ground_truth", "instances", inst, st)
            dv = os.path.join(root, "instances", inst, "derived", st)
            obs = np.load(os.path.join(dv, "temperature_observed.npy")).astype(np.float64)
            mask = np.load(os.path.join(dv, "mask.npy"))
            app = np.load(os.path.join(gt, "temperature_apparent.npy")).astype(np.float64)
            true = np.load(os.path.join(gt, "temperature_true.npy")).astype(np.float64)
            cond = np.load(os.path.join(gt, "conditions.npy")).astype(np.float64)
            keep = (mask == 1) & np.isfinite(obs) & np.isfinite(app) & (cond[..., 0] >= 0.5)
            ea = np.abs(obs - app)[keep]
            et = np.abs(obs - true)[keep]
            yield inst, st, keep.sum(), np.median(ea), np.percentile(ea, 95), np.median(et), \
                np.percentile(et, 95)


def main():
    root, label, states = sys.argv[1], sys.argv[2], set(sys.argv[3:])
    for inst, st, n, ma, pa, mt, pt in rows(root, states):
        print(f"{label:10s} {inst:20s} {st:8s} {n:8d} {ma:8.3f} {pa:8.3f} {mt:8.3f} {pt:8.3f}")


if __name__ == "__main__":
    main()
