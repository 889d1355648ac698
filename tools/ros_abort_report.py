#!/usr/bin/env python3
"""docs/results/ros_abort.md: the abort profile through ROS next to gfctl simulate (tools/run_ros_abort.sh).

Reads the metrics.json of one mission through launch/simulation.launch (tools/run_ros_mission.sh
--faults config/faults/abort_mid_mission.yaml) and of gfctl simulate with the same mission, profile,
seed and duration; writes per UAV the times from the abort's issue (accepted, retreat reached,
settled) and the least distances after it, and the whole missions' safety figures, side by side.
"""
import argparse
import datetime
import json
import subprocess
import sys

GAMMA_DIS_M = 2.5


def fmt(v, unit=""):
    return "never" if v is None else f"{v:.2f}{unit}"


def rel(rec, key, issued):
    return None if rec[key] is None else rec[key] - issued


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ros", required=True, help="metrics.json of the mission through ROS")
    ap.add_argument("--sim", required=True, help="metrics.json of gfctl simulate")
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--duration", type=float, required=True)
    ap.add_argument("--profile", required=True)
    ap.add_argument("--rtf", required=True, help="the ROS run's real-time factor")
    ap.add_argument("--load", required=True, help="the machine load, as measured by the caller")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    runs = {"ROS": json.load(open(a.ros)), "gfctl": json.load(open(a.sim))}
    for name, m in runs.items():
        if "abort" not in m:
            sys.exit(f"ros_abort_report.py: the {name} mission has no abort section (no faults.abort, or the abort never came)")
    commit = subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], capture_output=True, text=True).stdout.strip()
    if subprocess.run(["git", "status", "--porcelain", "--", "src", "include", "nodelets", "launch", "config"],
                      capture_output=True, text=True).stdout.strip():
        commit += " + uncommitted changes"
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    ros, sim = runs["ROS"], runs["gfctl"]
    lines = [
        f"# Abort through ROS: the power-tower mission with `{a.profile}`",
        "",
        f"Written by `tools/ros_abort_report.py` (via `tools/run_ros_abort.sh`; do not edit by hand) on {now}, "
        f"commit `{commit}`. Mission: `config/scenarios/power_towers.yaml` with `config/faults/{a.profile}.yaml` "
        f"(abort by the `{ros['abort']['source']}` at {ros['abort']['issued_s']:g} s), seed {a.seed}, run to "
        f"{a.duration:g} s: through `launch/simulation.launch` (`tools/run_ros_mission.sh`, real-time factor {a.rtf}; "
        "SimWorld asks the ground station's OperatorInterface for the abort at its time, as an operator does, and "
        "records every UAV's latched abort_state) and `gfctl simulate` (same seed and duration). "
        f"Machine load: {a.load}. What the abort does: [safety.md](../safety.md) §2.8; the 100-seed "
        "distribution of `gfctl simulate`: [abort.md](abort.md).",
        "",
        "Times from the abort's issue; distances from the issue to the end (true positions). Through ROS the "
        "world's clock waits for the send_abort call, so the first copy can reach every UAV within the clock step of "
        "the issue (accepted 0.00 s); `gfctl simulate` delays each copy by its operator link model.",
        "",
        "| UAV | run | accepted [s] | retreat reached [s] | settled [s] | final phase | min worker distance [m] | "
        "min obstacle distance [m] | min distance to a UAV [m] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for i in range(len(ros["abort"]["uavs"])):
        for name, m in runs.items():
            r, issued = m["abort"]["uavs"][i], m["abort"]["issued_s"]
            lines.append(
                f"| {'leader' if i == 0 else 'follower ' + str(i)} | {name} | {fmt(rel(r, 'accepted_s', issued))} | "
                f"{fmt(rel(r, 'retreat_reached_s', issued))} | {fmt(rel(r, 'settled_s', issued))} | {r['phase']} | "
                f"{fmt(r['min_worker_distance_m'])} | {fmt(r['min_obstacle_distance_m'])} | {fmt(r['min_uav_distance_m'])} |")
    lines += ["", "| whole mission | through ROS | gfctl simulate |", "|---|---|---|"]
    rows = [("slowest UAV settled after [s]", lambda m: fmt(m["abort"]["time_to_settle_max_s"])),
            ("collisions", lambda m: str(m["collisions"])),
            (f"min mutual distance [m] (Gamma_dis {GAMMA_DIS_M} m)", lambda m: fmt(m["min_mutual_distance_m"])),
            ("min obstacle distance [m]", lambda m: fmt(m["min_obstacle_distance_m"])),
            ("min worker distance [m]", lambda m: fmt(m["min_human_distance_m"]))]
    for label, f in rows:
        lines.append(f"| {label} | {f(ros)} | {f(sim)} |")
    ok = (ros["collisions"] == 0 and ros["min_mutual_distance_m"] >= GAMMA_DIS_M
          and ros["abort"]["time_to_settle_max_s"] is not None)
    lines += ["", "Through ROS: " + ("every UAV settled, no collision, every mutual distance above Gamma_dis."
                                     if ok else "NOT every UAV settled without a collision above Gamma_dis (see the table)."),
              ""]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
