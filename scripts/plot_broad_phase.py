#!/usr/bin/python3
"""Broad-phase time per particle versus N, from bench_broad_phase's JSON output.

usage: scripts/plot_broad_phase.py BENCH.json docs/figures/broad_phase.png
Prints a Markdown table of the figures it plots.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(source, target):
    with open(source) as f:
        runs = json.load(f)["benchmarks"]
    series = {}
    for run in runs:
        if run.get("run_type") == "aggregate":
            continue
        family, n = run["name"].split("/")[:2]
        label = "periodic" if "Periodic" in family else "open"
        series.setdefault(label, []).append(
            (int(n), run["time_per_particle"] * 1e9, run["checks_per_particle"]))
    print("| N | open ns/particle | open checks/particle | periodic ns/particle | periodic checks/particle |")
    print("| --- | --- | --- | --- | --- |")
    rows = {n: {} for s in series.values() for n, _, _ in s}
    for label, points in series.items():
        for n, ns, checks in points:
            rows[n][label] = (ns, checks)
    for n in sorted(rows):
        cells = []
        for label in ("open", "periodic"):
            ns, checks = rows[n].get(label, (float("nan"), float("nan")))
            cells += [f"{ns:.0f}", f"{checks:.1f}"]
        print(f"| {n} | " + " | ".join(cells) + " |")
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for label, points in sorted(series.items()):
        points.sort()
        ax.plot([p[0] for p in points], [p[1] for p in points], "o-", label=label)
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("N spheres (packing fraction 0.24)")
    ax.set_ylabel("time per particle [ns]")
    ax.set_title("Cell-list broad phase: O(N) means a flat line")
    ax.legend()
    fig.tight_layout()
    fig.savefig(target, dpi=120)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
