#!/usr/bin/env python3
"""The markdown table of `nematic_state` JSON lines (examples/nematic_state.cpp).

    /usr/bin/python3 scripts/nematic_state_table.py STATES.jsonl

One row per saved state: N, eta, t D_R (the state's time times D_R, --d-r, default the free
L/D = 5 rod's 0.02141 that brownian_rods prints), S, the order tensor's eigenvalues, the
slab profiles across x, y and z (P2 along the director per slab), their spread (largest minus
smallest slab over all three axes), g2 per shell, and g2 of the last shell over S^2 (1 in a
uniform nematic at distances beyond its local order; below 1 where ordered regions are
smaller than the box).
"""
import argparse
import json
import os


def fmt(values, digits=2):
    return " ".join(f"{v:.{digits}f}" if v is not None else "-" for v in values)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("states", help="JSON lines of nematic_state")
    parser.add_argument("--d-r", type=float, default=0.02141, help="D_R of the rods (time unit 1 / D_R)")
    args = parser.parse_args()
    rows = [json.loads(line) for line in open(args.states) if line.strip()]
    edges = rows[0]["g2_edges"] if rows else []
    shells = " / ".join(f"{a:g}-{b:g}" for a, b in zip(edges[:-1], edges[1:]))
    print(f"| state | N | eta | t D_R | S | Q eigenvalues | slabs across x | across y | across z | slab spread | g2 at r = {shells} | last g2 / S^2 |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        slabs = [v for axis in "xyz" for v in r[f"slab_order_{axis}"] if v is not None]
        spread = max(slabs) - min(slabs)
        last = r["g2"][-1]
        ratio = f"{last / r['S'] ** 2:.2f}" if last is not None else "-"
        print(f"| `{os.path.basename(r['state'])}` | {r['N']} | {r['eta']:.2f} | {r['time'] * args.d_r:.2f} | {r['S']:.3f} | "
              f"{fmt(r['order_tensor_eigenvalues'])} | {fmt(r['slab_order_x'])} | {fmt(r['slab_order_y'])} | "
              f"{fmt(r['slab_order_z'])} | {spread:.2f} | {fmt(r['g2'])} | {ratio} |")


if __name__ == "__main__":
    main()
