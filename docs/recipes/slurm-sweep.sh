#!/bin/bash
# A dermis sweep as a Slurm job array: one array task per shard, then a merge
# job that runs once every shard has succeeded.
#
#   bash docs/recipes/slurm-sweep.sh    # on a login node: submits the array, then the merge
#
# (`sbatch docs/recipes/slurm-sweep.sh` submits the array alone; merge by hand
# afterwards with `dermis sweep merge $OUT --out-dir $OUT/merged`.)
#
# Each task runs `dermis sweep --shard auto`: dermis reads SLURM_ARRAY_TASK_ID,
# _MIN, _STEP and _COUNT (shard = (ID - MIN) / STEP + 1 of COUNT) and writes
# $OUT/points-shard-I-of-N.jsonl, one line per point as it completes. Every task
# renders its own reference, so the tasks share nothing but $OUT, which must be
# on storage all nodes see. Keep the array regular (1-N or 1-N:STEP): an
# irregular list such as 1,4,9 is refused. Re-submitting one failed index
# (sbatch --array=2 ...) rewrites that shard's file; add --resume to keep the
# points it finished.
#
# Knobs (environment, or edit here): DERMIS (binary), OUT (shared folder),
# SWEEP_ARGS (the sweep's options: every shard must get the same ones, or the
# merge refuses their different sweep hashes).
#SBATCH --job-name=dermis-sweep
#SBATCH --array=1-3
#SBATCH --cpus-per-task=8
#SBATCH --time=02:00:00
#SBATCH --output=dermis-sweep-%A_%a.out
set -euo pipefail

DERMIS=${DERMIS:-dermis}
OUT=${OUT:-$PWD/sweep-shards}
SWEEP_ARGS=${SWEEP_ARGS:---frames 4}

if [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
    # Submitted (or run) as a plain script: submit the array, then the merge.
    script=$(readlink -f "$0")
    export DERMIS OUT SWEEP_ARGS
    job=$(sbatch --parsable --export=ALL "$script")
    job=${job%%;*}
    sbatch --dependency=afterok:"$job" --job-name=dermis-sweep-merge \
        --output=dermis-sweep-merge-%j.out --export=ALL \
        --wrap="$DERMIS sweep merge '$OUT' --out-dir '$OUT/merged'"
    echo "submitted array $job and its merge; results in $OUT/merged"
    exit 0
fi

mkdir -p "$OUT"
# LP_NUM_THREADS: lavapipe's threads, the cores Slurm gave the task (recorded
# in each shard's fingerprint; merge warns when shards differ).
export LP_NUM_THREADS=${LP_NUM_THREADS:-${SLURM_CPUS_PER_TASK:-}}
# shellcheck disable=SC2086 # SWEEP_ARGS is a list of options
exec "$DERMIS" sweep --shard auto --out-dir "$OUT" $SWEEP_ARGS
