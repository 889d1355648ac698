#!/bin/bash
# gfctl corridor on unseen random paths through config/scenarios/power_towers.yaml, checked by
# an independent Python checker (tools/reference/check_corridor.py) against every occupied
# voxel centre exported by gfctl map: unit rows, seeds inside, neighbours share their
# waypoint, no voxel centre strictly inside any polytope. Fixed seeds.
set -euo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
PY=/usr/bin/python3
$PY -c "import numpy" 2>/dev/null || PY=/opt/gesture_formation/venv/bin/python
SCEN="$SRC/config/scenarios/power_towers.yaml"
"$GFCTL" map --scenario "$SCEN" --export-points "$OUT/pts.csv" --out "$OUT/map.bt" > "$OUT/map.log" 2>&1 || { cat "$OUT/map.log"; exit 1; }
grep "occupied voxels" "$OUT/map.log"
test -s "$OUT/map.bt"
$PY "$SRC/tools/reference/random_corridor_paths.py" --points "$OUT/pts.csv" --seed 20250401 --count 12 --out-dir "$OUT/paths"
for clearance in 0.5 0.2; do
  for path in "$OUT"/paths/path_*.csv; do
    name=$(basename "$path" .csv)
    "$GFCTL" corridor --scenario "$SCEN" --path "$path" --out "$OUT/$name.json" --clearance $clearance > "$OUT/$name.log" 2>&1 \
      || { echo "gfctl corridor failed on $name:"; cat "$OUT/$name.log"; cat "$path"; exit 1; }
    echo "== $name clearance $clearance: $(cat "$OUT/$name.log")"
    $PY "$SRC/tools/reference/check_corridor.py" --corridor "$OUT/$name.json" --points "$OUT/pts.csv" --path "$path"
  done
done
