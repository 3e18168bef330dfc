#!/usr/bin/python3
"""Checks a LeRobot dataset written by `hearth sim export` against the HDF5
collections it came from, reading the Parquet files through a reader's dump
(DuckDB's from tests/io/read_parquet.js, or the Arrow Rust reader's from
tests/io/read_parquet_arrow.js) and everything else with numpy, h5py and OpenCV:

  check_lerobot.py check DIR DUMP.json EVAL_DIR|- [--no-thermal] [--expect-flip] FILE.hdf5...
  check_lerobot.py synthetic OUT.hdf5

`check`: every row against its HDF5 demo (state with an axis-angle computed
here another way: OpenCV's Rodrigues matrix, its quaternion, openpi's
quat2axisangle), every PNG decoded against the HDF5 frame rotated 180 degrees
and against what `hearth sim eval` encoded for that frame (EVAL_DIR/ep<E>_f<K>_
<feature>.npy, written by test_lerobot.c), the meta files rebuilt as LeRobot's
writer (lerobot 0cf86487 with datasets 3.6, numpy) would write them and
compared as text, and norm_stats.json; a dynamic-temperature collection's
obs/thermal_state against the thermal_state column and its names; the axis-angle must not jump between frames (with
--expect-flip some demo's ee_ori must, so that check is not idle). Exits 1
listing what differs.

`synthetic`: a small collection in hearth's layout (320-pixel images, so the
statistics downsample; demo lengths 120 and 5; an orientation crossing half a
turn about x; an instruction with quotes and non-ASCII letters)."""
import base64
import json
import math
import os
import sys

import cv2
import h5py
import numpy as np

FAILS = []


def check(cond, msg):
    if not cond:
        FAILS.append(msg)
    return cond


# ---- LeRobot's statistics (compute_stats.py of lerobot 0cf86487), in numpy ----
def num_samples(n, lo=100, hi=10_000, power=0.75):
    lo = min(lo, n)
    return max(lo, min(int(n**power), hi))


def sample_indices(n):
    return np.round(np.linspace(0, n - 1, num_samples(n))).astype(int).tolist()


def downsample(chw, target=150, threshold=300):
    _, h, w = chw.shape
    if max(w, h) < threshold:
        return chw
    f = int(w / target) if w > h else int(h / target)
    return chw[:, ::f, ::f]


def feature_stats(a, axis, keepdims):
    return {"min": np.min(a, axis=axis, keepdims=keepdims), "max": np.max(a, axis=axis, keepdims=keepdims),
            "mean": np.mean(a, axis=axis, keepdims=keepdims), "std": np.std(a, axis=axis, keepdims=keepdims),
            "count": np.array([len(a)])}


def episode_stats(columns, features):
    """columns: feature -> np.ndarray (T, ...) or, for images, a list of HWC uint8 frames"""
    out = {}
    for key, ft in features.items():
        data = columns[key]
        if ft["dtype"] == "image":
            picked = [downsample(np.transpose(data[i], (2, 0, 1))) for i in sample_indices(len(data))]
            arr = np.empty((len(picked), *picked[0].shape), dtype=np.uint8)
            for i, p in enumerate(picked):
                arr[i] = p
            st = feature_stats(arr, (0, 2, 3), True)
            out[key] = {k: v if k == "count" else np.squeeze(v / 255.0, axis=0) for k, v in st.items()}
        else:
            out[key] = feature_stats(data, 0, data.ndim == 1)
    return out


def tolist(stats):
    return {k: {s: v.tolist() for s, v in st.items()} for k, st in stats.items()}


# ---- the state's orientation, computed another way ----
def axis_angle(rotvec):
    """continuous axis-angle: quaternion of the rotation (from its matrix) in the
    hemisphere of (w x y z) = (0 1 0 0), then openpi's _quat2axisangle"""
    R, _ = cv2.Rodrigues(np.asarray(rotvec, dtype=np.float64).reshape(3, 1))
    t = np.trace(R)
    cands = [
        np.array([1 + t, R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]),
        np.array([R[2, 1] - R[1, 2], 1 + R[0, 0] - R[1, 1] - R[2, 2], R[0, 1] + R[1, 0], R[0, 2] + R[2, 0]]),
        np.array([R[0, 2] - R[2, 0], R[0, 1] + R[1, 0], 1 - R[0, 0] + R[1, 1] - R[2, 2], R[1, 2] + R[2, 1]]),
        np.array([R[1, 0] - R[0, 1], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1], 1 - R[0, 0] - R[1, 1] + R[2, 2]]),
    ]
    q = max(cands, key=np.linalg.norm)  # the best conditioned of the four
    q = q / np.linalg.norm(q)
    if q[1] < 0:
        q = -q
    xyzw = np.array([q[1], q[2], q[3], q[0]])
    w = min(1.0, max(-1.0, xyzw[3]))
    den = np.sqrt(1.0 - w * w)
    if math.isclose(den, 0.0):
        return np.zeros(3)
    return (xyzw[:3] * 2.0 * math.acos(w)) / den


