#!/usr/bin/env bash
# Draws OUT/timeline.png for a mission run through ROS (SimWorld's timeline.csv / events.csv):
# writes OUT/scene.json (the scenario's solids, as gfctl simulate writes them) and calls
# tools/plot_timeline.py with the tools venv's matplotlib. Used by tools/run_ros_mission.sh and
# tools/run_multihost.sh.   tools/plot_mission.sh OUT MISSION_FILE [DEVEL_DIR or BUILD_DIR]
# (default: the build tools/lib/devel_dir.bash finds; without one, scene.json is not written)
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail
cd "$(dirname "$0")/.."
OUT=$1
MISSION=$2
source tools/lib/devel_dir.bash
DEVEL=$(gf_devel_dir . "${3:-}" 2> /dev/null) || DEVEL=/nonexistent
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
GFCTL=$DEVEL/lib/gesture_formation/gfctl
if [ -x "$GFCTL" ] && "$GFCTL" simulate --scenario "$MISSION" --out "$T/scene" --duration 0.1 --no-plot > /dev/null 2>&1; then
  cp "$T/scene/scene.json" "$OUT/scene.json"
fi
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || PY=python3
"$PY" tools/plot_timeline.py "$OUT" > /dev/null 2>&1 && echo "wrote $OUT/timeline.png" || echo "timeline.png not drawn (needs matplotlib: $PY tools/plot_timeline.py $OUT)"
