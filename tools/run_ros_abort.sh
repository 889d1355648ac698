#!/usr/bin/env bash
# The abort profile through ROS (docs/safety.md §2.8, docs/ros.md "Abort"): the power-tower mission
# with config/faults/abort_mid_mission.yaml through launch/simulation.launch (tools/run_ros_mission.sh:
# SimWorld asks the OperatorInterface for the abort at faults.abort.t_s and records every UAV's
# abort_state into metrics.json `abort`), then gfctl simulate with the same seed and duration, then
# docs/results/ros_abort.md written by tools/ros_abort_report.py (both side by side, the load).
#
#   tools/run_ros_abort.sh                 # seed 1, 160 s (a minute after the abort), rtf 2
#
# Environment: GF_SEED (1), GF_DURATION (160), GF_RTF (2), GF_PROFILE (abort_mid_mission), GF_OUT (the
# missions' folder, default a temporary one), GF_REPORT (docs/results/ros_abort.md). Runs nice -n 10.
# Exit code: 0 when through ROS every UAV settled, no collision and the mutual distance kept Gamma_dis.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/lib/devel_dir.bash
GFCTL=$(gf_devel_dir . || echo /nonexistent)/lib/gesture_formation/gfctl
SEED=${GF_SEED:-1}
DURATION=${GF_DURATION:-160}
RTF=${GF_RTF:-2}
PROFILE=${GF_PROFILE:-abort_mid_mission}
OUT=${GF_OUT:-$(mktemp -d)}
[ -x "$GFCTL" ] || { echo "run_ros_abort.sh: $GFCTL missing: tools/build.sh" >&2; exit 2; }
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
wall0=$(date +%s)
nice -n 10 tools/run_ros_mission.sh --out "$OUT/ros" --seed "$SEED" --duration "$DURATION" --rtf "$RTF" \
  --faults "config/faults/$PROFILE.yaml" || echo "run_ros_abort.sh: run_ros_mission.sh failed (exit $?); the report says what happened" >&2
[ -f "$OUT/ros/metrics.json" ] || { echo "run_ros_abort.sh: no $OUT/ros/metrics.json" >&2; exit 1; }
ros_wall_s=$(( $(date +%s) - wall0 ))
load_mid=$(cut -d' ' -f1-3 /proc/loadavg)
nice -n 10 "$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --fault-profile "$PROFILE" \
  --seed "$SEED" --duration "$DURATION" --no-plot --out "$OUT/sim" > "$OUT/simulate.log" 2>&1 \
  || { echo "run_ros_abort.sh: gfctl simulate failed (see $OUT/simulate.log)" >&2; tail -20 "$OUT/simulate.log" >&2; exit 1; }
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
python3 tools/ros_abort_report.py --ros "$OUT/ros/metrics.json" --sim "$OUT/sim/metrics.json" --seed "$SEED" \
  --duration "$DURATION" --profile "$PROFILE" --rtf "$RTF" \
  --load "1/5/15-min averages before the ROS run $load_before, after it $load_mid ($ros_wall_s s wall), after gfctl simulate $load_after; $(nproc) cores shared with other jobs" \
  --out "${GF_REPORT:-docs/results/ros_abort.md}"
