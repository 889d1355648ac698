#!/bin/bash
# The operator's abort through the ROS system (docs/safety.md §2.8, docs/ros.md "Abort"):
# simulation.launch (3 UAV managers + world, LCM inside a private network namespace), at sim
# t = 12 s `tools/gf_command.py abort` (OperatorInterface → the ground station's LcmBridge → every
# UAV's LcmBridge → its FormationPlanner's ReplanStep; every UAV relays the abort it accepted with its heartbeats). Checks
# (test/ros/abort_check.py): every UAV accepts it and its latched abort_state reaches at_retreat
# (the mission's abort.after: hover) within the limit; after settling each keeps the worker at
# least abort.retreat_distance_m − arrival_tolerance_m away and its goal's layer; SimWorld's
# metrics.json reports no collision and the mutual distance above Γ_dis.
set -o pipefail
source "$(dirname "$0")/common.bash"
need_netns
sim_inner_start duration:=45 gesture_prefix:=/world/unused
cat >> "$T/inner.sh" <<INNER
timeout 90 python3 "$SRC/test/ros/abort_check.py" "$SRC" "$SRC/config/scenarios/power_towers.yaml" "$T/out"
rc=\$?
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 115 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, aborts)"; grep -aE "ERROR|refuses|abort|Abort" "$T/launch.log" | head -30; }
exit $rc
