#!/bin/bash
# record.launch beside a running simulation, then replay.launch of that bag with the site's
# scenario (docs/ros.md "Reviewing a flight"): the bag is lz4-compressed and holds the onboard
# topics but no simulation truth and no rviz markers; on replay the Visualizer draws every UAV
# (body, frustum, plan), the worker and its covariance, and the map again from the bag.
set -o pipefail
source "$(dirname "$0")/common.bash"
need_netns
sim_inner_start duration:=25
cat >> "$T/inner.sh" <<INNER
roslaunch gesture_formation record.launch bag:=$T/flight.bag > "$T/record.log" 2>&1 &
record=\$!
while kill -0 \$launch 2>/dev/null && [ ! -f "$T/out/metrics.json" ]; do sleep 1; done
kill -INT \$record; wait \$record
kill -INT \$launch; wait \$launch
INNER
timeout 80 unshare -n bash "$T/inner.sh" || fail "simulation + record.launch did not finish (see launch.log)"
[ -f "$T/flight.bag" ] || { fail "no bag written: $(tail -5 "$T/record.log")"; exit 1; }
python3 - "$T/flight.bag" <<'PY' || fail "the recorded bag (above)"
import sys, rosbag
bag = rosbag.Bag(sys.argv[1])
topics = bag.get_type_and_topic_info().topics
bad = 0
compression = bag.get_compression_info().compression
if compression != "lz4":
    print("FAIL: bag compression", compression, "not lz4"); bad += 1
for t in ["/uav0/odometry", "/uav1/odometry", "/uav2/odometry", "/uav0/plan", "/uav1/plan", "/uav2/plan",
          "/uav0/worker_state", "/uav0/formation_params", "/uav0/gesture_status", "/diagnostics", "/tf"]:
    if t not in topics or topics[t].message_count == 0:
        print("FAIL: topic", t, "not recorded; the bag has", sorted(topics)); bad += 1
for t in ["/visualization/markers", "/visualization/map", "/world/worker_truth", "/clock"]:
    if t in topics:
        print("FAIL: topic", t, "recorded (markers and truth are not onboard topics)"); bad += 1
sys.exit(1 if bad else 0)
PY
# Replay with the scenario: the Visualizer draws it again.
start_master
roslaunch -p "$PORT" gesture_formation replay.launch bag:="$T/flight.bag" rviz:=false \
  scenario_file:="$SRC/config/scenarios/power_towers.yaml" > "$T/replay.log" 2>&1 & pids+=($!)
timeout 40 python3 - <<'PY' || fail "replay: markers missing (see replay.log)"
import sys, time, rospy
from visualization_msgs.msg import MarkerArray
rospy.init_node("replay_check", anonymous=True)
seen = {}
def cb(m):
    for k in m.markers:
        seen.setdefault(k.ns, set()).add(k.id)
rospy.Subscriber("/visualization/markers", MarkerArray, cb)
map_seen = []
rospy.Subscriber("/visualization/map", MarkerArray, lambda m: map_seen.append(len(m.markers)))
want = {"uavs": {0, 1, 2}, "frusta": {0, 1, 2}, "plans": {0}, "worker": {0}, "worker_cov": {0}}
t0 = time.time()
while time.time() - t0 < 30 and not (all(want[k] <= seen.get(k, set()) for k in want) and map_seen):
    time.sleep(0.2)
missing = {k: sorted(want[k] - seen.get(k, set())) for k in want if not want[k] <= seen.get(k, set())}
print("replay markers:", {k: sorted(v) for k, v in seen.items()}, "map messages:", len(map_seen))
if missing or not map_seen:
    print("FAIL: missing", missing, "map" if not map_seen else "")
    sys.exit(1)
if "worker_truth" in seen:
    print("FAIL: a truth marker from a bag without truth"); sys.exit(1)
PY
[ "$fails" -eq 0 ] && echo "record_replay: bag lz4 with the onboard topics; replay draws 3 UAVs, plans, worker, covariance, map" \
  || echo "record_replay: $fails failures"
exit $((fails > 0))
