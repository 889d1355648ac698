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
need_netns
sim_inner_start duration:=40 gesture_prefix:=/world/unused
cat >> "$T/inner.sh" <<INNER
timeout 75 python3 "$SRC/test/ros/assistance_check.py" "$SRC"
rc=\$?
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 100 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, assistance)"; grep -aE "ERROR|refuses|ssistance" "$T/launch.log" | grep -av '^ \* /' | head -20; }
exit $rc
