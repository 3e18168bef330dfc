#!/usr/bin/env bash
# One shard of a demonstration collection, as a task of a Slurm job array:
#   sbatch --array=0-<N-1> scripts/slurm_collect.sh TASK LAYOUTS PREFIX [collect options...]
# Task I of the N-task array runs
#   hearth sim collect --task TASK --layouts LAYOUTS --shard I/N --out PREFIX.partI.hdf5 ...
# (the same LAYOUTS, seed and options in every task); merge the parts with
# scripts/slurm_merge.sh or `hearth sim merge`. $HEARTH names the hearth
# executable (default: hearth on PATH). See docs/cluster.md.
#SBATCH --job-name=hearth-collect
#SBATCH --cpus-per-task=1
#SBATCH --output=hearth-collect-%A_%a.log
set -euo pipefail
if [ $# -lt 3 ] || [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
  echo "usage: sbatch --array=0-<N-1> $0 TASK LAYOUTS PREFIX [hearth sim collect options...]" >&2
  exit 2
fi
task=$1 layouts=$2 prefix=$3
shift 3
n=${SLURM_ARRAY_TASK_COUNT:-$((SLURM_ARRAY_TASK_MAX + 1))}
i=$((SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-0}))
exec "${HEARTH:-hearth}" sim collect --task "$task" --layouts "$layouts" --shard "$i/$n" \
  --out "$prefix.part$i.hdf5" --quiet "$@"
