#!/usr/bin/env bash
# Installs what hearth needs on Debian (12, bookworm) and builds it.
#   scripts/setup.sh [--sanitize] [BUILD_DIR]
# Idempotent: packages already present are not reinstalled; the build is
# incremental. Needs root (or sudo) only when packages are missing.
set -euo pipefail
cd "$(dirname "$0")/.."

sanitize=0
if [ "${1:-}" = "--sanitize" ]; then sanitize=1; shift; fi
build=${1:-build}
[ $sanitize = 1 ] && [ "$build" = build ] && build=build-asan

pkgs="build-essential cmake pkg-config clang libclang-rt-14-dev git
  libembree-dev libjansson-dev libpng-dev zlib1g-dev libdeflate-dev libjpeg62-turbo-dev libtiff-dev
  liblapacke-dev liblapack-dev libblas-dev libhdf5-dev
  libmujoco-dev libosmesa6-dev libegl-dev libegl-mesa0
  python3 python3-numpy python3-h5py python3-opencv python3-websockets python3-msgpack
  munge slurmctld slurmd slurm-client"
missing=""
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
# node + npm run the Khronos glTF validator; any install of them will do
command -v node >/dev/null 2>&1 || missing="$missing nodejs"
command -v npm >/dev/null 2>&1 || missing="$missing npm"
if [ -n "$missing" ]; then
  echo "setup: installing$missing"
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO=sudo
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi

# The Khronos glTF validator (npm) checks every GLB hearth writes.
if [ ! -e .tools/node_modules/gltf-validator/package.json ]; then
  echo "setup: installing gltf-validator (npm) into .tools/"
  mkdir -p .tools
  npm install --silent --no-audit --no-fund --prefix .tools gltf-validator@2.0.0-dev.3.10 >/dev/null 2>&1 ||
    echo "setup: warning: gltf-validator could not be installed; the GLB validator test will fail"
fi
# DuckDB (npm; its native library ships inside @duckdb/node-bindings-linux-x64)
# reads back every Parquet file hearth writes (io/test_parquet, export/test_lerobot).
if [ ! -e .tools/node_modules/@duckdb/node-api/package.json ]; then
  echo "setup: installing @duckdb/node-api (npm) into .tools/"
  mkdir -p .tools
  npm install --silent --no-audit --no-fund --prefix .tools @duckdb/node-api@1.5.6-r.1 >/dev/null 2>&1 ||
    echo "setup: warning: @duckdb/node-api could not be installed; the Parquet read-back tests will fail"
fi
# The Arrow Rust Parquet reader (npm parquet-wasm) with Arrow's JavaScript
# library is the second independent reader of those files.
if [ ! -e .tools/node_modules/parquet-wasm/package.json ] || [ ! -e .tools/node_modules/apache-arrow/package.json ]; then
  echo "setup: installing parquet-wasm and apache-arrow (npm) into .tools/"
  mkdir -p .tools
  npm install --silent --no-audit --no-fund --prefix .tools parquet-wasm@0.8.0 apache-arrow@21.2.0 >/dev/null 2>&1 ||
    echo "setup: warning: parquet-wasm could not be installed; the Parquet read-back tests will fail"
fi

type=RelWithDebInfo
extra=""
if [ $sanitize = 1 ]; then type=Debug; extra="-DHEARTH_SANITIZE=ON"; fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=$type $extra >/dev/null
cmake --build "$build" -j"$(nproc)"
