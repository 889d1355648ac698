#!/usr/bin/env bash
# The Monte Carlo fault matrix (the power-tower mission under every fault profile of
# config/faults/, seeds 1..100), now a thin wrapper of tools/campaign.py (docs/campaigns.md):
# the campaign config/campaigns/fault_matrix.yaml runs on a local Dask cluster into the store
# docs/results/campaigns.sqlite (a mission already stored is never run again: the command
# resumes), then the report docs/results/reliability.md and its figure are written from it.
#
#   tools/run_fault_matrix.sh                 # every profile, 100 seeds, then the report
#   tools/run_fault_matrix.sh --report-only   # the report from the store
#
# Environment: GF_SEEDS (seeds 1..N instead of 1..100), GF_PROFILES ("loss50 harsh": these
# profiles only), GF_STORE (the store), GF_REPORT (the report; the figure fault_matrix.png goes
# beside it), GFCTL (the binary), GF_WORKERS (local workers, default: the cores). Anything
# else (variants, a cluster): tools/campaign.py run|report directly.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || { echo "run_fault_matrix.sh: $PY missing: run tools/setup.sh (the tools venv has Dask)" >&2; exit 2; }
STORE=(--store "${GF_STORE:-docs/results/campaigns.sqlite}")
SELECT=()
[ -z "${GF_SEEDS:-}" ] || SELECT+=(--seeds "1..$GF_SEEDS")
[ -z "${GF_PROFILES:-}" ] || SELECT+=(--profiles "$GF_PROFILES")
rc=0
if [ "${1:-}" != "--report-only" ]; then  # failed missions (exit 1) are stored and reported; bad input (2) stops
  "$PY" tools/campaign.py "${STORE[@]}" run config/campaigns/fault_matrix.yaml "${SELECT[@]}" \
    ${GF_WORKERS:+--workers "$GF_WORKERS"} || rc=$?
  [ "$rc" -le 1 ] || exit "$rc"
fi
"$PY" tools/campaign.py "${STORE[@]}" report config/campaigns/fault_matrix.yaml "${SELECT[@]}" --out "${GF_REPORT:-docs/results/reliability.md}"
exit "$rc"
