#!/usr/bin/python3
"""Broms & Tornberg Fig. 7b-d from fig7_rod_chains' JSON lines.

usage: scripts/plot_fig7.py FIG7.jsonl OUT.png

Left (7b): the distances d(lambda) of consecutive rods after the contact step against d_hat,
percentiles over all rods of all chains (whiskers min and max, box 10th-90th, line the median),
with d = d_hat and each d_hat's median d_try. Middle (7c): (d - d_hat) / d_hat at the trial
step (no contact forces) and after, the same statistics. Right (7d): histograms of the contact
force lambda / |f| of the pairs that pushed (lambda > 0), one per d_hat.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def boxes(ax, positions, samples, width, colour, label):
    for x, s in zip(positions, samples):
        s = np.asarray(s)
        lo, p10, p50, p90, hi = np.min(s), *np.percentile(s, [10, 50, 90]), np.max(s)
        ax.plot([x, x], [lo, p10], color=colour, lw=0.8)
        ax.plot([x, x], [p90, hi], color=colour, lw=0.8)
        ax.add_patch(plt.Rectangle((x - width / 2, p10), width, p90 - p10, fill=False, ec=colour))
        ax.plot([x - width / 2, x + width / 2], [p50, p50], color=colour, lw=1.5)
    ax.plot([], [], color=colour, label=label)


def main(source, target):
    chains = [json.loads(line) for line in open(source) if line.strip()]
    chains = [c for c in chains if c["record"] == "chain"]
    d_hats = sorted({c["d_hat"] for c in chains})
    by = {d: [c for c in chains if c["d_hat"] == d] for d in d_hats}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.3))
    ax = axes[0]
    logs = np.log10(d_hats)
    after = [np.concatenate([c["d_after"] for c in by[d]]) for d in d_hats]
    boxes(ax, logs, [np.log10(np.maximum(a, 1e-12)) for a in after], 0.2, "tab:blue", "d(lambda), all rods")
    ax.plot(logs, logs, "k-", lw=0.8, label="d = d_hat")
    ax.plot(logs, [np.log10(np.median([c["d_try"] for c in by[d]])) for d in d_hats], "r^", ms=5,
            label="median d_try")
    ax.set_xlabel("log10 d_hat")
    ax.set_ylabel("log10 d(lambda) (d <= 0 drawn at 1e-12)")
    ax.set_title("7b: distance after the contact step", fontsize=9)
    ax.legend(fontsize=7)
    ax = axes[1]
    before = [np.concatenate([(np.asarray(c["d_before"]) - d) / d for c in by[d]]) for d in d_hats]
    after_rel = [np.concatenate([(np.asarray(c["d_after"]) - d) / d for c in by[d]]) for d in d_hats]
    boxes(ax, logs - 0.12, before, 0.18, "tab:red", "before (trial step)")
    boxes(ax, logs + 0.12, after_rel, 0.18, "tab:blue", "after")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_yscale("symlog", linthresh=1e-4)
    ax.set_xlabel("log10 d_hat")
    ax.set_ylabel("(d - d_hat) / d_hat")
    ax.set_title("7c: relative distance, min / 10% / median / 90% / max", fontsize=9)
    ax.legend(fontsize=7)
    ax = axes[2]
    bins = np.logspace(-5, 1.5, 40)
    for d in d_hats:
        f = np.concatenate([c["lambda_over_f"] for c in by[d]])
        if f.size:
            ax.hist(np.clip(f, bins[0], bins[-1]), bins=bins, histtype="step", label=f"d_hat = {d:g}")
    ax.set_xscale("log")
    ax.set_xlabel("lambda / |f| (pairs with lambda > 0)")
    ax.set_title("7d: contact force over the push", fontsize=9)
    ax.legend(fontsize=7)
    c0 = chains[0]
    fig.suptitle(f"Fig. 7: {len(by[d_hats[0]])} chains of {c0['rods']} rods per d_hat, dt = 0.05, "
                 f"|f| = 2 d_hat^(1/3); {source.split('/')[-1]}", fontsize=9)
    fig.tight_layout()
    fig.savefig(target, dpi=120)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
