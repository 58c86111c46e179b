#!/bin/bash
# The GPU figures of docs/design/pass-analysis.md: the default frame's work counters
# and bound-by verdicts at 4096² and 1024² (the irradiance pass in both
# formulations), the cost of --counters (interleaved, off against on), and
# the frame with counters off against a base build. Run from the repository
# root:
#
#   DERMIS=target/release/dermis BASE=old/dermis OUT=gpu docs/recipes/gpu-counters.sh
#
# BASE is optional (no comparison with it). TESTS, optional, names test
# binaries (cargo test --no-run) to run there too, e.g. the counters' and the
# bound-by verdict's. Every step is bounded by `timeout` and appends to
# $OUT/log.txt; a failed step is logged and the next one runs.
set -u
: "${DERMIS:?set DERMIS to the dermis binary}" "${OUT:?set OUT to an output folder}"
mkdir -p "$OUT/r" "$OUT/il"
LOG=$OUT/log.txt
export DERMIS_ASSETS=${DERMIS_ASSETS:-$PWD/assets}
FRAMES=${FRAMES:-30}    # per render: 5 warm-up, the rest measured
RUNS=${RUNS:-6}         # per side of each comparison
step() {
    local limit=$1
    shift
    echo "=== $(date +%T) $*" >>"$LOG"
    timeout "$limit" "$@" >>"$LOG" 2>&1
    echo "=== rc $? $(date +%T)" >>"$LOG"
}
command -v nvidia-smi >/dev/null && nvidia-smi >>"$LOG" 2>&1
"$DERMIS" info >>"$LOG" 2>&1 || { echo "no Vulkan device (see $LOG)" >&2; exit 1; }
for t in ${TESTS:-}; do
    step 120 "$t" --test-threads 1
done
for res in 4096 1024; do
    step 120 "$DERMIS" render --irradiance-res $res --frames "$FRAMES" --warmup 5 --ruler \
        --counters --timings --report "$OUT/r/counters-$res.json" --out "$OUT/r/counters-$res.png"
done
step 120 "$DERMIS" render --irradiance-res 4096 --irradiance-shading raster --frames "$FRAMES" \
    --warmup 5 --ruler --counters --timings --report "$OUT/r/counters-4096-raster.json" \
    --out "$OUT/r/counters-4096-raster.png" --trace "$OUT/r/trace-4096-raster.json"
step 300 "$DERMIS" interleave --runs "$RUNS" --frames "$FRAMES" \
    --base-args "--irradiance-res 1024" --new-args "--irradiance-res 1024 --counters" \
    --out-dir "$OUT/il/counters-cost"
if [ -n "${BASE:-}" ]; then
    step 300 "$DERMIS" interleave --runs "$RUNS" --frames "$FRAMES" --base-bin "$BASE" \
        --new-bin "$DERMIS" --base-args "--irradiance-res 1024" --new-args "--irradiance-res 1024" \
        --out-dir "$OUT/il/off-vs-base"
fi
grep -c "^=== rc 0" "$LOG" | xargs echo "steps that succeeded:"
