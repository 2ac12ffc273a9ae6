#!/usr/bin/python3
"""Broms & Tornberg Fig. 9 (b, c) from fig9_boomerangs' JSON lines.

usage: scripts/plot_fig9.py FIG9.jsonl [MORE.jsonl ...] docs/figures/fig9_boomerangs.png

Left (9b): the smallest distance over all pairs after the contact step against d_hat, one
point per configuration and per input file (a mobility model or solver). Right (9c): the
flagged pairs' distances d^P before the contact forces (at the trial step) and after, over
d_hat, histograms over all configurations of the first file.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    rows = [json.loads(line) for line in open(path) if line.strip()]
    rows = [r for r in rows if r.get("record") == "step" and "pair_d_before" in r]
    if not rows:
        sys.exit(f"{path}: no fig9_boomerangs step records")
    return rows


def label(rows):
    return f"{rows[0]['mobility']}, {rows[0]['solver']}"


def main(sources, target):
    sets = [load(s) for s in sources]
    fig, (ax_b, ax_c) = plt.subplots(1, 2, figsize=(10.0, 4.0))
    lo = min(r["d_hat"] for rows in sets for r in rows) * 0.8
    hi = max(r["d_hat"] * max(1.0, r["min_d_over_d_hat_after"]) for rows in sets for r in rows) * 1.25
    for rows, marker in zip(sets, "os^dv"):
        ax_b.scatter([r["d_hat"] for r in rows], [r["min_d_over_d_hat_after"] * r["d_hat"] for r in rows], s=9,
                     marker=marker, alpha=0.7, label=label(rows))
    ax_b.plot([lo, hi], [lo, hi], "k-", lw=0.8, label="min d = d_hat")
    ax_b.set_xscale("log")
    ax_b.set_yscale("log")
    ax_b.set_xlim(lo, hi)
    ax_b.set_ylim(lo, hi)
    ax_b.set_xlabel("d_hat (minimum gap at t)")
    ax_b.set_ylabel("min d over all pairs at t + dt")
    ax_b.set_title("9b")
    ax_b.legend(fontsize=7)
    rows = sets[0]
    before = np.concatenate([np.array(r["pair_d_before"]) / r["d_hat"] for r in rows])
    after = np.concatenate([np.array(r["pair_d_after"]) / r["d_hat"] for r in rows])
    bins = np.linspace(-10.0, 20.0, 121)
    for values, name in ((before, "before (trial step)"), (after, "after")):
        ax_c.hist(np.clip(values, bins[0], bins[-1]), bins=bins, alpha=0.6, label=name)
    ax_c.axvline(1.0, color="k", lw=0.8)
    ax_c.set_yscale("log")
    ax_c.set_xlabel("d / d_hat of flagged pairs (clipped to [-10, 20])")
    ax_c.set_title(f"9c: {label(rows)}, {len(rows)} configurations, {before.size} pairs")
    ax_c.legend(fontsize=7)
    fig.suptitle(f"Fig. 9: {rows[0]['boomerangs']} boomerangs, side {rows[0]['side']:g}, |F_ext| = 100, dt = 0.01, "
                 f"{rows[0]['directions']} directions", fontsize=10)
    fig.tight_layout()
    fig.savefig(target, dpi=130)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1:-1], sys.argv[-1])
