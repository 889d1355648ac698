#!/usr/bin/env bash
# The worker walks, unseen, towards a holding UAV (docs/safety.md §3): power-tower mission, seed 1,
# fault profile worker_approaches_holding_uav (the leader's camera blind from 205 s, the UAVs holding
# from ~208 s; at 210 s the worker turns back and walks at 1.2 m/s to the point below follower 2,
# which holds 2 m above his mid-body). Run to 228 s (he arrives at ~219 s and stands there). Every
# UAV near the growing reach backs off (a modes.csv row "backing off from the worker's reach ...", follower 2 among them); while he is
# unseen no UAV comes within Gamma_dis of him (metrics.json worker_approach); Gamma_dis between the
# UAVs, no collision. (Without the reach he walks to 1.7 m of follower 2: docs/safety.md §3.)
# Usage: gfctl_simulate_worker_approach.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile worker_approaches_holding_uav \
  --out "$TMP/run" --seed 1 --duration 228 --no-plot > "$TMP/run.log" 2>&1 || { echo "FAIL: gfctl exited $?"; cat "$TMP/run.log"; exit 1; }
python3 - "$TMP/run" <<'PY'
import csv, json, sys
d = sys.argv[1]
m = json.load(open(f"{d}/metrics.json"))
a = m.get("worker_approach")
problems = []
if a is None:
    sys.exit("FAIL: metrics.json has no worker_approach")
if not (abs(a["unseen_from_s"] - 210.0) < 0.02 and a["unseen_to_s"] > 227.9): problems.append(f"unseen phase {a['unseen_from_s']}-{a['unseen_to_s']}")
if a["gamma_dis_violations"] != 0: problems.append(f"Gamma_dis violations {a['gamma_dis_violations']}")
if not a["min_distance_m"] >= a["gamma_dis_m"]: problems.append(f"min distance {a['min_distance_m']:.2f} < {a['gamma_dis_m']}")
backoffs = {r["uav"] for r in csv.DictReader(open(f"{d}/modes.csv"))
            if r["reason"].startswith("backing off from the worker's reach") and float(r["t"]) >= 205}
if "2" not in backoffs: problems.append(f"follower 2 did not back off: {sorted(backoffs)}")
if m["min_mutual_distance_m"] < 2.5: problems.append(f"min mutual {m['min_mutual_distance_m']:.2f} < 2.5")
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
# He did walk to follower 2's spot: at the end he is within 1 m (horizontally) of where it was at 210 s.
rows = list(csv.DictReader(open(f"{d}/timeline.csv")))
at = lambda t: min(rows, key=lambda r: abs(float(r["t"]) - t))
end, turn = rows[-1], at(210.0)
gap = ((float(end["worker_x"]) - float(turn["2_x"])) ** 2 + (float(end["worker_y"]) - float(turn["2_y"])) ** 2) ** 0.5
if gap > 1.0: problems.append(f"the worker ended {gap:.2f} m from follower 2's spot of 210 s")
print(("FAIL " if problems else "ok   ") + "worker approach: " + ("; ".join(problems) if problems else
      f"min distance unseen {a['min_distance_m']:.2f} m (per UAV {[round(u['min_distance_m'], 2) for u in a['uavs']]}), "
      f"backed off: {sorted(backoffs)}"))
sys.exit(1 if problems else 0)
PY
