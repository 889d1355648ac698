#!/bin/bash
# gfctl plan rejects bad input with exit code 2 and a message naming the file and field
# (docs/design.md §8); a NaN-free but impossible start (inside the ground) is answered with a
# braking fallback and its reason, exit 0.
set -uo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
SCEN="$SRC/config/scenarios/power_towers.yaml"
fails=0
expect() {  # expect CODE PATTERN -- command...
  local code=$1 pattern=$2
  shift 3
  "$@" > "$OUT/out.log" 2> "$OUT/err.log"
  local rc=$?
  if [ "$rc" != "$code" ] || ! grep -q -- "$pattern" "$OUT/err.log" "$OUT/out.log"; then
    echo "FAIL: '$*' gave exit $rc (want $code), stderr:"; cat "$OUT/err.log"; echo "(want pattern '$pattern')"
    fails=$((fails + 1))
  else
    echo "ok: exit $rc: $(head -1 "$OUT/err.log")"
  fi
}
cat > "$OUT/missing.json" <<JSON
{"scenario": "$SCEN", "dt_s": -0.2, "state": {"p": [1, 2]}, "worker": {"p": [0, 0, 1]}}
JSON
cat > "$OUT/noref.json" <<JSON
{"scenario": "$SCEN", "uav_index": 0, "t_now_s": 0, "dt_s": 0.2, "steps": 5,
 "state": {"p": [-6, 6, 6]}, "worker": {"p": [0, 0, 1]}}
JSON
cat > "$OUT/badrows.json" <<JSON
{"scenario": "$SCEN", "uav_index": 0, "t_now_s": 0, "dt_s": 0.2, "steps": 3,
 "state": {"p": [-6, 6, 6]}, "worker": {"p": [0, 0, 1]}, "reference": [[0, 0, 5, 0, 0], [0, 0, 5, 0], [0, 0, 5, 0, 0]]}
JSON
cat > "$OUT/badcfg.yaml" <<YAML
limits: {max_speed_mps: -1, max_vertical_speed_mps: 9}
YAML
cat > "$OUT/badcfg.json" <<JSON
{"scenario": "$SCEN", "uav_index": 0, "t_now_s": 0, "dt_s": 0.2, "steps": 3, "planner_config": "badcfg.yaml",
 "state": {"p": [-6, 6, 6]}, "worker": {"p": [0, 0, 1]}, "reference": [[-6, 6, 6, 0, 0], [-6, 6, 6, 0, 0], [-6, 6, 6, 0, 0]]}
JSON
cat > "$OUT/ground.json" <<JSON
{"scenario": "$SCEN", "uav_index": 0, "t_now_s": 0, "dt_s": 0.2, "steps": 3,
 "state": {"p": [10, -10, 0.1]}, "worker": {"p": [0, 0, 1]}, "reference": [[10, -10, 0.1, 0, 0], [10, -10, 1, 0, 0], [10, -10, 2, 0, 0]]}
JSON
expect 2 "missing required option --out" -- "$GFCTL" plan --problem "$OUT/missing.json"
expect 2 "nope.json: cannot open" -- "$GFCTL" plan --problem "$OUT/nope.json" --out "$OUT/t.csv"
expect 2 "uav_index" -- "$GFCTL" plan --problem "$OUT/missing.json" --out "$OUT/t.csv"
expect 2 "dt_s" -- "$GFCTL" plan --problem "$OUT/missing.json" --out "$OUT/t.csv"
expect 2 "state.p" -- "$GFCTL" plan --problem "$OUT/missing.json" --out "$OUT/t.csv"
expect 2 "formation" -- "$GFCTL" plan --problem "$OUT/noref.json" --out "$OUT/t.csv"
expect 2 "reference\[1\]" -- "$GFCTL" plan --problem "$OUT/badrows.json" --out "$OUT/t.csv"
expect 2 "limits.max_speed_mps" -- "$GFCTL" plan --problem "$OUT/badcfg.json" --out "$OUT/t.csv"
expect 0 "fallback_brake" -- "$GFCTL" plan --problem "$OUT/ground.json" --out "$OUT/t.csv"
if ! grep -q '"status": "fallback_brake"' "$OUT/t.csv.json"; then echo "FAIL: ground: sidecar status"; fails=$((fails + 1)); fi
[ "$fails" -eq 0 ] && echo "gfctl_plan_errors: all passed" || echo "gfctl_plan_errors: $fails failures"
exit $((fails > 0))