# ---- reading ----
def value(v):
    if isinstance(v, str) and v in ("NaN", "Infinity", "-Infinity", "-0"):
        return float(v.replace("Infinity", "inf"))
    return v


def png(cell):
    buf = np.frombuffer(base64.b64decode(cell["bytes"]["base64"]), dtype=np.uint8)
    img = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
    return None if img is None else img[:, :, ::-1]


def attr_text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def load_demos(paths, thermal):
    demos = []
    for si, path in enumerate(paths):
        with h5py.File(path, "r") as f:
            data = f["data"]
            env = json.loads(attr_text(data.attrs["env_args"]))
            for k in range(int(data.attrs["num_demos"])):
                g = data[f"demo_{k}"]
                d = {"source": si, "demo": k, "file": os.path.basename(path), "task": env["env_name"][len("hearth_"):],
                     "seed": env["env_kwargs"]["seed"], "fps": env["env_kwargs"]["control_freq"],
                     "env": env["env_kwargs"], "layout": int(g.attrs["layout"]),
                     "instruction_index": int(g.attrs["instruction_index"]),
                     "instruction": attr_text(g.attrs["language_instruction"]),
                     "actions": g["actions"][()], "ee_pos": g["obs/ee_pos"][()], "ee_ori": g["obs/ee_ori"][()],
                     "gripper": g["obs/gripper_states"][()], "image": g["obs/agentview_rgb"][()],
                     "wrist_image": g["obs/eye_in_hand_rgb"][()]}
                if thermal:
                    d["thermal_image"] = g["obs/agentview_thermal"][()]
                    if "thermal_state" in g["obs"]:
                        ts = g["obs/thermal_state"]
                        d["thermal_state"] = ts[()]
                        d["thermal_names"] = attr_text(ts.attrs["region_names"]).split(";")
                demos.append(d)
    return demos


def expected_features(thermal, size, thermal_names=None):
    img = {"dtype": "image", "shape": [size, size, 3], "names": ["height", "width", "channel"]}
    fs = {"image": dict(img), "wrist_image": dict(img)}
    if thermal:
        fs["thermal_image"] = dict(img)
    fs["state"] = {"dtype": "float32", "shape": [8], "names": ["state"]}
    fs["actions"] = {"dtype": "float32", "shape": [7], "names": ["actions"]}
    if thermal and thermal_names:
        fs["thermal_state"] = {"dtype": "float32", "shape": [len(thermal_names)], "names": thermal_names}
    for k, dt in (("timestamp", "float32"), ("frame_index", "int64"), ("episode_index", "int64"),
                  ("index", "int64"), ("task_index", "int64")):
        fs[k] = {"dtype": dt, "shape": [1], "names": None}
    return fs


def hf_features(features):
    """datasets 3.6 Features.to_dict() of lerobot's get_hf_features_from_features"""
    out = {}
    for k, ft in features.items():
        if ft["dtype"] == "image":
            out[k] = {"_type": "Image"}
        elif ft["shape"] == [1]:
            out[k] = {"dtype": ft["dtype"], "_type": "Value"}
        else:
            out[k] = {"feature": {"dtype": ft["dtype"], "_type": "Value"}, "length": ft["shape"][0], "_type": "Sequence"}
    return out


def read_text(root, rel):
    with open(os.path.join(root, rel), encoding="utf-8") as f:
        return f.read()


