#!/usr/bin/env bash
# The abort profile (docs/safety.md §2.8): the power-tower mission with
# config/faults/abort_mid_mission.yaml (the operator aborts at 100 s), seeds 1..N, each run to
# GF_DURATION s (default 160: a minute after the abort), then docs/results/abort.md written from
# the missions' metrics.json by tools/abort_report.py (the distribution over seeds of each UAV's
# time to settle and its least distances after the abort; collisions; Gamma_dis violations).
#
#   tools/run_abort_profile.sh              # seeds 1..10
#   GF_SEEDS=100 tools/run_abort_profile.sh
#
# Environment: GF_SEEDS (default 10), GF_DURATION (160), GF_PROFILE (abort_mid_mission),
# GFCTL (default: gfctl of the build tools/lib/devel_dir.bash finds), GF_OUT (the missions' folder, default
# a temporary one), GF_REPORT (default docs/results/abort.md). Runs nice -n 10, one mission at a time.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/lib/devel_dir.bash
GFCTL=${GFCTL:-$(gf_devel_dir . || echo /nonexistent)/lib/gesture_formation/gfctl}
SEEDS=${GF_SEEDS:-10}
DURATION=${GF_DURATION:-160}
PROFILE=${GF_PROFILE:-abort_mid_mission}
OUT=${GF_OUT:-$(mktemp -d)}
[ -x "$GFCTL" ] || { echo "run_abort_profile.sh: $GFCTL missing: tools/build.sh gfctl" >&2; exit 2; }
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
wall0=$(date +%s)
nice -n 10 "$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --fault-profile "$PROFILE" \
  --seeds "1..$SEEDS" --duration "$DURATION" --threads 1 --no-plot --out "$OUT" > "$OUT/simulate.log" 2>&1 \
  || { echo "run_abort_profile.sh: gfctl simulate failed (see $OUT/simulate.log)" >&2; tail -20 "$OUT/simulate.log" >&2; exit 1; }
wall_s=$(( $(date +%s) - wall0 ))
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
python3 tools/abort_report.py --missions "$OUT" --seeds "$SEEDS" --duration "$DURATION" --profile "$PROFILE" \
  --load "before $load_before, after $load_after (1/5/15-min averages; $(nproc) cores), $wall_s s wall for all seeds" \
  --out "${GF_REPORT:-docs/results/abort.md}"
