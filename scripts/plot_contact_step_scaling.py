#!/usr/bin/python3
"""Time per step against the number of spheres (log-log), from contact_step_scaling's JSON lines.

usage: scripts/plot_contact_step_scaling.py RUN.jsonl [RUN.jsonl ...] OUT.png

One curve per cost mode for the contact step, one for the unconstrained step, and a line of
slope 1 through the smallest matrix-free point: O(N) cost lies parallel to it. Also prints the
local slopes d log(time) / d log(N) between successive sizes.
"""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def load(paths):
    rows = []
    for path in paths:
        for line in open(path):
            if line.strip().startswith("{"):
                rows.append(json.loads(line))
    return rows


def main(paths, out):
    rows = load(paths)
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for cost, marker in (("blocks", "D"), ("matrix-free", "o"), ("formed", "s")):
        pts = sorted((r["N"], r["contact_step_s"]) for r in rows if r["cost"] == cost)
        if not pts:
            continue
        ax.loglog(*zip(*pts), marker=marker, label=f"contact step, {cost}")
        for (n0, t0), (n1, t1) in zip(pts, pts[1:]):
            print(f"{cost}: N {n0} -> {n1}: slope {math.log(t1 / t0) / math.log(n1 / n0):.2f}")
    free = sorted({r["N"]: r["unconstrained_s"] for r in rows}.items())
    ax.loglog(*zip(*free), marker="^", linestyle="--", label="unconstrained step (U = M f, Q*)")
    mf = sorted((r["N"], r["contact_step_s"]) for r in rows if r["cost"] == "matrix-free")
    if mf:
        n0, t0 = mf[0]
        n_max = max(n for n, _ in mf)
        ax.loglog([n0, n_max], [t0, t0 * n_max / n0], color="gray", linewidth=0.8, label="slope 1 (O(N))")
    ax.set_xlabel("spheres N")
    ax.set_ylabel("wall time per step [s]")
    ax.set_title("One contact step, free draining, packing 0.3")
    ax.grid(True, which="both", linewidth=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1:-1], sys.argv[-1])
