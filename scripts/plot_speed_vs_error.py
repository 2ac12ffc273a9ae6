#!/usr/bin/python3
"""Cost of a contact step versus its error per solver and scene, from speed_vs_error's JSON lines.

usage: scripts/plot_speed_vs_error.py SPEED_VS_ERROR.jsonl [MORE.jsonl ...] docs/figures/speed_vs_error.png

The inputs are speed_vs_error's rows and, in the same format, those of
scripts/speed_vs_error_shapes.py (the rod and boomerang scenes).

One point per (scene, solver, cost mode): the median over the scene's configurations of the
wall time (left) and of the mobility applications (right), against the worst error over them,
error = max(shortfall, excess) per solve:
  shortfall = max(0, 1 - min d / d_hat)   how far the step falls short of d_hat,
  excess    = sum lambda / best - 1       how much more force than the cheapest solve that
                                          respects d_hat (to 1e-9); a missing excess counts 0.
Marker = solver, colour = scene; filled = formed cost mode, open = matrix-free.
Errors below 1e-12 are drawn at 1e-12.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

MARKERS = "osD^v<>pPX*h"
FLOOR = 1e-12


def error(row):
    return max(row["shortfall"], row["excess"] or 0.0, FLOOR)


def groups(rows):
    """(scene, solver, cost) -> rows, in first-seen order."""
    out = {}
    for r in rows:
        out.setdefault((r["scene"], r["solver"], r["cost"]), []).append(r)
    return out


def main(sources, target):
    rows = [json.loads(line) for source in sources for line in open(source) if line.strip()]
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    solvers = list(dict.fromkeys(r["solver"] for r in rows))
    colours = {s: f"C{k}" for k, s in enumerate(scenes)}
    markers = {s: MARKERS[k % len(MARKERS)] for k, s in enumerate(solvers)}
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2), sharex=True)
    for (scene, solver, cost), rs in groups(rows).items():
        x = max(error(r) for r in rs)
        for ax, key in zip(axes, ("wall_time_s", "mobility_applications")):
            y = max(np.median([r[key] for r in rs]), 0.5 if key == "mobility_applications" else 1e-5)
            ax.loglog([x], [y], markers[solver], color=colours[scene], markersize=7,
                      markerfacecolor=colours[scene] if cost == "formed" else "none")
    for ax, label in zip(axes, ("median wall time per step [s]", "median mobility applications per step")):
        ax.set_xlabel("worst error over configurations: max(shortfall, excess)")
        ax.set_ylabel(label)
        ax.grid(True, which="major", alpha=0.3)
    # Two legends: colour = scene, marker = solver (filled: formed, open: matrix-free).
    scene_handles = [plt.Line2D([], [], color=colours[s], marker="s", linestyle="", label=s) for s in scenes]
    solver_handles = [plt.Line2D([], [], color="0.3", marker=markers[s], linestyle="", label=s) for s in solvers]
    axes[0].legend(handles=scene_handles, title="scene", fontsize=8, loc="upper left")
    axes[1].legend(handles=solver_handles, title="solver (filled: formed)", fontsize=8, loc="upper left",
                   ncol=2)
    mobility = ", ".join(sorted({r["mobility"] for r in rows}))
    fig.suptitle(f"Contact step cost versus error ({mobility} mobility)")
    fig.tight_layout()
    fig.savefig(target, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1:-1], sys.argv[-1])
