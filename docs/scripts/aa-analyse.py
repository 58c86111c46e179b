#!/usr/bin/env python3
"""A/A noise and power of `dermis compare` (docs/guide/compare-in-ci.md, "Comparing runs").

Reads the pairs aa-interleave.sh wrote (pairK/base/run-*.json and
pairK/new/run-*.json: the same render, RUNS processes a side, interleaved) and
compares each pair's sides:

1. the |change| of every pass in A/A pairs: its 95th percentile over the first
   half of the pairs is the noise threshold it suggests;
2. the false-alarm rate: pairs in which any pass came out regressed or
   improved, over the second half (threshold from the first) and over all pairs
   at the default threshold, with every run and with the first N of each side
   (N from --runs);
3. the smallest change found: the B side's pass PASS scaled by 1 + d in every
   frame, for N runs per side (the first N of each side), the share of pairs in
   which `dermis compare` calls PASS regressed.

Usage: aa-analyse.py DIR [--pass blur3] [--runs 5,10] [--shifts 2,3,5,10,20]
Needs only Python's standard library and the dermis binary (DERMIS, default
target/release/dermis).
"""

import argparse
import glob
import json
import os
import shutil
import subprocess
import tempfile

DERMIS = os.environ.get("DERMIS", "target/release/dermis")


def compare(a, b, *extra):
    out = subprocess.run(
        [DERMIS, "compare", a, b, "--json", *extra],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout)


def side_copy(files, runs, scale_pass=None, scale=1.0):
    """The first `runs` reports of a side, PASS scaled; a temp folder."""
    folder = tempfile.mkdtemp()
    for path in files[:runs]:
        with open(path) as fh:
            r = json.load(fh)
        for f in r["per_frame"]:
            for p in f["passes"]:
                if p["name"] == scale_pass and p.get("gpu_ns") is not None:
                    p["gpu_ns"] *= scale
        with open(os.path.join(folder, os.path.basename(path)), "w") as fh:
            json.dump(r, fh)
    return folder


def percentile(v, q):
    v = sorted(v)
    return v[min(len(v) - 1, int(q * len(v)))] if v else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--pass", dest="pass_", default="blur3")
    ap.add_argument("--runs", default="5,10")
    ap.add_argument("--shifts", default="2,3,5,10,20")
    args = ap.parse_args()
    pairs = sorted(
        (os.path.join(d, "base"), os.path.join(d, "new"))
        for d in glob.glob(os.path.join(args.dir, "pair*"))
        if os.path.isdir(d)
    )
    print(f"{len(pairs)} A/A pairs in {args.dir}")
    results = [compare(a, b) for a, b in pairs]
    units = {c["passes"][0]["unit"] for c in results}
    print(f"unit chosen (auto): {sorted(units)}; samples per side: {results[0]['passes'][0]['base_samples']} runs")

    judged = lambda c: [p for p in c["passes"] if not p["ruler"]]
    changes = lambda cs: [abs(p["change"]) for c in cs for p in judged(c) if p["change"] is not None]
    half = len(results) // 2
    calib = percentile(changes(results[:half]), 0.95)
    print(f"|change| over all passes, all pairs: median {100 * percentile(changes(results), 0.5):.2f} %, "
          f"p95 {100 * percentile(changes(results), 0.95):.2f} %, max {100 * max(changes(results)):.2f} %")
    print(f"suggested noise threshold (p95 of the first {half} pairs): {100 * calib:.2f} %")

    def alarms(cs):
        bad = [c for c in cs if any(p["verdict"] in ("regressed", "improved") for p in judged(c))]
        return len(bad), len(cs)

    for label, cs in [("default threshold, all pairs", results)]:
        n, total = alarms(cs)
        verdicts = {}
        for c in cs:
            for p in judged(c):
                verdicts[p["verdict"]] = verdicts.get(p["verdict"], 0) + 1
        print(f"{label}: {n}/{total} pairs with a false alarm; verdicts {verdicts}")
    held_out = [compare(a, b, "--noise-threshold", f"{calib:.4f}") for a, b in pairs[half:]]
    n, total = alarms(held_out)
    print(f"threshold {100 * calib:.2f} %, held-out pairs: {n}/{total} with a false alarm")

    side = lambda d: sorted(glob.glob(os.path.join(d, "*.json")))
    for runs in [int(x) for x in args.runs.split(",")]:
        cs = []
        for a, b in pairs:
            fa, fb = side_copy(side(a), runs), side_copy(side(b), runs)
            cs.append(compare(fa, fb))
            shutil.rmtree(fa)
            shutil.rmtree(fb)
        n, total = alarms(cs)
        print(f"the first {runs} runs a side, default threshold: {n}/{total} pairs with a false alarm")
    print(f"\npower: share of pairs in which {args.pass_} × (1 + d) is called regressed")
    print("runs  " + "  ".join(f"{d:>5}%" for d in args.shifts.split(",")))
    for runs in [int(x) for x in args.runs.split(",")]:
        row = []
        for d in [float(x) for x in args.shifts.split(",")]:
            found = 0
            for a, b in pairs:
                fa = side_copy(side(a), runs)
                fb = side_copy(side(b), runs, args.pass_, 1 + d / 100)
                c = compare(fa, fb)
                shutil.rmtree(fa)
                shutil.rmtree(fb)
                p = next(p for p in c["passes"] if p["name"] == args.pass_)
                found += p["verdict"] == "regressed"
            row.append(f"{100 * found / len(pairs):>5.0f}%")
        print(f"{runs:>4}  " + "  ".join(row))


if __name__ == "__main__":
    main()
