#!/usr/bin/env python3
"""Table of contact_step_scaling runs of three builds or settings side by side: the median
contact step per N of each run, the median over runs, and the ratios of the medians.

  scripts/early_end_check_table.py DIR   (DIR holds before_*.jsonl, late_*.jsonl, after_*.jsonl)
"""
import glob
import json
import statistics
import sys
from collections import defaultdict


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "docs/data/early_end_check"
    runs = defaultdict(list)  # (N, label) -> [seconds]
    fields = {}
    for label in ("before", "late", "after"):
        for path in sorted(glob.glob(f"{folder}/{label}_*.jsonl")):
            for line in open(path):
                d = json.loads(line)
                runs[(d["N"], label)].append(d["contact_step_s"])
                fields[(d["N"], label)] = (d["iterations"], d["guarantee_rounds"], d["status"])
    sizes = sorted({n for n, _ in runs})
    print("| N | before: corrections (rounds) | ms per run | after, end checked late | ms per run | after | ms per run | before / after | late / after |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for n in sizes:
        cells = [f"{n:.0e}".replace("e+0", "e")]
        med = {}
        for label in ("before", "late", "after"):
            t = runs.get((n, label))
            if not t:
                cells += ["", ""]
                continue
            med[label] = statistics.median(t)
            its, rounds, status = fields[(n, label)]
            cells.append(f"{its} ({rounds})" if status == "converged" else f"{its} ({rounds}) {status}")
            cells.append(" / ".join(f"{x * 1e3:.1f}" for x in t))
        cells.append(f"{med['before'] / med['after']:.2f}" if "before" in med and "after" in med else "")
        cells.append(f"{med['late'] / med['after']:.2f}" if "late" in med and "after" in med else "")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
