# Shared setup of the ROS tests (sourced): private master on a random port, private ROS_HOME,
# the build's devel space, cleanup of every process started. Args of the test: SOURCE_DIR BUILD_DIR
# [DEVEL_DIR] (CMake passes CATKIN_DEVEL_PREFIX: BUILD_DIR/devel with tools/build.sh, the
# package's devel space in a catkin workspace); nothing needs sourcing beforehand.
SRC=$1
BUILD=$2
DEVEL=${3:-$BUILD/devel}
[ -f "$DEVEL/setup.bash" ] || { echo "FAIL: no devel space at $DEVEL (build first)"; exit 1; }
T=$(mktemp -d)
PORT=$((12000 + RANDOM % 2000))
export ROS_MASTER_URI=http://127.0.0.1:$PORT ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
export PATH=/usr/bin:/bin:$PATH
# shellcheck disable=SC1091
source "$DEVEL/setup.bash"
pids=()
fails=0
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null; done
  sleep 1
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  wait 2>/dev/null
  rm -rf "$T"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
# matches ARGS...: grep that reads its whole input. The tests run under pipefail, where `cmd | grep -q`
# can fail on a match: grep -q exits at the first matching line and a writer still writing (bash's
# echo writes line by line) dies of SIGPIPE, status 141 (ros_onboard_launch failed so in CI).
matches() { grep "$@" > /dev/null; }
start_master() {
  roscore -p "$PORT" > "$T/roscore.log" 2>&1 & pids+=($!)
  for _ in $(seq 50); do rosparam list > /dev/null 2>&1 && return 0; sleep 0.2; done
  echo "FAIL: no ROS master"; exit 1
}
make_key() {  # a fresh owner-only key file
  (umask 077; printf '1 %s active\n' "$(od -An -N32 -tx1 /dev/urandom | tr -d ' \n')" > "$1")
}
# LCM multicast stays on this machine: tests that run the simulation do so in a private network
# namespace (unshare -n), which needs root; without it they are skipped.
need_netns() { [ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (unshare -n keeps LCM on this machine)"; exit 77; }; }
# Writes the start of $T/inner.sh, the script a test runs in its namespace: loopback multicast,
# simulation.launch with per-sender keys ($T/keys), outputs in $T/out, real-time factor 1.5 and the
# given extra arguments (log $T/launch.log, pid in $launch), then a wait for sim time. The test
# appends its checks (cat >> "$T/inner.sh") and stops the launch itself.
sim_inner_start() {
  "$SRC/tools/make_fleet_keys.sh" "$T/keys" 0 1 2 100 > /dev/null
  mkdir -p "$T/out"
  cat > "$T/inner.sh" <<SIMSTART
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roslaunch -p $PORT gesture_formation simulation.launch key_dir:=$T/keys output_dir:=$T/out real_time_factor:=1.5 $* > "$T/launch.log" 2>&1 &
launch=\$!
for _ in \$(seq 50); do rosparam get /use_sim_time > /dev/null 2>&1 && break; sleep 0.2; done
SIMSTART
}
