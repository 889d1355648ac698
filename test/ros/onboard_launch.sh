#!/bin/bash
# onboard.launch (leader, in one manager; LCM on memq:// — nothing leaves the process) starts
# every nodelet without a refusal, and with odometry + a worker state the FormationPlanner plans
# at its rate (2.5 Hz) and sends the flight stack a MultiDOFJointTrajectory.
set -o pipefail
source "$(dirname "$0")/common.bash"
make_key "$T/keys"
MAP=$SRC/config/scenarios/power_towers.yaml
roslaunch -p "$PORT" gesture_formation onboard.launch uav_index:=0 key_file:="$T/keys" lcm_url:=memq:// \
  scenario_file:="$MAP" odometry_topic:=odom trajectory_topic:=flight/trajectory > "$T/launch.log" 2>&1 & pids+=($!)
for _ in $(seq 100); do rostopic list 2>/dev/null | matches "^/plan$" && break; sleep 0.3; done
# The leader 10 m north of a worker standing at (0, 10, 2)... camera looking south (heading -90°).
rostopic pub -s -r 20 /odom nav_msgs/Odometry \
  "{header: {stamp: now, frame_id: world}, child_frame_id: world, pose: {pose: {position: {x: 10, y: 10, z: 4}, orientation: {w: 0.7071068, z: -0.7071068}}}}" \
  > /dev/null 2>&1 & pids+=($!)
rostopic pub -s -r 20 /worker_state gesture_formation/WorkerState \
  "{header: {stamp: now, frame_id: world}, position: {x: 10, y: 0, z: 2}, covariance: [0.01,0,0,0,0,0, 0,0.01,0,0,0,0, 0,0,0.01,0,0,0, 0,0,0,0.01,0,0, 0,0,0,0,0.01,0, 0,0,0,0,0,0.01], source: uwb, accepted: true, last_fused: now}" \
  > /dev/null 2>&1 & pids+=($!)
sleep 3
rate=$(timeout 12 rostopic hz -w 20 /plan 2>/dev/null | grep -m2 "average rate" | tail -1 | awk '{print $3}')
awk -v r="$rate" 'BEGIN { exit !(r > 2.0 && r < 3.0) }' && echo "PASS: /plan at $rate Hz (2.5 expected)" || fail "/plan rate '$rate' (2.5 expected)"
mode=$(timeout 5 rostopic echo -n1 /plan/mode 2>/dev/null | head -1 | tr -d '"')
[ "$mode" = "track" ] && echo "PASS: a fresh worker state (last_fused now) is tracked" || fail "plan mode '$mode' with a fresh worker state (track expected)"
# The same state whose last fused measurement is old: the leader holds (docs/safety.md §1 rule 2).
kill "${pids[-1]}" 2>/dev/null
rostopic pub -s -r 20 /worker_state gesture_formation/WorkerState \
  "{header: {stamp: now, frame_id: world}, position: {x: 10, y: 0, z: 2}, covariance: [0.01,0,0,0,0,0, 0,0.01,0,0,0,0, 0,0,0.01,0,0,0, 0,0,0,0.01,0,0, 0,0,0,0,0.01,0, 0,0,0,0,0,0.01], source: none, accepted: false, predicted: true, last_fused: {secs: 1000, nsecs: 0}}" \
  > /dev/null 2>&1 & pids+=($!)
sleep 1.5
plan=$(timeout 5 rostopic echo -n1 /plan 2>/dev/null | grep -E "^(mode|mode_reason|fallback):")
echo "$plan" | matches "^mode: \"hold\"\|^mode: hold" && echo "$plan" | matches "^fallback: True" \
  && echo "$plan" | matches "worker not seen for more than max_worker_age_s" \
  && echo "PASS: an estimate not fused for longer than max_worker_age_s: the leader holds (flagged)" \
  || fail "stale estimate: expected mode hold, fallback True, the reason; got: $plan"
n=$(timeout 5 rostopic echo -n1 /flight/trajectory 2>/dev/null | grep -c "translation")
[ "${n:-0}" -ge 2 ] && echo "PASS: MultiDOFJointTrajectory on the remapped /flight/trajectory ($n points)" || fail "no MultiDOFJointTrajectory on /flight/trajectory"
grep -q "refuses to start" "$T/launch.log" && fail "a nodelet refused to start: $(grep -A3 'refuses' "$T/launch.log" | head -5)"
for n in formation_planner lcm_bridge worker_estimator gesture_commander view_observer perception; do
  grep -q "/$n" <(rosnode list 2>/dev/null) || fail "$n not running"
done
[ $fails -eq 0 ] || { echo "--- launch.log"; tail -30 "$T/launch.log"; }
exit $fails
