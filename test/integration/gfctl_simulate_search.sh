#!/usr/bin/env bash
# The leader's camera search for a lost worker (docs/safety.md §2.2): power-tower mission, seed 1,
# the leader's camera blind 8–25 s while the worker climbs the west tower. The leader holds from
# ~11 s (max_worker_age_s 3 s; its camera on the estimator's prediction), and searches from ~13 s,
# once the estimator has lost him (lost_timeout_s 5 s), sweeping its camera up and down through the
# estimate; the followers hold; after the camera works again the leader finds the climbing worker
# and all three track again within 8 s — without the search (search_timeout_s 0) nobody sees him
# again (he has climbed out of the held camera's view), which this test also checks. Γ_dis, no
# collision.
# Usage: gfctl_simulate_search.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
printf 'faults:\n  camera_blackouts: [[8, 25]]\n' > "$TMP/search.yaml"
printf 'faults:\n  camera_blackouts: [[8, 25]]\n  search_timeout_s: 0\n' > "$TMP/nosearch.yaml"
for f in search nosearch; do
  "$GFCTL" simulate --scenario "$SRC/config/scenarios/power_towers.yaml" --faults "$TMP/$f.yaml" --out "$TMP/$f" \
    --seed 1 --duration 45 --no-plot > "$TMP/$f.log" 2>&1 || { echo "FAIL $f: gfctl exited $?"; cat "$TMP/$f.log"; exit 1; }
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
why = "worker not seen for more than max_worker_age_s"
if not any(x[2] == "hold" and 10.9 <= x[0] <= 11.5 and x[3] == why for x in lead):
    problems.append(f"the leader did not hold from ~11 s: {lead}")
if not any(x[2] == "search" and 13.0 <= x[0] <= 13.5 and x[3] == why for x in lead):
    problems.append(f"the leader did not search from ~13 s (the estimator lost him at 13 s): {lead}")
for u in ("L", "1", "2"):
    back = [x for x in s if x[1] == u and x[2] == "track" and x[0] > 11]
    if not back or not 25.0 <= back[0][0] <= 33.0: problems.append(f"UAV {u} did not track again at 25-33 s: {back[:1]}")
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
