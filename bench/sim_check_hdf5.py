"""Open collected hearth sim files with h5py and check LIBERO's keys, shapes
and attributes (plus obs/agentview_thermal)."""
import json
import sys

import h5py

OBS = {"agentview_rgb": 4, "agentview_thermal": 4, "eye_in_hand_rgb": 4, "joint_states": 2,
       "gripper_states": 2, "ee_states": 2, "ee_pos": 2, "ee_ori": 2}

for path in sys.argv[1:]:
    with h5py.File(path, "r") as f:
        d = f["data"]
        info = json.loads(d.attrs["problem_info"])
        json.loads(d.attrs["env_args"])
        n = int(d.attrs["num_demos"])
        assert n == len([k for k in d if k.startswith("demo_")]), path
        for k in range(n):
            g = d["demo_%d" % k]
            T = int(g.attrs["num_samples"])
            assert g["actions"].shape == (T, 7)
            assert g["rewards"].shape == (T,) and g["dones"].shape == (T,)
            assert g["states"].shape[0] == T
            for key, rank in OBS.items():
                assert g["obs"][key].ndim == rank and g["obs"][key].shape[0] == T, (path, key)
            assert g.attrs["language_instruction"].decode() in info["language_instruction"]
        print("%s: %d demos, %d samples, instructions %s, row order %s" % (
            path, n, int(d.attrs["total"]), info["language_instruction"],
            d.attrs["image_row_order"].decode()))
