#!/usr/bin/python3
"""Runs openpi's own LiberoInputs / LiberoOutputs (src/openpi/policies/
libero_policy.py of an openpi checkout, unchanged) beside hearth_openpi's
HearthInputs / HearthOutputs on one observation in the form `hearth sim eval`
sends, without installing openpi: the file's imports that need JAX
(openpi.models.model, openpi.transforms) and einops are replaced by the few
names it uses (ModelType's three members, a DataTransformFn base class, the
one rearrange pattern).

  bench/openpi_libero_check.py OPENPI_CHECKOUT

Prints, per model type, whether HearthInputs(thermal=False) equals openpi's
LiberoInputs slot by slot and mask by mask, and whether HearthInputs
(thermal=True) puts the thermal view in the third slot with its mask on.
Exits 1 if either fails."""
import enum
import importlib.util
import os
import sys
import types

import numpy as np


def stand_ins():
    ein = types.ModuleType("einops")

    def rearrange(x, pattern):
        if pattern != "c h w -> h w c":
            raise ValueError(pattern)
        return np.transpose(x, (1, 2, 0))

    ein.rearrange = rearrange
    root, tr = types.ModuleType("openpi"), types.ModuleType("openpi.transforms")
    models, model = types.ModuleType("openpi.models"), types.ModuleType("openpi.models.model")
    tr.DataTransformFn = type("DataTransformFn", (), {})
    model.ModelType = enum.Enum("ModelType", {"PI0": "pi0", "PI0_FAST": "pi0_fast", "PI05": "pi05"})
    models.model, root.transforms, root.models = model, tr, models
    sys.modules.update({"einops": ein, "openpi": root, "openpi.transforms": tr,
                        "openpi.models": models, "openpi.models.model": model})
    return model.ModelType


def main(argv):
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    src = os.path.join(argv[0], "src", "openpi", "policies", "libero_policy.py")
    model_type = stand_ins()
    spec = importlib.util.spec_from_file_location("libero_policy", src)
    lp = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(lp)
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
    import hearth_openpi

    rng = np.random.default_rng(0)
    obs = {
        "observation/image": rng.integers(0, 256, (224, 224, 3), dtype=np.uint8),
        "observation/wrist_image": rng.integers(0, 256, (224, 224, 3), dtype=np.uint8),
        "observation/thermal_image": rng.integers(1, 256, (224, 224, 3), dtype=np.uint8),
        "observation/state": rng.random(8),
        "prompt": "pick up the hot cup",
    }
    bad = 0
    for mt in model_type:
        want = lp.LiberoInputs(model_type=mt)(dict(obs))
        off = hearth_openpi.HearthInputs(model_type=mt, thermal=False)(dict(obs))
        on = hearth_openpi.HearthInputs(model_type=mt, thermal=True)(dict(obs))
        same = set(off) == set(want) and all(
            np.array_equal(off["image"][k], want["image"][k]) and bool(off["image_mask"][k]) == bool(want["image_mask"][k])
            for k in want["image"]) and np.array_equal(off["state"], want["state"]) and off["prompt"] == want["prompt"]
        third = on["image"]["right_wrist_0_rgb"]
        thermal_ok = np.array_equal(third, obs["observation/thermal_image"]) and bool(on["image_mask"]["right_wrist_0_rgb"])
        actions = rng.random((10, 32))
        out_same = np.array_equal(lp.LiberoOutputs()({"actions": actions})["actions"],
                                  hearth_openpi.HearthOutputs()({"actions": actions})["actions"])
        print(f"{mt.name}: thermal=False equals openpi's LiberoInputs: {same}; thermal=True third slot "
              f"is the thermal view with mask on: {thermal_ok}; outputs equal LiberoOutputs': {out_same}")
        bad += not (same and thermal_ok and out_same)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
