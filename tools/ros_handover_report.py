#!/usr/bin/env python3
"""The leader_dropout_for_good profile through ROS beside gfctl simulate (tools/run_ros_leader_dropout.sh
writes its runs; this writes docs/results/ros_leader_dropout.md).

usage: ros_handover_report.py --runs DIR [DIR ...] --silence-s T --limit-s L --duration S --rtf X --load TEXT --out FILE

Each DIR holds one seed: ros/ (SimWorld's metrics.json, events.csv, leadership.csv) and sim/ (gfctl
simulate's metrics.json, events.csv) of the same seed and duration. From leadership.csv (every UAV's
leadership_state as SimWorld received it: t_s, uav, term, leader, acting) the acting intervals of each
UAV run from an acting state's stamp to that UAV's next state (or the end); the report gives the UAV
acting at the silence, the first other UAV to act and when (the hand-over time: its first acting
stamp − the silence), the most UAVs acting at one instant, the requests issued after the silence and
applied (events.csv), and the safety figures of both runs. Exit code: 1 when through ROS a seed had a
collision, two acting at once, no new leader within the limit, or a request after the hand-over not
applied; else 0."""
import argparse
import csv
import json
import math
import os
import sys


def acting_intervals(rows, t_end):
    """{uav: [(from, to)]} from the leadership states in order of arrival."""
    by_uav = {}
    for r in rows:
        by_uav.setdefault(r["uav"], []).append(r)
    out = {}
    for uav, states in by_uav.items():
        iv = []
        for k, s in enumerate(states):
            if s["acting"]:
                to = states[k + 1]["t_s"] if k + 1 < len(states) else t_end
                iv.append((s["t_s"], to))
        out[uav] = iv
    return out


def max_acting(iv):
    """The most UAVs whose intervals overlap at one instant (touching ends do not overlap)."""
    edges = sorted([(a, 1) for v in iv.values() for a, _ in v] + [(b, -1) for v in iv.values() for _, b in v],
                   key=lambda e: (e[0], e[1]))
    best = cur = 0
    for _, d in edges:
        cur += d
        best = max(best, cur)
    return best


def requests_after(events_path, t0):
    """(applied, total) of the requests issued at or after t0 (the operator's and the recognised gestures';
    rows of source worker are performances no camera recognised, not requests)."""
    applied = total = 0
    with open(events_path) as f:
        for row in csv.DictReader(f):
            if float(row["t"]) >= t0 and row["source"] != "worker":
                total += 1
                applied += row["status"] == "applied"
    return applied, total


def read_leadership(path):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append({"t_s": float(r["t_s"]), "uav": int(r["uav"]), "term": int(r["term"]),
                         "leader": int(r["leader"]), "acting": r["acting"] == "1"})
    return rows


def seed_row(run, silence_s, limit_s):
    ros = json.load(open(os.path.join(run, "ros", "metrics.json")))
    sim = json.load(open(os.path.join(run, "sim", "metrics.json")))
    t_end = ros["sim_time_s"]
    iv = acting_intervals(read_leadership(os.path.join(run, "ros", "leadership.csv")), t_end)
    before = [u for u, v in iv.items() if any(a <= silence_s < b for a, b in v)]
    silent = before[0] if len(before) == 1 else None
    firsts = sorted((a, u) for u, v in iv.items() if u != silent for a, _ in v if a >= silence_s)
    new_s, new = firsts[0] if firsts else (math.nan, None)
    handover = new_s - silence_s if new is not None else math.nan
    applied, total = requests_after(os.path.join(run, "ros", "events.csv"), silence_s + (handover if new is not None else 0.0))
    lead = sim.get("leadership", {})
    row = {
        "seed": ros["seed"], "silent": silent, "new": new, "handover_s": handover, "max_acting": max_acting(iv),
        "applied": applied, "total": total, "sim_handover_s": lead.get("handover_s"), "sim_new": lead.get("new_leader"),
        "sim_applied": lead.get("requests_after_applied"), "sim_total": lead.get("requests_after"),
        "ros": ros, "sim": sim,
    }
    row["ok"] = (ros["collisions"] == 0 and row["max_acting"] <= 1 and new is not None and handover <= limit_s
                 and applied == total)
    return row


def fmt(v, digits=2):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    return f"{v:.{digits}f}" if isinstance(v, float) else str(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", nargs="+", required=True)
    ap.add_argument("--silence-s", type=float, required=True, help="faults.leader_silence.t_s of the profile")
    ap.add_argument("--limit-s", type=float, required=True, help="the hand-over limit (silence_limit + stagger + 2 election timeouts)")
    ap.add_argument("--duration", type=float, required=True)
    ap.add_argument("--rtf", required=True)
    ap.add_argument("--load", required=True)
    ap.add_argument("--commit", required=True)
    ap.add_argument("--date", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    rows = [seed_row(r, a.silence_s, a.limit_s) for r in a.runs]
    lines = [
        "# The leader_dropout_for_good profile through ROS (written by `tools/run_ros_leader_dropout.sh`)",
        "",
        f"Run on {a.date}, commit `{a.commit}`. Mission: `config/scenarios/power_towers.yaml` with "
        f"`config/faults/leader_dropout_for_good.yaml` (at {a.silence_s:g} s the radio of the UAV acting as leader dies for good: "
        "SimWorld unloads its LcmBridge), to "
        f"{a.duration:g} s, through `tools/run_ros_mission.sh --leadership` (simulation.launch leadership:=true, real-time factor "
        f"{a.rtf}), beside `gfctl simulate` with the same seed, profile and duration. Machine: {a.load}. "
        "What the UAVs do: [safety.md](../safety.md) §1.2; hand-over limit "
        f"{a.limit_s:g} s. Acting intervals through ROS: every UAV's `leadership_state` as SimWorld received it "
        "(`leadership.csv`), from an acting state's stamp to the UAV's next state.",
        "",
        "| seed | silent UAV | new leader (ROS / gfctl) | hand-over [s] (ROS / gfctl) | most acting at once (ROS) | "
        "requests after the silence applied (ROS / gfctl) | collisions (ROS / gfctl) | min mutual [m] (ROS / gfctl) | "
        "min worker [m] (ROS / gfctl) | min obstacle [m] (ROS / gfctl) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ros, sim = r["ros"], r["sim"]
        lines.append(
            f"| {r['seed']} | {fmt(r['silent'])} | {fmt(r['new'])} / {fmt(r['sim_new'])} | {fmt(r['handover_s'])} / "
            f"{fmt(r['sim_handover_s'])} | {r['max_acting']} | {r['applied']}/{r['total']} / {fmt(r['sim_applied'])}/{fmt(r['sim_total'])} | "
            f"{ros['collisions']} / {sim['collisions']} | {fmt(ros['min_mutual_distance_m'])} / {fmt(sim['min_mutual_distance_m'])} | "
            f"{fmt(ros['min_human_distance_m'])} / {fmt(sim['min_human_distance_m'])} | "
            f"{fmt(ros['min_obstacle_distance_m'])} / {fmt(sim['min_obstacle_distance_m'])} |")
    bad = [r["seed"] for r in rows if not r["ok"]]
    lines += ["", f"Seeds failing a ROS check (collision, two acting, no new leader within {a.limit_s:g} s, a request "
              f"after the hand-over not applied): {', '.join(map(str, bad)) if bad else 'none'}.", ""]
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
