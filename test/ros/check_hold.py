#!/usr/bin/env python3
"""Checks a ROS simulation run with a camera blackout [A, B] (test/ros/worker_lost_hold.sh):
every UAV enters hold between A + max_worker_age_s (less one camera frame: the last detection
before the blackout) and 1.5 s later, none before; the leader searches from A + LOST_TIMEOUT_S
(the estimator has lost the worker; docs/safety.md §2.2) to 1.5 s later; each is slow while holding,
each tracks again within 6 s after B; Γ_dis, no collision, plans_hold counted.
Usage: check_hold.py OUT_DIR A B MAX_WORKER_AGE_S LOST_TIMEOUT_S"""
import csv
import json
import sys

out, a, b, age, lost = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
fails = 0


def check(ok, what):
    global fails
    print(("PASS: " if ok else "FAIL: ") + what)
    fails += 0 if ok else 1


modes = list(csv.DictReader(open(f"{out}/modes.csv")))
metrics = json.load(open(f"{out}/metrics.json"))
timeline = list(csv.DictReader(open(f"{out}/timeline.csv")))
labels = ["L", "1", "2"]
for uav in range(3):
    rows = [(float(r["t"]), r["mode"], r["reason"]) for r in modes if r["uav"] == labels[uav]]
    # Listen before moving (docs/safety.md §2.4): the first replanning(s) hold until every other
    # follower's plan has arrived, then track — long before the blackout; the checks below are
    # about the blackout's hold.
    check(len(rows) >= 2 and rows[0][1] == "hold" and rows[0][2].startswith("listening:") and rows[1][1] == "track"
          and rows[1][0] - rows[0][0] <= 0.85 and rows[1][0] < a, f"UAV {uav} listens at its start, then tracks: {rows[:2]}")
    if rows and rows[0][2].startswith("listening:"):
        rows = rows[2:] if len(rows) >= 2 and rows[1][1] == "track" else rows[1:]
    holds = [r for r in rows if r[1] == "hold"]
    check(len(holds) >= 1 and all(a + age - 0.1 <= t <= a + age + 1.5 for t, _, _ in holds),
          f"UAV {uav} holds only after the estimate is {age} s old: {holds}")
    searches = [r for r in rows if r[1] == "search"]
    if uav == 0:
        check(len(searches) >= 1 and all(a + lost - 0.1 <= t <= a + lost + 1.5 for t, _, _ in searches),
              f"the leader searches only once the estimator lost the worker ({lost} s): {searches}")
    else:
        check(not searches, f"UAV {uav} never searches: {searches}")
    if holds:
        t_hold = holds[0][0]
        back = [r for r in rows if r[1] == "track" and r[0] > t_hold]
        if uav == 0:
            back_search = [r for r in rows if r[1] == "track" and searches and r[0] > searches[0][0]]
            check(back_search == back, f"the leader went from search back to track: {rows}")
        check(len(back) >= 1 and b <= back[0][0] <= b + 6.0, f"UAV {uav} tracks again after the blackout: {back[:1]}")
        reason = holds[0][2]
        want = "worker not seen for more than max_worker_age_s" if uav == 0 else "worker estimate older than max_worker_age_s"
        check(reason == want, f"UAV {uav} hold reason '{reason}'")
    # Stopped while holding: braking from the tracking speed takes < 1 s at 4 m/s^2.
    speeds = [float(r[f"{labels[uav]}_speed"]) for r in timeline if a + age + 1.5 <= float(r["t"]) <= b]
    check(len(speeds) > 0 and max(speeds) < 1.0, f"UAV {uav} speed while holding max {max(speeds) if speeds else 'n/a'} m/s < 1.0")
check(isinstance(metrics.get("plans_hold"), int) and metrics["plans_hold"] > 0, f"plans_hold counted: {metrics.get('plans_hold')}")
check("plans_hold" not in metrics.get("not_measured_keys", []), "plans_hold is measured")
check(metrics["min_mutual_distance_m"] >= 2.5, f"min mutual distance {metrics['min_mutual_distance_m']:.2f} m >= 2.5")
check(metrics["collisions"] == 0, f"collisions {metrics['collisions']}")
sys.exit(1 if fails else 0)
