#!/usr/bin/env bash
# Build the libFuzzer targets with clang and run each for N seconds
# (default 60) starting from its corpus in fuzz/corpus/<name>/.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-60}
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHEARTH_FUZZ=ON -DHEARTH_SIM=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" >/dev/null
for f in build-fuzz/fuzz_*; do
  [ -x "$f" ] || continue
  name=$(basename "$f"); short=${name#fuzz_}
  work=$(mktemp -d)
  cp fuzz/corpus/"$short"/* "$work"/ 2>/dev/null || true
  echo "fuzz: $short for ${secs}s"
  log=$(mktemp)
  if ! "$f" -max_total_time="$secs" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$PWD/build-fuzz/$short-" "$work" >"$log" 2>&1; then
    tail -60 "$log"
    echo "fuzz: $short failed; the input is build-fuzz/$short-*" >&2
    rm -rf "$work" "$log"
    exit 1
  fi
  tail -2 "$log"
  rm -rf "$work" "$log"
done
