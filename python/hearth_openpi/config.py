"""openpi training configs for hearth's tasks, with the paper's settings.

Two conditions, trained and evaluated alike except for the third image:

  pi05_hearth_thermal  front RGB, wrist RGB and the front thermal view
  pi05_hearth_rgb      front RGB and wrist RGB; the third slot zeros, masked

Both start from openpi's released pi0.5 LIBERO checkpoint and take the rest
of openpi's `pi05_libero` config (model, optimiser, learning-rate schedule,
EMA), with the global batch size 512, 10,000 optimiser steps and seed 42.

`describe_train_config` gives the settings as a plain dict (no openpi
needed); `make_train_config` builds openpi's TrainConfig from that dict
(openpi is imported inside it); `register` adds both configs to openpi's
config table so that openpi's scripts find them by name (see
hearth_openpi.run and docs/training.md).

Run `python3 -m hearth_openpi.config` to print both descriptions as JSON.
"""

from __future__ import annotations

import json
import os
import sys

from hearth_openpi import policy

# openpi publishes its pi0.5 LIBERO fine-tune at this directory (README
# "Fine-Tuned Models"; scripts/serve_policy.py's default LIBERO checkpoint);
# the weights are in its params/ subdirectory, which is what openpi's
# CheckpointWeightLoader and create_trained_policy read.
PI05_LIBERO_CHECKPOINT = "gs://openpi-assets/checkpoints/pi05_libero"
PI05_LIBERO_PARAMS = PI05_LIBERO_CHECKPOINT + "/params"
# openpi's own pi05_libero config fine-tunes from the base model instead
PI05_BASE_PARAMS = "gs://openpi-assets/checkpoints/pi05_base/params"

# the openpi config whose remaining settings are kept
BASE_CONFIG = "pi05_libero"

NAME_THERMAL = "pi05_hearth_thermal"
NAME_RGB = "pi05_hearth_rgb"
# the LeRobot dataset id: openpi opens $HF_LEROBOT_HOME/<repo_id>
DEFAULT_REPO_ID = "hearth/sim"

# the paper's optimisation settings (section "Policy Training")
PAPER_BATCH_SIZE = 512
PAPER_NUM_TRAIN_STEPS = 10_000
PAPER_SEED = 42

# environment variables read by register()
ENV_REPO_ID = "HEARTH_OPENPI_REPO_ID"
ENV_ASSETS_DIR = "HEARTH_OPENPI_ASSETS_DIR"


def default_name(thermal: bool) -> str:
    return NAME_THERMAL if thermal else NAME_RGB


def repack_structure(thermal: bool) -> dict:
    """openpi RepackTransform structure: observation key <- LeRobot feature.
    `prompt` is the frame's task string, which openpi puts under "prompt"
    before repacking (DataConfig.prompt_from_task). The RGB-only condition
    does not read the thermal feature at all."""
    s = {
        policy.KEY_IMAGE: "image",
        policy.KEY_WRIST_IMAGE: "wrist_image",
    }
    if thermal:
        s[policy.KEY_THERMAL_IMAGE] = "thermal_image"
    s[policy.KEY_STATE] = "state"
    s[policy.KEY_ACTIONS] = "actions"
    s[policy.KEY_PROMPT] = "prompt"
    return s


