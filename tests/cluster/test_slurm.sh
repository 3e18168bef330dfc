#!/usr/bin/env bash
# A single-node Slurm cluster brought up by the test itself (munged,
# slurmctld, slurmd from Debian's munge, slurmctld, slurmd, slurm-client),
# used to run the scale-out scripts as job arrays:
#   (a) scripts/slurm_collect.sh: a 3-shard collection, merged, must be the
#       bytes of a single `hearth sim collect` run;
#   (b) scripts/slurm_build.sh: a 2-shard `hearth build` of a tiny synthetic
#       release must be the tree of a local build.
# The daemons run as root (as CI does) with every path under a temporary
# directory and ports picked free, and are stopped on exit, failure or not.
#   test_slurm.sh HEARTH_EXE SOURCE_DIR
# Exit 77 (skipped) without the Slurm and munge programs or without root.
set -uo pipefail
hearth=$(readlink -f "$1")
src=$(readlink -f "$2")
for p in munged slurmctld slurmd sbatch sinfo scancel; do
  if ! command -v "$p" >/dev/null 2>&1; then
    echo "test_slurm: skipped: $p is not installed (scripts/setup.sh installs munge and Slurm)"
    exit 77
  fi
done
if [ "$(id -u)" != 0 ]; then
  echo "test_slurm: skipped: the test cluster runs its daemons as root"
  exit 77
fi

base=${HEARTH_TEST_TMP:-/tmp}/cluster
rm -rf "$base" && mkdir -p "$base" || exit 1
# munged wants every directory above its socket searchable by all, which a
# checkout under /root is not: the daemons' own files live under /tmp
run=$(mktemp -d "${TMPDIR:-/tmp}/hearth-slurm.XXXXXX") || exit 1
chmod 755 "$run"
mkdir -p "$run/munge" "$run/state" "$run/spool" "$run/log"
chmod 700 "$run/munge"

