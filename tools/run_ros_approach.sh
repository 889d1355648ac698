#!/usr/bin/env bash
# The worker_approaches_holding_uav profile through ROS (docs/safety.md §3): for each seed the
# power-tower mission with config/faults/worker_approaches_holding_uav.yaml through
# tools/run_ros_mission.sh (SimWorld turns the worker towards the holding UAV and records the approach),
# then gfctl simulate with the same seed and duration, then docs/results/ros_worker_approach.md written
# by tools/ros_approach_report.py (side by side, the load).
#
#   tools/run_ros_approach.sh            # seeds 1 2, 240 s, rtf 1
#
# Environment: GF_SEEDS ("1 2"), GF_DURATION (240), GF_RTF (1), GF_OUT (the runs' folder, default a
# temporary one), GF_REPORT (docs/results/ros_worker_approach.md). Runs nice -n 10.
# Exit code: the report's (0 when through ROS no seed had a collision or a Gamma_dis violation).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/lib/devel_dir.bash
GFCTL=$(gf_devel_dir . || echo /nonexistent)/lib/gesture_formation/gfctl
SEEDS=${GF_SEEDS:-1 2}
DURATION=${GF_DURATION:-240}
RTF=${GF_RTF:-1}
OUT=${GF_OUT:-$(mktemp -d)}
[ -x "$GFCTL" ] || { echo "run_ros_approach.sh: $GFCTL missing: tools/build.sh" >&2; exit 2; }
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
runs=()
for seed in $SEEDS; do
  run="$OUT/seed$seed"
  nice -n 10 tools/run_ros_mission.sh --out "$run/ros" --seed "$seed" --duration "$DURATION" --rtf "$RTF" \
    --faults config/faults/worker_approaches_holding_uav.yaml || echo "run_ros_approach.sh: seed $seed: run_ros_mission.sh failed (exit $?)" >&2
  [ -f "$run/ros/metrics.json" ] || { echo "run_ros_approach.sh: seed $seed: no $run/ros/metrics.json" >&2; exit 1; }
  nice -n 10 "$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --fault-profile worker_approaches_holding_uav \
    --seed "$seed" --duration "$DURATION" --no-plot --out "$run/sim" > "$run/simulate.log" 2>&1 \
    || { echo "run_ros_approach.sh: gfctl simulate failed (see $run/simulate.log)" >&2; exit 1; }
  runs+=("$run")
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
python3 tools/ros_approach_report.py --runs "${runs[@]}" --duration "$DURATION" --rtf "$RTF" \
  --commit "$(git rev-parse --short=10 HEAD)$(git diff --quiet HEAD -- . ':!docs/results' || echo ' (with uncommitted changes)')" \
  --date "$(date -u '+%Y-%m-%d %H:%M UTC')" \
  --load "$(nproc) cores shared with other jobs; 1/5/15-min load averages before $load_before, after $load_after" \
  --out "${GF_REPORT:-docs/results/ros_worker_approach.md}"
