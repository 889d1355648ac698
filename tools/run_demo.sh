#!/usr/bin/env bash
# The main job (README): installs what is missing (tools/setup.sh), builds gfctl and the
# nodelets, and flies the paper's simulated power-tower mission (config/scenarios/power_towers.yaml:
# 3 UAVs, the worker at both towers, 25 view-adaptation requests incl. 6 gestures) through the
# ROS system — launch/simulation.launch headless: one nodelet manager per UAV, LCM between them
# in a private network namespace, sim time (tools/run_ros_mission.sh, docs/ros.md). Records
# results/demo/mission.bag, writes metrics.json, timeline.csv, events.csv and timeline.png,
# prints a summary. As root, or as a user with sudo (setup and the network namespace only).
#   tools/run_demo.sh                     # seed 1 → results/demo/
#   tools/run_demo.sh --rviz              # the same with rviz open
#   GF_DEMO_SEED=7 tools/run_demo.sh      # another seed (any run_ros_mission.sh option may follow)
#   GF_DEMO_RSS_BUDGET_MB=0 tools/run_demo.sh     # print the UAV managers' peak RSS without checking it
# Exit code: non-zero when the setup, the build or the mission failed (did not finish, a
# collision, or a UAV nodelet manager's peak resident set above GF_DEMO_RSS_BUDGET_MB, default the
# design budget of 150 MB, docs/design.md §7).
# The one-process variant without ROS is `gfctl simulate` (README).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh > /dev/null
BUILD_DIR=${GF_BUILD_DIR:-build}
mkdir -p "$BUILD_DIR"
echo "== build: gfctl, the nodelets and their messages (tools/build.sh; log $BUILD_DIR/demo_build.log)"
LOG=$BUILD_DIR/demo_build.log
build() { tools/build.sh gfctl gesture_formation_nodelets gesture_formation_sim_nodelets gesture_formation_generate_messages > "$LOG" 2>&1; }
if ! build; then
  built=false
  if grep -q "Please rerun cmake" "$LOG"; then
    # A build tree configured before a message changed its dependencies (catkin's check): configure again.
    echo "   the messages' dependencies changed since $BUILD_DIR was configured: cmake again ($BUILD_DIR/demo_cmake.log)"
    cmake -S . -B "$BUILD_DIR" > "$BUILD_DIR/demo_cmake.log" 2>&1 && build && built=true
  fi
  if ! $built; then
    tail -30 "$LOG" >&2
    echo "$0: the build failed (full log: $LOG)" >&2
    exit 1
  fi
fi
echo "== the power-tower mission through launch/simulation.launch, seed ${GF_DEMO_SEED:-1} (451 s simulated at 2x real time)"
# Each UAV's nodelet manager's peak resident set is printed and checked (GF_DEMO_RSS_BUDGET_MB, 0: not checked).
exec tools/run_ros_mission.sh --seed "${GF_DEMO_SEED:-1}" --rss-budget-mb "${GF_DEMO_RSS_BUDGET_MB:-150}" "$@"
