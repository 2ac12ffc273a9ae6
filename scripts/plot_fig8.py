#!/usr/bin/python3
"""Broms & Tornberg Fig. 8d-e from fig8_biaxial's JSON lines: the order parameter S(t) (eq. 33)
and the largest |x| of any rod, for each contact-direction choice.

usage: scripts/plot_fig8.py [--dt DT] OUT.png RUN.jsonl[.gz] [RUN.jsonl[.gz] ...]

One panel per (d_hat, dt) (only those of time step DT with --dt): S(t) of every run file (one
line per file: its solver and contact directions, d^P = particle, d^S = surface, line = line
contacts; multiblob runs in black, free-draining ones in their directions' colour; a run
whose rods start turned, fig8_biaxial --tilt, read from its first step, dash-dotted). A run that
stopped early (a failed separation) ends in a cross. The second row: max |x_i| against t, the
third: the largest rod turn from the start orientation (max_turn), same lines.
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


def main(target, sources, only_dt=None):
    runs = [load(p) for p in sources]
    keys = sorted({(s["d_hat_over_R"], s["dt"]) for _, sums in runs for s in sums
                   if only_dt is None or s["dt"] == only_dt}, key=lambda k: (k[0], -k[1]))
    fig, axes = plt.subplots(3, len(keys), figsize=(3.3 * len(keys) + 1.0, 8.5), squeeze=False, sharex=True)
    for col, (d_hat, dt) in enumerate(keys):
        top, bottom, turns = axes[0][col], axes[1][col], axes[2][col]
        for steps, sums in runs:
            summary = [s for s in sums if (s["d_hat_over_R"], s["dt"]) == (d_hat, dt)]
            if not summary:
                continue
            s = summary[0]
            sel = [r for r in steps if (r["d_hat_over_R"], r["dt"]) == (d_hat, dt)]
            t = [0.0] + [r["t"] for r in sel]
            S = [1.0] + [r["S"] for r in sel]
            x = [0.0] + [r["max_abs_x"] for r in sel]
            tilt = sel[0]["max_turn"] if sel else 0.0
            turn = [tilt] + [r["max_turn"] for r in sel]
            colour, label = STYLE[s["directions"]]
            label = f"{label}, {s['solver']}"
            if s.get("mobility") == "multiblob":
                colour, label = "k", label + ", multiblob"
            style = DASH.get(s["solver"], ":")
            if tilt > 0.0:
                style, label = "-.", label + f", tilt {tilt:.0e}"
            top.plot(t, S, style, color=colour, lw=1.1, label=label)
            bottom.plot(t, [max(v, 1e-17) for v in x], style, color=colour, lw=1.1)
            turns.plot(t, [max(v, 1e-17) for v in turn], style, color=colour, lw=1.1)
            if s["error"]:
                top.plot(t[-1], S[-1], "x", color=colour, ms=7)
                bottom.plot(t[-1], max(x[-1], 1e-17), "x", color=colour, ms=7)
                turns.plot(t[-1], max(turn[-1], 1e-17), "x", color=colour, ms=7)
        top.axhline(0.999, color="k", lw=0.6, ls=":")
        top.axvline(4.36, color="grey", lw=0.6, ls=":")
        top.set_ylim(-0.55, 1.05)
        top.set_title(f"d_hat = {d_hat:g} R_rod, dt = {dt:g}", fontsize=9)
        bottom.set_yscale("log")
        bottom.set_ylim(1e-17, 10.0)
        bottom.axhline(1e-6, color="k", lw=0.6, ls=":")
        turns.set_yscale("log")
        turns.set_ylim(1e-17, 10.0)
        turns.set_xlabel("t")
    axes[0][0].set_ylabel("S (eq. 33)")
    axes[1][0].set_ylabel("max |x_i| (0 drawn at 1e-17)")
    axes[2][0].set_ylabel("max rod turn, rad (0 at 1e-17)")
    axes[0][0].legend(fontsize=6, loc="lower left")
    fig.suptitle("Fig. 8d-e: 30 rods in biaxial compression (eq. 32), free draining unless multiblob;\nx: run stopped "
                 "(failed separation); dotted: S = 0.999, |x| = 1e-6, the paper's T_S = 4.36", fontsize=9)
    fig.tight_layout()
    fig.savefig(target, dpi=120)


if __name__ == "__main__":
    args = sys.argv[1:]
    dt = None
    if args[:1] == ["--dt"]:
        if len(args) < 2:
            sys.exit(__doc__)
        dt, args = float(args[1]), args[2:]
    if len(args) < 2:
        sys.exit(__doc__)
    main(args[0], args[1:], dt)
