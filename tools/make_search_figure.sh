#!/usr/bin/env bash
# Regenerates docs/images/search_climbing_worker.png (docs/safety.md §2.2): the power-tower mission,
# seed 1, the leader's camera blind 8–25 s while the worker climbs the west tower, once with the
# camera search and once without (search_timeout_s: 0), drawn by tools/plot_search.py.
# Usage: tools/make_search_figure.sh [GFCTL]   (default: gfctl of the build tools/lib/devel_dir.bash finds)
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/lib/devel_dir.bash
GFCTL=${1:-$(gf_devel_dir . || echo /nonexistent)/lib/gesture_formation/gfctl}
PY=/opt/gesture_formation/venv/bin/python
[ -x "$GFCTL" ] || { echo "make_search_figure.sh: $GFCTL not built (tools/build.sh)" >&2; exit 2; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
printf 'faults:\n  camera_blackouts: [[8, 25]]\n' > "$TMP/search.yaml"
printf 'faults:\n  camera_blackouts: [[8, 25]]\n  search_timeout_s: 0\n' > "$TMP/hold.yaml"
for v in search hold; do
  "$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --faults "$TMP/$v.yaml" --seed 1 --duration 45 \
    --out "$TMP/$v" --no-plot > "$TMP/$v.log" || { cat "$TMP/$v.log"; exit 1; }
done
"$PY" tools/plot_search.py --search "$TMP/search" --hold "$TMP/hold" --blackout 8 25 --out docs/images/search_climbing_worker.png
