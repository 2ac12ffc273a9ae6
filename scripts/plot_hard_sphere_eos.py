#!/usr/bin/python3
"""The equation of state of Brownian hard spheres from brownian_hard_spheres' JSON lines.

Left: Z against the packing fraction eta, one marker per step size and the dt -> 0
extrapolation, with Carnahan-Starling. Right: Z / Z_CS - 1 against sqrt(dt) per packing
fraction, with the fitted line down to dt = 0.

usage: /usr/bin/python3 scripts/plot_hard_sphere_eos.py EOS.jsonl OUT.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def carnahan_starling(eta):
    return (1 + eta + eta**2 - eta**3) / (1 - eta) ** 3


def main(path, out):
    rows = [json.loads(line) for line in open(path) if line.strip()]
    measured = [r for r in rows if not r.get("extrapolated")]
    extrapolated = [r for r in rows if r.get("extrapolated")]
    d_hat = measured[0]["d_hat"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    eta = np.linspace(0.0, 0.48, 200)
    left.plot(eta, carnahan_starling(eta), "k-", lw=1, label="Carnahan-Starling")
    for dt in sorted({r["dt"] for r in measured}, reverse=True):
        sel = [r for r in measured if r["dt"] == dt]
        left.errorbar([r["eta"] for r in sel], [r["Z"] for r in sel], yerr=[r["Z_error"] for r in sel], fmt="o",
                      ms=4, capsize=2, label=f"dt = {dt:g}")
    if extrapolated:
        etas = [r["phi"] * (1 + 0.5 * d_hat) ** 3 for r in extrapolated]
        left.errorbar(etas, [r["Z"] for r in extrapolated], yerr=[r["Z_error"] for r in extrapolated], fmt="s",
                      mfc="none", ms=7, capsize=3, color="k", label="dt -> 0")
    left.set_xlabel("eta = phi (1 + d_hat / 2a)^3")
    left.set_ylabel("Z = P / (n kT)")
    left.set_yscale("log")
    left.legend(fontsize=8)
    left.set_title(f"Brownian hard spheres, N = {measured[0]['N']}")
    for phi in sorted({r["phi"] for r in measured}):
        sel = sorted((r for r in measured if r["phi"] == phi), key=lambda r: r["dt"])
        s = np.sqrt([r["dt"] for r in sel])
        dev = np.array([r["Z"] / r["Z_CS"] - 1 for r in sel])
        err = np.array([r["Z_error"] / r["Z_CS"] for r in sel])
        line = right.errorbar(s, 100 * dev, yerr=100 * err, fmt="o-", ms=4, capsize=2, label=f"phi = {phi:g}")
        fit = [r for r in extrapolated if r["phi"] == phi]
        if fit:
            x = np.array([0.0, s.max()])
            z = fit[0]["Z"] + fit[0]["slope_sqrt_dt"] * x
            right.plot(x, 100 * (z / fit[0]["Z_CS"] - 1), "--", color=line[0].get_color(), lw=1)
    right.axhline(0, color="k", lw=0.8)
    right.set_xlabel("sqrt(dt)  (time unit a^2 / D0)")
    right.set_ylabel("Z / Z_CS - 1  (%)")
    right.set_xlim(left=0)
    right.legend(fontsize=8)
    right.set_title("step-size error and its extrapolation")
    fig.tight_layout()
    fig.savefig(out, dpi=120)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