pids=()
teardown() {
  if [ -n "${SLURM_CONF:-}" ] && [ -e "$SLURM_CONF" ]; then
    scancel --quiet --full --user=root >/dev/null 2>&1 || true
  fi
  # the daemons this test started, by their process ids, newest first
  for ((k = ${#pids[@]} - 1; k >= 0; k--)); do kill "${pids[k]}" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  rm -rf "$run"
}
trap teardown EXIT

fail() {
  echo "test_slurm: FAILED: $*"
  for f in "$run"/log/*.log; do
    [ -e "$f" ] || continue
    echo "---- tail of $f"
    tail -n 30 "$f"
  done
  exit 1
}

# two free TCP ports for slurmctld and slurmd
read -r ctld_port d_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')

# ---- munge: a fresh key, socket under $run/sock ------------------------------
mkdir -p "$run/sock" && chmod 755 "$run/sock"
head -c 1024 /dev/urandom > "$run/munge/munge.key" && chmod 400 "$run/munge/munge.key"
munged --foreground --key-file="$run/munge/munge.key" --socket="$run/sock/munge.socket" \
  --pid-file="$run/sock/munged.pid" --seed-file="$run/munge/seed" --log-file="$run/log/munged.log" \
  >> "$run/log/munged.out.log" 2>&1 &
pids+=($!)
for _ in $(seq 1 100); do [ -S "$run/sock/munge.socket" ] && break; sleep 0.1; done
[ -S "$run/sock/munge.socket" ] || fail "munged did not start"

# ---- slurm.conf: one node, localhost, no cgroups ------------------------------
export SLURM_CONF="$run/slurm.conf"
cat > "$SLURM_CONF" <<EOF
ClusterName=hearthtest
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$run/sock/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
StateSaveLocation=$run/state
SlurmdSpoolDir=$run/spool
SlurmctldPidFile=$run/slurmctld.pid
SlurmdPidFile=$run/slurmd.pid
SlurmctldLogFile=$run/log/slurmctld.log
SlurmdLogFile=$run/log/slurmd.log
NodeName=localhost CPUs=2 State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i -f "$SLURM_CONF" >> "$run/log/slurmctld.log" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$SLURM_CONF" >> "$run/log/slurmd.log" 2>&1 &
pids+=($!)
state=""
for _ in $(seq 1 300); do
  state=$(sinfo -h -n localhost -o %T 2>/dev/null | head -n 1)
  [ "$state" = idle ] && break
  sleep 0.2
done
[ "$state" = idle ] || fail "the node did not come up idle (state '$state')"
echo "test_slurm: cluster up (slurmctld :$ctld_port, slurmd :$d_port)"

export HEARTH="$hearth"
cd "$base" || exit 1

# ---- (a) a collection as a 3-task job array, merged -----------------------------
"$hearth" synth --out "$base/assets" --categories cup,canned_drink,electric_kettle,eraser,orange,smartphone,sponge \
  --states neutral,hot,iced --views 2 --triangles 800 --texture 64 --map-res 32 --no-calibration --draft-rgb \
  --seed 1 --quiet > "$base/synth_assets.log" 2>&1 || fail "synth (assets): $(tail -n 5 "$base/synth_assets.log")"
copts=(--release "$base/assets" --ground-truth --size 32 --seed 3)
"$hearth" sim collect --task H1 --layouts 3 "${copts[@]}" --quiet --out "$base/one.hdf5" > "$base/one.log" 2>&1 ||
  fail "single collection: $(tail -n 5 "$base/one.log")"
timeout 900 sbatch --wait --array=0-2 --output="$base/collect_%a.log" \
  "$src/scripts/slurm_collect.sh" H1 3 "$base/col" "${copts[@]}" > "$base/sbatch_collect.log" 2>&1 ||
  fail "collection array: $(cat "$base/sbatch_collect.log") $(cat "$base"/collect_*.log 2>/dev/null | tail -n 20)"
"$src/scripts/slurm_merge.sh" "$base/merged.hdf5" "$base/col" 3 > "$base/merge.log" 2>&1 ||
  fail "merge: $(cat "$base/merge.log")"
cmp "$base/one.hdf5" "$base/merged.hdf5" || fail "3 Slurm shards merged differ from a single collection"
echo "test_slurm: (a) collection: 3 array tasks merged = a single run ($(stat -c %s "$base/one.hdf5") bytes)"

# ---- (b) a release build as a 2-task job array ---------------------------------------
"$hearth" synth --out "$base/rel" --draft-rgb --seed 11 --categories cup --instances 4 --views 2 \
  --triangles 600 --texture 64 --map-res 32 --no-calibration --threads 2 --quiet > "$base/synth_rel.log" 2>&1 ||
  fail "synth (release): $(tail -n 5 "$base/synth_rel.log")"
cp "$base/rel/ground_truth/rig.json" "$base/rel/calibration/rig.json" && cp -a "$base/rel" "$base/rel_slurm" || exit 1
bopts=(--resolution 32 --no-bake)
"$hearth" build "$base/rel" "${bopts[@]}" -j 2 --threads 2 --quiet > "$base/build_local.log" 2>&1 ||
  fail "local build: $(tail -n 5 "$base/build_local.log")"
timeout 900 sbatch --wait --array=0-1 --output="$base/build_%a.log" \
  "$src/scripts/slurm_build.sh" "$base/rel_slurm" "${bopts[@]}" > "$base/sbatch_build.log" 2>&1 ||
  fail "build array: $(cat "$base/sbatch_build.log") $(cat "$base"/build_*.log 2>/dev/null | tail -n 20)"
# build stamps record input times, not content: left out (as tests/cli/test_build.c)
tree_hash() { (cd "$1" && find . -type f ! -path '*/.stamps/*' | LC_ALL=C sort | xargs sha256sum); }
tree_hash "$base/rel" > "$base/hash_local.txt"
tree_hash "$base/rel_slurm" > "$base/hash_slurm.txt"
cmp "$base/hash_local.txt" "$base/hash_slurm.txt" ||
  fail "the 2-shard Slurm build differs from the local build: $(diff "$base/hash_local.txt" "$base/hash_slurm.txt" | head -n 10)"
echo "test_slurm: (b) build: 2 array tasks = a local build ($(wc -l < "$base/hash_local.txt") files)"
echo "test_slurm: passed"
exit 0
