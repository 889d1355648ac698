#!/usr/bin/env bash
# gfctl simulate: a short mission per scenario with the safety assertions of issue 7:
# min mutual distance >= Gamma_dis 2.5 m, obstacle clearance >= the planner's verification
# clearance 0.5 m (distance field: to voxel centres), no collisions; every output file written.
# Usage: gfctl_simulate_missions.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail=0
for spec in power_towers:60 open_field:84 dense_pillars:30; do
  name=${spec%%:*}
  dur=${spec##*:}
  "$GFCTL" simulate --scenario "$SRC/config/scenarios/$name.yaml" --out "$TMP/$name" --seed 3 --duration "$dur" --no-plot \
    > "$TMP/$name.log" 2>&1 || { echo "FAIL $name: gfctl exited $?"; cat "$TMP/$name.log"; fail=1; continue; }
  for f in metrics.json timeline.csv events.csv scene.json; do
    [ -s "$TMP/$name/$f" ] || { echo "FAIL $name: $f missing"; fail=1; }
  done
  python3 - "$TMP/$name/metrics.json" "$name" <<'PY' || fail=1
import json, sys
m = json.load(open(sys.argv[1]))
name = sys.argv[2]
problems = []
for k in ["min_mutual_distance_m", "min_obstacle_distance_m", "min_human_distance_m", "collisions",
          "distance_error_rms_m", "angle_error_rms_deg", "requests_applied", "gesture_success_rate",
          "gesture_mean_latency_s", "false_adaptations", "planning_ms_median", "planning_ms_p99",
          "human_estimate_error_rms_m"]:
    if k not in m:
        problems.append(f"key {k} missing (docs/design.md §8.4)")
if m["min_mutual_distance_m"] < 2.5:
    problems.append(f"min_mutual_distance_m {m['min_mutual_distance_m']:.3f} < 2.5")
if m["min_obstacle_distance_m"] < 0.5:
    problems.append(f"min_obstacle_distance_m {m['min_obstacle_distance_m']:.3f} < 0.5")
if m["collisions"] != 0:
    problems.append(f"collisions {m['collisions']}")
if m["min_human_distance_m"] < 2.5:
    problems.append(f"min_human_distance_m {m['min_human_distance_m']:.3f} < 2.5")
print(("FAIL " if problems else "ok   ") + name + ": " + (", ".join(problems) if problems else
      f"mutual {m['min_mutual_distance_m']:.2f} obstacle {m['min_obstacle_distance_m']:.2f} "
      f"human {m['min_human_distance_m']:.2f} rtf {m['real_time_factor']:.1f}"))
sys.exit(1 if problems else 0)
PY
done
exit $fail
