#!/bin/bash
# The SetpointRelay nodelet when ROS time goes back (a simulation restarted, a bag looped;
# docs/ros.md, onboard::SetpointRelay::accept): under simulated time (/clock from the check
# itself, test/ros/relay_clock_jump_check.py) the relay flies a plan made at 100 s; the clock
# jumps back to 5 s; a plan of the new timeline replaces the held one at once (before: refused as
# older until the clock caught up) and the relay says so in its log, once; plans of the old
# timeline still queued (t0 100.6 s at the jump, 100.7 s later) are refused and never flown. The core's rules are unit-tested
# (SetpointRelayTest.AfterRosTimeWentBackANewPlanReplacesTheHeldOne); this runs the nodelet's glue.
set -o pipefail
command -v roscore > /dev/null || { echo "SKIP: no ROS (roscore not found)"; exit 77; }
source "$(dirname "$0")/common.bash"
start_master
rosparam set /use_sim_time true
roslaunch -p "$PORT" gesture_formation flight_stack.launch flight_stack:=mavros setpoints:=position rate_hz:=50 \
  > "$T/launch.log" 2>&1 & pids+=($!)
timeout 60 python3 "$SRC/test/ros/relay_clock_jump_check.py" || fails=$((fails + $?))
grep -q "refuses to start" "$T/launch.log" && fail "a nodelet refused to start: $(grep -A4 refuses "$T/launch.log" | head -6)"
n=$(grep -c "SetpointRelay: ROS time went back (held plan from 100.5 s, now [0-9.]* s): the new plan replaced it" "$T/launch.log")
[ "$n" -eq 1 ] && echo "PASS: the relay logged the jump and the replacement once (not for the refused 100.6 s plan)" \
  || fail "the clock jump's replacement logged $n times (1 expected)"
grep -q "plan refused (nothing from it is used): plan t0 100.6 s: more than 1 s after now" "$T/launch.log" \
  && echo "PASS: the old timeline's plan queued at the jump refused, named" || fail "no named refusal of the 100.6 s plan"
grep -q "plan refused (nothing from it is used): plan t0 100.7 s: more than 1 s after now" "$T/launch.log" \
  && echo "PASS: the old timeline's plan refused, named" || fail "no named refusal of the old timeline's plan"
[ $fails -eq 0 ] || { echo "--- launch.log"; tail -30 "$T/launch.log"; }
exit $fails
