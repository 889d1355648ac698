#!/usr/bin/env bash
# The sideways camera sweep (faults.search_horizontal_speed_mps, docs/safety.md §2.2): power-tower
# mission, seed 1, the leader's camera blind 210–230 s while the worker walks along the line
# (1.1 m/s, +x) from the west tower to the east one. The estimator extrapolates him for 5 s and then
# holds the estimate ~16 m behind him; the vertical sweep alone never finds him again (the leader
# looks south, he is ~50° to its left), which this test checks; with the sideways sweep at 1.5 m/s
# the leader sees him again within 8 s of the blackout's end and every UAV tracks. Γ_dis, no
# collision. (The run stops at 237 s, before the formation's long catch-up, whose planning times
# safety.md §2.2 reports.)
# Usage: gfctl_simulate_search_sideways.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
printf 'faults:\n  camera_blackouts: [[210, 230]]\n  search_horizontal_speed_mps: 0\n' > "$TMP/vertical.yaml"
printf 'faults:\n  camera_blackouts: [[210, 230]]\n  search_horizontal_speed_mps: 1.5\n' > "$TMP/sideways.yaml"
for f in vertical sideways; do
  "$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --faults "$TMP/$f.yaml" --out "$TMP/$f" \
    --seed 1 --duration 237 --no-plot > "$TMP/$f.log" 2>&1 || { echo "FAIL $f: gfctl exited $?"; cat "$TMP/$f.log"; exit 1; }
done
python3 - "$TMP" <<'PY'
import csv, json, sys
d = sys.argv[1]
problems = []
def modes(run):
    return [(float(r["t"]), r["uav"], r["mode"]) for r in csv.DictReader(open(f"{d}/{run}/modes.csv"))]
v, s = modes("vertical"), modes("sideways")
for name, run in (("vertical", v), ("sideways", s)):
    if not any(x[1] == "L" and x[2] == "search" and 214.0 <= x[0] <= 216.0 for x in run):
        problems.append(f"{name}: the leader did not search from ~215 s: {[x for x in run if x[0] > 200]}")
if any(x[2] == "track" and x[0] > 213 for x in v):
    problems.append(f"vertical sweep only: the worker was found again: {[x for x in v if x[0] > 213]}")
back = {u: [x[0] for x in s if x[1] == u and x[2] == "track" and x[0] > 213] for u in ("L", "1", "2")}
for u, ts in back.items():
    if not ts or not 230.0 <= ts[0] <= 237.0: problems.append(f"sideways: UAV {u} did not track again at 230-237 s: {ts[:1]}")
for name in ("vertical", "sideways"):
    m = json.load(open(f"{d}/{name}/metrics.json"))
    if m["min_mutual_distance_m"] < 2.5: problems.append(f"{name}: min mutual {m['min_mutual_distance_m']:.2f} < 2.5")
    if m["collisions"] != 0: problems.append(f"{name}: collisions {m['collisions']}")
print(("FAIL " if problems else "ok   ") + "sideways search: " + ("; ".join(problems) if problems else
      "vertical only: never found again; sideways: all track again at " + str({u: ts[0] for u, ts in back.items()})))
sys.exit(1 if problems else 0)
PY
