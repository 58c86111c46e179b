#!/bin/bash
# The real-GPU measurements of docs/records/2026-11-26-h200.md: per-pass
# GPU timestamps of the default scene and the lit close-up, an interleaved
# comparison with a base build, the irradiance pass's raster and compute
# formulations side by side, and both sweeps. Run from the repository root:
#
#   DERMIS=target/release/dermis BASE=old/dermis OUT=gpu docs/recipes/gpu-measure.sh
#
# BASE is optional (no comparison without it). DERMIS_DEVICE picks the device
# as for dermis itself. Every step is bounded by `timeout` and appends to
# $OUT/log.txt; a failed step is logged and the next one runs.
set -u
: "${DERMIS:?set DERMIS to the dermis binary}" "${OUT:?set OUT to an output folder}"
mkdir -p "$OUT/r" "$OUT/il"
LOG=$OUT/log.txt
export DERMIS_ASSETS=${DERMIS_ASSETS:-$PWD/assets}
FRAMES=${FRAMES:-30}    # per render: 5 warm-up, the rest measured
RUNS=${RUNS:-8}         # per side of each comparison
step() {
    local limit=$1
    shift
    echo "=== $(date +%T) $*" >>"$LOG"
    timeout "$limit" "$@" >>"$LOG" 2>&1
    echo "=== rc $? $(date +%T)" >>"$LOG"
}
command -v nvidia-smi >/dev/null && nvidia-smi >>"$LOG" 2>&1
"$DERMIS" info >>"$LOG" 2>&1 || { echo "no Vulkan device (see $LOG)" >&2; exit 1; }
for res in 1024 4096 8192; do
    for chain in adaptive full; do
        step 120 "$DERMIS" render --irradiance-res $res --chain $chain --frames "$FRAMES" --warmup 5 \
            --ruler --timings --report "$OUT/r/render-$res-$chain.json" --out "$OUT/r/render-$res-$chain.png"
    done
done
step 120 "$DERMIS" render --scene docs/scenes/close-up-lights.toml --irradiance-res 1024 \
    --frames "$FRAMES" --warmup 5 --ruler --timings --report "$OUT/r/closeup-1024.json" \
    --out "$OUT/r/closeup-1024.png"
if [ -n "${BASE:-}" ]; then
    for res in 1024 4096; do
        step 300 "$DERMIS" interleave --runs "$RUNS" --frames "$FRAMES" --base-bin "$BASE" \
            --new-bin "$DERMIS" --base-args "--irradiance-res $res" --new-args "--irradiance-res $res" \
            --out-dir "$OUT/il/il-$res"
    done
fi
# The irradiance pass's two formulations side by side (`auto` runs compute on
# a GPU; docs/records/2026-11-27-compute-irradiance.md, "The irradiance pass in compute").
for res in 1024 4096; do
    step 300 "$DERMIS" interleave --runs "$RUNS" --frames "$FRAMES" --allow-setup-change \
        --base-args "--irradiance-res $res --irradiance-shading raster" \
        --new-args "--irradiance-res $res --irradiance-shading compute" \
        --out-dir "$OUT/il/shading-$res"
done
step 600 "$DERMIS" sweep --resolutions 256,512,1024,2048,4096,8192 --frames 20 \
    --reference-resolution 4096 --out-dir "$OUT/sweep-default"
step 600 "$DERMIS" sweep --scene docs/scenes/close-up-lights.toml \
    --resolutions 512,1024,2048,4096,8192 --frames 20 --reference-resolution 4096 \
    --out-dir "$OUT/sweep-closeup"
grep -c "^=== rc 0" "$LOG" | xargs echo "steps that succeeded:"
