#!/usr/bin/python3
"""The smallest sum of lambda (eq. 15, `barrier-working-set`) against the complementarity
solution (the default solver), configuration by configuration, from fig4_spheres runs.

usage: scripts/compare_solver_sums.py DEFAULT.jsonl WORKING_SET.jsonl [DEFAULT.jsonl WORKING_SET.jsonl ...]

Each pair of files is one fig4_spheres run per solver with the same scene options (the same
configurations in the same order). Prints one markdown row per pair: dt, configurations, both
converged, how many have a working-set sum more than 1e-3 below the default's, the median,
smallest and largest relative difference, and the median applications of each solver.
"""
import json
import statistics
import sys


def steps(path):
    return [r for r in (json.loads(line) for line in open(path) if line.strip()) if r.get("record") == "step"]


def row(default_path, working_set_path):
    a, b = steps(default_path), steps(working_set_path)
    if [r["config"] for r in a] != [r["config"] for r in b] or not a:
        sys.exit(f"{default_path} and {working_set_path} do not hold the same configurations")
    both = [(x, y) for x, y in zip(a, b) if x["status"] == "converged" and y["status"] == "converged"]
    rel = [y["lambda_sum"] / x["lambda_sum"] - 1.0 for x, y in both if x["lambda_sum"] > 0.0]
    apps = [statistics.median(r["mobility_applications"] for r in run) for run in (a, b)]
    print(f"| {a[0]['mobility']} | {a[0]['dt']:g} | {len(a)} | {len(both)} | {sum(r < -1e-3 for r in rel)} "
          f"| {statistics.median(rel):.1e} | {min(rel):.1e} | {max(rel):.1e} | {apps[0]:g} / {apps[1]:g} |")


def main(paths):
    print("| mobility | dt | configs | both converged | working set > 1e-3 below | median (ws / default - 1) "
          "| min | max | median applications, default / working set |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for k in range(0, len(paths), 2):
        row(paths[k], paths[k + 1])


if __name__ == "__main__":
    if len(sys.argv) < 3 or len(sys.argv) % 2 != 1:
        sys.exit(__doc__)
    main(sys.argv[1:])
