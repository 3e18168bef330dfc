"""Open collected hearth sim files with h5py and check LIBERO's keys, shapes
and attributes (plus obs/agentview_thermal). Usage: sim_check_hdf5.py FILE..."""
import json
import sys

import h5py

OBS = {"agentview_rgb": 4, "agentview_thermal": 4, "eye_in_hand_rgb": 4, "joint_states": 2,
       "gripper_states": 2, "ee_states": 2, "ee_pos": 2, "ee_ori": 2}
WIDTH = {"joint_states": 7, "gripper_states": 2, "ee_states": 6, "ee_pos": 3, "ee_ori": 3}


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


for path in sys.argv[1:]:
    with h5py.File(path, "r") as f:
        d = f["data"]
        info = json.loads(text(d.attrs["problem_info"]))
        # LIBERO reads one instruction string here
        assert isinstance(info["language_instruction"], str), path
        instructions = json.loads(text(d.attrs["instructions"]))
        assert info["language_instruction"] == instructions[0], path
        json.loads(text(d.attrs["env_args"]))
        n = int(d.attrs["num_demos"])
        demos = sorted(k for k in d if k.startswith("demo_"))
        assert demos == sorted("demo_%d" % k for k in range(n)), (path, demos)
        total, per = 0, {}
        size = None
        for k in range(n):
            g = d["demo_%d" % k]
            T = int(g.attrs["num_samples"])
            total += T
            assert g["actions"].shape == (T, 7), (path, k)
            assert abs(g["actions"][()]).max() <= 1.0, (path, k)
            assert g["rewards"].shape == (T,) and g["dones"].shape == (T,)
            assert g["dones"][-1] == 1 and g["rewards"][-1] == 1
            assert g["states"].shape[0] == T
            for key, rank in OBS.items():
                a = g["obs"][key]
                assert a.ndim == rank and a.shape[0] == T, (path, key)
                if rank == 4:
                    assert a.dtype == "uint8" and a.shape[3] == 3, (path, key)
                    size = size or a.shape[1:3]
                    assert a.shape[1:3] == size, (path, key)
                else:
                    assert a.shape[1] == WIDTH[key], (path, key)
            ins = text(g.attrs["language_instruction"])
            assert ins in instructions, (path, ins)
            per[ins] = per.get(ins, 0) + 1
        assert total == int(d.attrs["total"]), path
        print("%s: %d demos, %d samples, images %s, row order %s, per instruction %s" % (
            path, n, total, tuple(size) if size else None, text(d.attrs["image_row_order"]),
            per))
