#!/usr/bin/env bash
# Hashes of what the main commands write, to check that a change of code
# that should not change behaviour keeps every output byte:
#   bench/same_bytes.sh BUILD_DIR OUT_DIR > hashes.txt
# Runs the demo (virtual-rig release, full build, report), a calibration
# (synth with calibration captures, detect, calibrate) and a 3-layout H1
# collection, then lists sha256 of every file written (sorted by path).
# Compare two builds with: diff <(bench/same_bytes.sh A /tmp/a) <(bench/same_bytes.sh B /tmp/b)
set -euo pipefail
build=$(cd "$1" && pwd)
out=$2
rm -rf "$out"; mkdir -p "$out"
h="$build/hearth"
"$h" demo "$out/demo" --quiet >/dev/null
"$h" synth --out "$out/calib" --categories cup --states neutral --views 3 --seed 7 >/dev/null 2>&1
"$h" detect "$out/calib" >/dev/null
"$h" calibrate "$out/calib" >/dev/null
"$h" sim collect --task H1 --layouts 3 --out "$out/h1.hdf5" --quiet >/dev/null
cd "$out"
# build stamps record file times, not content: left out
# the report names the release's path: hashed with OUT_DIR replaced
find . -type f -not -path "*/.stamps/*" | LC_ALL=C sort | while read -r f; do
  case "$f" in
    *.html) echo "$(sed "s|$out|OUT_DIR|g" "$f" | sha256sum | cut -c1-16) $f" ;;
    *) echo "$(sha256sum < "$f" | cut -c1-16) $f" ;;
  esac
done
