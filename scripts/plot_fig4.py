#!/usr/bin/python3
"""Broms & Tornberg Fig. 4 (c-e) from fig4_spheres' JSON lines (run with --pairs).

usage: scripts/plot_fig4.py FIG4.jsonl docs/figures/fig4_spheres.png

Left and middle, one per packing density: the flagged pairs' distances before the contact
forces (at the trial step, over d_try) and after (over d_hat), histograms over all
configurations (Fig. 4c, e). Right: the smallest distance over all pairs after the step
against d_hat, one point per configuration (Fig. 4d).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(source, target):
    rows = [json.loads(line) for line in open(source) if line.strip()]
    rows = [r for r in rows if "pair_d_trial_over_d_try" in r]
    if not rows:
        sys.exit(f"{source}: no per-pair records (run fig4_spheres with --pairs)")
    densities = sorted({r["phi"] for r in rows}, reverse=True)
    fig, axes = plt.subplots(1, len(densities) + 1, figsize=(4.2 * (len(densities) + 1), 3.6))
    bins = np.linspace(-1.0, 3.0, 81)
    for ax, phi in zip(axes, densities):
        sel = [r for r in rows if r["phi"] == phi]
        before = np.concatenate([r["pair_d_trial_over_d_try"] for r in sel])
        after = np.concatenate([r["pair_d_after_over_d_hat"] for r in sel])
        ax.hist(np.clip(before, bins[0], bins[-1]), bins=bins, alpha=0.6, label="before: d / d_try (trial step)")
        ax.hist(np.clip(after, bins[0], bins[-1]), bins=bins, alpha=0.6, label="after: d / d_hat")
        ax.axvline(1.0, color="k", lw=0.8)
        ax.set_yscale("log")
        ax.set_xlabel("normalised distance of flagged pairs (clipped to [-1, 3])")
        ax.set_title(f"packing {phi:.0%}: {len(sel)} configurations, {before.size} pairs")
        ax.legend(fontsize=7)
    ax = axes[-1]
    for phi, marker in zip(sorted(densities), "so"):  # the sparser first: fewer points on top
        sel = [r for r in rows if r["phi"] == phi]
        ax.scatter([r["d_hat"] for r in sel], [r["min_d_over_d_hat_after"] * r["d_hat"] for r in sel], s=8,
                   marker=marker, label=f"packing {phi:.0%}")
    lims = [min(r["d_hat"] for r in rows) * 0.8, max(r["d_hat"] for r in rows) * 1.25]
    ax.plot(lims, lims, "k-", lw=0.8, label="min d = d_hat")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lims)
    ax.set_ylim(lims)
    ax.set_xlabel("d_hat (minimum gap at t)")
    ax.set_ylabel("min d over all pairs at t + dt")
    ax.legend(fontsize=7)
    solver, mobility = rows[0]["solver"], rows[0]["mobility"]
    fig.suptitle(f"Fig. 4: 500 spheres, |f| = 100, dt = 0.01, {mobility} mobility, solver {solver}", fontsize=10)
    fig.tight_layout()
    fig.savefig(target, dpi=130)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
