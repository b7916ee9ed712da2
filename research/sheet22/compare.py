#!/usr/bin/env python3
"""Pair the out-of-plane modes of a solid CSV and a beam CSV (from sheet.py) by
order (o1, o2, ...) at each load and print the gap (solid/beam - 1).
Usage: python3 compare.py SOLID.csv BEAM.csv [n_out]"""
import csv, sys

def load(path):
    rows = {}
    for r in csv.reader(l for l in open(path) if not l.startswith("case")):
        P, tx, ty, mode, f, kind = r[-6:]
        rows.setdefault(float(P), {"tip": (float(tx), float(ty)), "in": [], "out": []})[kind].append(float(f))
    return rows

def main():
    s, b = load(sys.argv[1]), load(sys.argv[2])
    k = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    print("P_N,tipx_solid,tipx_beam,in1_solid,in1_beam," + ",".join(f"o{i}_solid,o{i}_beam,o{i}_gap_pct" for i in range(1, k + 1)))
    for P in sorted(s):
        if P not in b:
            continue
        S, B = s[P], b[P]
        row = [f"{P:g}", f"{S['tip'][0]:.5f}", f"{B['tip'][0]:.5f}", f"{S['in'][0]:.3f}", f"{B['in'][0]:.3f}"]
        for i in range(k):
            fs, fb = S["out"][i], B["out"][i]
            row += [f"{fs:.3f}", f"{fb:.3f}", f"{100 * (fs / fb - 1):+.2f}"]
        print(",".join(row))

main()
