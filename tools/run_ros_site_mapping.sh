#!/usr/bin/env bash
# The construction site through ROS with rendered cameras and live maps (issue 35; docs/mapping.md
# §9): for each seed tools/run_ros_mission.sh --mission config/scenarios/construction_site.yaml
# --camera rendered --mapping (SimCamera draws the unmapped obstacles, every FormationPlanner plans on
# a live map of its rendered depth, SimWorld counts the unmapped obstacles), the bag's /diagnostics
# read back (rostopic echo -b), then docs/results/ros_site_mapping.md written by
# tools/ros_site_report.py (safety, requests, fallbacks, live-map frames and changes, memory, load).
#
#   tools/run_ros_site_mapping.sh        # seed 1, the whole mission (52 s), rtf 0.25
#
# Environment: GF_SEEDS ("1"), GF_RTF (0.25), GF_OUT (the runs' folder, default a temporary one),
# GF_REPORT (docs/results/ros_site_mapping.md; with GF_SHARE=1 ros_site_mapping_share.md), GF_SHARE (1: config/mapping.yaml with share.enabled —
# the UAVs exchange their live-map changes over LCM, docs/mapping.md §8; the report then shows the
# updates sent and merged).
# Exit code: the report's (0 when no seed had a collision or came nearer an obstacle than 0.5 m).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
SEEDS=${GF_SEEDS:-1}
RTF=${GF_RTF:-0.25}
OUT=${GF_OUT:-$(mktemp -d)}
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
MAPPING_CONFIG=config/mapping.yaml
if [ "${GF_SHARE:-0}" = 1 ]; then
  MAPPING_CONFIG="$OUT/mapping_share.yaml"
  mkdir -p "$OUT"
  sed 's/^  enabled: false/  enabled: true/' config/mapping.yaml > "$MAPPING_CONFIG"
  grep -q "^  enabled: true" "$MAPPING_CONFIG" || { echo "run_ros_site_mapping.sh: could not enable share in $MAPPING_CONFIG" >&2; exit 2; }
fi
runs=()
for seed in $SEEDS; do
  run="$OUT/seed$seed"
  tools/run_ros_mission.sh --out "$run" --seed "$seed" --rtf "$RTF" --mission config/scenarios/construction_site.yaml \
    --camera rendered --mapping --mapping-config "$MAPPING_CONFIG" || echo "run_ros_site_mapping.sh: seed $seed: run_ros_mission.sh exited $?" >&2
  [ -f "$run/metrics.json" ] || { echo "run_ros_site_mapping.sh: seed $seed: no $run/metrics.json" >&2; exit 1; }
  # shellcheck disable=SC1091
  (set +u; source "$(source tools/lib/devel_dir.bash; gf_devel_dir .)/setup.bash"; rostopic echo -b "$run/mission.bag" -p /diagnostics > "$run/diag.csv")
  runs+=("$run")
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
python3 tools/ros_site_report.py --runs "${runs[@]}" --rtf "$RTF" --share "${GF_SHARE:-0}" \
  --commit "$(git rev-parse --short=10 HEAD)$(git diff --quiet HEAD -- . ':!docs/results' || echo ' (with uncommitted changes)')" \
  --date "$(date -u '+%Y-%m-%d %H:%M UTC')" \
  --load "$(nproc) cores shared with other jobs; 1/5/15-min load averages before $load_before, after $load_after" \
  --out "${GF_REPORT:-docs/results/ros_site_mapping$([ "${GF_SHARE:-0}" = 1 ] && echo _share).md}"
