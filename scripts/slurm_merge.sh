#!/bin/bash
#SBATCH --job-name=plyscape-merge
#SBATCH --time=00:10:00
# After the array has finished: `sbatch --dependency=afterok:<jobid>
# scripts/slurm_merge.sh`. Merges the shards into results/<study>/, then
# `compare --resume` finds every start done, runs CMA-ES on the same budget
# and writes comparison.csv. Same environment as slurm_multistart.sh; NAME
# is the study's `[study] name`.
set -euo pipefail
STUDY=${STUDY:-studies/sar_optimize.toml}
NAME=${NAME:-sar_optimize}
SHARDS=${SHARDS:-8}
PLYSCAPE=${PLYSCAPE:-target/release/plyscape}
"$PLYSCAPE" merge results/"$NAME"/shard-*-of-"$SHARDS" --quiet
"$PLYSCAPE" compare "$STUDY" --resume --quiet
