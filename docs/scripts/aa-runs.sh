#!/usr/bin/env bash
# A/A noise of `dermis compare` (docs/performance.md, "Comparing runs"): GROUPS
# identical run reports of RUNS runs each (render --runs), to be compared in
# pairs (g0 vs g1, g2 vs g3, …) by aa-analyse.py. Usage:
#   docs/scripts/aa-runs.sh OUT_DIR [GROUPS=40] [RUNS=10] [render options…]
set -euo pipefail
out=${1:?usage: aa-runs.sh OUT_DIR [GROUPS] [RUNS] [render options...]}
groups=${2:-40}
runs=${3:-10}
shift $(( $# < 3 ? $# : 3 ))
dermis=${DERMIS:-target/release/dermis}
mkdir -p "$out"
for ((g = 0; g < groups; g++)); do
    [ -s "$out/g$g.json" ] && continue # resumable
    "$dermis" render --frames 3 --runs "$runs" --ruler \
        --report "$out/g$g.json.tmp" --out "$out/last.png" "$@" >/dev/null
    mv "$out/g$g.json.tmp" "$out/g$g.json"
    echo "group $((g + 1))/$groups done ($(cut -d' ' -f1-3 /proc/loadavg))"
done
