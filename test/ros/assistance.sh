#!/bin/bash
# The worker's request for assistance through the ROS system (docs/safety.md §2.10), simulation.launch
# with LCM inside a private network namespace: a request as the leader's GestureCommander publishes
# it on a fired {event: assist_requested} reaches the leader's planner (latched assistance_state) and
# the ground station over LCM (/operator/assistance); while it is pending the worker's gesture
# commands are rejected (the leader's acknowledgement says why) and the operator's applied;
# `tools/gf_command.py ack-assist` releases it (the leader's state and the ground's say
# acknowledged) and the worker's gestures are applied again; a second ack-assist is refused. The
# Visualizer shows a red banner in rviz while the request is pending.
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
"$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 100 > /dev/null
mkdir -p "$T/out"
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out duration:=40 \
  real_time_factor:=1.5 gesture_prefix:=/world/unused > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
timeout 75 python3 "$SRC/test/ros/assistance_check.py" "$SRC"
rc=\$?
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 100 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, assistance)"; grep -aE "ERROR|refuses|ssistance" "$T/launch.log" | grep -av '^ \* /' | head -20; }
exit $rc
