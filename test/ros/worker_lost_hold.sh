#!/bin/bash
# The hold rule in the ROS system (docs/safety.md §1 rules 2–4, §2.2): simulation.launch with a
# fault profile that blinds the leader's camera from 8 to 14 s. Every FormationPlanner must hold
# (mode `hold` in its plans, SimWorld's modes.csv) once the estimate's last fused measurement is
# older than max_worker_age_s (3 s) — the leader from its own estimate, the followers from the
# estimate they receive over LCM — brake to a stop, the leader search with its camera once its
# estimator has lost the worker (lost_timeout_s 5 s), and track again when detections return; Γ_dis
# and no collision throughout (test/ros/check_hold.py).
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
make_key "$T/keys"
mkdir -p "$T/out"
# The hold rule as such: the worker assumed still (reach_walking_speed_mps 0: no back-off from his
# growing reach, docs/safety.md §3 — gfctl simulate's WorkerApproachTest and ReplanStepReachTest).
cat > "$T/blackout.yaml" <<YAML
faults:
  camera_blackouts: [[8, 14]]
  reach_walking_speed_mps: 0
YAML
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_file:=$T/keys output_dir:=$T/out duration:=24 \
  real_time_factor:=1.5 faults:=$T/blackout.yaml > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
python3 "$SRC/test/ros/watch_modes.py" "$T/modes.txt" > /dev/null 2>&1 &
watch=\$!
for _ in \$(seq 120); do [ -f "$T/out/metrics.json" ] && break; sleep 0.5; done
sleep 0.5
python3 "$SRC/test/ros/check_hold.py" "$T/out" 8 14 3.0 5.0
rc=\$?
kill \$watch
# rviz shows why a UAV does not track: the Visualizer's mode labels during the blackout.
python3 - "$T/modes.txt" <<'PY' || rc=\$((rc+1))
import sys
rows = [l.split(" ", 2) for l in open(sys.argv[1]).read().splitlines()]
rows = [(float(t), int(i), text) for t, i, text in rows]
bad = 0
def check(ok, what):
    global bad
    print(("PASS: " if ok else "FAIL: ") + what)
    bad += 0 if ok else 1
lead = [r for r in rows if r[1] == 0]
check(any(t >= 13.0 and x.startswith("search: worker not seen") for t, _, x in lead),
      "rviz label 'search: worker not seen ...' above the leader: %s" % sorted({x for _, _, x in lead}))
for i in (1, 2):
    check(any(x.startswith("hold: worker estimate older") for _, j, x in rows if j == i), "rviz label 'hold: ...' above follower %d" % i)
# Not tracking: the start's listening (docs/safety.md §2.4; its own label) and the blackout. A planner
# listens from its first replanning for at most max_plan_age_s (1 s) — when that first replanning
# comes depends on the machine's load (nodelets loading, the map), so each UAV's listening is timed
# from its own first listening label: at most 1 s + one replanning period (0.4 s) + a label tick.
start = [r for r in rows if r[2].startswith("hold: listening:")]
listen = {i: (min(t for t, j, _ in start if j == i), max(t for t, j, _ in start if j == i)) for i in {j for _, j, _ in start}}
check(rows and all(last - first <= 1.5 for first, last in listen.values()) and
      not any((t < 10.5 or t > 16.5) and not x.startswith("hold: listening:") for t, _, x in rows),
      "labels only while not tracking (listening per UAV, first - last label: %s, each <= 1.5 s; the blackout 10.9-14.5 s: %s)"
      % ({i: "%.2f-%.2f" % v for i, v in sorted(listen.items())}, [r[0] for r in rows if not r[2].startswith("hold: listening:")][:1] +
         [r[0] for r in rows if not r[2].startswith("hold: listening:")][-1:]))
sys.exit(bad)
PY
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 85 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, holds)"; grep -aE "ERROR|refuses|hold|track" "$T/launch.log" | head -30; }
exit $rc
