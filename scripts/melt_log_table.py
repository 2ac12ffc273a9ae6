#!/usr/bin/env python3
"""The per-step diagnostics of brownian_rods --progress (its stderr lines "melt {...}"), one
markdown row per log: steps, steps sub-stepped, steps by status, and the wall time of the
contact steps (all, median, the largest, and the share spent in sub-stepped steps).

    /usr/bin/python3 scripts/melt_log_table.py LOG [LOG ...]

With --cost, the columns of a solver comparison instead (scripts/dense_rod_solver_cost.sh):
medians of flagged pairs, pushed pairs and solver iterations per step, sub-stepped steps, steps
solved again by another solver, the wall time per step (median) and in all, the smallest
min d / d_hat and the largest correction turn over the steps, and how the run ended (the
log's last line when it is not a step: the stepper's message, or the timeout's exit status).

    /usr/bin/python3 scripts/melt_log_table.py --cost LOG [LOG ...]

With --totals, the sums that compare two builds on the same runs: solver iterations in all and
in the first step (the one step two builds solve from the same state, when a run starts from a
checkpoint), the wall time in all and per iteration, the steps not converged (committed within
the separation margin) and sub-stepped, and the smallest min d / d_hat.

    /usr/bin/python3 scripts/melt_log_table.py --totals LOG [LOG ...]
"""
import json
import os
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


def run_end(path):
    """The log's lines after its last step: why the run stopped (empty when it did not)."""
    with open(path) as f:
        lines = [line.strip() for line in f if line.strip()]
    tail = []
    for line in reversed(lines):
        if line.startswith("melt {"):
            break
        tail.append(line)
    return " / ".join(reversed(tail)).replace("|", "/")


def cost_row(path):
    steps = steps_of(path)
    name = os.path.basename(path)
    end = run_end(path) or "ran to the end"
    if not steps:
        return f"| {name} | 0 | | | | | | | | | | {end} |"
    med = lambda key: statistics.median(s[key] for s in steps)
    wall = [s["wall_time_s"] for s in steps]
    substepped = sum(1 for s in steps if s["substeps"] > 1)
    again = sum(1 for s in steps if s["fallbacks"] > 0)
    return (f"| {name} | {len(steps)} | {med('flagged_pairs'):.0f} | {med('active_pairs'):.0f} | "
            f"{med('iterations'):.0f} | {substepped} | {again} | {statistics.median(wall):.3f} | {sum(wall):.1f} | "
            f"{min(s['min_distance_ratio'] for s in steps):.4f} | {max(s['max_correction_turn'] for s in steps):.3f} | "
            f"{end} |")


def totals_row(path):
    steps = steps_of(path)
    if not steps:
        return f"| {path} | 0 | | | | | | | |"
    iterations = sum(s["iterations"] for s in steps)
    wall = sum(s["wall_time_s"] for s in steps)
    not_converged = sum(1 for s in steps if s["status"] != "converged")
    substepped = sum(1 for s in steps if s["substeps"] > 1)
    return (f"| {path} | {len(steps)} | {iterations} | {steps[0]['iterations']} | {wall:.1f} | {1000 * wall / max(iterations, 1):.2f} | "
            f"{not_converged} | {substepped} | {min(s['min_distance_ratio'] for s in steps):.4f} |")


TABLES = {  # option: (header, row of one log)
    "--totals": (["log", "steps", "iterations", "first step's iterations", "wall (s)", "wall per iteration (ms)", "not converged",
                  "sub-stepped", "min d / d_hat"], totals_row),
    "--cost": (["log", "steps", "flagged pairs", "pushed pairs", "iterations", "sub-stepped", "solved again",
                "median step (s)", "all steps (s)", "min d / d_hat", "largest turn (rad)", "end"], cost_row),
    None: (["log", "steps", "sub-stepped", "status", "wall, all steps", "median step", "largest step",
            "wall in sub-stepped steps"], row),
}


def main():
    args = sys.argv[1:]
    option = next((a for a in args if a in TABLES), None)
    paths = [a for a in args if a not in TABLES]
    if not paths:
        sys.exit(__doc__)
    header, make_row = TABLES[option]
    print("| " + " | ".join(header) + " |")
    print("|" + " --- |" * len(header))
    for path in paths:
        print(make_row(path))


if __name__ == "__main__":
    main()
