#!/usr/bin/python3
"""The nematic order parameter S against time from brownian_rods --progress logs (stderr
lines "melt {...}" with "nematic_order"), one curve per log.

usage: scripts/plot_nematic_order.py OUT.png DT_D_R LABEL=LOG[,LOG...] [LABEL=LOG[,LOG...] ...]

DT_D_R: the melt's step in rotational times (--melt-dt); time is step x DT_D_R. Several logs
of one label are one run continued (brownian_rods --load-state): each log's steps count on
from the previous log's last logged step (so --progress must divide the melt's steps);
LOG:STEP keeps a log's lines up to that step (a run branched from a checkpoint of another:
the other's log up to the checkpoint, then the branch's log), and LOG@DT (LOG:STEP@DT) gives
that log its own step in rotational times (a branch run at another --melt-dt). Prints per
run: the last time, S at the start and the end, and the mean and spread of S over the last
quarter of the logged time.
"""
import json
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def order_of(paths, dt):
    """Times (t D_R) and S of one run, its logs one after the other."""
    times, order = [], []
    for spec in paths.split(","):
        spec, _, own_dt = spec.partition("@")
        path, _, last = spec.partition(":")
        step_dt = float(own_dt) if own_dt else dt
        with open(path) as f:
            lines = [json.loads(line[len("melt "):]) for line in f if line.startswith("melt {")]
        if last:
            lines = [s for s in lines if s["step"] <= int(last)]
        if not lines or "nematic_order" not in lines[0]:
            sys.exit(f"{path}: no melt lines with nematic_order (run brownian_rods with --progress K)")
        offset = times[-1] if times else 0.0
        times += [offset + s["step"] * step_dt for s in lines]
        order += [s["nematic_order"] for s in lines]
    return times, order


def main():
    if len(sys.argv) < 4 or any("=" not in a for a in sys.argv[3:]):
        sys.exit(__doc__)
    out, dt = sys.argv[1], float(sys.argv[2])
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    print("| run | last t D_R | S at the first line | S at the last | S over the last quarter (mean +- sd) |")
    print("| --- | --- | --- | --- | --- |")
    for spec in sys.argv[3:]:
        label, path = spec.split("=", 1)
        t, order = order_of(path, dt)
        tail = [s for ts, s in zip(t, order) if ts >= 0.75 * t[-1]]
        spread = statistics.stdev(tail) if len(tail) > 1 else 0.0
        print(f"| {label} | {t[-1]:.2f} | {order[0]:.3f} | {order[-1]:.3f} | "
              f"{statistics.mean(tail):.3f} +- {spread:.3f} |")
        ax.plot(t, order, label=label)
    ax.set_xlabel("t D_R")
    ax.set_ylabel("nematic order S")
    ax.set_ylim(0.0, 1.0)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)


if __name__ == "__main__":
    main()
