#!/usr/bin/env bash
# Set up (packages, build) and run the main job on the embedded default: the
# virtual capture rig. Output goes to out/demo (or the directory given).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/hearth demo "${1:-out/demo}"
