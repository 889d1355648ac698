#!/usr/bin/env bash
# Obstacles the prior map lacks (issue 35; docs/mapping.md §7, docs/simulation.md §2): the
# construction site, seed 1, 34 s — the worker walks east under a crane arm that is not in the prior
# map, past a parked truck that is not either. With mapping (every UAV integrates its synthetic depth
# frames into its live map and plans on it) the crane arm is discovered and avoided: 0 collisions,
# least obstacle distance (mapped and unmapped) >= the verification clearance 0.5 m (as the other
# mission tests), the arm's sight-to-avoidance time measured. The control: the same seed with
# --mapping off (the planners blind to it) comes closer to the crane arm than 0.5 m or collides —
# so the scenario really puts the arm on the route and the first run's result is the mapping's.
# And a scenario with bad unmapped_obstacles / mission.mapping values is refused naming each.
# Usage: gfctl_simulate_unmapped.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
SCEN="$SRC/config/scenarios/construction_site.yaml"
# Bad unmapped obstacles and mapping settings: refused before any run, every problem named at once.
sed -e 's/    moves: {from_s: 24.0, to_s: 34.0, velocity_mps: \[2.0, -1.0, 0.0\]}/    moves: {from_s: 24.0, to_s: 14.0, velocity_mps: [2.0, -1.0]}/' \
    -e 's/    rate_hz: 5.0/    rate_hz: 0/' -e "s#../../third_party_models#$SRC/third_party_models#" "$SCEN" > "$TMP/bad.yaml"
rc=0
"$GFCTL" simulate --scenario "$TMP/bad.yaml" --out "$TMP/bad" --duration 1 --no-plot > "$TMP/bad.log" 2>&1 || rc=$?
for want in "mission.mapping.rate_hz: value 0 is out of range" "unmapped_obstacles[2].moves.velocity_mps: expected 3 numbers, got 2" \
            "unmapped_obstacles[2].moves.to_s: must be >= from_s (24), got 14"; do
  grep -qF "$want" "$TMP/bad.log" || { echo "FAIL bad scenario (exit $rc): no '$want' in:"; cat "$TMP/bad.log"; exit 1; }
done
[ "$rc" = 2 ] || { echo "FAIL bad scenario: exit $rc, expected 2"; exit 1; }
for run in on off; do
  "$GFCTL" simulate --scenario "$SCEN" --out "$TMP/$run" --seed 1 --duration 34 --no-plot --mapping "$run" \
    > "$TMP/$run.log" 2>&1 || { echo "FAIL mapping $run: gfctl exited $?"; cat "$TMP/$run.log"; exit 1; }
done
python3 - "$TMP" <<'PY'
import json, sys
d = sys.argv[1]
CLEARANCE = 0.5  # planner.verify_clearance_m (config/planner.yaml)
on, off = (json.load(open(f"{d}/{r}/metrics.json")) for r in ("on", "off"))
problems = []
def arm(m):
    return next(o for o in m["site_mapping"]["obstacles"] if o["name"] == "crane_arm")
a_on, a_off = arm(on), arm(off)
if not on["site_mapping"]["mapping"]: problems.append("mapping on: site_mapping.mapping is false")
if on["collisions"] != 0: problems.append(f"mapping on: {on['collisions']} collisions")
if on["min_obstacle_distance_m"] < CLEARANCE:
    problems.append(f"mapping on: min obstacle distance {on['min_obstacle_distance_m']:.2f} m < {CLEARANCE}")
if a_on["first_seen_s"] is None: problems.append("mapping on: the crane arm was never seen")
if a_on["avoided_s"] is None: problems.append("mapping on: no plan avoided the crane arm after it was seen")
if a_on["min_distance_m"] < CLEARANCE: problems.append(f"mapping on: crane arm at {a_on['min_distance_m']:.2f} m")
if not on["site_mapping"]["coverage"] > 0: problems.append("mapping on: coverage 0")
if off["site_mapping"]["mapping"] or a_off["first_seen_s"] is not None:
    problems.append("mapping off: the UAVs still mapped")
if not (a_off["min_distance_m"] < CLEARANCE or off["collisions"] > 0):
    problems.append(f"control: blind planners kept {a_off['min_distance_m']:.2f} m from the crane arm and did not collide: "
                    "the arm is not on the route, the test proves nothing")
print(("FAIL " if problems else "ok   ") + "unmapped: " + ("; ".join(problems) if problems else
      f"mapping on: arm seen {a_on['first_seen_s']:.2f} s (UAV {a_on['first_seen_uav']}), avoided {a_on['avoided_s']:.2f} s, "
      f"arm min {a_on['min_distance_m']:.2f} m, min obstacle {on['min_obstacle_distance_m']:.2f} m, 0 collisions, coverage "
      f"{on['site_mapping']['coverage']:.2f}; mapping off: arm min {a_off['min_distance_m']:.2f} m, collisions {off['collisions']}"))
sys.exit(1 if problems else 0)
PY