def check_dataset(root, dump_path, eval_dir, thermal, expect_flip, paths):
    demos = load_demos(paths, thermal)
    with open(dump_path) as f:
        dump = {os.path.relpath(d["file"], root): d for d in json.load(f)}
    size = demos[0]["image"].shape[1]
    fps = demos[0]["fps"]
    names = demos[0].get("thermal_names")
    check(all(d.get("thermal_names") == names for d in demos), "demos with different thermal_state columns")
    features = expected_features(thermal, size, names)
    image_keys = [k for k, ft in features.items() if ft["dtype"] == "image"]

    # tasks in order of first appearance, as LeRobotDatasetMetadata.add_task
    tasks = []
    for d in demos:
        if d["instruction"] not in tasks:
            tasks.append(d["instruction"])
    want_tasks = "".join(json.dumps({"task_index": i, "task": t}, ensure_ascii=False) + "\n" for i, t in enumerate(tasks))
    check(read_text(root, "meta/tasks.jsonl") == want_tasks, "meta/tasks.jsonl differs from LeRobot's")

    info_text = read_text(root, "meta/info.json")
    info = json.loads(info_text)
    total = sum(len(d["actions"]) for d in demos)
    want_info = {"codebase_version": "v2.1", "robot_type": "panda", "total_episodes": len(demos),
                 "total_frames": total, "total_tasks": len(tasks), "total_videos": 0,
                 "total_chunks": (len(demos) + 999) // 1000, "chunks_size": 1000, "fps": fps,
                 "splits": {"train": f"0:{len(demos)}"},
                 "data_path": "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet",
                 "video_path": "videos/chunk-{episode_chunk:03d}/{video_key}/episode_{episode_index:06d}.mp4",
                 "features": features, "hearth": info.get("hearth")}
    check(info_text == json.dumps(want_info, indent=4, ensure_ascii=False),
          "meta/info.json differs from what LeRobot writes (json.dump indent=4)")
    srcs = (info.get("hearth") or {}).get("sources", [])
    check(len(srcs) == len(paths), "info.json hearth.sources: one per input")
    first = 0
    for si, s in enumerate(srcs):
        n = sum(1 for d in demos if d["source"] == si)
        check(s.get("file") == os.path.basename(paths[si]) and s.get("episodes") == f"{first}:{first + n}"
              and s.get("task") == demos[first]["task"] and s.get("seed") == demos[first]["seed"],
              f"info.json hearth.sources[{si}] = {s}")
        first += n

    ep_lines = read_text(root, "meta/episodes.jsonl").splitlines(True)
    st_lines = read_text(root, "meta/episodes_stats.jsonl").splitlines(True)
    check(len(ep_lines) == len(demos) and len(st_lines) == len(demos), "one meta line per episode")
    hf_meta = json.dumps({"info": {"features": hf_features(features)}})
    index = 0
    all_state, all_actions = [], []
    raw_jump, max_step = 0.0, 0.0
    evals = 0
    for e, d in enumerate(demos):
        T = len(d["actions"])
        rel = f"data/chunk-{e // 1000:03d}/episode_{e:06d}.parquet"
        if not check(rel in dump, f"{rel}: missing"):
            continue
        pq = dump[rel]
        rows = pq["rows"]
        check(len(rows) == T, f"{rel}: {len(rows)} rows, the demo has {T}")
        check(pq["kv"].get("huggingface") == hf_meta, f"{rel}: 'huggingface' metadata differs from datasets'")
        check([c["name"] for c in pq["columns"]] == list(features), f"{rel}: columns {pq['columns']}")
        check(pq["meta"]["num_row_groups"] == (T + 99) // 100, f"{rel}: row groups of 100 rows expected")
        types = {c["name"]: c["type"] for c in pq["columns"]}
        # the types each reader gives the columns LeRobot's writer (pyarrow via datasets) makes
        image_t, list_t, float_t, int_t = {
            "duckdb": ('STRUCT("bytes" BLOB, "path" VARCHAR)', "FLOAT[]", "FLOAT", "BIGINT"),
            "arrow": ("Struct<{bytes:Binary, path:Utf8}>", "List<Float32>", "Float32", "Int64"),
        }[pq.get("reader", "duckdb")]
        for k in image_keys:
            check(types[k] == image_t, f"{rel}: {k} is {types[k]}")
        check(types["state"] == list_t and types["actions"] == list_t and types["timestamp"] == float_t
              and (names is None or types["thermal_state"] == list_t)
              and all(types[k] == int_t for k in ("frame_index", "episode_index", "index", "task_index")),
              f"{rel}: column types {types}")
        task = tasks.index(d["instruction"])
        state = np.zeros((T, 8), np.float32)
        actions = np.zeros((T, 7), np.float32)
        th = np.zeros((T, len(names)), np.float32) if names else None
        images = {k: [] for k in image_keys}
        for i, r in enumerate(rows[:T]):
            ok = (r["frame_index"] == i and r["episode_index"] == e and r["index"] == index + i and
                  r["task_index"] == task and np.float32(r["timestamp"]) == np.float32(i / fps))
            check(ok, f"{rel} row {i}: indices or timestamp wrong: {[r[k] for k in ('frame_index', 'episode_index', 'index', 'task_index', 'timestamp')]}")
            state[i] = [value(v) for v in r["state"]]
            actions[i] = [value(v) for v in r["actions"]]
            if names:
                th[i] = [value(v) for v in r["thermal_state"]]
            for k in image_keys:
                check(r[k]["path"] == f"frame_{i:06d}.png", f"{rel} row {i}: {k}.path = {r[k]['path']}")
                img = png(r[k])
                if not check(img is not None and img.shape == (size, size, 3), f"{rel} row {i}: {k} is no {size}x{size} RGB PNG"):
                    img = np.zeros((size, size, 3), np.uint8)
                images[k].append(img)
                check(np.array_equal(img, d[k][i][::-1, ::-1]), f"{rel} row {i}: {k} != the HDF5 frame rotated 180 degrees")
                ev = os.path.join(eval_dir, f"ep{e}_f{i}_{k}.npy") if eval_dir != "-" else ""
                if ev and os.path.exists(ev):
                    evals += 1
                    check(np.array_equal(np.load(ev), img), f"{rel} row {i}: {k} != what sim eval sends for that frame")
        check(np.array_equal(actions, d["actions"].astype(np.float32)), f"{rel}: actions != the HDF5's")
        if names:
            check(d["thermal_state"].dtype == np.float32 and np.array_equal(th, d["thermal_state"]),
                  f"{rel}: thermal_state != the HDF5's obs/thermal_state")
        check(np.array_equal(state[:, :3], d["ee_pos"].astype(np.float32)), f"{rel}: state[0:3] != ee_pos")
        check(np.array_equal(state[:, 6:], d["gripper"].astype(np.float32)), f"{rel}: state[6:8] != gripper_states")
        aa = np.array([axis_angle(r) for r in d["ee_ori"]])
        err = np.abs(state[:, 3:6].astype(np.float64) - aa).max()
        check(err < 2e-6, f"{rel}: state[3:6] differs from the continuous axis-angle by {err}")
        if T > 1:
            raw_jump = max(raw_jump, np.abs(np.diff(d["ee_ori"], axis=0)).max())
            max_step = max(max_step, np.abs(np.diff(state[:, 3:6], axis=0)).max())
        # episode lines as LeRobot writes them (plus the hearth mapping)
        ep = {"episode_index": e, "tasks": [d["instruction"]], "length": T,
              "hearth": {"source": d["source"], "demo": d["demo"], "task": d["task"], "seed": d["seed"],
                         "layout": d["layout"], "instruction_index": d["instruction_index"]}}
        check(e < len(ep_lines) and ep_lines[e] == json.dumps(ep, ensure_ascii=False) + "\n",
              f"meta/episodes.jsonl line {e} differs")
        cols = {"state": state, "actions": actions, "timestamp": np.stack([i / fps for i in range(T)]),
                "frame_index": np.stack(list(range(T))), "episode_index": np.full((T,), e),
                "index": np.arange(index, index + T), "task_index": np.array([task] * T)}
        if names:
            cols["thermal_state"] = th
        cols.update(images)
        want = json.dumps({"episode_index": e, "stats": tolist(episode_stats(cols, features))}, ensure_ascii=False)
        if e < len(st_lines) and st_lines[e] != want + "\n":
            got = json.loads(st_lines[e])["stats"]
            exp = json.loads(want)["stats"]
            diff = [f"{k}.{s}" for k in exp for s in exp[k] if got.get(k, {}).get(s) != exp[k][s]]
            check(False, f"meta/episodes_stats.jsonl line {e} differs from LeRobot's: {diff}")
        all_state.append(state)
        all_actions.append(actions)
        index += T
    check(max_step < 0.5, f"state's axis-angle jumps by {max_step} between frames")
    if expect_flip:
        check(raw_jump > 6, f"no demo's ee_ori flips sign (largest step {raw_jump}): the continuity check is idle")
    if eval_dir != "-":
        check(evals > 0, "no sim eval frame to compare")

    ns = json.loads(read_text(root, "norm_stats.json"))["norm_stats"]
    for key, arr in (("state", np.concatenate(all_state)), ("actions", np.concatenate(all_actions))):
        a = arr.astype(np.float64)
        n = len(a)
        got = ns.get(key, {})
        s = np.sort(a, axis=0)
        want = {"mean": a.mean(axis=0), "std": a.std(axis=0),
                "q01": s[max(0, math.ceil(0.01 * n) - 1)], "q99": s[max(0, math.ceil(0.99 * n) - 1)]}
        for stat, v in want.items():
            g = np.array(got.get(stat, []), dtype=np.float64)
            check(g.shape == v.shape and np.allclose(g, v, rtol=1e-12, atol=1e-12),
                  f"norm_stats.json {key}.{stat}: {g} != {v}")
    return raw_jump


def synthetic(path):
    rng = np.random.default_rng(5)
    size = 320
    with h5py.File(path, "w") as f:
        data = f.create_group("data")
        env = {"env_name": "hearth_H2", "type": 1,
               "env_kwargs": {"control_freq": 20, "camera_heights": size, "camera_widths": size,
                              "controller": "OSC_POSE", "seed": 7, "asset_source": "synthetic", "shadows": False,
                              "renderer": "none"}}
        data.attrs["env_args"] = np.bytes_(json.dumps(env))
        data.attrs["image_row_order"] = np.bytes_("opengl_bottom_row_first")
        data.attrs["num_demos"] = np.int64(2)
        instructions = ["pick up the iced can and place it on the mat",
                        'pick up the "n\u00f6rmal" can \u2014 and place it on the mat\\']
        yy, xx = np.mgrid[0:size, 0:size]
        for k, T in enumerate((120, 5)):
            g = data.create_group(f"demo_{k}")
            g.attrs["num_samples"] = np.int64(T)
            g.attrs["layout"] = np.int64(40 + k)
            g.attrs["instruction_index"] = np.int64(k)
            g.attrs["language_instruction"] = instructions[k]  # a variable-length string
            ang = np.linspace(3.0, 3.3, T)  # about x, through half a turn
            ori = np.array([cv2.Rodrigues(cv2.Rodrigues(np.array([[a], [0.02], [0.01]]))[0])[0].ravel() for a in ang])
            g["actions"] = rng.uniform(-1, 1, (T, 7))
            obs = g.create_group("obs")
            obs["ee_pos"] = rng.uniform(-0.3, 1.2, (T, 3))
            obs["ee_ori"] = ori
            obs["gripper_states"] = rng.uniform(-0.04, 0.04, (T, 2))
            for v, name in enumerate(("agentview_rgb", "eye_in_hand_rgb", "agentview_thermal")):
                frames = np.empty((T, size, size, 3), np.uint8)
                for i in range(T):
                    base = (xx * (v + 1) + yy * 2 + i * 3) % 256
                    frames[i] = np.stack([base, (base + 85) % 256, 255 - base], -1).astype(np.uint8)
                    frames[i] ^= rng.integers(0, 4, (size, size, 3), dtype=np.uint8)
                obs[name] = frames


def main(argv):
    if len(argv) >= 2 and argv[0] == "synthetic":
        synthetic(argv[1])
        return 0
    flags = [a for a in argv[4:] if a.startswith("--")]
    files = [a for a in argv[4:] if not a.startswith("--")]
    if len(argv) < 5 or argv[0] != "check" or not files or set(flags) - {"--no-thermal", "--expect-flip"}:
        print(__doc__, file=sys.stderr)
        return 2
    jump = check_dataset(argv[1], argv[2], argv[3], "--no-thermal" not in flags, "--expect-flip" in flags, files)
    for m in FAILS[:40]:
        print("FAIL:", m, file=sys.stderr)
    if len(FAILS) > 40:
        print(f"... and {len(FAILS) - 40} more", file=sys.stderr)
    print(f"check_lerobot: {len(FAILS)} failures (largest ee_ori step between frames: {jump:.3f} rad)")
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
