#!/usr/bin/env python3
"""The worker_approaches_holding_uav profile through ROS beside gfctl simulate (tools/run_ros_approach.sh
writes its runs; this writes docs/results/ros_worker_approach.md).

usage: ros_approach_report.py --runs DIR [DIR ...] --duration S --rtf X --load TEXT --commit C --date D --out FILE

Each DIR holds one seed: ros/metrics.json (SimWorld) and sim/metrics.json (gfctl simulate) of the same
seed and duration; both carry `worker_approach` (sim::ApproachRecorder over the true positions of
every step: the least distance of each UAV to the worker while he walks unseen, and the Gamma_dis
violations). Exit code: 1 when through ROS a seed had a collision or a Gamma_dis violation; else 0."""
import argparse
import json
import os
import sys


def fmt(v, digits=2):
    return "—" if v is None else (f"{v:.{digits}f}" if isinstance(v, float) else str(v))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    for k in ("--duration", "--rtf", "--load", "--commit", "--date", "--out"):
        ap.add_argument(k, required=True)
    ap.add_argument("--runs", nargs="+", required=True)
    a = ap.parse_args()
    lines = [
        "# The worker walks, unseen, towards a holding UAV — through ROS (written by `tools/run_ros_approach.sh`)",
        "",
        f"Run on {a.date}, commit `{a.commit}`. Mission: `config/scenarios/power_towers.yaml` with "
        "`config/faults/worker_approaches_holding_uav.yaml` (at 210 s the worker turns towards UAV 2 and walks to the "
        f"point below it, the camera blind), to {a.duration} s, through `tools/run_ros_mission.sh` (simulation.launch, "
        f"real-time factor {a.rtf}; SimWorld records the approach like gfctl simulate), beside `gfctl simulate` with the "
        f"same seed, profile and duration. Machine: {a.load}. What the UAVs do: [safety.md](../safety.md) §3; the "
        "100-seed gfctl record: [worker_approach.md](worker_approach.md).",
        "",
        "| seed | least distance to the worker, unseen [m] (ROS / gfctl) | per UAV (ROS) | per UAV (gfctl) | "
        "Gamma_dis violations (ROS / gfctl) | collisions (ROS / gfctl) | min mutual [m] (ROS / gfctl) | min obstacle [m] (ROS / gfctl) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    bad = []
    for run in a.runs:
        ros = json.load(open(os.path.join(run, "ros", "metrics.json")))
        sim = json.load(open(os.path.join(run, "sim", "metrics.json")))
        ra, sa = ros.get("worker_approach") or {}, sim.get("worker_approach") or {}
        per = lambda s: ", ".join(fmt(u["min_distance_m"]) for u in s.get("uavs", []))  # noqa: E731
        lines.append(
            f"| {ros['seed']} | {fmt(ra.get('min_distance_m'))} / {fmt(sa.get('min_distance_m'))} | {per(ra)} | {per(sa)} | "
            f"{fmt(ra.get('gamma_dis_violations'))} / {fmt(sa.get('gamma_dis_violations'))} | {ros['collisions']} / {sim['collisions']} | "
            f"{fmt(ros['min_mutual_distance_m'])} / {fmt(sim['min_mutual_distance_m'])} | "
            f"{fmt(ros['min_obstacle_distance_m'])} / {fmt(sim['min_obstacle_distance_m'])} |")
        if ros["collisions"] != 0 or not ra or ra.get("gamma_dis_violations") != 0:
            bad.append(ros["seed"])
    lines += ["", "Seeds failing through ROS (a collision, a Gamma_dis violation, or no approach recorded): "
              f"{', '.join(map(str, bad)) if bad else 'none'}.", ""]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
