#!/usr/bin/env python3
"""Z of Brownian spherocylinders against the step size, from brownian_rods' JSON lines
(any number of files; runs of one seed at several --dt may come from several files), and its
extrapolation to dt -> 0, run by run and for the runs together:

    /usr/bin/python3 scripts/rod_eos_fit.py [--plot FIGURE.png] RUNS.jsonl [RUNS.jsonl ...]

Per run (a seed and its melt), and for the mean over the runs at each dt (error bars combined
in quadrature): Z at each dt D_R, the weighted straight line Z = Z_0 + c sqrt(dt) (weights 1 / error^2, as
brownian_rods' own "dt -> 0" row, examples/common/brownian_pressure.hpp) with its chi^2 per
degree of freedom, and with three or more step sizes the line through the smallest two and
the parabola Z = Z_0 + c1 sqrt(dt) + c2 dt, each against McGrother et al.'s Monte Carlo Z
where the runs carry it (`mcgrother_Z`).
"""
import argparse
import json
import math

import numpy as np


def load(paths):
    """(eta, run) -> {dt: record}; only the passive (U0 = 0) runs. A run is a seed and its
    melt (older files without a seed field: the file), so that one start is never mixed with
    another's."""
    runs = {}
    for path in paths:
        with open(path) as f:
            for line in f:
                r = json.loads(line)
                if r.get("u0_over_L_DR", 0) != 0 or "Z" not in r or r.get("extrapolated"):
                    continue
                run = f"seed {r['seed']}, melt {r.get('melt', 0):g}" if "seed" in r else path
                runs.setdefault((round(r["eta"], 6), run), {})[r["dt_D_R"]] = r
    return runs


def weighted_fit(x, z, err, degree):
    """Z = sum_k a_k x^k by weighted least squares; (coefficients, their covariance, chi^2 / dof)."""
    X = np.vander(np.asarray(x), degree + 1, increasing=True)
    w = 1.0 / np.asarray(err) ** 2
    normal = X.T @ (w[:, None] * X)
    covariance = np.linalg.inv(normal)
    a = covariance @ (X.T @ (w * np.asarray(z)))
    dof = len(x) - degree - 1
    chi2 = float(np.sum(w * (np.asarray(z) - X @ a) ** 2)) / dof if dof > 0 else float("nan")
    return a, covariance, chi2


def fits(points):
    """points: [(dt, Z, error)] -> [(name, Z_0, error, chi^2 / dof)]."""
    points = sorted(points)
    x = [math.sqrt(p[0]) for p in points]
    z = [p[1] for p in points]
    e = [p[2] for p in points]
    out = []
    if len(points) >= 2:
        a, c, chi2 = weighted_fit(x, z, e, 1)
        out.append(("line, every dt", a[0], math.sqrt(c[0, 0]), chi2))
    if len(points) >= 3:
        a, c, chi2 = weighted_fit(x[:2], z[:2], e[:2], 1)
        out.append(("line, smallest two dt", a[0], math.sqrt(c[0, 0]), chi2))
        a, c, chi2 = weighted_fit(x, z, e, 2)
        out.append(("parabola in sqrt(dt)", a[0], math.sqrt(c[0, 0]), chi2))
    return out


def against(z0, error, reference):
    """Z_0 against the Monte Carlo Z, in percent and in error bars of Z_0."""
    if not reference:
        return ""
    return f"{100 * (z0 / reference - 1):+.1f}% ({abs(z0 - reference) / error:.1f} error bars)"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--plot", help="write Z against sqrt(dt D_R) with the fits to this file")
    args = parser.parse_args()
    runs = load(args.runs)
    by_eta = {}
    for (eta, run), per_dt in sorted(runs.items()):
        by_eta.setdefault(eta, {})[run] = per_dt
    panels = []
    for eta, runs_at in by_eta.items():
        reference = next(iter(next(iter(runs_at.values())).values())).get("mcgrother_Z")
        print(f"eta {eta}" + (f", McGrother et al. Z = {reference:.4f}" if reference else ""))
        print("| run | dt D_R: Z +- error (S) | fit | Z_0 | chi^2 / dof | Z_0 against McGrother |")
        print("| --- | --- | --- | --- | --- | --- |")
        series = []
        for run, per_dt in runs_at.items():
            points = [(dt, r["Z"], r["Z_error"]) for dt, r in per_dt.items()]
            label = ", ".join(f"{dt:g}: {r['Z']:.3f} +- {r['Z_error']:.3f}"
                              + (f" (S {r['nematic_order']:.2f})" if "nematic_order" in r else "")
                              for dt, r in sorted(per_dt.items()))
            series.append((run, points))
            if len(points) < 2:
                print(f"| {run} | {label} | - | | | |")
            for name, z0, err, chi2 in fits(points):
                print(f"| {run} | {label} | {name} | {z0:.3f} +- {err:.3f} | {chi2:.2f} | {against(z0, err, reference)} |")
        common = sorted(set.intersection(*[set(p) for p in runs_at.values()]))
        if len(runs_at) > 1 and len(common) >= 2:
            points = []
            for dt in common:
                zs = [per_dt[dt]["Z"] for per_dt in runs_at.values()]
                es = [per_dt[dt]["Z_error"] for per_dt in runs_at.values()]
                points.append((dt, sum(zs) / len(zs), math.sqrt(sum(e * e for e in es)) / len(es)))
            series.append(("mean of the runs", points))
            label = ", ".join(f"{dt:g}: {z:.3f} +- {e:.3f}" for dt, z, e in points)
            for name, z0, err, chi2 in fits(points):
                print(f"| mean of {len(runs_at)} | {label} | {name} | {z0:.3f} +- {err:.3f} | {chi2:.2f} | {against(z0, err, reference)} |")
        panels.append((eta, reference, series))
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4), squeeze=False)
        for ax, (eta, reference, series) in zip(axes[0], panels):
            for label, points in series:
                points = sorted(points)
                x = [math.sqrt(p[0]) for p in points]
                drawn = ax.errorbar(x, [p[1] for p in points], yerr=[p[2] for p in points], marker="o", ls="none",
                                    capsize=3, label=label)
                color = drawn.lines[0].get_color()
                grid = np.linspace(0.0, max(x), 50)
                if len(points) >= 2:
                    a, _, _ = weighted_fit(x, [p[1] for p in points], [p[2] for p in points], 1)
                    ax.plot(grid, a[0] + a[1] * grid, lw=0.8, color=color, ls=":")
                if len(points) >= 3:
                    a, _, _ = weighted_fit(x, [p[1] for p in points], [p[2] for p in points], 2)
                    ax.plot(grid, a[0] + a[1] * grid + a[2] * grid ** 2, lw=0.8, color=color)
            if reference:
                ax.axhline(reference, color="k", ls="--", lw=0.8, label="McGrother et al. 1996 (MC)")
            ax.set_xlabel("sqrt(dt D_R)")
            ax.set_ylabel("Z = P / (n kT)")
            ax.set_title(f"L/D = 5 spherocylinders, eta = {eta}\n(dotted: line in sqrt(dt), solid: parabola)", fontsize=10)
            ax.set_xlim(left=0.0)
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)


if __name__ == "__main__":
    main()
