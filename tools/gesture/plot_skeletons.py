#!/usr/bin/env python3
"""Draws one frame of each motion of a `gfctl synth-gestures` dataset (the middle frame of
the pose for gestures, the middle frame otherwise) as a montage, to look at the poses.

    plot_skeletons.py --data DIR --out montage.png
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

LIMBS = [(5, 7), (7, 9), (6, 8), (8, 10), (5, 6), (11, 12), (5, 11), (6, 12), (11, 13), (13, 15), (12, 14),
         (14, 16), (0, 1), (0, 2), (1, 3), (2, 4)]
LEFT = {1, 3, 5, 7, 9, 11, 13, 15}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    meta = {r["sequence"]: r for r in csv.DictReader(open(f"{a.data}/sequences.csv"))}
    rows = {}
    for r in csv.DictReader(open(f"{a.data}/skeletons.csv")):
        rows.setdefault(r["sequence"], []).append(r)
    chosen = {}
    for sid, m in meta.items():
        key = m["motion"]
        if key in chosen:
            continue
        frames = rows[sid]
        held = [f for f in frames if f["label"] != "0"]
        chosen[key] = (m, (held or frames)[len(held or frames) // 2])
    keys = sorted(chosen)
    cols = 4
    fig, axes = plt.subplots((len(keys) + cols - 1) // cols, cols, figsize=(3 * cols, 3.6 * ((len(keys) + cols - 1) // cols)))
    for ax in axes.flat:
        ax.axis("off")
    for ax, key in zip(axes.flat, keys):
        m, f = chosen[key]
        u, v, w, h = (float(f[k]) for k in "uvwh")
        pts = [(float(f[f"x{k}"]), float(f[f"y{k}"]), float(f[f"c{k}"])) for k in range(17)]
        ax.add_patch(plt.Rectangle((u, v), w, h, fill=False, ec="grey", lw=0.8))
        for i, j in LIMBS:
            if pts[i][2] > 0 and pts[j][2] > 0:
                ax.plot([pts[i][0], pts[j][0]], [pts[i][1], pts[j][1]], "-",
                        color="tab:blue" if i in LEFT and j in LEFT else "tab:red" if i not in LEFT and j not in LEFT else "k", lw=1.5)
        ax.scatter([p[0] for p in pts if p[2] > 0], [p[1] for p in pts if p[2] > 0], s=8, c="k")
        ax.set_xlim(u - 0.2 * w, u + 1.2 * w)
        ax.set_ylim(v + 1.05 * h, v - 0.05 * h)
        ax.set_aspect("equal")
        ax.set_title(f"{key} (id {m['gesture_id']})\nd {float(m['distance_m']):.0f} m, el {float(m['elevation_deg']):.0f}°, "
                     f"az {float(m['azimuth_deg']):.0f}°", fontsize=8)
    fig.suptitle("gfctl synth-gestures: one frame per motion (blue = left side, red = right)")
    fig.tight_layout()
    fig.savefig(a.out, dpi=80)


if __name__ == "__main__":
    main()
