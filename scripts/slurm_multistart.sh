#!/bin/bash
#SBATCH --job-name=plyscape-multistart
#SBATCH --array=0-7
#SBATCH --cpus-per-task=16
#SBATCH --time=12:00:00
# One multistart shard per array task (submit from the repository root:
# `sbatch scripts/slurm_multistart.sh`). --resume makes a requeued task
# continue where it stopped. STUDY, SHARDS (= the array size) and PLYSCAPE
# may be set in the environment (`sbatch --export=ALL,STUDY=...`).
set -euo pipefail
STUDY=${STUDY:-studies/sar_optimize.toml}
SHARDS=${SHARDS:-8}
PLYSCAPE=${PLYSCAPE:-target/release/plyscape}
"$PLYSCAPE" multistart "$STUDY" --shard "${SLURM_ARRAY_TASK_ID}/${SHARDS}" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --resume --quiet
