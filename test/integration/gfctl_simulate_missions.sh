#!/usr/bin/env bash
# gfctl simulate: a short mission per scenario with the safety assertions of issue 7:
# min mutual distance >= Gamma_dis 2.5 m, obstacle clearance >= the planner's verification
# clearance 0.5 m (distance field: to voxel centres), no collisions; every output file written;
# votes.csv has a fired row for each gesture command of events.csv (its frame at most 0.5 s before
# the command, the same id).
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
  for f in metrics.json timeline.csv events.csv scene.json votes.csv; do
    [ -s "$TMP/$name/$f" ] || { echo "FAIL $name: $f missing"; fail=1; }
  done
  python3 - "$TMP/$name" "$name" <<'PY' || fail=1
import csv, sys
d, name = sys.argv[1], sys.argv[2]
votes = list(csv.DictReader(open(f"{d}/votes.csv")))
fired = [(float(v["t"]), v["dominant_id"]) for v in votes if v["fired"] == "1"]
commands = [(float(e["t"]), e["gesture_id"]) for e in csv.DictReader(open(f"{d}/events.csv")) if e["source"] == "gesture"]
problems = []
if not votes or any(v["id_L"] == "" or v["fused_id"] == "" for v in votes):
    problems.append(f"votes.csv: {len(votes)} rows, or an empty id")
# a frame is stamped when its images were taken and closed (and acted on) a little later
if len(fired) != len(commands) or any(g != h or not 0 <= t - s <= 0.5 for (s, g), (t, h) in zip(fired, commands)):
    problems.append(f"votes.csv fired {fired} but events.csv has the gesture commands {commands}")
print(("FAIL " if problems else "ok   ") + name + " votes.csv: " + (", ".join(problems) if problems else
      f"{len(votes)} frames, {len(fired)} fired = the gesture commands"))
sys.exit(1 if problems else 0)
PY
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
