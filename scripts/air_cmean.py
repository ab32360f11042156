#!/usr/bin/env python3
"""c_mean of the crumpling samples with and without [air] (docs/AIR.md "c_mean").

Simulates each sample (no rendering) for seeds 1..N without [air], with
[air] (still air, the defaults; [sim] mass_damping keeps its 0.5/s) and,
with --no-damping, with [air] and no Rayleigh mass damping
([sim] mass_damping = 0: the air the only drag), reads c_mean_mean (docs/BENCH.md: the mean over
the frames of the mean |l - L| / L over the edges) from each run's summary
and prints a Markdown table: medians, ranges, the probability that a run
with air has the larger c_mean (Mann-Whitney U / (n m)) and its two-sided p
(normal approximation, ties averaged).

Usage: scripts/air_cmean.py [--crumple build/crumple] [--seeds 20] [--jobs 2]
       [--samples crumple,cylinder-fold,...] [--no-damping]
"""
import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAMPLES = "crumple,cylinder-fold,first-singularity,moebius,unload,slide-on-table,wiggle"
EXTRA = {"without": "", "air": "\n[air]\n", "air, no damping": "\n[air]\n\n[sim]\nmass_damping = 0.0\n"}


def find(obj, key):
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k == key:
                return v
            found = find(v, key)
            if found is not None:
                return found
    return None


def run(crumple, tmp, sample, seed, condition):
    work = os.path.join(tmp, f"{sample}-{seed}-{condition.replace(' ', '_').replace(',', '')}")
    shutil.copytree(os.path.join(ROOT, "samples", sample), work)
    with open(os.path.join(work, "scene.toml"), "a") as f:
        f.write(EXTRA[condition])
    subprocess.run([crumple, "simulate", work, "--out", work + "/out", "--seed", str(seed)],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(work, "out", "summary.json")) as f:
        value = find(json.load(f), "c_mean_mean")
    shutil.rmtree(work)
    return value


def mann_whitney(a, b):
    """P(a > b) as U / (n m) and the two-sided p of the normal approximation."""
    both = sorted([(x, 0) for x in a] + [(x, 1) for x in b])
    ranks, i = [0.0] * len(both), 0
    while i < len(both):
        j = i
        while j < len(both) and both[j][0] == both[i][0]:
            j += 1
        for k in range(i, j):
            ranks[k] = (i + j + 1) / 2
        i = j
    u = sum(r for r, (_, g) in zip(ranks, both) if g == 0) - len(a) * (len(a) + 1) / 2
    n, m = len(a), len(b)
    sd = math.sqrt(n * m * (n + m + 1) / 12)
    p = math.erfc(abs(u - n * m / 2) / sd / math.sqrt(2)) if sd > 0 else 1.0
    return u / (n * m), p


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--crumple", default=os.path.join(ROOT, "build", "crumple"))
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--samples", default=SAMPLES)
    ap.add_argument("--no-damping", action="store_true")
    args = ap.parse_args()
    conditions = ["without", "air"] + (["air, no damping"] if args.no_damping else [])
    runs = [(s, seed, c) for s in args.samples.split(",") for seed in range(1, args.seeds + 1)
            for c in conditions]
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.jobs) as pool:
        values = list(pool.map(lambda r: run(args.crumple, tmp, *r), runs))
    table = {}
    for (s, _, c), v in zip(runs, values):
        table.setdefault((s, c), []).append(v)
    head = " | ".join(f"{c}: median [range]" for c in conditions)
    print(f"c_mean over seeds 1-{args.seeds}.\n")
    print(f"| sample | {head} | P(air > without) | p |")
    print("| --- | " + "--- | " * len(conditions) + "--- | --- |")
    for s in args.samples.split(","):
        cells = [f"{statistics.median(table[(s, c)]):.3g} [{min(table[(s, c)]):.3g}, "
                 f"{max(table[(s, c)]):.3g}]" for c in conditions]
        prob, p = mann_whitney(table[(s, "air")], table[(s, "without")])
        print(f"| {s} | " + " | ".join(cells) + f" | {prob:.2f} | {p:.2f} |")


if __name__ == "__main__":
    sys.exit(main())
