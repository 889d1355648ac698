#!/usr/bin/env python3
"""Compares two CSV files with the same header: numbers to an absolute tolerance
(nan equals nan), other fields exactly. Exit 0 when equal, 1 with the first differences.

    compare_csv.py A.csv B.csv [--atol 1e-6]
"""
import argparse
import csv
import math
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--atol", type=float, default=1e-6)
    args = ap.parse_args()
    with open(args.a) as fa, open(args.b) as fb:
        ra, rb = list(csv.reader(fa)), list(csv.reader(fb))
    if ra[0] != rb[0]:
        print(f"headers differ: {ra[0]} vs {rb[0]}")
        return 1
    if len(ra) != len(rb):
        print(f"row counts differ: {len(ra) - 1} vs {len(rb) - 1}")
        return 1
    bad, worst = 0, 0.0
    for i, (x, y) in enumerate(zip(ra[1:], rb[1:]), start=2):
        for name, u, v in zip(ra[0], x, y):
            try:
                fu, fv = float(u), float(v)
            except ValueError:
                if u != v:
                    bad += 1
                    if bad <= 10:
                        print(f"line {i} field {name}: '{u}' vs '{v}'")
                continue
            if math.isnan(fu) and math.isnan(fv):
                continue
            diff = abs(fu - fv) if not (math.isnan(fu) or math.isnan(fv)) else math.inf
            worst = max(worst, diff)
            if diff > args.atol:
                bad += 1
                if bad <= 10:
                    print(f"line {i} field {name}: {u} vs {v} (diff {diff:.3g})")
    print(f"compared {len(ra) - 1} rows: {bad} differences beyond {args.atol}; max abs diff {worst:.3g}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
