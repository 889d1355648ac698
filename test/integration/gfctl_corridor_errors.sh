#!/bin/bash
# gfctl map / corridor reject bad input with exit code 2 and a message naming file, line and
# field (design.md §8); a path through a tower leg is reported, not answered with a bad polytope.
set -uo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
SCEN="$SRC/config/scenarios/power_towers.yaml"
fails=0
expect() {  # expect CODE PATTERN -- command...
  local code=$1 pattern=$2
  shift 3
  "$@" > "$OUT/out.log" 2> "$OUT/err.log"
  local rc=$?
  if [ "$rc" != "$code" ] || ! grep -q -- "$pattern" "$OUT/err.log"; then
    echo "FAIL: '$*' gave exit $rc (want $code), stderr:"; cat "$OUT/err.log"; echo "(want pattern '$pattern')"
    fails=$((fails + 1))
  else
    echo "ok: exit $rc: $(head -1 "$OUT/err.log")"
  fi
}
printf 'x,y,z\n-8,-10,8\n0,-10,12\n' > "$OUT/good.csv"
printf 'x,y\n-8,-10\n0,-10\n' > "$OUT/nocol.csv"
printf 'x,y,z\n-8,-10,8\n0,abc,12\n' > "$OUT/badnum.csv"
printf 'x,y,z\n-8,-10,8\n' > "$OUT/short.csv"
# Along a row of ground voxel centres (z = 0.1, x and y at (i + 0.5) * 0.2).
printf 'x,y,z\n-5.1,-10.1,0.1\n-1.1,-10.1,0.1\n' > "$OUT/hit.csv"
# Through the west tower's leg near (2.63, 2.63) at z = 5: accepted with a warning.
printf 'x,y,z\n2.63,-5,5\n2.63,10,5\n' > "$OUT/leg.csv"
printf 'x,y,z\n-8,-10,8\n-8,-10,8\n' > "$OUT/dup.csv"
cat > "$OUT/bad_scenario.yaml" <<'YAML'
map:
  resolution_m: -0.2
  bounds: {min: [0, 0, 0], max: [10, 10]}
boxes:
  - {center: [1, 2, 3], size: [1, 0, 1], colour: red}
worker_route: {anything: goes}
YAML
expect 2 "missing required option --path" -- "$GFCTL" corridor --scenario "$SCEN" --out "$OUT/c.json"
expect 2 "unknown option --bogus" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/good.csv" --out "$OUT/c.json" --bogus 1
expect 2 "clearance" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/good.csv" --out "$OUT/c.json" --clearance -1
expect 2 "nocol.csv.*z" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/nocol.csv" --out "$OUT/c.json"
expect 2 "badnum.csv:3: field 'y'" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/badnum.csv" --out "$OUT/c.json"
expect 2 "at least 2 waypoints" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/short.csv" --out "$OUT/c.json"
expect 2 "hit.csv:2: segment to line 3: obstacle point" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/hit.csv" --out "$OUT/c.json"
expect 0 "leg.csv:2: the segment passes" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/leg.csv" --out "$OUT/leg.json"
expect 2 "dup.csv:2: .*shorter than" -- "$GFCTL" corridor --scenario "$SCEN" --path "$OUT/dup.csv" --out "$OUT/c.json"
expect 2 "bad_scenario.yaml:2: map.resolution_m" -- "$GFCTL" corridor --scenario "$OUT/bad_scenario.yaml" --path "$OUT/good.csv" --out "$OUT/c.json"
expect 2 "bad_scenario.yaml:3: map.bounds.max" -- "$GFCTL" map --scenario "$OUT/bad_scenario.yaml" --export-points "$OUT/p.csv"
expect 2 "bad_scenario.yaml:5: boxes\[0\].size\[1\]" -- "$GFCTL" map --scenario "$OUT/bad_scenario.yaml" --export-points "$OUT/p.csv"
expect 2 "boxes\[0\].colour: unknown key" -- "$GFCTL" map --scenario "$OUT/bad_scenario.yaml" --export-points "$OUT/p.csv"
expect 2 "missing.yaml: cannot open" -- "$GFCTL" map --scenario "$OUT/missing.yaml" --export-points "$OUT/p.csv"
expect 2 "export-points" -- "$GFCTL" map --scenario "$SCEN"
# The rejected path through the leg wrote no corridor file.
[ ! -e "$OUT/c.json" ] || { echo "FAIL: a corridor file was written for rejected input"; fails=$((fails + 1)); }
# Worker-route sections of a scenario are not the world loader's business.
grep -q "worker_route" "$OUT/err.log" && { echo "FAIL: foreign section reported"; fails=$((fails + 1)); }
exit $fails
