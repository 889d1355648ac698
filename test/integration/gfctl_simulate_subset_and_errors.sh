#!/usr/bin/env bash
# 1. An operator request for a subset of UAVs changes only theirs: open field, one request
#    "[2].distance_m +2" at t = 10 s; follower 2's reference goes 8 → 10 m and its actual
#    distance follows, the leader's and follower 1's references never change.
# 2. A bad mission section is refused (exit 2) with every problem named (field and value).
# 3. --threads (the camera views classified concurrently) changes nothing: the run of 1. with
#    --threads 1 and --threads 3 writes byte-identical timeline, events and modes; a bad
#    --threads value is refused (exit 2) naming it.
# Usage: gfctl_simulate_subset_and_errors.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
# Keep the world and the mission, replace the requests.
sed '/^  requests:/,$d' "$SRC/config/scenarios/open_field.yaml" > "$TMP/subset.yaml"
cat >> "$TMP/subset.yaml" <<'Y'
  requests:
    - {t_s: 10, target: [2], parameter: distance_m, increment: 2}
Y
"$GFCTL" simulate --scenario "$TMP/subset.yaml" --out "$TMP/out" --seed 2 --duration 20 --no-plot \
  --model "$SRC/third_party_models/gesture_lstm/gesture_lstm.onnx" --threads 3 > /dev/null
python3 - "$TMP/out/timeline.csv" "$TMP/out/events.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
f = lambda r, k: float(r[k])
bad = []
for lab, want in (("L", 10.0), ("1", 8.0)):
    vals = {f(r, f"{lab}_d_ref") for r in rows}
    if vals != {want}:
        bad.append(f"{lab}_d_ref changed: {sorted(vals)}")
before = {f(r, "2_d_ref") for r in rows if f(r, "t") < 10.0}
after = {f(r, "2_d_ref") for r in rows if f(r, "t") > 10.5}
if before != {8.0} or after != {10.0}:
    bad.append(f"2_d_ref before {sorted(before)} after {sorted(after)} (want 8 then 10)")
end = rows[-1]
if abs(f(end, "2_d_t") - 10.0) > 1.0:
    bad.append(f"follower 2 distance at the end {f(end, '2_d_t'):.2f}, want 10 +- 1")
ev = [e for e in csv.DictReader(open(sys.argv[2])) if e["source"] == "operator"]
if len(ev) != 1 or ev[0]["status"] != "applied" or ev[0]["uavs"] != "2":
    bad.append(f"events: {ev}")
if bad:
    sys.exit("FAIL " + "; ".join(bad))
print("ok: only follower 2's distance changed")
PY
# Bad mission: a plant key missing, a negative mass, an unknown target, an unknown key.
sed -e 's/mass_kg: 3.2, //' -e 's/mass_kg: 1.5/mass_kg: -1.5/' -e '/^  requests:/,$d' \
  "$SRC/config/scenarios/open_field.yaml" > "$TMP/bad.yaml"
cat >> "$TMP/bad.yaml" <<'Y'
  requests:
    - {t_s: 10, target: follower7, parameter: distance_m, increment: 2}
  bogus_key: 1
Y
set +e
"$GFCTL" simulate --scenario "$TMP/bad.yaml" --out "$TMP/bad" --no-plot > "$TMP/bad.log" 2>&1
rc=$?
set -e
[ $rc -eq 2 ] || { echo "FAIL bad mission: exit $rc, want 2"; cat "$TMP/bad.log"; exit 1; }
for want in "mission.uavs\[0\].plant.mass_kg: missing" "mission.uavs\[1\].plant.mass_kg: value -1.5" \
            "follower7" "mission.bogus_key: unknown key"; do
  grep -q "$want" "$TMP/bad.log" || { echo "FAIL bad mission: no message matching '$want'"; cat "$TMP/bad.log"; exit 1; }
done
echo "ok: bad mission refused with every problem named"
# 3. Threads change nothing (the classifications reach the timeline's gesture columns).
"$GFCTL" simulate --scenario "$TMP/subset.yaml" --out "$TMP/out1" --seed 2 --duration 20 --no-plot \
  --model "$SRC/third_party_models/gesture_lstm/gesture_lstm.onnx" --threads 1 > /dev/null
for f in timeline.csv events.csv modes.csv; do
  cmp -s "$TMP/out/$f" "$TMP/out1/$f" || { echo "FAIL --threads 3 vs 1: $f differs"; diff "$TMP/out/$f" "$TMP/out1/$f" | head; exit 1; }
done
set +e
"$GFCTL" simulate --scenario "$TMP/subset.yaml" --out "$TMP/bad_threads" --no-plot --threads 0 > "$TMP/threads.log" 2>&1
rc=$?
set -e
[ $rc -eq 2 ] && grep -q "\-\-threads: expected an integer 1..16, got '0'" "$TMP/threads.log" ||
  { echo "FAIL --threads 0: exit $rc"; cat "$TMP/threads.log"; exit 1; }
echo "ok: --threads 1 and 3 give identical files; --threads 0 refused"
