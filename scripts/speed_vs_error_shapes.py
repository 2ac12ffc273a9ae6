#!/usr/bin/python3
"""Speed-versus-error rows for the rod and boomerang scenes, from the drivers' own JSON lines.

usage: scripts/speed_vs_error_shapes.py OUT.jsonl RUN.jsonl [RUN.jsonl ...]

Each RUN is the output of one `fig7_rod_chains` (records "chain") or `fig9_boomerangs`
(records "step") run with one solver and one cost mode; the runs of one scene must use the
same seeds, so that configuration k is the same scene in every run. Per configuration the
solves are scored as `speed_vs_error` scores its sphere scenes (examples/speed_vs_error.cpp):
  shortfall = max(0, 1 - min d / d_hat)
  excess    = sum lambda / best - 1, best = the smallest sum lambda among that configuration's
              solves with min d >= d_hat (1 - 1e-9); null where no solve reaches it
              (0 where best = 0 and this solve pushed nothing either).
Writes the rows to OUT in speed_vs_error's format (scripts/plot_speed_vs_error.py plots
them) and prints the summary table in markdown: per scene, solver and cost mode the median
wall time and applications, the worst shortfall, the median and largest excess and the steps
not converged. Scenes: "rod-chains" (Fig. 7, every d_hat of the run together) and
"boomerangs-MOBILITY" (Fig. 9).
"""
import json
import statistics
import sys

RESPECTS_D_HAT = 1.0 - 1e-9  # examples/common/sphere_experiment.hpp kRespectsDHat


def solves(path):
    """The run's solves as speed_vs_error rows (without shortfall and excess yet)."""
    for line in open(path):
        if not line.strip():
            continue
        r = json.loads(line)
        if r.get("record") == "chain":
            yield {"scene": "rod-chains", "config": f"{r['d_hat']:.6g}/{r['chain']}", "d_hat": r["d_hat"],
                   "mobility": r["mobility"], "directions": r["directions"], "solver": r["solver"],
                   "cost": r["cost"], "nc": r["nc"], "min_d_over_d_hat_after": r["min_d_over_d_hat"],
                   "mobility_applications": r["mobility_applications"], "wall_time_s": r["wall_time_s"],
                   "lambda_sum": r["lambda_sum"], "status": r["status"]}
        elif r.get("record") == "step":
            mobility = r["mobility"] + ("" if r["mobility"] == "free-draining" else f"-{r['blob_model']}")
            yield {"scene": f"boomerangs-{mobility}", "config": r["config"], "d_hat": r["d_hat"],
                   "mobility": mobility, "directions": r["directions"], "solver": r["solver"], "cost": r["cost"],
                   "nc": r["flagged"], "min_d_over_d_hat_after": r["min_d_over_d_hat_after"],
                   "mobility_applications": r["applications"], "wall_time_s": r["wall_time_s"],
                   "lambda_sum": r["lambda_sum"], "status": r["status"]}


def score(rows):
    """Shortfall and excess per row, against the best separated solve of its configuration."""
    by_config = {}
    for r in rows:
        by_config.setdefault((r["scene"], r["config"]), []).append(r)
    for group in by_config.values():
        separated = [r["lambda_sum"] for r in group if r["min_d_over_d_hat_after"] >= RESPECTS_D_HAT]
        best = min(separated) if separated else None
        for r in group:
            r["shortfall"] = max(0.0, 1.0 - r["min_d_over_d_hat_after"])
            if best is None:
                r["excess"] = None
            elif best > 0.0:
                r["excess"] = r["lambda_sum"] / best - 1.0
            else:
                r["excess"] = 0.0 if r["lambda_sum"] == 0.0 else None


def table(rows):
    groups = {}
    for r in rows:
        groups.setdefault((r["scene"], r["solver"], r["cost"]), []).append(r)
    print("| scene | solver | cost | configs | median wall | median applications | worst shortfall | median excess "
          "| max excess | not converged |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for (scene, solver, cost), rs in groups.items():
        excess = [r["excess"] for r in rs if r["excess"] is not None]
        print(f"| {scene} | {solver} | {cost} | {len(rs)} | {statistics.median(r['wall_time_s'] for r in rs):.4f} s "
              f"| {statistics.median(r['mobility_applications'] for r in rs):g} "
              f"| {max(r['shortfall'] for r in rs):.2e} "
              f"| {statistics.median(excess) if excess else float('nan'):.2e} "
              f"| {max(excess) if excess else float('nan'):.2e} "
              f"| {sum(r['status'] != 'converged' for r in rs)} |")


def main(target, sources):
    rows = [row for path in sources for row in solves(path)]
    if not rows:
        sys.exit("no chain or step records in " + ", ".join(sources))
    keys = {}
    for r in rows:  # one solve per (configuration, solver, cost): a repeated run would score twice
        key = (r["scene"], r["config"], r["solver"], r["cost"])
        if key in keys:
            sys.exit(f"two solves of {key} (the same run given twice?)")
        keys[key] = r
    score(rows)
    with open(target, "w") as out:
        for r in rows:
            out.write(json.dumps(r, separators=(",", ":")) + "\n")
    table(rows)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
