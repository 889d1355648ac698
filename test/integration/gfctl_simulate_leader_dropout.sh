#!/usr/bin/env bash
# gfctl simulate with the fault profile leader_dropout_for_good (config/faults/leader_dropout_for_good.yaml:
# the leader's radio dies at 60 s for good) on the power-tower mission shortened to 100 s, seed 1,
# with the real planner. Asserts docs/safety.md §1.2: a new leader acts within silence_limit_s +
# candidacy_stagger_s + 2 election_timeout_s (4.5 s with the defaults) of the silence; at no step
# do two UAVs act (metrics.json leadership.steps_two_acting) and at no timeline row (acting_*
# columns); the silent leader's lease lapses within lease_s (1 s); the operator's request of 88 s is
# applied by the new leader; no collision, mutual distance >= Gamma_dis 2.5 m, worker distance >=
# 2.5 m, obstacle distance >= 0.5 m.
# Usage: gfctl_simulate_leader_dropout.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile leader_dropout_for_good \
  --out "$TMP/run" --seed 1 --duration 100 --threads 1 --no-plot > "$TMP/run.log" 2>&1 \
  || { echo "FAIL: gfctl exited $?"; cat "$TMP/run.log"; exit 1; }
python3 - "$TMP/run" <<'PY'
import csv, json, sys
d = sys.argv[1]
m = json.load(open(d + "/metrics.json"))
l = m.get("leadership")
if l is None:
    print("FAIL: metrics.json has no leadership section"); sys.exit(1)
problems = []
limit = 2.0 + 0.5 + 2 * 1.0  # LeadershipConfig defaults (the scenario sets none)
if l["silenced_uav"] != 0 or l["silent_from_s"] != 60 or l["silent_to_s"] != "for_good":
    problems.append(f"silence {l['silenced_uav']} from {l['silent_from_s']} to {l['silent_to_s']}")
if l["new_leader"] not in (1, 2) or l["handover_s"] is None or l["handover_s"] > limit:
    problems.append(f"new leader {l['new_leader']} after {l['handover_s']} s (limit {limit})")
if l["max_acting"] != 1 or l["steps_two_acting"] != 0:
    problems.append(f"max acting {l['max_acting']}, steps with two acting {l['steps_two_acting']}")
if l["silenced_last_acting_s"] is None or l["silenced_last_acting_s"] > 61.0:
    problems.append(f"the silent leader acted until {l['silenced_last_acting_s']}")
rows = list(csv.DictReader(open(d + "/timeline.csv")))
cols = [c for c in rows[0] if c.startswith("acting_")]
if cols != ["acting_L", "acting_1", "acting_2"]:
    problems.append(f"acting columns {cols}")
two = [r["t"] for r in rows if sum(int(r[c]) for c in cols) > 1]
if two: problems.append(f"two acting at t {two[:5]}")
late = [r for r in rows if float(r["t"]) > 70 and int(r[f"acting_{l['new_leader']}"]) != 1]
if late: problems.append(f"the new leader does not act at t {late[0]['t']}")
events = list(csv.DictReader(open(d + "/events.csv")))
q = [e for e in events if e["source"] == "operator" and float(e["t"]) == 88]
if len(q) != 1 or q[0]["status"] != "applied": problems.append(f"request of 88 s: {q}")
if l["requests_after"] < 1 or l["requests_after_applied"] != l["requests_after"]:
    problems.append(f"requests after the hand-over {l['requests_after_applied']}/{l['requests_after']} applied")
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
if m["min_mutual_distance_m"] < 2.5: problems.append(f"min mutual {m['min_mutual_distance_m']:.2f} < 2.5")
if m["min_human_distance_m"] < 2.5: problems.append(f"min worker distance {m['min_human_distance_m']:.2f} < 2.5")
if m["min_obstacle_distance_m"] < 0.5: problems.append(f"min obstacle {m['min_obstacle_distance_m']:.2f} < 0.5")
print(("FAIL " if problems else "ok   ") + "leader dropout for good: " + (", ".join(problems) if problems else
      f"UAV {l['new_leader']} acts {l['handover_s']:.2f} s after the silence, never two acting, "
      f"{l['requests_after_applied']}/{l['requests_after']} later requests applied, min mutual "
      f"{m['min_mutual_distance_m']:.2f} m, worker {m['min_human_distance_m']:.2f} m, obstacle {m['min_obstacle_distance_m']:.2f} m"))
sys.exit(1 if problems else 0)
PY
