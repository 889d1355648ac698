#!/usr/bin/env bash
# gfctl simulate with the fault profile abort_mid_mission (config/faults/abort_mid_mission.yaml:
# the operator aborts at 100 s while the worker works at height on the west tower) on the
# power-tower mission shortened to 135 s, seed 1. Asserts docs/safety.md §2.8: every UAV accepts
# the abort within a second, reaches its retreat goal and hovers there by the end, each goal in the
# UAV's own layer and >= abort.retreat_distance_m (15 m) from the worker's position then (less the
# estimate error and the arrival tolerance: 14 m); after the abort no collision, mutual distance
# >= Gamma_dis 2.5 m, obstacle distance >= the verification clearance 0.5 m, worker distance >= the
# planner's worker_safety_distance_m 3 m. Then the same with the abort from the worker's gesture,
# with mission.abort.after: land (to 150 s): every UAV at its landing approach point (2 m above
# the ground), the spots >= Gamma_dis apart; and from search / hold (the leader's camera blind from
# 90 s: at 100 s it searches, the followers hold) the same as the first; and with follower 2's
# computer down 95-112 s (it misses every copy from the ground station) it aborts from the others'
# relay once back (listening first) and settles too (to 150 s). Link outages (docs/safety.md §2.8):
# the ground station's link to the leader down 95-115 s — the leader aborts from the followers'
# relay within a second, as the others; to every UAV down 95-103.9 s (the whole burst, 100-101.8 s,
# and the first resends lost) — every UAV aborts from the resend at 104.8 s within a second.
# Usage: gfctl_simulate_abort.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail=0
printf 'faults:\n  abort: {t_s: 100, source: gesture}\n' > "$TMP/gesture_abort.yaml"
printf 'faults:\n  camera_blackouts: [[90, 130]]\n  abort: {t_s: 100, source: operator}\n' > "$TMP/search_abort.yaml"
printf 'faults:\n  follower_dropouts: [{uav: 2, from_s: 95, to_s: 112}]\n  abort: {t_s: 100, source: operator}\n' > "$TMP/dropout_abort.yaml"
printf 'faults:\n  operator_outages: [{uav: 0, from_s: 95, to_s: 115}]\n  abort: {t_s: 100, source: operator}\n' > "$TMP/leader_outage.yaml"
printf 'faults:\n  operator_outages: [{uav: 0, from_s: 95, to_s: 103.9}, {uav: 1, from_s: 95, to_s: 103.9}, {uav: 2, from_s: 95, to_s: 103.9}]\n  abort: {t_s: 100, source: operator}\n' > "$TMP/all_outage.yaml"
# The power-tower mission with abort.after: land (the model path made absolute for the copy).
sed -e "s|gesture_model: \.\./\.\./|gesture_model: $SRC/|" -e 's|^  worker:$|  abort: {after: land}\n  worker:|' \
  "$SRC/config/scenarios/power_towers.yaml" > "$TMP/power_towers_land.yaml"
for run in operator gesture land search dropout leader_outage all_outage; do
  faults=(--fault-profile abort_mid_mission)
  scenario="$SRC/config/scenarios/power_towers.yaml"
  duration=135
  [ "$run" = gesture ] && faults=(--faults "$TMP/gesture_abort.yaml")
  [ "$run" = search ] && faults=(--faults "$TMP/search_abort.yaml")
  [ "$run" = dropout ] && { faults=(--faults "$TMP/dropout_abort.yaml"); duration=150; }
  [ "$run" = leader_outage ] && faults=(--faults "$TMP/leader_outage.yaml")
  [ "$run" = all_outage ] && { faults=(--faults "$TMP/all_outage.yaml"); duration=150; }
  [ "$run" = land ] && { faults=(--faults "$SRC/config/faults/abort_mid_mission.yaml"); scenario="$TMP/power_towers_land.yaml"; duration=150; }
  "$GFCTL" simulate --scenario "$scenario" "${faults[@]}" --out "$TMP/$run" \
    --seed 1 --duration "$duration" --threads 1 --no-plot > "$TMP/$run.log" 2>&1 \
    || { echo "FAIL $run: gfctl exited $?"; cat "$TMP/$run.log"; exit 1; }
  python3 - "$TMP/$run" "$run" <<'PY' || fail=1
