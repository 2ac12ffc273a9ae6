#!/usr/bin/env python3
"""Before against after: the same driver's JSON lines from two builds, record by record.

    compare_runs.py --key phi,cost,solver --where part=jammed \
        --before old_1.jsonl old_2.jsonl ... --after new_1.jsonl new_2.jsonl ...
    compare_runs.py --key phi,config --summary --before a.jsonl --after b.jsonl

Records are matched by --key (its fields' values; floats rounded to 6 digits); a file given
several times over (repeated runs) gives each key several wall times, of which the median is
shown (--time names another time field, e.g. contact_step_s or phases_s.solve). Files may be gzipped (.gz). The table: per key, each --fields value before and after (from the last run) and the
median wall_time_s before and after with their ratio. --summary instead prints, per field, in
how many keys it differs, the largest relative difference of numbers, and the sums before and
after, and the summed median wall time.
"""
import argparse
import gzip
import json
import statistics
import sys


def key_of(record, fields):
    values = []
    for f in fields:
        v = record.get(f)
        values.append(round(v, 6) if isinstance(v, float) else v)
    return tuple(values)


def field(record, path):
    """A field by dotted path (phases_s.solve); NaN where missing."""
    for part in path.split("."):
        if not isinstance(record, dict) or part not in record:
            return float("nan")
        record = record[part]
    return record


def load(paths, key_fields, where, time_field="wall_time_s"):
    walls, last = {}, {}
    for path in paths:
        with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as handle:
            for line in handle:
                record = json.loads(line)
                if any(str(record.get(f)) != v for f, v in where):
                    continue
                if any(f not in record for f in key_fields):
                    continue
                k = key_of(record, key_fields)
                walls.setdefault(k, []).append(field(record, time_field))
                last[k] = record
    return walls, last


def fmt(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--key", required=True, help="comma-separated fields that identify a record")
    p.add_argument("--where", default="", help="comma-separated field=value filters")
    p.add_argument("--fields", default="iterations,mobility_applications,min_d_over_d_hat_after,complementarity_residual,status")
    p.add_argument("--summary", action="store_true")
    p.add_argument("--time", default="wall_time_s",
                   help="the time to compare, a dotted path (contact_step_s, phases_s.solve); default wall_time_s")
    p.add_argument("--before", nargs="+", required=True)
    p.add_argument("--after", nargs="+", required=True)
    a = p.parse_args()
    key_fields = a.key.split(",")
    where = [tuple(w.split("=", 1)) for w in a.where.split(",") if w]
    fields = a.fields.split(",")
    wb, rb = load(a.before, key_fields, where, a.time)
    wa, ra = load(a.after, key_fields, where, a.time)
    keys = [k for k in rb if k in ra]
    if len(keys) != len(rb) or len(keys) != len(ra):
        print(f"warning: {len(rb)} keys before, {len(ra)} after, {len(keys)} in both", file=sys.stderr)
    if a.summary:
        print(f"{len(keys)} records matched by {a.key}")
        for f in fields:
            differ, rel = 0, 0.0
            sb = sa = 0.0
            numeric = True
            for k in keys:
                u, v = rb[k].get(f), ra[k].get(f)
                differ += u != v
                if isinstance(u, (int, float)) and isinstance(v, (int, float)) and not isinstance(u, bool):
                    sb += u
                    sa += v
                    if u != v:
                        rel = max(rel, abs(u - v) / max(abs(u), abs(v)))
                else:
                    numeric = False
            line = f"{f}: differs in {differ}"
            if numeric:
                line += f", largest relative difference {rel:.3g}, sum {fmt(sb)} -> {fmt(sa)}"
            print(line)
        tb = sum(statistics.median(wb[k]) for k in keys)
        ta = sum(statistics.median(wa[k]) for k in keys)
        print(f"{a.time} (sum of medians): {tb:.4g} -> {ta:.4g}, ratio {tb / ta:.2f}")
        return
    head = key_fields + [f"{f} (before, after)" for f in fields] + [
        f"{a.time}, median of {len(wb[keys[0]])} (before)", f"median of {len(wa[keys[0]])} (after)", "ratio"]
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * len(head))
    for k in keys:
        cells = [fmt(v) for v in k]
        cells += [f"{fmt(rb[k].get(f))}, {fmt(ra[k].get(f))}" for f in fields]
        mb, ma = statistics.median(wb[k]), statistics.median(wa[k])
        cells += [f"{mb * 1e3:.1f} ms", f"{ma * 1e3:.1f} ms", f"{mb / ma:.2f}"]
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
