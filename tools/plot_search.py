#!/usr/bin/env python3
"""Draws the leader's camera search for a lost worker (docs/safety.md §2.2) from two `gfctl
simulate` runs of the same mission and camera blackout: one with the search, one without
(`search_timeout_s: 0`, the plain hold).

Top: the worker's height (truth) and each run's estimate. Bottom: the worker's elevation as seen
from the leader (truth) and the leader camera's pitch with its vertical field of view (± the half
angle) in each run; the blackout shaded, the leader's mode changes marked.

Usage: /opt/gesture_formation/venv/bin/python tools/plot_search.py --search DIR --hold DIR
       --blackout A B [--half-fov-deg 21.3] --out FILE
"""
import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def series(rows, key):
    return [float(r[key]) for r in rows]


def elevation_deg(r):
    dx = float(r["worker_x"]) - float(r["L_x"])
    dy = float(r["worker_y"]) - float(r["L_y"])
    dz = float(r["worker_z"]) - float(r["L_z"])
    return math.degrees(math.atan2(dz, math.hypot(dx, dy)))


def leader_modes(path):
    return [(float(r["t"]), r["mode"]) for r in read(path) if r["uav"] == "L"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--search", required=True, help="gfctl simulate output with the search")
    ap.add_argument("--hold", required=True, help="the same mission with search_timeout_s: 0")
    ap.add_argument("--blackout", nargs=2, type=float, required=True, metavar=("A", "B"))
    ap.add_argument("--half-fov-deg", type=float, default=math.degrees(math.atan2(240.0, 615.0)),
                    help="the camera's vertical half field of view (config/estimator.yaml: atan(cy / fy))")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    runs = [("with the search", a.search, "tab:blue"), ("hold only", a.hold, "tab:orange")]
    data = {}
    for label, d, _ in runs:
        rows = read(f"{d}/timeline.csv")
        if not rows:
            sys.exit(f"plot_search.py: {d}/timeline.csv is empty")
        data[label] = (rows, leader_modes(f"{d}/modes.csv"))

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 7), sharex=True, height_ratios=[1, 1.4])
    rows0 = data[runs[0][0]][0]
    t0 = series(rows0, "t")
    top.plot(t0, series(rows0, "worker_z"), color="black", lw=2, label="worker height (truth)")
    for label, _, color in runs:
        rows = data[label][0]
        top.plot(series(rows, "t"), series(rows, "est_z"), color=color, lw=1.2, ls="--", label=f"estimate, {label}")
    top.set_ylabel("height [m]")
    top.legend(loc="upper left", fontsize=8)

    for label, _, color in runs:
        rows, modes = data[label]
        t = series(rows, "t")
        pitch = series(rows, "L_pitch_deg")
        bottom.fill_between(t, [p - a.half_fov_deg for p in pitch], [p + a.half_fov_deg for p in pitch],
                            color=color, alpha=0.18, lw=0)
        bottom.plot(t, pitch, color=color, lw=1.2, label=f"leader camera pitch ± half FOV, {label}")
        for tm, mode in modes:
            if tm > 0:
                for ax in (top, bottom):
                    ax.axvline(tm, color=color, lw=0.8, ls=":")
                bottom.text(tm + 0.15, 0.98, mode, transform=bottom.get_xaxis_transform(), fontsize=7, color=color,
                            rotation=90, va="top")
    bottom.plot(t0, [elevation_deg(r) for r in rows0], color="black", lw=2,
                label="worker elevation seen from the leader (truth, search run)")
    for ax in (top, bottom):
        ax.axvspan(a.blackout[0], a.blackout[1], color="0.85", zorder=0)
    bottom.text(a.blackout[0] + 0.3, bottom.get_ylim()[0] + 2, "camera blind", fontsize=8, color="0.3")
    bottom.set_ylabel("angle above the horizon [deg]")
    bottom.set_xlabel("t [s]   (dotted: the leader's mode changes, its run's colour)")
    bottom.legend(loc="lower right", fontsize=8)
    fig.suptitle(f"The leader loses a climbing worker for {a.blackout[1] - a.blackout[0]:.0f} s: hold vs camera search")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"plot_search.py: wrote {a.out}")


if __name__ == "__main__":
    main()
