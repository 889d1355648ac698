#!/usr/bin/env python3
"""Checks what SimWorld wrote at the end of a short simulation.launch run (test/ros/
simulation_launch.sh: 40 s of the power-tower mission; a gesture 2 injected at the leader at
t ~ 8 s; the mission's first operator request at t = 20 s): metrics.json carries every design.md
§8.4 key with the definitions of gfctl simulate (sim::MetricsAccumulator), and the requests
were followed through the ROS system — applied by the leader (FormationParams.last_command_*)
and adapted to by the UAVs' next plans (PlannedTrajectory.params_version / planned_at).
usage: check_sim_metrics.py OUTPUT_DIR; prints one line per check; exit code = failures."""
import csv
import json
import math
import sys

DESIGN_KEYS = ["min_mutual_distance_m", "min_obstacle_distance_m", "min_human_distance_m", "collisions",
               "distance_error_rms_m", "angle_error_rms_deg", "requests_applied", "gesture_success_rate",
               "gesture_mean_latency_s", "false_adaptations", "planning_ms_median", "planning_ms_p99",
               "human_estimate_error_rms_m"]
fails = 0


def check(ok, what):
    global fails
    print(("PASS: " if ok else "FAIL: ") + what)
    fails += 0 if ok else 1


def num(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return float("nan")


def main():
    out = sys.argv[1]
    m = json.load(open(f"{out}/metrics.json"))
    missing = [k for k in DESIGN_KEYS if k not in m]
    check(not missing, "metrics.json has every design.md §8.4 key" + (f" (missing {missing})" if missing else ""))
    check(abs(num(m.get("sim_time_s")) - 40.0) < 0.05, f"the mission ran to its 40 s (sim_time_s {m.get('sim_time_s')})")
    check(m.get("collisions") == 0, f"no collision ({m.get('collisions')})")
    check(2.5 <= num(m.get("min_mutual_distance_m")) < 50, f"min mutual distance {m.get('min_mutual_distance_m')} m >= 2.5")
    check(0.0 < num(m.get("min_obstacle_distance_m")) < 50 and m.get("min_obstacle_uav") in (0, 1, 2),
          f"min obstacle distance {m.get('min_obstacle_distance_m')} m (exact near the solids) by UAV {m.get('min_obstacle_uav')}")
    check(0.0 < num(m.get("human_estimate_error_rms_m")) < 1.0, f"estimate error {m.get('human_estimate_error_rms_m')} m RMS")
    check(0.0 < num(m.get("distance_error_rms_m")) < 5.0, f"distance error {m.get('distance_error_rms_m')} m RMS")
    check(m.get("plans", 0) > 3 * 2.5 * 30, f"{m.get('plans')} plans counted (3 UAVs at 2.5 Hz)")
    check(m.get("gestures_performed") == 0 and m.get("false_adaptations") == 1,
          f"the injected gesture (no worker gesture before 72 s) is 1 false adaptation "
          f"(performed {m.get('gestures_performed')}, false {m.get('false_adaptations')})")
    check("commands_stale" in m.get("not_measured_keys", []) and m.get("commands_stale") is None,
          "what ROS cannot observe is null and listed (not_measured_keys)")
    # Listen before moving (docs/safety.md §2.4): each FormationPlanner holds from its first
    # replanning until a plan made since then has arrived from every other follower — one or two
    # replanning periods (0.4 s) at the start; no other hold in a mission without faults.
    check(isinstance(m.get("plans_hold"), int) and m.get("plans_hold") <= 3 * 2
          and "plans_hold" not in m.get("not_measured_keys", []),
          f"no hold replanning in a mission without faults but the start's listening, at most 2 per UAV "
          f"(plans_hold {m.get('plans_hold')}, from the plans' mode)")
    modes = list(csv.DictReader(open(f"{out}/modes.csv")))
    per_uav = {u: [(num(r["t"]), r["mode"], r["reason"]) for r in modes if r["uav"] == u] for u in ("L", "1", "2")}
    ok = all(len(rows) == 2 and rows[0][1] == "hold" and rows[0][2].startswith("listening:") and rows[1][1] == "track"
             and 0.0 < rows[1][0] - rows[0][0] <= 0.8 + 0.05 for rows in per_uav.values())
    check(ok and len(modes) == 6,
          f"modes.csv: each UAV listens at its first plan, then tracks within 2 replanning periods and stays "
          f"tracking ({per_uav})")
    rows = list(csv.DictReader(open(f"{out}/events.csv")))
    op = [r for r in rows if r["source"] == "operator" and abs(num(r["t"]) - 20.0) < 0.02]
    ok = len(op) == 1 and op[0]["status"] == "applied" and \
        num(op[0]["applied_t"]) <= num(op[0]["adaptation_start_t"]) < num(op[0]["applied_t"]) + 1.0 and \
        op[0]["uavs"] == "L;1;2"
    check(ok, "the operator request at 20 s (all.distance_m -1): applied by the leader, adapted to by the next plans "
          + (str({k: op[0][k] for k in ("status", "applied_t", "adaptation_start_t", "uavs")}) if op else "(no row)"))
    g = [r for r in rows if r["source"] == "gesture"]
    # Each process follows /clock on its own subscription: the leader's clock (applied_t) may lag the
    # injecting process's (t, the gesture's stamp) by a few 10 ms ticks.
    skew = 0.05
    ok = len(g) == 1 and g[0]["status"] == "applied" and num(g[0]["t"]) - skew <= num(g[0]["applied_t"]) <= \
        num(g[0]["adaptation_start_t"]) < num(g[0]["t"]) + 1.5 and g[0]["description"].startswith("gesture 2")
    check(ok, "the injected gesture: fired, applied, adapted to " + (str(g) if len(g) != 1 else
          str({k: g[0][k] for k in ("t", "description", "status", "applied_t", "adaptation_start_t")})))
    tl = list(csv.DictReader(open(f"{out}/timeline.csv")))
    check(len(tl) > 350 and "est_x" in tl[0] and "L_plan_status" in tl[0] and not math.isnan(num(tl[-1]["est_x"])),
          f"timeline.csv in gfctl simulate's columns at 10 Hz ({len(tl)} rows)")
    pl = list(csv.DictReader(open(f"{out}/plans.csv")))
    check(len(pl) > 100 and {r["uav"] for r in pl} == {"L", "1", "2"} and
          all(r["status"] in ("optimized", "fallback_previous", "fallback_brake") for r in pl) and
          all(r["reason"] for r in pl if r["status"] != "optimized"),
          f"plans.csv: every UAV's replannings with status and, when not optimized, the reason ({len(pl)} rows)")
    return fails


if __name__ == "__main__":
    sys.exit(main())
