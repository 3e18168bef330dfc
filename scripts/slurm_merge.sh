#!/usr/bin/env bash
# Merge the N parts a scripts/slurm_collect.sh array wrote into OUT.hdf5
# (the bytes one unsharded run writes); as a job after the array:
#   sbatch --dependency=afterok:<array job id> scripts/slurm_merge.sh OUT.hdf5 PREFIX N
# or by hand: scripts/slurm_merge.sh OUT.hdf5 PREFIX N. With
# --split-instructions, run it once per instruction with PREFIX.partI_instr<k>
# files: scripts/slurm_merge.sh OUT_instr<k>.hdf5 PREFIX N _instr<k>.
#SBATCH --job-name=hearth-merge
#SBATCH --cpus-per-task=1
#SBATCH --output=hearth-merge-%j.log
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 OUT.hdf5 PREFIX N [SUFFIX]" >&2
  exit 2
fi
out=$1 prefix=$2 n=$3 suffix=${4:-}
parts=()
for ((i = 0; i < n; i++)); do parts+=("$prefix.part$i$suffix.hdf5"); done
exec "${HEARTH:-hearth}" sim merge "$out" "${parts[@]}"
