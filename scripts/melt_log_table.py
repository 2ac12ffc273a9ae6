#!/usr/bin/env python3
"""The per-step diagnostics of brownian_rods --progress (its stderr lines "melt {...}"), one
markdown row per log: steps, steps sub-stepped, steps by status, and the wall time of the
contact steps (all, median, the largest, and the share spent in sub-stepped steps).

    /usr/bin/python3 scripts/melt_log_table.py LOG [LOG ...]
"""
import json
import statistics
import sys


def steps_of(path):
    with open(path) as f:
        return [json.loads(line[len("melt "):]) for line in f if line.startswith("melt {")]


def row(path):
    steps = steps_of(path)
    if not steps:
        return f"| {path} | 0 | | | | | | |"
    wall = [s["wall_time_s"] for s in steps]
    substepped = [s for s in steps if s["substeps"] > 1]
    statuses = {}
    for s in steps:
        statuses[s["status"]] = statuses.get(s["status"], 0) + 1
    status = ", ".join(f"{count} {name}" for name, count in sorted(statuses.items()))
    share = sum(s["wall_time_s"] for s in substepped) / sum(wall)
    return (f"| {path} | {len(steps)} | {len(substepped)} | {status} | {sum(wall):.1f} s | "
            f"{statistics.median(wall):.2f} s | {max(wall):.1f} s | {100 * share:.0f}% |")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print("| log | steps | sub-stepped | status | wall, all steps | median step | largest step | wall in sub-stepped steps |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for path in sys.argv[1:]:
        print(row(path))


if __name__ == "__main__":
    main()
