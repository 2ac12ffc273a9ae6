#!/usr/bin/python3
"""Two-sphere mobility error versus gap per model, from pair_mobility_accuracy's JSON lines.

usage: scripts/plot_pair_mobility.py ACCURACY.jsonl docs/figures/pair_mobility.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FUNCTIONS = [("x11a", "self, along the line"), ("x12a", "mutual, along the line"),
             ("y11c", "self rotation, across")]


def main(source, target):
    rows = [json.loads(line) for line in open(source) if line.strip()]
    models = sorted({r["model"] for r in rows}, key=lambda m: (m != "rpy", len(m), m))
    fig, axes = plt.subplots(1, len(FUNCTIONS), figsize=(12, 3.6), sharey=True)
    for ax, (name, title) in zip(axes, FUNCTIONS):
        for model in models:
            pts = sorted((r["gap"], abs(r[name] - r[name + "_exact"])) for r in rows if r["model"] == model)
            ax.loglog([p[0] for p in pts], [max(p[1], 1e-12) for p in pts], "o-", label=model)
        ax.set_title(f"{name}: {title}")
        ax.set_xlabel("gap / a")
    axes[0].set_ylabel("|model - exact|")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(target, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
