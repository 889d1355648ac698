#!/usr/bin/env python3
"""docs/results/abort.md from the metrics.json of abort missions (tools/run_abort_profile.sh).

Per UAV over the seeds, min / median / max of: the time from the abort's issue to acceptance,
to the retreat goal reached and to settled; the least distances after the abort to the worker,
the obstacles and the other UAVs. Mission-wide: collisions, min mutual distance (Gamma_dis 2.5 m),
min obstacle distance (verification clearance 0.5 m).
"""
import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys

GAMMA_DIS_M = 2.5
CLEARANCE_M = 0.5


def stats(values):
    vals = [v for v in values if v is not None]
    missing = len(values) - len(vals)
    if not vals:
        return "never"
    text = f"{min(vals):.2f} / {statistics.median(vals):.2f} / {max(vals):.2f}"
    return text + (f" ({missing} never)" if missing else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--missions", required=True, help="folder with seed_N/metrics.json")
    ap.add_argument("--seeds", type=int, required=True)
    ap.add_argument("--duration", type=float, required=True)
    ap.add_argument("--profile", required=True)
    ap.add_argument("--load", required=True, help="the machine load, as measured by the caller")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    missions = []
    for seed in range(1, a.seeds + 1):
        path = os.path.join(a.missions, f"seed_{seed}", "metrics.json")
        if not os.path.exists(path):
            sys.exit(f"abort_report.py: {path} missing")
        missions.append(json.load(open(path)))
    if any("abort" not in m for m in missions):
        sys.exit("abort_report.py: a mission has no abort section (profile without faults.abort?)")
    n_uav = len(missions[0]["abort"]["uavs"])
    commit = subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--", "src", "include", "config"], capture_output=True,
                           text=True).stdout.strip()
    if dirty:
        commit += " + uncommitted changes to src/include/config"
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    issued = missions[0]["abort"]["issued_s"]
    lines = [
        "# Abort: the power-tower mission with `" + a.profile + "`",
        "",
        f"Written by `tools/abort_report.py` (via `tools/run_abort_profile.sh`; do not edit by hand) on {now}, "
        f"commit `{commit}`. Mission: `config/scenarios/power_towers.yaml` with `config/faults/{a.profile}.yaml` "
        f"(abort by the `{missions[0]['abort']['source']}` at {issued:g} s), run to {a.duration:g} s, seeds 1..{a.seeds}, "
        "real planner, estimator and gesture LSTM (`gfctl simulate --threads 1`, nice -n 10). "
        f"Machine load: {a.load}. What the abort does: [safety.md](../safety.md) §2.8.",
        "",
        "Each cell: **min / median / max over seeds**; times from the abort's issue; distances from the issue to the "
        "end (true positions). Settled = hovering at the retreat goal (`abort.after: hover`).",
        "",
        "| UAV | accepted [s] | retreat reached [s] | settled [s] | min worker distance [m] | min obstacle distance [m] | min distance to a UAV [m] | final phase |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for i in range(n_uav):
        rec = [m["abort"]["uavs"][i] for m in missions]
        rel = lambda key: [None if r[key] is None else r[key] - m["abort"]["issued_s"] for r, m in zip(rec, missions)]
        phases = sorted({r["phase"] for r in rec})
        lines.append(
            f"| {'leader' if i == 0 else 'follower ' + str(i)} | {stats(rel('accepted_s'))} | {stats(rel('retreat_reached_s'))} | "
            f"{stats(rel('settled_s'))} | {stats([r['min_worker_distance_m'] for r in rec])} | "
            f"{stats([r['min_obstacle_distance_m'] for r in rec])} | {stats([r['min_uav_distance_m'] for r in rec])} | "
            f"{', '.join(phases)} |")
    settle = [m["abort"]["time_to_settle_max_s"] for m in missions]
    collisions = sum(m["collisions"] for m in missions)
    gamma = sum(1 for m in missions if m["min_mutual_distance_m"] < GAMMA_DIS_M)
    clear = sum(1 for m in missions if m["min_obstacle_distance_m"] < CLEARANCE_M)
    lines += [
        "",
        f"Every UAV settled: time of the slowest UAV per seed {stats(settle)} s.",
        "",
        f"Whole missions (before and after the abort): collisions {collisions} in {a.seeds} missions; "
        f"missions with a mutual distance below Gamma_dis {GAMMA_DIS_M} m: {gamma} "
        f"(min mutual {stats([m['min_mutual_distance_m'] for m in missions])} m); "
        f"below the obstacle clearance {CLEARANCE_M} m: {clear} "
        f"(min obstacle {stats([m['min_obstacle_distance_m'] for m in missions])} m); "
        f"min worker distance {stats([m['min_human_distance_m'] for m in missions])} m.",
        "",
        "Per seed (seed: slowest settle [s], min mutual [m], min obstacle [m], collisions): "
        + "; ".join(f"{s + 1}: {'never' if m['abort']['time_to_settle_max_s'] is None else format(m['abort']['time_to_settle_max_s'], '.2f')}, "
                    f"{m['min_mutual_distance_m']:.2f}, {m['min_obstacle_distance_m']:.2f}, {m['collisions']}"
                    for s, m in enumerate(missions)) + ".",
        "",
    ]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
