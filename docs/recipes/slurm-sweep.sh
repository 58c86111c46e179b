#!/bin/bash
# A dermis sweep as a Slurm job array: one array task per shard, then a merge
# job that runs once every shard has succeeded.
#
#   bash docs/recipes/slurm-sweep.sh          # on a login node: submits the array, then the merge
#   bash docs/recipes/slurm-sweep.sh 2        # retry: shard 2 alone (--resume), then the merge again
#   bash docs/recipes/slurm-sweep.sh 1,3      # retry: shards 1 and 3
#
# Each task runs `dermis sweep --shard auto` with DERMIS_SHARD_TOTAL=$SHARDS:
# the Slurm task ID is the shard number (1..SHARDS), so a retried index renders
# its own shard (not the whole sweep as "shard 1/1"), and with --resume only the
# points its log lacks. Each task writes $OUT/points-shard-I-of-N.jsonl, one
# line per point as it completes, and renders its own reference: the tasks share
# nothing but $OUT, which must be on storage all nodes see.
#
# The merge job waits for every task with afterok and --kill-on-invalid-dep=yes:
# if a task fails, Slurm cancels the merge instead of leaving it pending for
# ever (DependencyNeverSatisfied). Retry the failed shards as above; the retry
# submits a merge of its own.
#
# Knobs (environment, or edit here): DERMIS (binary), OUT (shared folder),
# SHARDS (tasks; every submission of one sweep must use the same), CPUS (cores
# per task; default: 8, or fewer if the smallest node of the partition has
# fewer, so the tasks can start; a request no node can hold, which Slurm would
# leave PENDING (PartitionConfig) for ever, is refused before submitting), SWEEP_ARGS (the sweep's options:
# every shard must get the same ones, or the merge refuses their different
# sweep hashes), SBATCH_ARGS (more sbatch options: --partition, --account).
#
# (`sbatch --array=1-3 docs/recipes/slurm-sweep.sh` submits the array alone with
# the directives below; merge by hand afterwards with
# `dermis sweep merge $OUT --out-dir $OUT/merged`. Run that way, the task count
# must equal SHARDS (default 3): dermis refuses a mismatch; and nothing checks
# --cpus-per-task: edit it below to at most a node's CPUs, `sinfo -o %c`.)
#SBATCH --job-name=dermis-sweep
#SBATCH --cpus-per-task=2
#SBATCH --time=02:00:00
#SBATCH --output=dermis-sweep-%A_%a.out
set -euo pipefail

DERMIS=${DERMIS:-dermis}
OUT=${OUT:-$PWD/sweep-shards}
SHARDS=${SHARDS:-3}
SWEEP_ARGS=${SWEEP_ARGS:---frames 4}

if [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
    # Run as a plain script: submit the array (or a retry), then the merge.
    script=$(readlink -f "$0")
    indices=${1:-1-$SHARDS}
    if [ $# -gt 0 ]; then
        case "$1" in
        *[!0-9,]* | "" | ,* | *,,* | *,)
            echo "usage: $0 [I[,J...]] (shard numbers in 1..$SHARDS to retry)" >&2
            exit 2
            ;;
        esac
        for i in ${1//,/ }; do
            if [ "$i" -lt 1 ] || [ "$i" -gt "$SHARDS" ]; then
                echo "$0: shard $i is not in 1..$SHARDS (SHARDS=$SHARDS)" >&2
                exit 2
            fi
        done
        # Keep the points the failed run finished.
        case " $SWEEP_ARGS " in
        *" --resume "*) ;;
        *) SWEEP_ARGS="$SWEEP_ARGS --resume" ;;
        esac
    fi
    if [ -z "${CPUS:-}" ]; then
        # The smallest node's CPU count (sinfo %c), at most 8.
        smallest=$(sinfo -h -o %c 2>/dev/null | tr -dc '0-9\n' | sort -n | head -1 || true)
        CPUS=8
        if [ -n "$smallest" ] && [ "$smallest" -lt "$CPUS" ]; then
            CPUS=$smallest
        fi
    fi
    export DERMIS OUT SHARDS SWEEP_ARGS
    # Slurm accepts a task no node can hold and leaves it PENDING
    # (PartitionConfig) for ever (EnforcePartLimits=NO, the default): ask it
    # first whether the array can ever run (sbatch --test-only, Slurm 22.05).
    # shellcheck disable=SC2086 # SBATCH_ARGS is a list of options
    if ! why=$(sbatch --test-only --array="$indices" --cpus-per-task="$CPUS" \
        ${SBATCH_ARGS:-} "$script" 2>&1); then
        echo "$0: Slurm cannot run a task of $CPUS CPUs here: $why" >&2
        echo "(set CPUS to at most a node's CPU count, \`sinfo -o %c\`, or fix SBATCH_ARGS)" >&2
        exit 2
    fi
    # shellcheck disable=SC2086
    job=$(sbatch --parsable --export=ALL --array="$indices" --cpus-per-task="$CPUS" \
        ${SBATCH_ARGS:-} "$script")
    job=${job%%;*}
    # shellcheck disable=SC2086
    merge=$(sbatch --parsable --dependency=afterok:"$job" --kill-on-invalid-dep=yes \
        --job-name=dermis-sweep-merge --output=dermis-sweep-merge-%j.out --export=ALL \
        ${SBATCH_ARGS:-} --wrap="'$DERMIS' sweep merge '$OUT' --out-dir '$OUT/merged'")
    merge=${merge%%;*}
    echo "submitted array $job (shards $indices of $SHARDS, $CPUS CPUs each) and merge $merge;"
    echo "results in $OUT/merged. If a shard fails, the merge is cancelled: retry it with"
    echo "  bash $0 I    # I: the failed shard's number (its task ID)"
    exit 0
fi

mkdir -p "$OUT"
# The shard count: the task ID is the shard, whatever array it came from.
export DERMIS_SHARD_TOTAL=${DERMIS_SHARD_TOTAL:-$SHARDS}
# LP_NUM_THREADS: lavapipe's threads, the cores Slurm gave the task (recorded
# in each shard's fingerprint; merge warns when shards differ).
export LP_NUM_THREADS=${LP_NUM_THREADS:-${SLURM_CPUS_PER_TASK:-}}
# shellcheck disable=SC2086 # SWEEP_ARGS is a list of options
exec "$DERMIS" sweep --shard auto --out-dir "$OUT" $SWEEP_ARGS
