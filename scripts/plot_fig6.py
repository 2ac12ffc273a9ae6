#!/usr/bin/python3
"""Broms & Tornberg Fig. 5b against Fig. 6 from fig4_spheres --table1 JSON lines.

usage: scripts/plot_fig6.py SUM.jsonl DISSIPATION.jsonl docs/figures/fig6_extra_pairs.png

The "extra" pairs are those flagged at d_try x 1.1 or x 1.2 but not at d_try x 1 (TOL 5e-6,
the driver's "extra_pairs" records). Histograms of their lambda / |f|, one panel per
objective of eq. 14: the sum of lambda (Fig. 5b) and the dissipation lambda^T D^T M D lambda
(Fig. 6). Prints per objective and multiplier: how many extra pairs, how many carry a force
above 1e-6 |f|, their median and largest lambda / |f|.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

FORCE_FLOOR = 1e-6  # lambda / |f| below this counts as no force (the histogram's left edge)


def extra_pairs(source):
    rows = [json.loads(line) for line in open(source) if line.strip()]
    rows = [r for r in rows if r.get("record") == "extra_pairs"]
    if not rows:
        sys.exit(f"{source}: no extra_pairs records (run fig4_spheres --table1)")
    objectives = {r["objective"] for r in rows}
    if len(objectives) != 1:
        sys.exit(f"{source}: records of several objectives {sorted(objectives)}")
    by_multiplier = {}
    for r in rows:
        by_multiplier.setdefault(r["d_try_multiplier"], []).extend(r["lambda_over_f"])
    configs = len({r["config"] for r in rows})
    return objectives.pop(), configs, {m: np.array(v) for m, v in sorted(by_multiplier.items())}


def main(sum_source, dissipation_source, target):
    panels = [extra_pairs(sum_source), extra_pairs(dissipation_source)]
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.6), sharey=True)
    bins = np.logspace(np.log10(FORCE_FLOOR), 1, 43)
    print(f"{'objective':<12} {'d_try':<6} {'configs':>7} {'extra pairs':>11} {'with force':>10} "
          f"{'median':>9} {'max':>9}  (lambda / |f|, force: > {FORCE_FLOOR:g})")
    for ax, (objective, configs, by_multiplier) in zip(axes, panels):
        for multiplier, values in by_multiplier.items():
            forced = values[values > FORCE_FLOOR]
            median = np.median(forced) if forced.size else 0.0
            largest = forced.max() if forced.size else 0.0
            print(f"{objective:<12} x {multiplier:<4.1f} {configs:7d} {values.size:11d} {forced.size:10d} "
                  f"{median:9.3g} {largest:9.3g}")
            ax.hist(np.clip(values, bins[0], bins[-1]), bins=bins, alpha=0.6,
                    label=f"d_try x {multiplier:g}: {forced.size} of {values.size} pairs with force")
        ax.set_xscale("log")
        ax.set_xlabel(f"lambda / |f| of the extra pairs (clipped to [{FORCE_FLOOR:g}, 10])")
        title = "sum of lambda (Fig. 5b)" if objective == "sum" else "dissipation (Fig. 6)"
        ax.set_title(f"{title}, {configs} configurations", fontsize=10)
        ax.legend(fontsize=7)
    axes[0].set_ylabel("pairs")
    fig.tight_layout()
    fig.savefig(target, dpi=130)
    print(f"wrote {target}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
