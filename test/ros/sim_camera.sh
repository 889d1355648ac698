#!/bin/bash
# simulation.launch camera:=rendered (docs/ros.md "Rendered cameras"): every UAV's SimCamera renders
# colour (rgb8), aligned depth (32FC1) and CameraInfo on the RealSense topics at its camera rate in
# sim time; the depth is finite at the worker's true position; the leader's Perception nodelet
# finds the worker with a stereo range from the rendered depth; SimWorld publishes no detection and
# no classification (test/ros/sim_camera_check.py). Exit 77 (skipped) when not root (the LCM
# namespace) or when this machine has no EGL device (gfctl render says so).
set -o pipefail
source "$(dirname "$0")/common.bash"
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }
GFCTL=$DEVEL/lib/gesture_formation/gfctl
"$GFCTL" render --scenario "$SRC/config/scenarios/power_towers.yaml" --t 1 --uav 0 --out "$T/probe.png" > "$T/probe.log" 2>&1
rc=$?
if [ $rc -eq 1 ] && grep -q "EGL\|OpenGL" "$T/probe.log"; then echo "SKIP: no EGL device here: $(cat "$T/probe.log")"; exit 77; fi
[ $rc -eq 0 ] || { echo "FAIL: gfctl render exit $rc: $(cat "$T/probe.log")"; exit 1; }
"$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 100 > /dev/null
mkdir -p "$T/out"
# The mission's camera rate (15 Hz: the estimator's process noise is per step, the LSTM's windows) at a third of
# real time: 5 frames per wall second per UAV, which 2 busy cores render and perceive (docs/ros.md).
RATE=15
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out duration:=30 \
  real_time_factor:=0.33 camera:=rendered camera_rate:=$RATE > "$T/launch.log" 2>&1 &
launch=\$!
# sim time starts once every planner is up; the leader's first frame, then 25 s of wall time
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
timeout 90 rostopic echo -n 1 /uav0/camera/color/camera_info > /dev/null 2>&1 || echo "no camera info after 90 s"
timeout 60 python3 "$SRC/test/ros/sim_camera_check.py" 25 $RATE
rc=\$?
grep -q "refuses to start" "$T/launch.log" && { echo "FAIL: a nodelet refused to start: \$(grep -m1 -A3 'refuses to start' "$T/launch.log")"; rc=\$((rc+1)); }
kill -INT \$launch; wait \$launch
exit \$rc
INNER
timeout 170 unshare -n bash "$T/inner.sh"
rc=$?
[ $rc -eq 0 ] || { echo "--- launch.log (tail)"; grep -v "^\s*$" "$T/launch.log" | tail -25; }
exit $rc
