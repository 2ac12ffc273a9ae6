#!/usr/bin/python3
"""Where the time of brownian_rods --progress 1 runs goes: steps committed whole against
sub-stepped ones, over the first N steps that every log has (logs may be gzipped).

usage: scripts/substep_cost_table.py LABEL=LOG [LABEL=LOG ...]
"""
import gzip
import json
import statistics
import sys


def steps_of(path):
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as f:
        return [json.loads(line[len("melt "):]) for line in f if line.startswith("melt {")]


def main():
    if len(sys.argv) < 2 or any("=" not in a for a in sys.argv[1:]):
        sys.exit(__doc__)
    runs = [(spec.split("=", 1)[0], steps_of(spec.split("=", 1)[1])) for spec in sys.argv[1:]]
    n = min(len(steps) for _, steps in runs)
    print(f"first {n} steps of each log")
    print("| run | total (s) | median step (s) | corrections: median / mean | sub-stepped steps | their time (s) | "
          "whole steps' time (s) | not_converged (within the margin) | solved again |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for label, steps in runs:
        s = steps[:n]
        wall = [x["wall_time_s"] for x in s]
        its = [x["iterations"] for x in s]
        sub = [x["wall_time_s"] for x in s if x["substeps"] > 1]
        print(f"| {label} | {sum(wall):.1f} | {statistics.median(wall):.3f} | {statistics.median(its):g} / "
              f"{statistics.mean(its):.1f} | {len(sub)} | {sum(sub):.1f} | {sum(wall) - sum(sub):.1f} | "
              f"{sum(1 for x in s if x['status'] == 'not_converged')} | {sum(1 for x in s if x['fallbacks'] > 0)} |")


if __name__ == "__main__":
    main()
