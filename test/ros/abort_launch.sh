#!/bin/bash
# The operator's abort through the ROS system (docs/safety.md §2.8, docs/ros.md "Abort"):
# simulation.launch (3 UAV managers + world, LCM inside a private network namespace), at sim
# t = 12 s `tools/gf_command.py abort` (OperatorInterface → the ground station's LcmBridge → every
# UAV's LcmBridge → its FormationPlanner's ReplanStep; the leader relays it in its share). Checks
# (test/ros/abort_check.py): every UAV accepts it and its latched abort_state reaches at_retreat
# (the mission's abort.after: hover) within the limit; after settling each keeps the worker at
# least abort.retreat_distance_m − arrival_tolerance_m away and its goal's layer; SimWorld's
# metrics.json reports no collision and the mutual distance above Γ_dis.
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
"$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 100 > /dev/null
mkdir -p "$T/out"
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out duration:=45 \
  real_time_factor:=1.5 gesture_prefix:=/world/unused > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
timeout 90 python3 "$SRC/test/ros/abort_check.py" "$SRC" "$SRC/config/scenarios/power_towers.yaml" "$T/out"
rc=\$?
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 115 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (errors, aborts)"; grep -aE "ERROR|refuses|abort|Abort" "$T/launch.log" | head -30; }
exit $rc
