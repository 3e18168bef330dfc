"""The openpi side of hearth_openpi.config: imports openpi at import time, so
only hearth_openpi.config imports it, inside its functions. Classes live at
module level so openpi's spawned data-loader workers can unpickle the
transforms they carry."""

from __future__ import annotations

import dataclasses
import pathlib

import openpi.models.model as _model
import openpi.models.pi0_config as pi0_config
import openpi.training.config as _config
import openpi.training.weight_loaders as weight_loaders
import openpi.transforms as _transforms
import tyro

from hearth_openpi import config as _hconfig
from hearth_openpi import policy


@dataclasses.dataclass(frozen=True)
class LeRobotHearthDataConfig(_config.DataConfigFactory):
    """Data pipeline for a LeRobot dataset written by `hearth sim export
    --lerobot`: repack the features to the eval client's keys, then
    HearthInputs / HearthOutputs, then openpi's standard model transforms.
    Actions are already deltas (OSC pose increments), so no delta
    transform is added."""

    # the condition; fixed by the config's name, so hidden from the CLI
    thermal: tyro.conf.Suppress[bool] = True

    def create(self, assets_dirs: pathlib.Path, model_config: _model.BaseModelConfig) -> _config.DataConfig:
        repack = _transforms.Group(inputs=[_transforms.RepackTransform(_hconfig.repack_structure(self.thermal))])
        data_transforms = _transforms.Group(
            inputs=[policy.HearthInputs(model_type=model_config.model_type, thermal=self.thermal)],
            outputs=[policy.HearthOutputs()],
        )
        model_transforms = _config.ModelTransformFactory()(model_config)
        return dataclasses.replace(
            self.create_base_config(assets_dirs, model_config),
            repack_transforms=repack,
            data_transforms=data_transforms,
            model_transforms=model_transforms,
        )


def build_train_config(desc: dict, **overrides) -> _config.TrainConfig:
    """openpi TrainConfig from a describe_train_config dict: openpi's
    pi05_libero config with hearth's model, data, weights, batch size,
    steps, seed and policy metadata put in."""
    base = _config.get_config(desc["based_on"])
    m = desc["model"]
    model = pi0_config.Pi0Config(
        pi05=m["pi05"], action_horizon=m["action_horizon"], discrete_state_input=m["discrete_state_input"]
    )
    if model.model_type.value != m["model_type"]:
        raise ValueError(f"hearth_openpi: openpi built a {model.model_type} model, expected {m['model_type']}")
    d = desc["data"]
    data = LeRobotHearthDataConfig(
        repo_id=d["repo_id"],
        assets=_config.AssetsConfig(assets_dir=d["assets_dir"], asset_id=d["asset_id"]),
        base_config=_config.DataConfig(prompt_from_task=d["prompt_from_task"]),
        thermal=desc["thermal"],
    )
    fields = {
        "name": desc["name"],
        "model": model,
        "data": data,
        "weight_loader": weight_loaders.CheckpointWeightLoader(desc["weight_loader"]["params_path"]),
        "pytorch_weight_path": desc["pytorch_weight_path"],
        "batch_size": desc["batch_size"],
        "num_train_steps": desc["num_train_steps"],
        "seed": desc["seed"],
        "policy_metadata": dict(desc["policy_metadata"]),
    }
    fields.update(overrides)
    return dataclasses.replace(base, **fields)


def add_to_openpi(cfgs: list[_config.TrainConfig]) -> list[str]:
    """Put the configs into openpi's module-level config table (the list
    and the name -> config dict that get_config() and cli() read)."""
    table = _config._CONFIGS_DICT
    for cfg in cfgs:
        old = table.get(cfg.name)
        if old is not None and not isinstance(old.data, LeRobotHearthDataConfig):
            raise ValueError(f"hearth_openpi: openpi already has a config named '{cfg.name}'")
        table[cfg.name] = cfg
        lst = _config._CONFIGS
        for i, c in enumerate(lst):
            if c.name == cfg.name:
                lst[i] = cfg
                break
        else:
            lst.append(cfg)
    return [c.name for c in cfgs]
