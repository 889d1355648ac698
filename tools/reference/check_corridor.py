#!/usr/bin/env python3
"""Independent checker of `gfctl corridor` output (docs/design.md §8.6) against the map's occupied
voxel centres from `gfctl map --export-points` (docs/design.md §8.5). Written from the contract,
not from the C++ code.

    check_corridor.py --corridor corridor.json --points pts.csv --path path.csv [--tol 1e-6]

Checks: one polytope per path segment with seeds equal to the segment's ends; every A row is
a unit vector (|‖a‖ − 1| ≤ 1e-9); both seeds satisfy A x ≤ b + tol; consecutive polytopes
share their common waypoint; no voxel centre lies strictly inside any polytope
(max_i (A_i x − b_i) < 0 is a violation); time_ms is a non-negative number.
Prints a summary and exits 1 on the first kind of failure found (listing up to 5 cases).
"""
import argparse
import csv
import json
import math
import sys

import numpy as np


def load_csv_xyz(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows], dtype=float).reshape(-1, 3)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--corridor", required=True)
    ap.add_argument("--points", required=True)
    ap.add_argument("--path", required=True)
    ap.add_argument("--tol", type=float, default=1e-6)
    args = ap.parse_args()

    with open(args.corridor) as f:
        doc = json.load(f)
    if set(doc.keys()) != {"polytopes", "time_ms"}:
        return fail(f"top-level keys {sorted(doc.keys())} != ['polytopes', 'time_ms']")
    if not isinstance(doc["time_ms"], (int, float)) or doc["time_ms"] < 0 or not math.isfinite(doc["time_ms"]):
        return fail(f"time_ms {doc['time_ms']!r} is not a non-negative number")
    path = load_csv_xyz(args.path)
    pts = load_csv_xyz(args.points)
    polys = doc["polytopes"]
    if len(polys) != len(path) - 1:
        return fail(f"{len(polys)} polytopes for {len(path) - 1} segments")

    problems = []
    min_inside_margin = math.inf
    min_exclusion = math.inf
    for k, poly in enumerate(polys):
        if set(poly.keys()) != {"A", "b", "seed"}:
            problems.append(f"polytope {k}: keys {sorted(poly.keys())}")
            continue
        A = np.array(poly["A"], dtype=float).reshape(-1, 3)
        b = np.array(poly["b"], dtype=float).reshape(-1)
        seed = np.array(poly["seed"], dtype=float).reshape(-1, 3)
        if A.shape[0] != b.shape[0] or A.shape[0] == 0:
            problems.append(f"polytope {k}: A has {A.shape[0]} rows, b {b.shape[0]}")
            continue
        norms = np.linalg.norm(A, axis=1)
        bad = np.nonzero(np.abs(norms - 1.0) > 1e-9)[0]
        if bad.size:
            problems.append(f"polytope {k}: rows {bad[:5].tolist()} are not unit (norms {norms[bad[:5]].tolist()})")
        if seed.shape != (2, 3) or not np.allclose(seed, path[k:k + 2], atol=1e-9):
            problems.append(f"polytope {k}: seed {seed.tolist()} != segment {path[k:k + 2].tolist()}")
        for s in seed:
            v = float(np.max(A @ s - b))
            min_inside_margin = min(min_inside_margin, -v)
            if v > args.tol:
                problems.append(f"polytope {k}: seed {s.tolist()} violates A x <= b by {v:g}")
        if k > 0:
            prev_A = np.array(polys[k - 1]["A"], dtype=float).reshape(-1, 3)
            prev_b = np.array(polys[k - 1]["b"], dtype=float)
            shared = path[k]
            if float(np.max(prev_A @ shared - prev_b)) > args.tol or float(np.max(A @ shared - b)) > args.tol:
                problems.append(f"polytopes {k - 1} and {k} do not both contain waypoint {k} {shared.tolist()}")
        if pts.shape[0]:
            # Chunked to bound memory: (rows x points) per chunk.
            for start in range(0, pts.shape[0], 200000):
                chunk = pts[start:start + 200000]
                worst = np.max(chunk @ A.T - b[None, :], axis=1)  # > 0: outside some plane
                min_exclusion = min(min_exclusion, float(np.min(worst)))
                inside = np.nonzero(worst < 0.0)[0]
                if inside.size:
                    ex = chunk[inside[:3]].tolist()
                    problems.append(f"polytope {k}: {inside.size} voxel centres strictly inside, e.g. {ex}")
    print(f"check_corridor: {len(polys)} polytopes, {pts.shape[0]} voxel centres; min seed margin "
          f"{min_inside_margin:.6g} m, min exclusion {min_exclusion:.6g} m, time_ms {doc['time_ms']:.4g}")
    if problems:
        for p in problems[:5]:
            print("FAIL:", p)
        if len(problems) > 5:
            print(f"... {len(problems) - 5} more")
        return 1
    return 0


def fail(msg):
    print("FAIL:", msg)
    return 1


if __name__ == "__main__":
    sys.exit(main())
