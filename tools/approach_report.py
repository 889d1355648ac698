#!/usr/bin/env python3
"""docs/results/worker_approach.md from the metrics.json of worker-approach missions
(tools/run_approach_profile.sh), or from a campaign store's rows of the profile (tools/campaign.py).

The unseen phase (metrics.json `worker_approach`: from the worker's turn towards a holding UAV
until the camera blackout ends or the mission does): per UAV over the seeds, min / median / max of
its least true distance to the worker, and the Gamma_dis violations (entries below the formation's
Gamma_dis); the distribution of the least distance of any UAV; the back-offs from modes.csv.
Mission-wide: collisions, min mutual distance (Gamma_dis 2.5 m), min obstacle distance (0.5 m).
A store keeps each mission's metrics.json but no modes.csv: from --store the page says the back-offs are
not available.

  tools/approach_report.py --missions DIR --seeds N --duration S --profile P --load L --out FILE [--commit SHA]
  tools/approach_report.py --store FILE [--commit PREFIX] --profile P --load L --out FILE
"""
import argparse
import csv
import datetime
import json
import os
import sqlite3
import statistics
import subprocess
import sys

GAMMA_DIS_M = 2.5
CLEARANCE_M = 0.5


def stats(values):
    vals = [v for v in values if v is not None]
    if not vals:
        return "never"
    return f"{min(vals):.2f} / {statistics.median(vals):.2f} / {max(vals):.2f}"


def quantiles(values):
    vals = sorted(values)
    pick = lambda q: vals[min(len(vals) - 1, int(q * (len(vals) - 1) + 0.5))]
    return (f"min {vals[0]:.2f}, 5 % {pick(0.05):.2f}, 25 % {pick(0.25):.2f}, median {pick(0.5):.2f}, "
            f"75 % {pick(0.75):.2f}, max {vals[-1]:.2f}")


def backoffs(path):
    """Per UAV: the first back-off row of modes.csv as (t, "backoff" | "none": no goal found)."""
    first = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            uav = 0 if row["uav"] == "L" else int(row["uav"])
            for prefix, kind in (("backing off from the worker's reach", "backoff"), ("no back-off goal", "none")):
                if row["reason"].startswith(prefix) and uav not in first:
                    first[uav] = (float(row["t"]), kind)
    return first


def from_folder(folder, n_seeds):
    """Seeds 1..n_seeds of folder/seed_N: (seeds, metrics, first back-offs per UAV)."""
    missions, modes = [], []
    for seed in range(1, n_seeds + 1):
        d = os.path.join(folder, f"seed_{seed}")
        if not os.path.exists(os.path.join(d, "metrics.json")):
            sys.exit(f"approach_report.py: {d}/metrics.json missing")
        missions.append(json.load(open(os.path.join(d, "metrics.json"))))
        modes.append(backoffs(os.path.join(d, "modes.csv")))
    return list(range(1, n_seeds + 1)), missions, modes


