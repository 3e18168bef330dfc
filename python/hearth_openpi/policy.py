"""Input and output transforms that let an openpi pi0 / pi0-FAST / pi0.5 policy
read hearth's observations.

`HearthInputs` maps one observation (the dict hearth's `sim eval` sends, or one
training frame after the repack transform of `hearth_openpi.config`) to the
model's input dict; `HearthOutputs` cuts the model's padded actions back to
hearth's 7 numbers. They take the place of openpi's LiberoInputs /
LiberoOutputs: same constructor field (`model_type`), same call, same
returned keys. The one difference is the third image slot
(`right_wrist_0_rgb`), which LIBERO leaves as zeros and which hearth fills
with the front thermal view (`observation/thermal_image`, Turbo colours).

Nothing here imports openpi: `model_type` may be openpi's `ModelType` enum
member or its string value, and the classes are plain frozen dataclasses
with `__call__(data) -> dict`, which is all openpi's DataTransformFn
protocol asks for.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

# observation keys sent by `hearth sim eval` (src/eval/eval_run.c,
# hearth_eval_encode_obs) and produced by the training repack transform
KEY_IMAGE = "observation/image"
KEY_WRIST_IMAGE = "observation/wrist_image"
KEY_THERMAL_IMAGE = "observation/thermal_image"
KEY_STATE = "observation/state"
KEY_PROMPT = "prompt"
KEY_ACTIONS = "actions"

# the model's image slots, in openpi's order (openpi.models.model.IMAGE_KEYS)
SLOT_BASE = "base_0_rgb"
SLOT_LEFT_WRIST = "left_wrist_0_rgb"
SLOT_RIGHT_WRIST = "right_wrist_0_rgb"
IMAGE_SLOTS = (SLOT_BASE, SLOT_LEFT_WRIST, SLOT_RIGHT_WRIST)

# the string values of openpi.models.model.ModelType
MODEL_PI0 = "pi0"
MODEL_PI0_FAST = "pi0_fast"
MODEL_PI05 = "pi05"
MODEL_TYPES = (MODEL_PI0, MODEL_PI0_FAST, MODEL_PI05)

# hearth's action: [dx dy dz dax day daz grip] (docs/simulation.md)
ACTION_DIM = 7
# hearth's state: ee_pos (3), ee_ori (3), gripper_states (2)
STATE_DIM = 8


def model_type_value(model_type: Any) -> str:
    """The string value ("pi0", "pi0_fast", "pi05") of an openpi ModelType
    member, of its value, or of its member name ("PI0_FAST"); ValueError
    for anything else."""
    v = getattr(model_type, "value", model_type)
    if isinstance(v, str):
        if v in MODEL_TYPES:
            return v
        if v.lower() in MODEL_TYPES:
            return v.lower()
    raise ValueError(f"hearth_openpi: model_type {model_type!r} is not one of {', '.join(MODEL_TYPES)}")


def parse_image(image: Any) -> np.ndarray:
    """An image as uint8 height x width x 3, converted the way openpi's LIBERO
    policy does it: float images (LeRobot hands them out as float32 in
    [0, 1]) are scaled by 255 and truncated to uint8, and an image whose
    first axis has length 3 is taken as channels-first and moved to
    channels-last. uint8 HWC images (what the eval client sends) pass
    through unchanged."""
    image = np.asarray(image)
    if np.issubdtype(image.dtype, np.floating):
        image = (255 * image).astype(np.uint8)
    if image.shape[0] == 3:
        image = np.transpose(image, (1, 2, 0))
    return image


def _pad_last(x: Any, dim: int) -> Any:
    """Zero-pad the last axis of x to dim (no-op when it is already that long
    or longer)."""
    x = np.asarray(x)
    if x.shape[-1] >= dim:
        return x
    pad = [(0, 0)] * (x.ndim - 1) + [(0, dim - x.shape[-1])]
    return np.pad(x, pad)


@dataclasses.dataclass(frozen=True)
class HearthInputs:
    """hearth observation -> openpi model input.

    Fields:
      model_type: which model reads the inputs (openpi ModelType or its
        string value). It only decides the mask of an empty third slot.
      thermal: True puts `observation/thermal_image` into the third slot
        with its mask on (the paper's RGB-thermal condition; the key must
        be present). False gives the RGB-only condition: the third slot is
        zeros whatever the observation holds, masked exactly as openpi's
        LiberoInputs masks its padding slot (off for pi0 and pi0.5, on for
        pi0-FAST, which never masks padding images).
      action_dim: None (the default, as in current openpi, where the model
        transforms pad) leaves state and actions as they are; a number pads
        both with zeros to that length, as openpi's LiberoInputs did while
        it still had an action_dim field.

    Returns {"state", "image": {slot: uint8 HxWx3}, "image_mask": {slot:
    numpy bool}, "actions" (when given), "prompt" (when given)}.
    """

    model_type: Any
    thermal: bool = True
    action_dim: int | None = None

    def __post_init__(self) -> None:
        model_type_value(self.model_type)  # fail at construction, not per frame
        if self.action_dim is not None and int(self.action_dim) < 1:
            raise ValueError(f"hearth_openpi: action_dim {self.action_dim!r} must be positive")

    def __call__(self, data: dict) -> dict:
        base = parse_image(data[KEY_IMAGE])
        wrist = parse_image(data[KEY_WRIST_IMAGE])
        if self.thermal:
            if KEY_THERMAL_IMAGE not in data:
                raise KeyError(
                    f"hearth_openpi: the thermal policy needs '{KEY_THERMAL_IMAGE}' in the observation "
                    f"(keys present: {', '.join(sorted(map(str, data)))}); "
                    "run `hearth sim eval` without --no-thermal, or serve the RGB-only config"
                )
            third = parse_image(data[KEY_THERMAL_IMAGE])
            if third.ndim < 3 or third.shape[-1] != 3:
                raise ValueError(
                    f"hearth_openpi: '{KEY_THERMAL_IMAGE}' has shape {third.shape}, expected height x width x 3"
                )
            third_mask = np.True_
        else:
            third = np.zeros_like(base)
            third_mask = np.True_ if model_type_value(self.model_type) == MODEL_PI0_FAST else np.False_

        state = data[KEY_STATE]
        if self.action_dim is not None:
            state = _pad_last(state, int(self.action_dim))
        inputs = {
            "state": state,
            "image": {SLOT_BASE: base, SLOT_LEFT_WRIST: wrist, SLOT_RIGHT_WRIST: third},
            "image_mask": {SLOT_BASE: np.True_, SLOT_LEFT_WRIST: np.True_, SLOT_RIGHT_WRIST: third_mask},
        }
        if KEY_ACTIONS in data:
            actions = data[KEY_ACTIONS]
            if self.action_dim is not None:
                actions = _pad_last(actions, int(self.action_dim))
            inputs[KEY_ACTIONS] = actions
        if KEY_PROMPT in data:
            inputs[KEY_PROMPT] = data[KEY_PROMPT]
        return inputs


@dataclasses.dataclass(frozen=True)
class HearthOutputs:
    """openpi model output -> hearth action chunk: keeps the first
    `action_dim` (7) numbers of every action (the model pads to its own
    action dimension), over any leading batch / horizon axes."""

    action_dim: int = ACTION_DIM

    def __call__(self, data: dict) -> dict:
        return {KEY_ACTIONS: np.asarray(np.asarray(data[KEY_ACTIONS])[..., : self.action_dim])}


def image_keys(thermal: bool) -> list[str]:
    """The observation image keys a policy of this condition reads."""
    keys = [KEY_IMAGE, KEY_WRIST_IMAGE]
    if thermal:
        keys.append(KEY_THERMAL_IMAGE)
    return keys


def server_metadata(thermal: bool) -> dict:
    """The metadata a policy server of this condition announces on connect
    (openpi's WebsocketPolicyServer sends its `metadata` map as the first
    message). The training configs of hearth_openpi.config set it as
    TrainConfig.policy_metadata, so scripts/serve_policy.py sends it
    unchanged; a hand-made server passes it as
    WebsocketPolicyServer(policy, metadata=server_metadata(thermal)).
    `hearth_thermal` says whether the policy reads the thermal view, so a
    client can refuse a thermal evaluation against a server that ignores
    it (and the reverse)."""
    return {
        "hearth_adapter": "hearth_openpi",
        "hearth_thermal": bool(thermal),
        "image_keys": image_keys(thermal),
        "state_dim": STATE_DIM,
        "action_dim": ACTION_DIM,
    }


def make_hearth_example(thermal: bool = True, size: int = 224, seed: int = 0) -> dict:
    """A random observation in the form `hearth sim eval` sends (uint8 HWC
    images, float64 state of 8, a prompt), for smoke-testing a policy."""
    rng = np.random.default_rng(seed)
    obs = {
        KEY_IMAGE: rng.integers(0, 256, size=(size, size, 3), dtype=np.uint8),
        KEY_WRIST_IMAGE: rng.integers(0, 256, size=(size, size, 3), dtype=np.uint8),
        KEY_STATE: rng.random(STATE_DIM),
        KEY_PROMPT: "pick up the hot cup and place it on the mat",
    }
    if thermal:
        obs[KEY_THERMAL_IMAGE] = rng.integers(0, 256, size=(size, size, 3), dtype=np.uint8)
    return obs
