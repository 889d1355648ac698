#!/bin/bash
# The flight-stack relay (launch/flight_stack.launch, MAVROS convention) against hand-made
# messages (test/ros/flight_stack_check.py): the OdometryAdapter turns local_position/odom (body
# twist, child base_link) + a camera mount 20 deg down into the planner's odometry and refuses a
# wrong child_frame_id, naming it (rate-limited in the log, counted on /diagnostics); the
# SetpointRelay samples a plan into PoseStamped / TwistStamped / gimbal setpoints, holds the
# plan's last point after its end and refuses plans in another frame or of another UAV.
set -o pipefail
command -v roscore > /dev/null || { echo "SKIP: no ROS (roscore not found)"; exit 77; }
source "$(dirname "$0")/common.bash"
start_master
roslaunch -p "$PORT" gesture_formation flight_stack.launch flight_stack:=mavros setpoints:=both rate_hz:=50 \
  camera_mount_rpy_rad:="[0.0, 0.3490658503988659, 0.0]" > "$T/launch.log" 2>&1 & pids+=($!)
for _ in $(seq 100); do rostopic list 2>/dev/null | matches "^/gimbal/target$" && rostopic list 2>/dev/null | matches "^/odometry$" && break; sleep 0.3; done
timeout 60 python3 "$SRC/test/ros/flight_stack_check.py" || fails=$((fails + $?))
grep -q "refuses to start" "$T/launch.log" && fail "a nodelet refused to start: $(grep -A4 refuses "$T/launch.log" | head -6)"
# The refusal is named and rate-limited: 30 wrong messages in 1.5 s, at most one line per 2 s.
n=$(grep -c "odometry refused (nothing from it is used): odometry_in child_frame_id: expected 'base_link', received 'odom'" "$T/launch.log")
[ "$n" -ge 1 ] && [ "$n" -le 2 ] && echo "PASS: the refusal logged $n time(s) for 30 messages (rate-limited, naming the field)" \
  || fail "refusal logged $n times (1-2 expected)"
grep -q "plan refused (nothing from it is used): plan_in header.frame_id: expected 'map', received 'world'" "$T/launch.log" \
  && echo "PASS: the plan in another frame refused, named" || fail "no named refusal of the plan in frame world"
[ $fails -eq 0 ] || { echo "--- launch.log"; tail -30 "$T/launch.log"; }
exit $fails
