"""hearth_openpi: plugs hearth's simulated tasks into openpi (pi0 / pi0.5).

- HearthInputs / HearthOutputs: openpi data transforms, in place of
  LiberoInputs / LiberoOutputs, with the thermal view in the third image slot;
- server_metadata: what a policy server announces (does it read the thermal view);
- hearth_openpi.config: the paper's two training configs (thermal, RGB-only);
- hearth_openpi.run: runs one of openpi's scripts with those configs registered.

Importing this package needs numpy only; openpi is imported by the functions
that build openpi objects. See docs/training.md.
"""

from hearth_openpi.policy import (
    ACTION_DIM,
    IMAGE_SLOTS,
    STATE_DIM,
    HearthInputs,
    HearthOutputs,
    image_keys,
    make_hearth_example,
    parse_image,
    server_metadata,
)

__all__ = [
    "ACTION_DIM",
    "IMAGE_SLOTS",
    "STATE_DIM",
    "HearthInputs",
    "HearthOutputs",
    "image_keys",
    "make_hearth_example",
    "parse_image",
    "server_metadata",
]
