#!/usr/bin/env python3
"""Plots a scenario's occupied voxels, a path and its corridors (polytope vertices by
half-space intersection) to a PNG.  Run with the tools venv:

    /opt/gesture_formation/venv/bin/python tools/plot_corridors.py \
        --points pts.csv --path path.csv --corridor corridor.json --out docs/images/corridors_power_towers.png

pts.csv from `gfctl map --export-points`, corridor.json from `gfctl corridor` (design.md §8.5-6).
"""
import argparse
import csv
import itertools
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from scipy.spatial import ConvexHull, HalfspaceIntersection  # noqa: E402


def xyz(path):
    with open(path, newline="") as f:
        return np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in csv.DictReader(f)])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", required=True)
    ap.add_argument("--path", required=True)
    ap.add_argument("--corridor", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    pts = xyz(args.points)
    path = xyz(args.path)
    polys = json.load(open(args.corridor))["polytopes"]
    pts = pts[pts[:, 2] > 0.3]  # hide the ground layer
    fig = plt.figure(figsize=(12, 7))
    ax = fig.add_subplot(111, projection="3d")
    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], s=0.3, c="0.35", alpha=0.35, linewidths=0)
    colors = plt.cm.tab10(np.linspace(0, 1, 10))
    for k, p in enumerate(polys):
        A, b = np.array(p["A"]), np.array(p["b"])
        interior = np.mean(np.array(p["seed"]), axis=0)
        hs = HalfspaceIntersection(np.hstack([A, -b[:, None]]), interior)
        hull = ConvexHull(hs.intersections)
        faces = [hs.intersections[s] for s in hull.simplices]
        ax.add_collection3d(Poly3DCollection(faces, alpha=0.12, facecolor=colors[k % 10], edgecolor="none"))
    ax.plot(path[:, 0], path[:, 1], path[:, 2], "r-o", lw=2, ms=3)
    lo, hi = np.array([-12, -16, 0]), np.array([62, 16, 36])
    ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]"); ax.set_zlabel("z [m]")
    ax.view_init(elev=18, azim=-60)
    ax.set_title(f"power_towers.yaml: {len(polys)} corridors along a {np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)):.0f} m path")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
