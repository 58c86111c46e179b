#!/usr/bin/env bash
# A/A noise of `dermis compare` (docs/guide/compare-in-ci.md, "Comparing runs"): PAIRS
# interleaved comparisons of a render with itself, RUNS processes a side
# (dermis interleave), each kept in OUT_DIR/pairK/{base,new}/ for
# aa-analyse.py. Resumable: finished pairs are skipped. Usage:
#   docs/scripts/aa-interleave.sh OUT_DIR [PAIRS=20] [RUNS=10] "render options"
set -euo pipefail
out=${1:?usage: aa-interleave.sh OUT_DIR [PAIRS] [RUNS] "render options"}
pairs=${2:-20}
runs=${3:-10}
args=${4:-}
dermis=${DERMIS:-target/release/dermis}
mkdir -p "$out"
for ((k = 1; k <= pairs; k++)); do
    [ -s "$out/pair$k.txt" ] && continue
    rm -rf "$out/pair$k"
    "$dermis" interleave --runs "$runs" --frames 3 --base-args "$args" \
        --new-args "$args" --out-dir "$out/pair$k" 2>/dev/null >"$out/pair$k.txt.tmp"
    mv "$out/pair$k.txt.tmp" "$out/pair$k.txt"
    echo "pair $k/$pairs: $(tail -1 "$out/pair$k.txt" | cut -d'(' -f1)($(cut -d' ' -f1-3 /proc/loadavg))"
done
