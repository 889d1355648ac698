#!/usr/bin/env python3
"""Random collision-free polyline paths through a map, for testing `gfctl corridor`.

    random_corridor_paths.py --points pts.csv --seed 7 --count 10 --out-dir DIR
        [--waypoints 8] [--min-clearance 0.3] [--z-range 1.5 34]

Reads the occupied voxel centres (`gfctl map --export-points`), draws random walks of
`--waypoints` points with 3-8 m segments inside the points' bounding box, and keeps a
segment only when every voxel centre lies at least `--min-clearance` m from it. Writes
DIR/path_<i>.csv with columns x,y,z. Deterministic for a seed.
"""
import argparse
import csv
import os
import sys

import numpy as np


def seg_dist(p0, p1, pts):
    d = p1 - p0
    t = np.clip(((pts - p0) @ d) / float(d @ d), 0.0, 1.0)
    return np.min(np.linalg.norm(pts - (p0 + t[:, None] * d), axis=1)) if len(pts) else np.inf


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", required=True)
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--count", type=int, default=10)
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--waypoints", type=int, default=8)
    ap.add_argument("--min-clearance", type=float, default=0.3)
    ap.add_argument("--z-range", type=float, nargs=2, default=[1.5, 34.0])
    args = ap.parse_args()
    with open(args.points, newline="") as f:
        pts = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in csv.DictReader(f)])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    lo[2], hi[2] = args.z_range
    rng = np.random.default_rng(args.seed)
    os.makedirs(args.out_dir, exist_ok=True)
    made = 0
    attempts = 0
    while made < args.count and attempts < 200 * args.count:
        attempts += 1
        p = rng.uniform(lo, hi)
        near = pts[np.linalg.norm(pts - p, axis=1) < args.min_clearance]
        if len(near):
            continue
        path = [p]
        tries = 0
        while len(path) < args.waypoints and tries < 200:
            tries += 1
            d = rng.normal(size=3)
            d[2] *= 0.4
            q = path[-1] + d / np.linalg.norm(d) * rng.uniform(3.0, 8.0)
            if np.any(q < lo) or np.any(q > hi):
                continue
            box_lo, box_hi = np.minimum(path[-1], q) - 1.0, np.maximum(path[-1], q) + 1.0
            local = pts[np.all((pts >= box_lo) & (pts <= box_hi), axis=1)]
            if seg_dist(path[-1], q, local) >= args.min_clearance:
                path.append(q)
        if len(path) < args.waypoints:
            continue
        with open(os.path.join(args.out_dir, f"path_{made}.csv"), "w") as f:
            f.write("x,y,z\n")
            for w in path:
                f.write(f"{w[0]:.6f},{w[1]:.6f},{w[2]:.6f}\n")
        made += 1
    if made < args.count:
        print(f"random_corridor_paths: only {made} of {args.count} paths found", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
