#!/usr/bin/python3
"""Open `hearth sim collect` files with h5py (Debian python3-h5py) and check
every key LIBERO's and robomimic's loaders read, with its type: string
attributes must come back as str (variable-length UTF-8), not bytes; JSON
attributes must parse; per-demo datasets must have the documented shapes;
image datasets one frame per deflate chunk, each chunk a zlib stream that
Python's zlib inflates to the frame.

usage: check_libero_keys.py FILE [--instructions N] [--size S]
  --instructions N: instructions the file holds (2, or 1 for a split file)
  --size S: the image side
"""
import argparse
import json
import sys
import zlib

import h5py
import numpy as np

DATA_STR = ["env_name", "problem_info", "env_args", "bddl_file_name", "bddl_file_content",
            "macros_image_convention", "instructions", "image_row_order", "thermal_colormap"]
DATA_INT = ["num_demos", "total"]
DEMO_STR = ["language_instruction", "model_file"]
DEMO_INT = ["num_samples", "layout", "instruction_index"]
# dataset -> (dtype kind, width or None for images)
DEMO_DS = {"actions": ("f", 7), "states": ("f", 71), "robot_states": ("f", 9), "rewards": ("u", None),
           "dones": ("u", None)}
OBS_DS = {"agentview_rgb": 4, "agentview_thermal": 4, "eye_in_hand_rgb": 4, "joint_states": 7,
          "gripper_states": 2, "ee_states": 6, "ee_pos": 3, "ee_ori": 3}


def fail(msg):
    print("check_libero_keys: " + msg, file=sys.stderr)
    sys.exit(1)


def want_str(obj, key, where):
    if key not in obj.attrs:
        fail("%s: no attribute %s" % (where, key))
    v = obj.attrs[key]
    if not isinstance(v, str):
        fail("%s@%s: h5py returns %s, expected str" % (where, key, type(v).__name__))
    return v


