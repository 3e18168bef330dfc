"""Run one of openpi's scripts with hearth's configs registered.

    python -m hearth_openpi.run SCRIPT [ARGS...]

from an openpi checkout (e.g. `uv run python -m hearth_openpi.run
scripts/train.py pi05_hearth_thermal --exp-name=thermal`). openpi's scripts
look configs up by name in openpi.training.config; this registers
pi05_hearth_thermal and pi05_hearth_rgb there (hearth_openpi.config.register,
which reads $HEARTH_OPENPI_REPO_ID and $HEARTH_OPENPI_ASSETS_DIR), then runs
SCRIPT as `__main__` with ARGS as its command line.
"""

from __future__ import annotations

import os
import runpy
import sys

USAGE = "usage: python -m hearth_openpi.run SCRIPT [ARGS...]   (SCRIPT: an openpi script, e.g. scripts/train.py)"


def main(argv: list[str]) -> int:
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE, file=sys.stderr if not argv else sys.stdout)
        return 0 if argv else 2
    script = argv[0]
    if not os.path.isfile(script):
        print(f"hearth_openpi.run: script '{script}' not found (run from an openpi checkout)", file=sys.stderr)
        return 2
    from hearth_openpi import config

    names = config.register()
    print(f"hearth_openpi: registered openpi configs {', '.join(names)}", file=sys.stderr)
    # as `python SCRIPT ARGS...` would: its directory first on the path
    sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
    sys.argv = [script, *argv[1:]]
    runpy.run_path(script, run_name="__main__")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
