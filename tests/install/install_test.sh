#!/usr/bin/env bash
# Install a build into a fresh prefix and use it from outside, the way a
# user of the installed library would:
#   install_test.sh CMAKE BUILD_DIR WORK_DIR LIBDIR CC SIM(0|1)
# 1. cmake --install BUILD_DIR --prefix WORK_DIR/prefix
# 2. build tests/install/outside.c with exactly `pkg-config --cflags --libs
#    hearth` (PKG_CONFIG_PATH = the prefix's pkgconfig directory) and run it;
#    with SIM, the same for outside_sim.c with hearth-sim
# 3. run the installed `hearth --help` and, with SIM, `hearth sim --help`
#    (which must find the installed hearth-sim beside hearth)
set -euo pipefail
cmake=$1 build=$2 work=$3 libdir=$4 cc=$5 sim=$6
here=$(cd "$(dirname "$0")" && pwd)
fail() { echo "install_test: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
"$cmake" --install "$build" --prefix "$prefix" >"$work/install.log" || {
  cat "$work/install.log" >&2; fail "cmake --install failed"; }

for f in bin/hearth include/hearth/hearth.h "$libdir/pkgconfig/hearth.pc" "$libdir/libhearth_core.a"; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
if [ "$sim" = 1 ]; then
  for f in bin/hearth-sim "$libdir/pkgconfig/hearth-sim.pc" "$libdir/libhearth_sim.a"; do
    [ -e "$prefix/$f" ] || fail "not installed: $f"
  done
fi

export PKG_CONFIG_PATH=$prefix/$libdir/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}
flags=$(pkg-config --cflags --libs hearth) || fail "pkg-config --cflags --libs hearth failed"
echo "pkg-config --cflags --libs hearth: $flags"
case "$flags" in *"$prefix"*) ;; *) fail "the flags do not point into $prefix" ;; esac
# shellcheck disable=SC2086 # the flags are words
"$cc" -std=c11 -Wall -Wextra -o "$work/outside" "$here/outside.c" $flags ||
  fail "outside.c did not build with: $flags"
"$work/outside" "$work" || fail "outside failed"

if [ "$sim" = 1 ]; then
  simflags=$(pkg-config --cflags --libs hearth-sim) || fail "pkg-config hearth-sim failed"
  echo "pkg-config --cflags --libs hearth-sim: $simflags"
  # shellcheck disable=SC2086
  "$cc" -std=c11 -Wall -Wextra -o "$work/outside_sim" "$here/outside_sim.c" $simflags ||
    fail "outside_sim.c did not build with: $simflags"
  "$work/outside_sim" || fail "outside_sim failed"
fi

# the installed executables, from a directory outside the build tree
cd "$work"
"$prefix/bin/hearth" --help >help.txt || fail "installed hearth --help failed"
grep -q '^usage: hearth' help.txt || fail "installed hearth --help printed no usage"
if [ "$sim" = 1 ]; then
  "$prefix/bin/hearth" sim --help >sim_help.txt 2>&1 || {
    cat sim_help.txt >&2; fail "installed hearth sim --help failed"; }
  grep -q '^usage: hearth sim' sim_help.txt || fail "installed hearth sim --help printed no usage"
fi
echo "install_test: passed ($prefix)"
