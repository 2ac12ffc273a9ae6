#!/usr/bin/python3
"""Broms & Tornberg Fig. 8d-e from fig8_biaxial's JSON lines: the order parameter S(t) (eq. 33)
and the largest |x| of any rod, for each contact-direction choice.

usage: scripts/plot_fig8.py OUT.png RUN.jsonl[.gz] [RUN.jsonl[.gz] ...]

One panel per (d_hat, dt): S(t) of every run file (one line per file: its solver and contact
directions, d^P = particle, d^S = surface, line = line contacts). A run that stopped early (a
failed separation) ends in a cross. The bottom row: max |x_i| against t, same lines.
"""
import gzip
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"particle": ("tab:blue", "d^P (particle)"), "surface": ("tab:orange", "d^S (surface)"),
         "line": ("tab:green", "line contacts"), "overlap-ends": ("tab:red", "overlap ends")}
DASH = {"default": "-", "lcp-newton": "--"}


def load(path):
    steps, summaries = [], []
    for line in (gzip.open(path, "rt") if path.endswith(".gz") else open(path)):
        if not line.strip():
            continue
        r = json.loads(line)
        (steps if r["record"] == "step" else summaries).append(r)
    return steps, summaries


def main(target, sources):
    runs = [load(p) for p in sources]
    keys = sorted({(s["d_hat_over_R"], s["dt"]) for _, sums in runs for s in sums}, key=lambda k: (k[0], -k[1]))
    fig, axes = plt.subplots(2, len(keys), figsize=(3.3 * len(keys), 6.0), squeeze=False, sharex=True)
    for col, (d_hat, dt) in enumerate(keys):
        top, bottom = axes[0][col], axes[1][col]
        for steps, sums in runs:
            summary = [s for s in sums if (s["d_hat_over_R"], s["dt"]) == (d_hat, dt)]
            if not summary:
                continue
            s = summary[0]
            sel = [r for r in steps if (r["d_hat_over_R"], r["dt"]) == (d_hat, dt)]
            t = [0.0] + [r["t"] for r in sel]
            S = [1.0] + [r["S"] for r in sel]
            x = [0.0] + [r["max_abs_x"] for r in sel]
            colour, label = STYLE[s["directions"]]
            style = DASH.get(s["solver"], ":")
            top.plot(t, S, style, color=colour, lw=1.1, label=f"{label}, {s['solver']}")
            bottom.plot(t, [max(v, 1e-17) for v in x], style, color=colour, lw=1.1)
            if s["error"]:
                top.plot(t[-1], S[-1], "x", color=colour, ms=7)
                bottom.plot(t[-1], max(x[-1], 1e-17), "x", color=colour, ms=7)
        top.axhline(0.999, color="k", lw=0.6, ls=":")
        top.axvline(4.36, color="grey", lw=0.6, ls=":")
        top.set_ylim(-0.55, 1.05)
        top.set_title(f"d_hat = {d_hat:g} R_rod, dt = {dt:g}", fontsize=9)
        bottom.set_yscale("log")
        bottom.set_ylim(1e-17, 10.0)
        bottom.axhline(1e-6, color="k", lw=0.6, ls=":")
        bottom.set_xlabel("t")
    axes[0][0].set_ylabel("S (eq. 33)")
    axes[1][0].set_ylabel("max |x_i| (0 drawn at 1e-17)")
    axes[0][0].legend(fontsize=6, loc="lower left")
    fig.suptitle("Fig. 8d-e: 30 rods in biaxial compression (eq. 32), free draining; x: run stopped "
                 "(failed separation); dotted: S = 0.999, |x| = 1e-6, the paper's T_S = 4.36", fontsize=9)
    fig.tight_layout()
    fig.savefig(target, dpi=120)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
