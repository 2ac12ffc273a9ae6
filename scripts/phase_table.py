#!/usr/bin/env python3
"""The contact step's time by phase (ContactStepResult::phase_times) from contact_step_scaling's
JSON lines, one Markdown table: per N and thread count, each phase's median over the step's
repeats in every run given ("a / b": run 1 / run 2), then the speed-up of two threads over one
per phase (the faster run of each count against each other).

    /usr/bin/python3 scripts/phase_table.py RUN1_threads1.jsonl RUN1_threads2.jsonl RUN2_threads1.jsonl ...

The thread count is read from the file name (..._threads<T>.jsonl); the files of one count are
the runs, in the order given.
"""
import json
import re
import sys

PHASES = ["setup", "solve", "end_check", "interior_check", "add_pairs", "finish"]


def ms(seconds):
    v = 1e3 * seconds
    return f"{v:.3g}" if v < 100 else f"{v:.0f}"


def main(paths):
    runs = {}  # (N, threads) -> [record per run]
    for path in paths:
        m = re.search(r"threads(\d+)\.jsonl$", path)
        if not m:
            sys.exit(f"{path}: the name must end in _threads<T>.jsonl")
        threads = int(m.group(1))
        with open(path) as f:
            for line in f:
                d = json.loads(line)
                runs.setdefault((d["N"], threads), []).append(d)
    print("| N | threads | contact step (ms) | " + " | ".join(p.replace("_", " ") for p in PHASES) + " | sphere-steps / s |")
    print("| --- | --- | --- | " + " | ".join("---" for _ in PHASES) + " | --- |")
    for (n, threads), ds in sorted(runs.items()):
        cells = [" / ".join(ms(d["contact_step_s"]) for d in ds)]
        cells += [" / ".join(ms(d["phases_s"][p]) for d in ds) for p in PHASES]
        rate = max(d["sphere_steps_per_s"] for d in ds)
        print(f"| {n:.0e} | {threads} | " + " | ".join(cells) + f" | {rate:.2g} (best) |")
    print()
    print("| N | " + " | ".join(p.replace("_", " ") for p in ["contact_step"] + PHASES) + " |")
    print("| --- | " + " | ".join("---" for _ in ["contact_step"] + PHASES) + " |")
    for n in sorted({n for n, _ in runs}):
        if (n, 1) not in runs or (n, 2) not in runs:
            continue
        cells = []
        for p in ["contact_step"] + PHASES:
            def best(ds):
                return min(d["contact_step_s"] if p == "contact_step" else d["phases_s"][p] for d in ds)
            one, two = best(runs[(n, 1)]), best(runs[(n, 2)])
            cells.append(f"{one / two:.2f}" if two > 0 else "-")
        print(f"| {n:.0e} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