def want_int(obj, key, where):
    if key not in obj.attrs:
        fail("%s: no attribute %s" % (where, key))
    v = obj.attrs[key]
    if not isinstance(v, (int, np.integer)):
        fail("%s@%s: %s, expected an integer" % (where, key, type(v).__name__))
    return int(v)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("file")
    ap.add_argument("--instructions", type=int, default=2)
    ap.add_argument("--size", type=int, default=0)
    a = ap.parse_args()
    with h5py.File(a.file, "r") as f:
        d = f["data"]
        s = {k: want_str(d, k, "data") for k in DATA_STR}
        n = {k: want_int(d, k, "data") for k in DATA_INT}
        info = json.loads(s["problem_info"])
        env_args = json.loads(s["env_args"])
        instructions = json.loads(s["instructions"])
        if not isinstance(info.get("language_instruction"), str) or info["language_instruction"] != instructions[0]:
            fail("problem_info.language_instruction %r is not instructions[0]" % (info,))
        if len(instructions) != a.instructions:
            fail("instructions %r: expected %d" % (instructions, a.instructions))
        for k in ("env_name", "type", "env_kwargs", "problem_name", "bddl_file"):
            if k not in env_args:
                fail("env_args has no %s" % k)
        if env_args["env_name"] != s["env_name"] or env_args["bddl_file"] != s["bddl_file_name"]:
            fail("env_args disagrees with env_name / bddl_file_name")
        if s["macros_image_convention"] != "opengl":
            fail("macros_image_convention %r" % s["macros_image_convention"])
        bddl = s["bddl_file_content"]
        for needle in ("(define (problem", "(:language " + instructions[0] + ")", "(:regions", "(:objects",
                       "(:init", "(:goal"):
            if needle not in bddl:
                fail("bddl_file_content lacks %r" % needle)
        demos = sorted(k for k in d if k.startswith("demo_"))
        if demos != sorted("demo_%d" % k for k in range(n["num_demos"])):
            fail("demos %r for num_demos %d" % (demos, n["num_demos"]))
        total = 0
        for k in range(n["num_demos"]):
            where = "data/demo_%d" % k
            g = d["demo_%d" % k]
            ds = {key: want_str(g, key, where) for key in DEMO_STR}
            di = {key: want_int(g, key, where) for key in DEMO_INT}
            T = di["num_samples"]
            total += T
            if ds["language_instruction"] not in instructions:
                fail("%s: instruction %r not in %r" % (where, ds["language_instruction"], instructions))
            if not ds["model_file"].startswith("<mujoco"):
                fail("%s@model_file is not MJCF" % where)
            init = g.attrs.get("init_state")
            if not isinstance(init, np.ndarray) or init.dtype != np.float64 or init.shape != (71,):
                fail("%s@init_state: expected float64 (71,), got %r" % (where, init))
            for key, (kind, width) in DEMO_DS.items():
                x = g[key]
                shape = (T, width) if width else (T,)
                if x.dtype.kind != kind or x.shape != shape:
                    fail("%s/%s: %s %r, expected kind %s shape %r" % (where, key, x.dtype, x.shape, kind, shape))
            if not np.array_equal(init, g["states"][0]):
                fail("%s: init_state is not states[0]" % where)
            rs = g["robot_states"][()]
            if not np.array_equal(rs[:, 0:2], g["obs/gripper_states"][()]) or \
               not np.array_equal(rs[:, 2:5], g["obs/ee_pos"][()]):
                fail("%s/robot_states: not [gripper_states, ee_pos, ee_quat]" % where)
            q = rs[:, 5:9]  # x y z w, robosuite's order
            if np.abs(np.linalg.norm(q, axis=1) - 1).max() > 1e-6:
                fail("%s/robot_states: the quaternion is not unit" % where)
            # the same rotation as obs/ee_ori (a rotation vector)
            q = q * np.where(q[:, 3:4] < 0, -1.0, 1.0)
            s_ = np.linalg.norm(q[:, :3], axis=1, keepdims=True)
            ang = 2 * np.arctan2(s_, q[:, 3:4])
            rv = np.where(s_ > 1e-12, q[:, :3] / np.maximum(s_, 1e-300) * ang, 2 * q[:, :3])
            if np.abs(rv - g["obs/ee_ori"][()]).max() > 1e-6:
                fail("%s/robot_states: its quaternion (x y z w) differs from obs/ee_ori" % where)
            for key, width in OBS_DS.items():
                x = g["obs"][key]
                if key.endswith("_rgb") or key.endswith("_thermal"):
                    S = a.size or x.shape[1]
                    if x.dtype != np.uint8 or x.shape != (T, S, S, 3):
                        fail("%s/obs/%s: %s %r" % (where, key, x.dtype, x.shape))
                    # one frame per chunk through the standard deflate
                    # filter: each stored chunk, inflated by Python's zlib,
                    # is its frame's pixels
                    if x.chunks != (1, S, S, 3) or x.compression != "gzip":
                        fail("%s/obs/%s: chunks %r, filter %r; expected (1, %d, %d, 3) gzip"
                             % (where, key, x.chunks, x.compression, S, S))
                    frames = x[()]
                    for t in range(T):
                        mask, raw = x.id.read_direct_chunk((t, 0, 0, 0))
                        if mask != 0 or zlib.decompress(raw) != frames[t].tobytes():
                            fail("%s/obs/%s: chunk %d is not its frame as a zlib stream" % (where, key, t))
                elif x.dtype != np.float64 or x.shape != (T, width):
                    fail("%s/obs/%s: %s %r, expected float64 (%d, %d)" % (where, key, x.dtype, x.shape, T, width))
        if total != n["total"]:
            fail("total %d, demos sum to %d" % (n["total"], total))
        print("%s: %d demos, %d samples, every LIBERO key present, strings are str" % (a.file, n["num_demos"], total))


main()
