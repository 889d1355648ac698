#!/usr/bin/env python3
"""Does our MoveNet pipeline find the rendered worker? Renders frames of the power-tower mission
from the followers' cameras (8 m from the worker in the formation's default geometry) with
`gfctl render`, runs `gfctl detect` (MoveNet multipose + KCF + MoveNet lightning) on each, and
compares with the render's truth: the share of frames where the worker is found, and the median
keypoint error (detected vs rendered joint, visible joints with confidence >= 0.3) as a fraction
of the truth box's height. Writes docs/results/render_movenet.md.

    /usr/bin/python3 tools/check_render_movenet.py [--gfctl PATH] [--seeds 1 2] [--out docs/results/render_movenet.md]
"""
import argparse
import csv
import datetime
import glob
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TIMES = (2, 20, 45, 75, 90, 108, 125, 140, 170, 200, 230, 260, 300, 320, 350, 385)


def one(gfctl, scenario, seed, t, uav, tmp):
    f = os.path.join(tmp, f"s{seed}_t{t}_u{uav}")
    r = subprocess.run([gfctl, "render", "--scenario", scenario, "--t", str(t), "--uav", str(uav), "--seed", str(seed),
                        "--out", f + ".png", "--truth", f + "_truth.csv"], capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"check_render_movenet: gfctl render failed: {r.stderr.strip()}")
    dist = float(r.stdout.split(" m from the worker")[0].split(",")[-1])
    motion = r.stdout.split("worker ")[1].split(" progress")[0]
    d = subprocess.run([gfctl, "detect", "--image", f + ".png", "--out", f + "_det.png", "--csv", f + "_det.csv"],
                       capture_output=True, text=True)
    if d.returncode:
        sys.exit(f"check_render_movenet: gfctl detect failed: {d.stderr.strip()}")
    lines = list(csv.reader(open(f + "_truth.csv")))
    truth = lines[1:18]
    box_h = int(lines[18][4].split("=")[1])
    det = list(csv.DictReader(open(f + "_det.csv")))
    found = bool(det) and det[0].get("w", "") not in ("", "0") and float(det[0]["w"]) > 0
    errs = []
    if found:
        for k in range(17):
            if truth[k][5] != "1" or float(det[0][f"c{k}"]) < 0.3:
                continue
            errs.append(np.hypot(float(det[0][f"x{k}"]) - float(truth[k][1]), float(det[0][f"y{k}"]) - float(truth[k][2])) / max(box_h, 1))
    return {"seed": seed, "t": t, "uav": uav, "dist": dist, "motion": motion, "box_h": box_h, "found": found,
            "err": float(np.median(errs)) if errs else float("nan")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--gfctl", default=None)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "render_movenet.md"))
    a = ap.parse_args()
    gfctl = a.gfctl or next((p for p in glob.glob(os.path.join(ROOT, "build", "**", "gfctl"), recursive=True)
                             if os.path.isfile(p) and os.access(p, os.X_OK)), None)
    if not gfctl:
        sys.exit("check_render_movenet: build gfctl first (tools/build.sh gfctl) or pass --gfctl")
    scenario = os.path.join(ROOT, "config", "scenarios", "power_towers.yaml")
    rows = []
    with tempfile.TemporaryDirectory(prefix="gf-render-movenet.") as tmp:
        for seed in a.seeds:
            for t in TIMES:
                for uav in (1, 2):
                    rows.append(one(gfctl, scenario, seed, t, uav, tmp))
                    print(rows[-1], flush=True)
    found = [r for r in rows if r["found"]]
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    L = ["# MoveNet on rendered frames\n",
         f"Written by `tools/check_render_movenet.py` on {datetime.date.today().isoformat()} at commit {commit}: "
         f"{len(rows)} frames of `config/scenarios/power_towers.yaml` rendered by `gfctl render` from the followers' "
         f"cameras (UAV 1 and 2 at their formation references, {min(r['dist'] for r in rows):.1f}–"
         f"{max(r['dist'] for r in rows):.1f} m from the worker) at t = {', '.join(map(str, TIMES))} s, seeds "
         f"{', '.join(map(str, a.seeds))} (outfit and skin tone drawn per seed), each through `gfctl detect` "
         "(MoveNet multipose + KCF + MoveNet lightning, one frame: detector only).\n",
         f"- worker found: **{len(found)} / {len(rows)} frames ({100 * len(found) / len(rows):.0f} %)**",
         f"- keypoint error (visible joints, confidence ≥ 0.3), median over found frames of the per-frame median, "
         f"as a fraction of the truth box height: **{100 * np.nanmedian([r['err'] for r in found]):.1f} %**\n",
         "| seed | t [s] | UAV | distance [m] | worker motion | box height [px] | found | keypoint error / box height |",
         "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        err = "" if np.isnan(r["err"]) else "%.1f %%" % (100 * r["err"])
        L.append(f"| {r['seed']} | {r['t']} | {r['uav']} | {r['dist']:.1f} | {r['motion']} | {r['box_h']} | "
                 f"{'yes' if r['found'] else 'no'} | {err} |")
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w", encoding="utf-8") as f:
        f.write("\n".join(L) + "\n")
    print(f"check_render_movenet: {len(found)}/{len(rows)} found; wrote {a.out}")


if __name__ == "__main__":
    main()