import csv, json, math, sys
d, run = sys.argv[1], sys.argv[2]
m = json.load(open(d + "/metrics.json"))
rows = list(csv.DictReader(open(d + "/timeline.csv")))
problems = []
a = m.get("abort")
if a is None:
    print(f"FAIL {run}: metrics.json has no abort section"); sys.exit(1)
if a["source"] != ("gesture" if run == "gesture" else "operator"): problems.append(f"source {a['source']}")
modes = list(csv.DictReader(open(d + "/modes.csv")))
if run == "search":  # the modes just before the abort: the leader searches, the followers hold
    before = {r["uav"]: r["mode"] for r in modes if float(r["t"]) < a["issued_s"]}
    if before != {"L": "search", "1": "hold", "2": "hold"}: problems.append(f"modes before the abort {before}")
final = "landed" if run == "land" else "at_retreat"
last = rows[-1]
worker = [float(last[k]) for k in ("worker_x", "worker_y", "worker_z")]
zs = []
for u in a["uavs"]:
    i, name = u["uav"], ("L" if u["uav"] == 0 else str(u["uav"]))
    # When it can first hear of the abort: follower 2 offline 95-112 s (from the others' relay once
    # back); every ground link down until 103.9 s (the resend at 104.8 s); otherwise at once.
    first = 112.0 if run == "dropout" and i == 2 else 104.8 if run == "all_outage" else a["issued_s"]
    if u["accepted_s"] is None or u["accepted_s"] - first > 1.0 or u["accepted_s"] < first:
        problems.append(f"uav {i} accepted at {u['accepted_s']}")
    if u["phase"] != final or u["settled_s"] is None: problems.append(f"uav {i} phase {u['phase']}")
    if u["min_uav_distance_m"] < 2.5: problems.append(f"uav {i} min mutual {u['min_uav_distance_m']:.2f} < 2.5")
    if u["min_obstacle_distance_m"] < 0.5: problems.append(f"uav {i} min obstacle {u['min_obstacle_distance_m']:.2f} < 0.5")
    if u["min_worker_distance_m"] < 3.0: problems.append(f"uav {i} min worker {u['min_worker_distance_m']:.2f} < 3")
    p = [float(last[f"{name}_{k}"]) for k in "xyz"]
    horizontal = math.hypot(p[0] - worker[0], p[1] - worker[1])
    if horizontal < 14.0: problems.append(f"uav {i} ends {horizontal:.1f} m from the worker (< 14)")
    zs.append(p)
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
# Each UAV in its own layer (10, 14, 18 m) or at its landing approach point (2 m; within the arrival
# tolerance); landing spots >= Gamma_dis apart.
for i, p in enumerate(zs):
    want = 2.0 if run == "land" else 10 + 4 * i
    if abs(p[2] - want) > 1.0: problems.append(f"uav {i} at height {p[2]:.2f}, want {want}")
    for q in zs[i + 1:]:
        if math.hypot(p[0] - q[0], p[1] - q[1]) < 2.5: problems.append(f"uav {i} ends < 2.5 m beside another horizontally")
print(("FAIL " if problems else "ok   ") + f"abort ({run}): " + (", ".join(problems) if problems else
      "settled " + ", ".join(f"{u['settled_s'] - a['issued_s']:.1f}" for u in a["uavs"]) + " s after the abort; min mutual "
      f"{min(u['min_uav_distance_m'] for u in a['uavs']):.2f} m, obstacle {min(u['min_obstacle_distance_m'] for u in a['uavs']):.2f} m, "
      f"worker {min(u['min_worker_distance_m'] for u in a['uavs']):.2f} m"))
sys.exit(1 if problems else 0)
PY
done
exit $fail
