#!/bin/bash
# The leader hand-over through ROS/LCM (docs/safety.md §1.2, docs/ros.md "Leader hand-over"):
# simulation.launch leadership:=true (3 UAV managers + world, LCM inside a private network namespace;
# every UAV runs the Leadership nodelet, its messages signed over LCM). At sim t = 8 s the leader's
# LcmBridge is unloaded: UAV 0 is silent on the link for good. Checks (test/ros/leader_handover_check.py):
# UAV 0 alone acts before; it stops acting within its lease; a follower acts within the election's
# limit; never two acting in any instant (every UAV's latched leadership_state, intervals from the
# stamps); the new leader's term is newer and every UAV still heard from agrees on it; an operator
# request after the hand-over is applied by the new leader (leadership:=true lets any UAV send the
# parameters; each planner publishes them only while it acts) and reaches the other follower; the new
# leader's estimator fuses its own camera (SimWorld's leader camera follows the acting UAV) and the
# other follower receives its estimate.
set -o pipefail
source "$(dirname "$0")/common.bash"
need_netns
sim_inner_start duration:=40 leadership:=true gesture_prefix:=/world/unused
cat >> "$T/inner.sh" <<INNER
timeout 80 python3 "$SRC/test/ros/leader_handover_check.py" "$SRC"
rc=\$?
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 110 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, leadership)"; grep -aE "ERROR|refuses|Leadership" "$T/launch.log" | head -30; }
exit $rc
