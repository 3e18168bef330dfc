#!/usr/bin/env bash
# One shard of a release build, as a task of a Slurm job array:
#   sbatch --array=0-<N-1> scripts/slurm_build.sh ROOT [build options...]
# Task I of the N-task array runs `hearth build ROOT --shard I/N ...`: the
# instances I, I+N, ... of release.json, each in its own directory, with
# -j and --threads from the CPUs Slurm gave the task. The shards together
# write the bytes one build writes. $HEARTH names the hearth executable
# (default: hearth on PATH). See docs/cluster.md.
#SBATCH --job-name=hearth-build
#SBATCH --cpus-per-task=1
#SBATCH --output=hearth-build-%A_%a.log
set -euo pipefail
if [ $# -lt 1 ] || [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
  echo "usage: sbatch --array=0-<N-1> $0 ROOT [hearth build options...]" >&2
  exit 2
fi
root=$1
shift
n=${SLURM_ARRAY_TASK_COUNT:-$((SLURM_ARRAY_TASK_MAX + 1))}
i=$((SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-0}))
cpus=${SLURM_CPUS_PER_TASK:-1}
exec "${HEARTH:-hearth}" build "$root" --shard "$i/$n" -j "$cpus" --threads "$cpus" --quiet "$@"
