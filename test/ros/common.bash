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
start_master() {
  roscore -p "$PORT" > "$T/roscore.log" 2>&1 & pids+=($!)
  for _ in $(seq 50); do rosparam list > /dev/null 2>&1 && return 0; sleep 0.2; done
  echo "FAIL: no ROS master"; exit 1
}
make_key() {  # a fresh owner-only key file
  (umask 077; printf '1 %s active\n' "$(od -An -N32 -tx1 /dev/urandom | tr -d ' \n')" > "$1")
}
