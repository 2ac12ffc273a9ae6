#!/usr/bin/python3
"""One Google Benchmark binary run at several OpenMP thread counts, side by side.

usage: scripts/bench_threads_table.py THREADS1.json THREADS2.json [...]

Each file is the --benchmark_out=FILE --benchmark_out_format=json of one run (the same
filter, OMP_NUM_THREADS set per run, repetitions allowed); the files are taken in the order of
their thread counts, the first as the reference. Prints a markdown table: per benchmark the
fastest repetition's wall time in each file, and the first file's time over each later one's.
"""
import json
import sys


def fastest(path):
    times, unit = {}, {}
    for b in json.load(open(path))["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        name = b["run_name"] if "run_name" in b else b["name"]
        times[name] = min(times.get(name, float("inf")), b["real_time"])
        unit[name] = b["time_unit"]
    return times, unit


def main(paths):
    runs = [fastest(p) for p in paths]
    names = list(runs[0][0])
    head = " | ".join(f"file {k + 1}" for k in range(len(paths)))
    ratios = " | ".join(f"file 1 / file {k + 1}" for k in range(1, len(paths)))
    print(f"| benchmark | {head} | {ratios} |")
    print("| --- |" + " --- |" * (2 * len(paths) - 1))
    for name in names:
        t = [r[0].get(name) for r in runs]
        cells = " | ".join(f"{x:.4g} {runs[0][1][name]}" if x else "-" for x in t)
        ratio = " | ".join(f"{t[0] / x:.2f}" if x else "-" for x in t[1:])
        print(f"| {name} | {cells} | {ratio} |")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1:])
