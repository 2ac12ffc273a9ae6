#!/usr/bin/env python3
"""Fig. 8 runs side by side: one markdown row per (solver, directions, d_hat, dt) of
fig8_biaxial's JSON lines, from a reference set of runs (BEFORE) and a new one (AFTER).

    scripts/fig8_runs_table.py --before docs/data/turn_guard_rerun/unguarded/fig8_*.jsonl.gz \
        --after docs/data/turn_guard_rerun/fig8_*.jsonl.gz

(files ending in .gz are read through gzip).

Per run: steps done, min S, max turn of a rod (from the start), and for AFTER the largest
contact-correction turn of a committed step, the sub-stepped steps and the contact sub-steps
another solver solved again after the default solver failed them (the step records'
`max_correction_turn`, `substeps` and `fallbacks`, where the driver wrote them), and what
stopped it.
"""
import argparse
import gzip
import json


def runs(paths):
    """(solver, directions, d_hat / R, dt) -> {summary, steps: [step records]}."""
    out = {}
    for path in paths:
        steps = {}
        with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as f:
            for line in f:
                r = json.loads(line)
                if r.get("record") == "step":
                    steps.setdefault((r["d_hat_over_R"], r["dt"]), []).append(r)
                elif r.get("record") == "summary":
                    key = (r["solver"], r["directions"], r["d_hat_over_R"], r["dt"])
                    out[key] = {"summary": r, "steps": steps.get((r["d_hat_over_R"], r["dt"]), [])}
    return out


def stopped(summary):
    error = summary.get("error")
    if not error:
        return "T_end"
    step = error.split(" from ")[0].replace("time step ", "step ")
    reasons = [reason for reason, words in (("turn", "max_correction_turn"), ("overlap inside", "overlap inside the step"),
                                            ("below d_hat", "below d_hat"), ("beyond box", "corrected motion"))
               if words in error]
    return f"{step}: {' + '.join(reasons)}" if reasons else step


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", nargs="+", required=True)
    ap.add_argument("--after", nargs="+", required=True)
    a = ap.parse_args()
    before, after = runs(a.before), runs(a.after)
    print("| solver | directions | d_hat / R_rod | dt | steps done: before, after | min S: before, after "
          "| max turn (rad): before, after | max correction turn of a step, after | sub-stepped steps, after "
          "| sub-steps solved again, after | stopped: before, after |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for key in sorted(after):
        s1, steps = after[key]["summary"], after[key]["steps"]
        s0 = before.get(key, {}).get("summary")
        turn = max((r.get("max_correction_turn") or 0.0 for r in steps), default=0.0)
        substepped = sum(1 for r in steps if r.get("substeps", 1) > 1)
        fallbacks = sum(r.get("fallbacks", 0) for r in steps)

        def pair(field, fmt):
            return (fmt.format(s0[field]) if s0 else "-") + ", " + fmt.format(s1[field])

        print(f"| {key[0]} | {key[1]} | {key[2]:g} | {key[3]:g} | {pair('steps', '{}')} | {pair('min_S', '{:.6f}')} "
              f"| {pair('max_turn', '{:.2g}')} | {turn:.3g} | {substepped} | {fallbacks} "
              f"| {stopped(s0) if s0 else '-'}; {stopped(s1)} |")


if __name__ == "__main__":
    main()
