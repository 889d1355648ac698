#!/usr/bin/env python3
"""Draws DIR/timeline.png from a `gfctl simulate` output directory (docs/simulation.md).

In the style of the paper's simulation timeline (Kratky et al., RA-L 2025, Fig. "Simulation
timeline"): per UAV the distance to the worker d_t, the pairwise UAV distances d_m, the
distance to the nearest obstacle d_o and the observation angle, with the references as
transparent lines and vertical markers when a command was applied (operator: red, worker's
gesture: blue), and ticks where a UAV's replanning failed (plans.csv: previous plan flown, or a
brake); plus a top and a side view of the trajectories with the towers, conductor
lines and other obstacles (scene.json).

Usage: /opt/gesture_formation/venv/bin/python tools/plot_timeline.py DIR [--out FILE]
"""
import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

COLORS = ["tab:red", "tab:green", "tab:blue", "tab:orange", "tab:purple"]


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def column(rows, key):
    out = []
    for r in rows:
        try:
            out.append(float(r[key]))
        except (ValueError, KeyError):
            out.append(float("nan"))
    return np.array(out)


def unwrap_deg(a):
    return np.degrees(np.unwrap(np.radians(a)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    d = args.dir
    rows = read_csv(os.path.join(d, "timeline.csv"))
    if not rows:
        sys.exit(f"{d}/timeline.csv: no rows")
    events = read_csv(os.path.join(d, "events.csv")) if os.path.exists(os.path.join(d, "events.csv")) else []
    scene = {}
    if os.path.exists(os.path.join(d, "scene.json")):
        with open(os.path.join(d, "scene.json")) as f:
            scene = json.load(f)
    t = column(rows, "t")
    labels = []
    i = 0
    while f"{'L' if i == 0 else i}_x" in rows[0]:
        labels.append("L" if i == 0 else str(i))
        i += 1
    pairs = [k for k in rows[0].keys() if k.startswith("d_m_")]

    fig = plt.figure(figsize=(14, 11))
    gs = fig.add_gridspec(5, 2, width_ratios=[1.6, 1.0], hspace=0.35, wspace=0.18)
    ax_dt = fig.add_subplot(gs[0, 0])
    ax_dm = fig.add_subplot(gs[1, 0], sharex=ax_dt)
    ax_do = fig.add_subplot(gs[2, 0], sharex=ax_dt)
    ax_phi = fig.add_subplot(gs[3, 0], sharex=ax_dt)
    ax_el = fig.add_subplot(gs[4, 0], sharex=ax_dt)
    ax_top = fig.add_subplot(gs[0:3, 1])
    ax_side = fig.add_subplot(gs[3:5, 1])

    for k, lab in enumerate(labels):
        c = COLORS[k % len(COLORS)]
        name = "leader" if lab == "L" else f"follower {lab}"
        ax_dt.plot(t, column(rows, f"{lab}_d_t"), color=c, lw=1.2, label=name)
        ax_dt.plot(t, column(rows, f"{lab}_d_ref"), color=c, lw=3, alpha=0.25)
        ax_do.plot(t, column(rows, f"{lab}_d_o"), color=c, lw=1.2)
        ax_phi.plot(t, unwrap_deg(column(rows, f"{lab}_phi_deg")), color=c, lw=1.2)
        ax_phi.plot(t, unwrap_deg(column(rows, f"{lab}_phi_ref_deg")), color=c, lw=3, alpha=0.25)
        ax_el.plot(t, column(rows, f"{lab}_elev_deg"), color=c, lw=1.2)
        ax_el.plot(t, column(rows, f"{lab}_elev_ref_deg"), color=c, lw=3, alpha=0.25)
    # d_m colours as in the paper: leader-follower pairs green/blue, follower-follower red.
    pair_colors = {"d_m_L_1": "tab:green", "d_m_L_2": "tab:blue", "d_m_1_2": "tab:red"}
    for p in pairs:
        ax_dm.plot(t, column(rows, p), color=pair_colors.get(p, "tab:gray"), lw=1.2, label=p[4:].replace("_", "-"))
    ax_dm.axhline(2.5, color="k", ls="--", lw=0.8, label=r"$\Gamma_{dis}$")
    ax_do.axhline(0.8, color="k", ls="--", lw=0.8, label="corridor clearance")

    for e in events:
        try:
            ta = float(e["applied_t"])
        except (ValueError, KeyError):
            continue
        if math.isnan(ta):
            continue
        col = "red" if e["source"] == "operator" else "blue"
        for ax in (ax_dt, ax_dm, ax_do, ax_phi, ax_el):
            ax.axvline(ta, color=col, lw=0.7, alpha=0.6)

    # Failed replannings (plans.csv): per UAV a row of ticks along the bottom of the d_t panel —
    # "|" the previous verified plan flown, "x" a brake plan — where a UAV fell behind and why is
    # then read in plans.csv.
    plans_path = os.path.join(d, "plans.csv")
    if os.path.exists(plans_path):
        plans = read_csv(plans_path)
        for k, lab in enumerate(labels):
            c = COLORS[k % len(COLORS)]
            y = 0.4 + 0.5 * k
            for status, marker, size in (("fallback_previous", "|", 20), ("fallback_brake", "x", 14)):
                ts = [float(r["t"]) for r in plans if r["uav"] == lab and r["status"] == status]
                if ts:
                    ax_dt.scatter(ts, [y] * len(ts), marker=marker, s=size, color=c, lw=0.8)
    ax_dt.set_ylim(bottom=0.0)
    ax_dt.set_ylabel(r"$d_t$ [m]")
    ax_dm.set_ylabel(r"$d_m$ [m]")
    ax_do.set_ylabel(r"$d_o$ [m]")
    ax_phi.set_ylabel(r"$^i\varphi$ [deg]")
    ax_el.set_ylabel("elevation [deg]")
    ax_el.set_xlabel("t [s]")
    ax_dt.legend(loc="upper right", fontsize=7, ncol=3)
    ax_dm.legend(loc="upper right", fontsize=7, ncol=4)
    ax_do.legend(loc="upper right", fontsize=7)
    ax_dt.set_title("thin: actual, wide transparent: reference; vertical lines: operator (red) / gesture (blue) commands;\n"
                    "ticks at the bottom: failed replannings per UAV (| previous plan flown, x brake; plans.csv)",
                    fontsize=8)

    # Top and side views.
    def draw_scene(ax, top):
        for tw in scene.get("towers", []):
            bx, by, bz = tw["base"]
            yaw = tw.get("yaw_rad", 0.0)
            h, w0, w1 = tw["height_m"], tw["base_width_m"] / 2, tw["top_width_m"] / 2
            if top:
                sq = np.array([[-w0, -w0], [w0, -w0], [w0, w0], [-w0, w0], [-w0, -w0]])
                R = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
                p = sq @ R.T + [bx, by]
                ax.fill(p[:, 0], p[:, 1], color="0.6", alpha=0.5)
                for a in tw["arms"]:
                    L = a["half_length_m"]
                    q = np.array([[0, -L], [0, L]]) @ R.T + [bx, by]
                    ax.plot(q[:, 0], q[:, 1], color="0.4", lw=2)
            else:
                ax.fill([bx - w0, bx + w0, bx + w1, bx - w1], [bz, bz, bz + h, bz + h], color="0.6", alpha=0.5)
                for a in tw["arms"]:
                    ax.plot([bx - 0.3, bx + 0.3], [bz + a["height_m"]] * 2, color="0.4", lw=2)
        for line in scene.get("conductors", []):
            p = np.array(line)
            if len(p):
                ax.plot(p[:, 0], p[:, 1] if top else p[:, 2], color="0.3", lw=0.6)
        for b in scene.get("boxes", []):
            cx, cy, cz = b["center"]
            sx, sy, sz = b["size"]
            yaw = b.get("yaw_rad", 0.0)
            if top:
                sq = np.array([[-sx, -sy], [sx, -sy], [sx, sy], [-sx, sy], [-sx, -sy]]) / 2
                R = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
                p = sq @ R.T + [cx, cy]
                ax.fill(p[:, 0], p[:, 1], color="0.7", alpha=0.5)
            else:
                ax.fill([cx - sx / 2, cx + sx / 2, cx + sx / 2, cx - sx / 2], [cz - sz / 2] * 2 + [cz + sz / 2] * 2,
                        color="0.7", alpha=0.5)
        for c in scene.get("cylinders", []):
            x0, y0, z0 = c["p0"]
            x1, y1, z1 = c["p1"]
            r = c["radius_m"]
            if top:
                ax.add_patch(plt.Circle((x0, y0), r, color="0.6", alpha=0.6))
            else:
                ax.fill([x0 - r, x0 + r, x1 + r, x1 - r], [z0, z0, z1, z1], color="0.6", alpha=0.6)

    draw_scene(ax_top, True)
    draw_scene(ax_side, False)
    wx, wy, wz = column(rows, "worker_x"), column(rows, "worker_y"), column(rows, "worker_z")
    for ax, top in ((ax_top, True), (ax_side, False)):
        ax.plot(wx, wy if top else wz, color="k", lw=2, label="worker")
        for k, lab in enumerate(labels):
            x, y, z = column(rows, f"{lab}_x"), column(rows, f"{lab}_y"), column(rows, f"{lab}_z")
            ax.plot(x, y if top else z, color=COLORS[k % len(COLORS)], lw=0.8,
                    label="leader" if lab == "L" else f"follower {lab}")
        xs = np.concatenate([column(rows, f"{lab}_x") for lab in labels] + [wx])
        ys = np.concatenate([column(rows, f"{lab}_{'y' if top else 'z'}") for lab in labels] + [wy if top else wz])
        if not top:
            ys = np.concatenate([ys, [0.0] + [tw["base"][2] + tw["height_m"] for tw in scene.get("towers", [])]])
        ax.set_xlim(np.nanmin(xs) - 4, np.nanmax(xs) + 4)
        ax.set_ylim(np.nanmin(ys) - 4, np.nanmax(ys) + 4)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]" if top else "z [m]")
    ax_top.set_title("top view", fontsize=9)
    ax_side.set_title("side view", fontsize=9)
    ax_top.legend(loc="upper right", fontsize=7)
    out = args.out or os.path.join(d, "timeline.png")
    fig.savefig(out, dpi=90, bbox_inches="tight")
    print(out)


if __name__ == "__main__":
    main()
