#!/usr/bin/python3
"""How fast the rods of fig8_biaxial's grid leave alignment: the growth of the largest turn.

usage: scripts/fig8_tilt_growth.py RUN.jsonl[.gz] [RUN.jsonl[.gz] ...]

For each run (d_hat, dt) the steps whose largest rod turn lies in the exponential window
[1e-13, 1e-4] rad give the growth factor g per step (the median of turn(n+1) / turn(n)).
A forward Euler step of a linear instability x' = sigma x has g = 1 + sigma dt, so
sigma = (g - 1) / dt is the same at every dt when the growth is the dynamics' own and not the
discretisation's. Prints one markdown row per run.
"""
import gzip
import json
import math
import statistics
import sys


def runs(path):
    steps = {}
    for line in (gzip.open(path, "rt") if path.endswith(".gz") else open(path)):
        if not line.strip():
            continue
        r = json.loads(line)
        if r["record"] == "step":
            steps.setdefault((r["d_hat_over_R"], r["dt"]), []).append(r)
    return steps


def main(paths):
    print("| file | d_hat / R_rod | dt | steps in window | growth per step g | (g - 1) / dt | ln(g) / dt |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for path in paths:
        for (d_hat, dt), steps in sorted(runs(path).items()):
            turns = [s["max_turn"] for s in steps]
            ratios = [b / a for a, b in zip(turns, turns[1:]) if 1e-13 <= a <= 1e-4 and 1e-13 <= b <= 1e-4]
            if len(ratios) < 3:
                print(f"| {path} | {d_hat} | {dt} | {len(ratios)} | - | - | - |")
                continue
            g = statistics.median(ratios)
            print(f"| {path} | {d_hat} | {dt} | {len(ratios)} | {g:.3f} | {(g - 1) / dt:.0f} | {math.log(g) / dt:.0f} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
