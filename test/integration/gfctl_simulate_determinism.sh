#!/usr/bin/env bash
# gfctl simulate is deterministic for a seed: the same seed gives identical metrics.json
# (except the wall-clock keys it lists in wall_clock_keys), timeline.csv, events.csv, modes.csv and
# plans.csv (but for its planning_ms column); another seed gives a different timeline. Usage: gfctl_simulate_determinism.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
S="$SRC/config/scenarios/power_towers.yaml"
"$GFCTL" simulate --scenario "$S" --out "$TMP/a" --seed 5 --duration 40 --no-plot > /dev/null
"$GFCTL" simulate --scenario "$S" --out "$TMP/b" --seed 5 --duration 40 --no-plot > /dev/null
"$GFCTL" simulate --scenario "$S" --out "$TMP/c" --seed 6 --duration 40 --no-plot > /dev/null
python3 - "$TMP" <<'PY'
import json, sys
d = sys.argv[1]
a, b = json.load(open(f"{d}/a/metrics.json")), json.load(open(f"{d}/b/metrics.json"))
wall = set(a["wall_clock_keys"]) | {"wall_clock_keys"}
diff = [k for k in a if k not in wall and a[k] != b.get(k)]
if diff:
    sys.exit("FAIL same seed, different metrics: " + ", ".join(f"{k}: {a[k]} vs {b.get(k)}" for k in diff))
if set(a) != set(b):
    sys.exit("FAIL metric keys differ")
PY
cmp -s "$TMP/a/timeline.csv" "$TMP/b/timeline.csv" || { echo "FAIL same seed, different timeline.csv"; exit 1; }
cmp -s "$TMP/a/events.csv" "$TMP/b/events.csv" || { echo "FAIL same seed, different events.csv"; exit 1; }
cmp -s "$TMP/a/modes.csv" "$TMP/b/modes.csv" || { echo "FAIL same seed, different modes.csv"; exit 1; }
# plans.csv: every replanning; identical but for its wall-clock column planning_ms.
python3 - "$TMP" <<'PY'
import csv, sys
d = sys.argv[1]
rows = {r: [{k: v for k, v in x.items() if k != "planning_ms"} for x in csv.DictReader(open(f"{d}/{r}/plans.csv"))]
        for r in "ab"}
if not rows["a"] or rows["a"] != rows["b"]:
    sys.exit(f"FAIL same seed, different plans.csv ({len(rows['a'])} vs {len(rows['b'])} rows)")
statuses = {x["status"] for x in rows["a"]}
if "optimized" not in statuses or any(x["uav"] not in ("L", "1", "2") for x in rows["a"]):
    sys.exit(f"FAIL plans.csv: statuses {statuses}, uavs {set(x['uav'] for x in rows['a'])}")
if any(x["status"] != "optimized" and not x["reason"] for x in rows["a"]):
    sys.exit("FAIL plans.csv: a failed replanning without its reason")
PY
if cmp -s "$TMP/a/timeline.csv" "$TMP/c/timeline.csv"; then echo "FAIL seeds 5 and 6 give the same timeline"; exit 1; fi
echo "ok: seed 5 twice identical, seed 6 differs"