def from_store(store, commit, profile):
    """The profile's rows in a campaign store at source commits starting with commit, by seed: (seeds,
    metrics, source commits, duration [s], missions finished first .. last)."""
    con = sqlite3.connect(f"file:{store}?mode=ro", uri=True)
    rows = con.execute("SELECT seed, metrics_json, source_commit, config_json, finished_utc FROM missions "
                       "WHERE profile = ? AND source_commit LIKE ? ORDER BY seed", (profile, commit + "%")).fetchall()
    con.close()
    if not rows:
        sys.exit(f"approach_report.py: {store}: no mission of {profile} at commit {commit or 'any'}")
    seeds = [r[0] for r in rows]
    durations = {json.loads(r[3])["duration_s"] for r in rows}
    if len(set(seeds)) != len(seeds) or len(durations) != 1:
        sys.exit(f"approach_report.py: {store}: {len(seeds) - len(set(seeds))} seeds stored twice, durations "
                 f"{sorted(durations)} (narrow --commit)")
    finished = sorted(r[4] for r in rows if r[4])
    return (seeds, [json.loads(r[1]) for r in rows], sorted({r[2][:10] for r in rows}), durations.pop(),
            f"{finished[0]} .. {finished[-1]}" if finished else "-")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--missions", help="folder with seed_N/metrics.json and modes.csv")
    src.add_argument("--store", help="a campaign store (tools/campaign.py): its rows of --profile")
    ap.add_argument("--seeds", type=int, help="with --missions: seeds 1..N")
    ap.add_argument("--duration", type=float, help="with --missions: the missions' length [s]")
    ap.add_argument("--profile", required=True)
    ap.add_argument("--load", required=True, help="the machine load, as measured by the caller")
    ap.add_argument("--out", required=True)
    ap.add_argument("--commit", help="with --missions: the commit gfctl was built from (default: HEAD, as git "
                    "reports it); with --store: only rows of source commits starting with this")
    a = ap.parse_args()
    if a.store:
        if not os.path.exists(a.store):
            sys.exit(f"approach_report.py: --store {a.store}: no such file")
        seeds, missions, commits, duration, finished = from_store(a.store, a.commit or "", a.profile)
        modes = None
    else:
        if a.seeds is None or a.duration is None:
            ap.error("--missions needs --seeds and --duration")
        seeds, missions, modes = from_folder(a.missions, a.seeds)
        duration = a.duration
    if any("worker_approach" not in m for m in missions):
        sys.exit("approach_report.py: a mission has no worker_approach section (profile without faults.worker_approach?)")
    ap0 = missions[0]["worker_approach"]
    n_uav = len(ap0["uavs"])
    if a.store:
        via = f"from the campaign store `{os.path.basename(a.store)}`, missions finished {finished}"
        commit = ", ".join(commits)
    else:
        via = "via `tools/run_approach_profile.sh`"
        commit = a.commit or subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], capture_output=True,
                                            text=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "src", "include", "config"],
                               capture_output=True, text=True).stdout.strip()
        if dirty and not a.commit:
            commit += " + uncommitted changes to src/include/config"
    n = len(seeds)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    violations = sum(m["worker_approach"]["gamma_dis_violations"] for m in missions)
    lines = [
        "# The worker walks, unseen, towards a holding UAV: the power-tower mission with `" + a.profile + "`",
        "",
        f"Written by `tools/approach_report.py` ({via}; do not edit by hand) on {now}, "
        f"commit `{commit}`. Mission: `config/scenarios/power_towers.yaml` with `config/faults/{a.profile}.yaml` (at "
        f"{ap0['t_s']:g} s the worker turns towards UAV {ap0['uav']} and walks to the point below it, the camera blind), "
        f"run to {duration:g} s, seeds {seeds[0]}..{seeds[-1]}, real planner, estimator and gesture LSTM (`gfctl "
        f"simulate --threads 1`{'' if a.store else ', nice -n 10'}). Machine load: {a.load}. What the UAVs do: "
        "[safety.md](../safety.md) §3.",
        "",
        f"Unseen phase: from the turn to the end of the blackout or of the run (true positions, every 0.01 s step); "
        f"Gamma_dis {ap0['gamma_dis_m']:g} m (the formation's `limits.safety_distance_m`).",
        "",
        f"**Gamma_dis violations in the unseen phase: {violations} in {n} missions.** "
        f"Least distance of any UAV to the worker per seed [m]: "
        f"{quantiles([m['worker_approach']['min_distance_m'] for m in missions])}.",
        "",
        "Each cell: **min / median / max over seeds**."
        + ("" if modes is not None else " Back-offs: not available from the store (they are read from each mission's "
           "modes.csv, which a campaign does not keep; metrics.json has no back-off figure): "
           "`tools/run_approach_profile.sh` gives them."),
        "",
        "| UAV | min distance to the worker, unseen [m] | Gamma_dis violations | backed off in | first back-off [s] |",
        "|---|---|---|---|---|",
    ]
    for i in range(n_uav):
        rec = [m["worker_approach"]["uavs"][i] for m in missions]
        if modes is None:
            backed_off = "not in the store | not in the store"
        else:
            first = [b.get(i) for b in modes]
            backed = sum(1 for f in first if f and f[1] == "backoff")
            backed_off = f"{backed} of {n} missions | {stats([f[0] for f in first if f])}"
        lines.append(
            f"| {'leader' if i == 0 else 'follower ' + str(i)} | {stats([r['min_distance_m'] for r in rec])} | "
            f"{sum(r['gamma_dis_violations'] for r in rec)} | {backed_off} |")
    collisions = sum(m["collisions"] for m in missions)
    gamma = sum(1 for m in missions if m["min_mutual_distance_m"] < GAMMA_DIS_M)
    clear = sum(1 for m in missions if m["min_obstacle_distance_m"] < CLEARANCE_M)
    lines += [
        "",
        f"Whole missions: collisions {collisions} in {n} missions; missions with a mutual distance below "
        f"Gamma_dis {GAMMA_DIS_M} m: {gamma} (min mutual {stats([m['min_mutual_distance_m'] for m in missions])} m); "
        f"below the obstacle clearance {CLEARANCE_M} m: {clear} "
        f"(min obstacle {stats([m['min_obstacle_distance_m'] for m in missions])} m); "
        f"min worker distance {stats([m['min_human_distance_m'] for m in missions])} m.",
        "",
        "Per seed (seed: least distance unseen [m], violations, min mutual [m], min obstacle [m], collisions): "
        + "; ".join(f"{s}: {m['worker_approach']['min_distance_m']:.2f}, {m['worker_approach']['gamma_dis_violations']}, "
                    f"{m['min_mutual_distance_m']:.2f}, {m['min_obstacle_distance_m']:.2f}, {m['collisions']}"
                    for s, m in zip(seeds, missions)) + ".",
        "",
    ]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