def describe_train_config(
    name: str | None = None,
    thermal: bool = True,
    repo_id: str = DEFAULT_REPO_ID,
    assets_dir: str | None = None,
    *,
    batch_size: int = PAPER_BATCH_SIZE,
    num_train_steps: int = PAPER_NUM_TRAIN_STEPS,
    seed: int = PAPER_SEED,
    params_path: str = PI05_LIBERO_PARAMS,
) -> dict:
    """The settings of one condition as a plain dict; make_train_config
    builds exactly this. `assets_dir`: the directory that holds
    <repo_id>/norm_stats.json (set it to $HF_LEROBOT_HOME to use the file
    `hearth sim export --lerobot` writes); None keeps openpi's default,
    assets/<name>/<repo_id>, where scripts/compute_norm_stats.py writes."""
    thermal = bool(thermal)
    if not repo_id:
        raise ValueError("hearth_openpi: repo_id is empty")
    if batch_size < 1 or num_train_steps < 1:
        raise ValueError(f"hearth_openpi: batch_size {batch_size} and num_train_steps {num_train_steps} must be positive")
    return {
        "name": name or default_name(thermal),
        "based_on": BASE_CONFIG,
        "thermal": thermal,
        "model": {
            "class": "Pi0Config",
            "model_type": policy.MODEL_PI05,
            "pi05": True,
            "action_horizon": 10,
            "discrete_state_input": False,
        },
        "weight_loader": {"class": "CheckpointWeightLoader", "params_path": params_path},
        "pytorch_weight_path": None,
        "batch_size": int(batch_size),
        "num_train_steps": int(num_train_steps),
        "seed": int(seed),
        "data": {
            "class": "LeRobotHearthDataConfig",
            "repo_id": repo_id,
            "asset_id": repo_id,
            "assets_dir": assets_dir,
            "prompt_from_task": True,
            "extra_delta_transform": False,
            "repack": repack_structure(thermal),
            "inputs": {"class": "HearthInputs", "model_type": policy.MODEL_PI05, "thermal": thermal},
            "outputs": {"class": "HearthOutputs", "action_dim": policy.ACTION_DIM},
        },
        "policy_metadata": policy.server_metadata(thermal),
    }


def make_train_config(
    name: str | None = None,
    thermal: bool = True,
    repo_id: str = DEFAULT_REPO_ID,
    assets_dir: str | None = None,
    *,
    batch_size: int = PAPER_BATCH_SIZE,
    num_train_steps: int = PAPER_NUM_TRAIN_STEPS,
    seed: int = PAPER_SEED,
    params_path: str = PI05_LIBERO_PARAMS,
    **overrides,
):
    """openpi TrainConfig for one condition (see describe_train_config);
    `overrides` are further TrainConfig fields (exp_name, num_workers,
    fsdp_devices, wandb_enabled, ...). Needs openpi importable."""
    desc = describe_train_config(
        name,
        thermal,
        repo_id,
        assets_dir,
        batch_size=batch_size,
        num_train_steps=num_train_steps,
        seed=seed,
        params_path=params_path,
    )
    try:
        from hearth_openpi import _openpi_build
    except ImportError as e:
        raise ImportError(
            "hearth_openpi.config.make_train_config needs openpi (and its jax, flax, tyro); "
            "run it inside openpi's environment, e.g. `uv run` in an openpi checkout "
            f"with hearth's python/ on PYTHONPATH ({e})"
        ) from e
    return _openpi_build.build_train_config(desc, **overrides)


def register(repo_id: str | None = None, assets_dir: str | None = None) -> list[str]:
    """Add pi05_hearth_thermal and pi05_hearth_rgb to openpi's config table
    (openpi.training.config), so get_config() and the CLI of
    scripts/train.py, compute_norm_stats.py and serve_policy.py know them.
    Unset arguments come from $HEARTH_OPENPI_REPO_ID (default "hearth/sim")
    and $HEARTH_OPENPI_ASSETS_DIR (default: openpi's assets/ layout).
    Registering again replaces hearth's entries; a non-hearth openpi config
    of the same name is an error. Returns the names."""
    repo_id = repo_id or os.environ.get(ENV_REPO_ID) or DEFAULT_REPO_ID
    assets_dir = assets_dir or os.environ.get(ENV_ASSETS_DIR) or None
    cfgs = [make_train_config(thermal=t, repo_id=repo_id, assets_dir=assets_dir) for t in (True, False)]
    from hearth_openpi import _openpi_build

    return _openpi_build.add_to_openpi(cfgs)


def main(argv: list[str]) -> int:
    if argv and argv[0] in ("-h", "--help"):
        print("usage: python3 -m hearth_openpi.config   (prints both conditions' settings as JSON)")
        return 0
    if argv:
        print(f"hearth_openpi.config: unexpected argument '{argv[0]}' (try --help)", file=sys.stderr)
        return 2
    out = {default_name(t): describe_train_config(thermal=t) for t in (True, False)}
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
