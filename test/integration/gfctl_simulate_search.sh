#!/usr/bin/env bash
# The leader's camera search for a lost worker (docs/safety.md §2.2): power-tower mission, seed 1,
# the leader's camera blind 8–20 s while the worker starts up the west tower (2.3 → 6.5 m). The
# leader holds from ~11 s in mode `search` (sweeping its camera up from the last estimate), the
# followers hold; when the camera works again the leader finds the climbing worker and all three
# track again within 2 s — without the search (search_timeout_s 0) nobody sees him again (he has
# climbed out of the held camera's view), which this test also checks. Γ_dis, no collision.
# Usage: gfctl_simulate_search.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
printf 'faults:\n  camera_blackouts: [[8, 20]]\n' > "$TMP/search.yaml"
printf 'faults:\n  camera_blackouts: [[8, 20]]\n  search_timeout_s: 0\n' > "$TMP/nosearch.yaml"
for f in search nosearch; do
  "$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --faults "$TMP/$f.yaml" --out "$TMP/$f" \
    --seed 1 --duration 32 --no-plot > "$TMP/$f.log" 2>&1 || { echo "FAIL $f: gfctl exited $?"; cat "$TMP/$f.log"; exit 1; }
done
python3 - "$TMP" <<'PY'
import csv, json, sys
d = sys.argv[1]
problems = []
def modes(run):
    return [(float(r["t"]), r["uav"], r["mode"], r["reason"]) for r in csv.DictReader(open(f"{d}/{run}/modes.csv"))]
s, n = modes("search"), modes("nosearch")
m = json.load(open(f"{d}/search/metrics.json"))
lead = [x for x in s if x[1] == "L"]
if not any(x[2] == "search" and 10.9 <= x[0] <= 11.5 and x[3] == "worker not seen for more than max_worker_age_s" for x in lead):
    problems.append(f"the leader did not search from ~11 s: {lead}")
if any(x[2] == "hold" for x in lead): problems.append(f"the leader held instead of searching: {lead}")
for u in ("L", "1", "2"):
    back = [x for x in s if x[1] == u and x[2] == "track" and x[0] > 11]
    if not back or not 20.0 <= back[0][0] <= 22.0: problems.append(f"UAV {u} did not track again at 20-22 s: {back[:1]}")
    if u != "L" and not any(x[1] == u and x[2] == "hold" for x in s): problems.append(f"follower {u} did not hold")
if any(x[2] == "track" and x[0] > 11 for x in n): problems.append(f"without the search the worker was found again: {n}")
if not any(x[1] == "L" and x[2] == "hold" for x in n): problems.append("search_timeout_s 0: the leader did not hold")
if m["min_mutual_distance_m"] < 2.5: problems.append(f"min mutual {m['min_mutual_distance_m']:.2f} < 2.5")
if m["collisions"] != 0: problems.append(f"collisions {m['collisions']}")
print(("FAIL " if problems else "ok   ") + "search: " + ("; ".join(problems) if problems else
      "leader searched from " + str([x[0] for x in lead if x[2] == "search"]) + ", all track again at " +
      str([[x[0] for x in s if x[1] == u and x[2] == "track" and x[0] > 11][0] for u in ("L", "1", "2")])))
sys.exit(1 if problems else 0)
PY
