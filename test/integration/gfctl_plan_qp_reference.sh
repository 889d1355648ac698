#!/bin/bash
# gfctl plan end to end on power_towers, and its trajectory QP compared with an independent
# solver (tools/reference/qp_reference.py: SciPy SLSQP) on small instances where corridor,
# inter-UAV and worker constraints are active. Also checks the CSV contract and sidecar JSON.
set -uo pipefail
GFCTL=$1
SRC=$2
PY=/opt/gesture_formation/venv/bin/python
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
fails=0
SCEN="$SRC/config/scenarios/power_towers.yaml"
# Reference rows [x, y, z, heading, pitch] of a straight line from A to B over STEPS steps.
ref() {  # ref AX AY AZ BX BY BZ STEPS
  "$PY" -c "import json,sys;a=list(map(float,sys.argv[1:4]));b=list(map(float,sys.argv[4:7]));n=int(sys.argv[7]);print(json.dumps([[a[i]+(b[i]-a[i])*k/(n-1) for i in range(3)]+[0.0,0.0] for k in range(n)]))" "$@"
}
# 1. Formation reference (stage 1 in gfctl) near the west tower.
cat > "$OUT/p1.json" <<JSON
{"scenario": "$SCEN", "uav_index": 0, "t_now_s": 0.0, "dt_s": 0.2, "steps": 8,
 "state": {"p": [-6, 6, 6], "v": [0.5, 0, 0]}, "worker": {"p": [0, 0, 12], "v": [0.2, 0, 0]},
 "formation": "$SRC/config/formation.yaml", "planner_config": "$SRC/config/planner.yaml"}
JSON
# 2. Reference into the tower lattice (projected; corridor rows active).
cat > "$OUT/p2.json" <<JSON
{"scenario": "$SCEN", "uav_index": 0, "t_now_s": 0.0, "dt_s": 0.2, "steps": 10,
 "state": {"p": [-4, 4, 6], "v": [0.5, -0.1, 0]}, "worker": {"p": [-8, 8, 1]},
 "reference": $(ref -4 4 6 2.7 2.7 6 10)}
JSON
# 3. Another UAV's plan hovering on the reference and the worker near it (half-spaces active).
OTHER=$("$PY" -c "import json;print(json.dumps([[0.0,-12.0,10.0] for k in range(10)]))")
cat > "$OUT/p3.json" <<JSON
{"scenario": "$SCEN", "uav_index": 1, "t_now_s": 5.0, "dt_s": 0.2, "steps": 10,
 "state": {"p": [-6, -12, 10], "v": [2, 0, 0]}, "worker": {"p": [-2, -9.5, 9]},
 "reference": $(ref -6 -12 10 1 -12 10 10),
 "other_plans": [{"uav_index": 0, "t0_s": 4.9, "dt_s": 0.2, "samples": $OTHER}]}
JSON
for p in p1 p2 p3; do
  if ! "$GFCTL" plan --problem "$OUT/$p.json" --out "$OUT/$p.csv" --dump-qp "$OUT/$p.qp.json" > "$OUT/$p.log" 2>&1; then
    echo "FAIL: gfctl plan $p:"; cat "$OUT/$p.log"; fails=$((fails + 1)); continue
  fi
  head -1 "$OUT/$p.log"
  if [ "$(head -1 "$OUT/$p.csv")" != "t,x,y,z,vx,vy,vz,ax,ay,az,heading,pitch" ]; then
    echo "FAIL: $p: CSV header"; fails=$((fails + 1))
  fi
  if ! grep -q '"status": "optimized"' "$OUT/$p.csv.json"; then
    echo "FAIL: $p: not optimized:"; cat "$OUT/$p.csv.json"; fails=$((fails + 1))
  fi
  if ! "$PY" "$SRC/tools/reference/qp_reference.py" "$OUT/$p.qp.json"; then
    echo "FAIL: $p: QP differs from the reference solver"; fails=$((fails + 1))
  fi
done
# The half-spaces of problem 3 really shaped the plan: distance to the other UAV >= 2.5 + 5*0.1.
"$PY" - "$OUT/p3.csv" <<'PYEOF' || fails=$((fails + 1))
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
d = min(math.dist((float(r["x"]), float(r["y"]), float(r["z"])), (0.0, -12.0, 10.0)) for r in rows[1:])
w = min(math.dist((float(r["x"]), float(r["y"]), float(r["z"])), (-2.0, -9.5, 9.0)) for r in rows[1:])
print(f"p3: min distance to the other UAV {d:.3f} m (need 3.0), to the worker {w:.3f} m (need 3.0)")
sys.exit(0 if d >= 3.0 - 1e-3 and w >= 3.0 - 1e-3 else 1)
PYEOF
[ "$fails" -eq 0 ] && echo "gfctl_plan_qp_reference: all passed" || echo "gfctl_plan_qp_reference: $fails failures"
exit $((fails > 0))
