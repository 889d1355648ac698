#!/usr/bin/env bash
# The worker-approach profile (docs/safety.md §3): the power-tower mission with
# config/faults/worker_approaches_holding_uav.yaml (the camera blind from 205 s; at 210 s the worker
# walks towards the point below a holding follower), seeds 1..N, each run to GF_DURATION s (default
# 240), then docs/results/worker_approach.md written from the missions' metrics.json and modes.csv by
# tools/approach_report.py (the least true distance worker-UAV in the unseen phase, Gamma_dis
# violations, back-offs; collisions; mutual and obstacle distances).
#
#   tools/run_approach_profile.sh              # seeds 1..10
#   GF_SEEDS=100 tools/run_approach_profile.sh
#
# Environment: GF_SEEDS (default 10), GF_DURATION (240), GF_PROFILE (worker_approaches_holding_uav),
# GFCTL (default: gfctl of the build tools/lib/devel_dir.bash finds), GF_OUT (the missions' folder, default
# a temporary one), GF_REPORT (default docs/results/worker_approach.md), GF_COMMIT (the commit GFCTL was
# built from, for the report; default HEAD). Runs nice -n 10, one mission
# at a time.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/lib/devel_dir.bash
GFCTL=${GFCTL:-$(gf_devel_dir . || echo /nonexistent)/lib/gesture_formation/gfctl}
SEEDS=${GF_SEEDS:-10}
DURATION=${GF_DURATION:-240}
PROFILE=${GF_PROFILE:-worker_approaches_holding_uav}
OUT=${GF_OUT:-$(mktemp -d)}
[ -x "$GFCTL" ] || { echo "run_approach_profile.sh: $GFCTL missing: tools/build.sh gfctl" >&2; exit 2; }
mkdir -p "$OUT"
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
wall0=$(date +%s)
# One mission at a time, each in OUT/seed_N; a seed whose metrics.json exists is not run again
# (stopped early: run again with the same GF_OUT, or report on the seeds done with a smaller GF_SEEDS).
for seed in $(seq 1 "$SEEDS"); do
  [ -f "$OUT/seed_$seed/metrics.json" ] && continue
  nice -n 10 "$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --fault-profile "$PROFILE" \
    --seed "$seed" --duration "$DURATION" --threads 1 --no-plot --out "$OUT/seed_$seed" > "$OUT/seed_$seed.log" 2>&1 \
    || { echo "run_approach_profile.sh: gfctl simulate failed for seed $seed (see $OUT/seed_$seed.log)" >&2;
         tail -20 "$OUT/seed_$seed.log" >&2; exit 1; }
done
wall_s=$(( $(date +%s) - wall0 ))
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
python3 tools/approach_report.py --missions "$OUT" --seeds "$SEEDS" --duration "$DURATION" --profile "$PROFILE" \
  --load "before $load_before, after $load_after (1/5/15-min averages; $(nproc) cores), $wall_s s wall for the seeds run by this call" \
  --out "${GF_REPORT:-docs/results/worker_approach.md}" ${GF_COMMIT:+--commit "$GF_COMMIT"}
