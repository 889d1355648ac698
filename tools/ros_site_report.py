#!/usr/bin/env python3
"""Writes docs/results/ros_site_mapping.md from tools/run_ros_site_mapping.sh's runs: per seed, the
construction site flown through ROS with rendered cameras and live maps (simulation.launch
camera:=rendered mapping:=true): the mission's safety and request figures (metrics.json of SimWorld,
which counts the unmapped obstacles), the planners' fallbacks, and each FormationPlanner's live-map
diagnostics from the bag's /diagnostics (frames integrated per wall second, voxel changes, refused
frames), with the UAV managers' peak resident memory.

  tools/ros_site_report.py --runs DIR... --rtf X --commit TEXT --date TEXT --load TEXT --out FILE

Each DIR holds metrics.json, processes.txt and diag.csv (`rostopic echo -b mission.bag -p
/diagnostics`). Exit 0 when no run had a collision and every run's least obstacle distance kept the
verification clearance (0.5 m, config/planner.yaml); 1 otherwise; 2 on bad input.
"""
import argparse
import csv
import json
import os
import re
import sys

CLEARANCE_M = 0.5  # planner.verify clearance_m (config/planner.yaml)


def live_map(diag_csv):
    """Per planner: diagnostics samples, mean frames per wall second, voxel changes, refused frames."""
    out = {}
    with open(diag_csv) as f:
        rows = list(csv.reader(f))
    for r in rows[1:]:
        name = next((x for x in r if x.startswith("FormationPlanner")), None)
        kv = {r[i]: r[i + 1] for i in range(len(r) - 1) if r[i].startswith("live_map_")}
        if not name or not kv:
            continue
        t = out.setdefault(name, {"n": 0, "fps": 0.0, "changes": 0, "refused": 0, "sent": 0, "merged": 0})
        t["n"] += 1
        t["sent"] += int(kv.get("live_map_updates_sent", 0))
        t["merged"] += int(kv.get("live_map_updates_merged", 0))
        t["fps"] += float(kv["live_map_frames_per_s"])
        t["changes"] += int(kv["live_map_changes"])
        t["refused"] += int(kv["live_map_refused"])
    return out


def peaks(processes_txt):
    """UAV managers' peak resident set [MB] from run_ros_mission.sh's processes.txt (pid, CPU time,
    resident kB, peak kB, command line with its __log file naming the process)."""
    found = {}
    with open(processes_txt) as f:
        for line in f:
            parts = line.split()
            m = re.search(r"/(uav\d)-manager-\d+\.log", line)
            if m and len(parts) >= 4:
                found[m.group(1)] = round(int(parts[3]) / 1024)
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", nargs="+", required=True)
    ap.add_argument("--rtf", required=True)
    ap.add_argument("--commit", required=True)
    ap.add_argument("--date", required=True)
    ap.add_argument("--load", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--share", default="0", help="1: the runs shared their live-map changes (share.enabled)")
    a = ap.parse_args()
    L = ["# Results: the construction site through ROS, rendered cameras and live maps"
         + (" shared between the UAVs" if a.share == "1" else ""), "",
         f"Written by `tools/run_ros_site_mapping.sh` on {a.date} at commit {a.commit}: per seed "
         "`tools/run_ros_mission.sh --mission config/scenarios/construction_site.yaml --camera rendered --mapping "
         f"--rtf {a.rtf}` — every UAV's camera rendered by SimCamera (the crane arm, the scaffolding and the truck "
         "drawn where they are), seen by the onboard Perception nodelet, and integrated into its FormationPlanner's "
         "live map (depth and CameraInfo topics of the camera, pose from tf), fused with the scenario's map"
         + ("; with map sharing (share.enabled: every UAV sends its own live-map changes over LCM and merges the "
            "others', docs/mapping.md §8)" if a.share == "1" else "") + "; "
         "SimWorld's obstacle distance and collisions count the unmapped obstacles. How: "
         "[mapping.md](../mapping.md) §9, [ros.md](../ros.md).", "",
         f"Machine: {a.load}. Wall-clock figures (planning, frames per wall second) under load are upper / lower bounds.", "",
         "| seed | collisions | min obstacle [m] | min mutual [m] | min human [m] | requests applied | planning median / p99 [ms] "
         "| fallbacks previous / brake of plans | live map frames per wall s (UAV 0/1/2) | voxel changes (0/1/2) | refused frames "
         "| map updates sent / merged (0/1/2) | managers' peak RSS [MB] |",
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    bad = []
    for run in a.runs:
        try:
            m = json.load(open(os.path.join(run, "metrics.json")))
            lm = live_map(os.path.join(run, "diag.csv"))
            rss = peaks(os.path.join(run, "processes.txt"))
        except (OSError, ValueError, KeyError) as e:
            print(f"ros_site_report: {run}: {e}", file=sys.stderr)
            return 2
        names = [f"FormationPlanner uav{i}" for i in range(3)]
        fps = " / ".join(f"{lm[n]['fps'] / lm[n]['n']:.2f}" if n in lm else "–" for n in names)
        ch = " / ".join(str(lm[n]["changes"]) if n in lm else "–" for n in names)
        refused = sum(lm[n]["refused"] for n in names if n in lm)
        updates = " / ".join(f"{lm[n]['sent']}/{lm[n]['merged']}" if n in lm else "–" for n in names)
        L.append(f"| {m['seed']} | {m['collisions']} | {m['min_obstacle_distance_m']:.2f} | {m['min_mutual_distance_m']:.2f} | "
                 f"{m['min_human_distance_m']:.2f} | {m['requests_applied']}/{m['requests_total']} | "
                 f"{m['planning_ms_median']:.1f} / {m['planning_ms_p99']:.1f} | {m['plans_fallback_previous']} / "
                 f"{m['plans_fallback_brake']} of {m['plans']} | {fps} | {ch} | {refused} | "
                 f"{updates} | "
                 f"{' / '.join(str(rss.get(f'uav{i}', '–')) for i in range(3))} |")
        if m["collisions"] > 0 or m["min_obstacle_distance_m"] < CLEARANCE_M:
            bad.append(str(m["seed"]))
        if not lm:
            bad.append(f"{m['seed']} (no live-map diagnostics)")
    L += ["", "Live map: frames integrated per wall second, averaged over the diagnostics periods (the camera "
          "renders `camera_rate` 5 frames per simulated second; at the run's real-time factor that is "
          f"5 × {a.rtf} per wall second at most); voxel changes: the live map's changes summed over the run.", ""]
    with open(a.out, "w") as f:
        f.write("\n".join(L))
    print("\n".join(L))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
