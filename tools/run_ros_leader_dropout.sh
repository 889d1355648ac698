#!/usr/bin/env bash
# The leader_dropout_for_good profile through ROS (docs/safety.md §1.2, docs/ros.md "Leader
# hand-over"): for each seed the power-tower mission with config/faults/leader_dropout_for_good.yaml
# through tools/run_ros_mission.sh --leadership (SimWorld unloads the acting UAV's LcmBridge at the
# silence and writes leadership.csv), then gfctl simulate with the same seed and duration, then
# docs/results/ros_leader_dropout.md written by tools/ros_handover_report.py (side by side, the load).
#
#   tools/run_ros_leader_dropout.sh            # seeds 1 2 3, 130 s, rtf 1
#
# Environment: GF_SEEDS ("1 2 3"), GF_DURATION (130: the operator's request at 120 s gets its time), GF_RTF (1), GF_OUT (the runs' folder, default a
# temporary one), GF_REPORT (docs/results/ros_leader_dropout.md). Runs nice -n 10.
# Exit code: the report's (0 when through ROS every seed had a new leader within the limit, never two
# acting, every request after the hand-over applied and no collision).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/lib/devel_dir.bash
GFCTL=$(gf_devel_dir . || echo /nonexistent)/lib/gesture_formation/gfctl
SEEDS=${GF_SEEDS:-1 2 3}
DURATION=${GF_DURATION:-130}
RTF=${GF_RTF:-1}
OUT=${GF_OUT:-$(mktemp -d)}
PROFILE=config/faults/leader_dropout_for_good.yaml
[ -x "$GFCTL" ] || { echo "run_ros_leader_dropout.sh: $GFCTL missing: tools/build.sh" >&2; exit 2; }
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
runs=()
for seed in $SEEDS; do
  run="$OUT/seed$seed"
  nice -n 10 tools/run_ros_mission.sh --out "$run/ros" --seed "$seed" --duration "$DURATION" --rtf "$RTF" \
    --faults "$PROFILE" --leadership || echo "run_ros_leader_dropout.sh: seed $seed: run_ros_mission.sh failed (exit $?)" >&2
  [ -f "$run/ros/metrics.json" ] && [ -f "$run/ros/leadership.csv" ] || { echo "run_ros_leader_dropout.sh: seed $seed: no metrics.json / leadership.csv in $run/ros" >&2; exit 1; }
  nice -n 10 "$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --fault-profile leader_dropout_for_good --seed "$seed" \
    --duration "$DURATION" --no-plot --out "$run/sim" > "$run/simulate.log" 2>&1 \
    || { echo "run_ros_leader_dropout.sh: gfctl simulate failed (see $run/simulate.log)" >&2; exit 1; }
  runs+=("$run")
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
silence=$(python3 -c "import yaml, sys; print(yaml.safe_load(open(sys.argv[1]))['faults']['leader_silence']['t_s'])" "$PROFILE")
python3 tools/ros_handover_report.py --runs "${runs[@]}" --silence-s "$silence" --limit-s 4.5 --duration "$DURATION" \
  --rtf "$RTF" --commit "$(git rev-parse --short=10 HEAD)$(git diff --quiet HEAD -- . ':!docs/results' || echo ' (with uncommitted changes)')" \
  --date "$(date -u '+%Y-%m-%d %H:%M UTC')" \
  --load "$(nproc) cores shared with other jobs; 1/5/15-min load averages before $load_before, after $load_after" \
  --out "${GF_REPORT:-docs/results/ros_leader_dropout.md}"
