#!/usr/bin/env bash
# gfctl simulate under the harsh fault profile (config/faults/harsh.yaml: 30 % inter-UAV loss,
# jitter, duplication, reordering, a follower dropout and rejoin, the worker lost 6 s, UWB and
# stereo dropouts, range outliers, gusts, a planner outage — all within the first 90 s) on the
# power-tower mission shortened to 90 s. Asserts the safety figures of docs/safety.md (mutual
# >= Gamma_dis 2.5 m, no collision, obstacle distance >= the planner's verification clearance
# 0.5 m), that the faults happened (messages lost, hold plans, offline/rejoin in modes.csv), and
# that bad fault files are refused with every problem listed.
# Usage: gfctl_simulate_faults.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail=0
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile harsh --out "$TMP/harsh" \
  --seed 2 --duration 90 --no-plot > "$TMP/harsh.log" 2>&1 || { echo "FAIL harsh: gfctl exited $?"; cat "$TMP/harsh.log"; exit 1; }
python3 - "$TMP/harsh" <<'PY' || fail=1
import csv, json, sys
d = sys.argv[1]
m = json.load(open(d + "/metrics.json"))
modes = list(csv.DictReader(open(d + "/modes.csv")))
problems = []
if m["min_mutual_distance_m"] < 2.5: problems.append(f"min_mutual_distance_m {m['min_mutual_distance_m']:.3f} < 2.5")
if m["min_obstacle_distance_m"] < 0.5: problems.append(f"min_obstacle_distance_m {m['min_obstacle_distance_m']:.3f} < 0.5")
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
if not m["messages_lost"] > 0.2 * m["messages_sent"]: problems.append(f"only {m['messages_lost']} of {m['messages_sent']} messages lost")
if not m["messages_duplicated"] > 0 or not m["messages_reordered"] > 0: problems.append("no duplication / reordering")
if not m["plans_hold"] > 0: problems.append("no hold plan (worker lost 50-56 s)")
if not m["range_outliers"] > 0: problems.append("no range outlier injected")
if not any(r["uav"] == "2" and r["mode"] == "offline" and abs(float(r["t"]) - 30) < 0.05 for r in modes): problems.append("follower 2 not offline at 30 s")
if not any(r["uav"] == "2" and r["mode"] == "rejoin" and abs(float(r["t"]) - 45) < 0.05 for r in modes): problems.append("follower 2 did not rejoin at 45 s")
if not any(r["uav"] == "2" and r["mode"] == "track" and float(r["t"]) > 45 for r in modes): problems.append("follower 2 never tracked again after rejoining")
if not any(r["uav"] == "1" and r["mode"] == "outage" for r in modes): problems.append("no planner outage of follower 1")
print(("FAIL " if problems else "ok   ") + "harsh: " + (", ".join(problems) if problems else
      f"mutual {m['min_mutual_distance_m']:.2f} obstacle {m['min_obstacle_distance_m']:.2f} human {m['min_human_distance_m']:.2f} "
      f"lost {m['messages_lost']}/{m['messages_sent']} hold {m['plans_hold']} rtf {m['real_time_factor']:.1f}"))
sys.exit(1 if problems else 0)
PY

# Regression (docs/safety.md §4.10): dup_reorder seed 32 — the leader headed at speed for where a
# yielding follower still was, the follower braked and its brake plan came 0.5 s late; before the
# braking envelope ahead of lower-priority plans the two came to 2.22 m at 286 s (3.90 m since).
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile dup_reorder --seed 32 \
  --duration 295 --threads 1 --out "$TMP/d32" --no-plot > "$TMP/d32.log" 2>&1 || { echo "FAIL dup_reorder 32: gfctl exited $?"; cat "$TMP/d32.log"; exit 1; }
python3 - "$TMP/d32" <<'PY' || fail=1
import json, sys
m = json.load(open(sys.argv[1] + "/metrics.json"))
ok = m["min_mutual_distance_m"] >= 2.5 and m["collisions"] == 0 and m["messages_reordered"] > 0
print(("ok   " if ok else "FAIL ") + f"dup_reorder seed 32 to 295 s: mutual {m['min_mutual_distance_m']:.2f} m (>= 2.5), "
      f"collisions {m['collisions']}, reordered {m['messages_reordered']}")
sys.exit(0 if ok else 1)
PY

# Regression (docs/safety.md §4.12): range_outliers seed 97 — the first UWB ranges were gross
# errors (1.15, 0.10, 0.45 m for a worker 10 m away); the leader planned on the track they
# initialised, turned its camera away from the worker and lost him for the whole mission (estimate
# error 42.6 m RMS). The leader now acts on a confirmed track only.
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile range_outliers --seed 97 \
  --duration 30 --threads 1 --out "$TMP/r97" --no-plot > "$TMP/r97.log" 2>&1 || { echo "FAIL range_outliers 97: gfctl exited $?"; cat "$TMP/r97.log"; exit 1; }
python3 - "$TMP/r97" <<'PY' || fail=1
import csv, json, sys
m = json.load(open(sys.argv[1] + "/metrics.json"))
rows = list(csv.DictReader(open(sys.argv[1] + "/timeline.csv")))
seen_late = sum(int(r["visible"]) for r in rows if float(r["t"]) >= 20.0)
ok = m["human_estimate_error_rms_m"] < 1.0 and seen_late > 0 and m["range_outliers"] > 0
print(("ok   " if ok else "FAIL ") + f"range_outliers seed 97 to 30 s: estimate error {m['human_estimate_error_rms_m']:.2f} m RMS (< 1), "
      f"worker in view in {seen_late} timeline rows after 20 s (> 0), outliers {m['range_outliers']}")
sys.exit(0 if ok else 1)
PY

# Bad fault files: exit 2, every problem listed with its field and value.
cat > "$TMP/bad.yaml" <<'YAML'
faults:
  link: {loss: 1.5}
  follower_dropouts: [{uav: 0, from_s: 20, to_s: 10}]
  max_share_age_s: 0
  typo_key: 1
YAML
set +e
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --faults "$TMP/bad.yaml" --out "$TMP/bad" --no-plot > "$TMP/bad.log" 2>&1
rc=$?
set -e
[ "$rc" = 2 ] || { echo "FAIL bad fault file: exit $rc (want 2)"; fail=1; }
for needle in "mission.faults.link.loss" "1.5" "follower_dropouts[0]" "mission.faults.max_share_age_s" "mission.faults.typo_key: unknown key" "bad.yaml"; do
  grep -qF -- "$needle" "$TMP/bad.log" || { echo "FAIL bad fault file: '$needle' not in the message:"; cat "$TMP/bad.log"; fail=1; }
done
set +e
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile no_such_profile --out "$TMP/x" > "$TMP/np.log" 2>&1
rc1=$?
"$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --fault-profile harsh --faults "$TMP/bad.yaml" --out "$TMP/x" > "$TMP/ex.log" 2>&1
rc2=$?
set -e
[ "$rc1" = 2 ] && grep -q "no_such_profile.yaml does not exist" "$TMP/np.log" || { echo "FAIL unknown profile: exit $rc1"; cat "$TMP/np.log"; fail=1; }
[ "$rc2" = 2 ] && grep -q "exclusive" "$TMP/ex.log" || { echo "FAIL --faults with --fault-profile: exit $rc2"; cat "$TMP/ex.log"; fail=1; }
[ $fail = 0 ] && echo "ok   bad fault files refused"
exit $fail
