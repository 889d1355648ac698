#!/bin/bash
# gfctl gesture-filter against the independent Python implementation
# (tools/reference/gesture_filter_reference.py): identical fired rows on generated gesture
# streams (fixed seeds) — bursty, noisy, with ties, sparse gaps beyond max_age_s, rows at
# the exact age and cooldown boundaries, invalid rows — under several configurations
# (the shipped config/gestures.yaml, small windows with min_measurements < K, distance and
# event mappings on 3 and 5 followers with limits that clamp).
set -euo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
PY=/usr/bin/python3

$PY - "$OUT" <<'PYEOF'
import random, sys
out = sys.argv[1]

def write(name, rows):
    with open(f"{out}/{name}.csv", "w") as f:
        f.write("t,gesture_id\n")
        for t, g in rows:
            f.write(f"{t},{g}\n")

def bursty(seed, n_blocks, rate_hz=10.0, purity=(0.6, 1.0), ids=(0, 1, 2, 3, 4)):
    rng = random.Random(seed)
    rows, t = [], 0.0
    for _ in range(n_blocks):
        g = rng.choice(ids)
        p = rng.uniform(*purity)
        for _ in range(rng.randint(3, 60)):
            t = round(t + rng.choice([1.0 / rate_hz, 1.0 / rate_hz, 0.0, 0.5 / rate_hz]), 6)  # bursts: equal times
            rows.append((t, g if rng.random() < p else rng.choice(ids)))
        if rng.random() < 0.3:
            t = round(t + rng.uniform(0.5, 30.0), 6)  # pauses, some longer than max_age_s
    return rows

write("bursty", bursty(1, 120))
write("noisy", bursty(2, 200, purity=(0.4, 0.95)))
# Ties: two gestures alternating exactly, then a clean run, then ties with 'none'.
ties = [(round(0.1 * k, 6), 1 + k % 2) for k in range(60)]
ties += [(round(6.0 + 0.1 * k, 6), 3) for k in range(40)]
ties += [(round(10.0 + 0.1 * k, 6), (0, 4)[k % 2]) for k in range(60)]
write("ties", ties)
# Sparse: one measurement every 1.5 s, so max_age_s bounds the window; exact boundaries
# (times are multiples of 0.25, exactly representable) hit t_i == t - t_c and t - t_last == t_d.
write("sparse", [(1.5 * k, 2 if (k // 25) % 2 == 0 else 4) for k in range(200)])
write("boundary", [(0.25 * k, 1) for k in range(400)])
# Invalid rows: out of order, unknown ids, non-integer id, nan time.
rng = random.Random(7)
rows = bursty(3, 40)
bad = []
for i, (t, g) in enumerate(rows):
    bad.append((t, g))
    r = rng.random()
    if r < 0.02:
        bad.append((round(t - 1.0, 6), 1))
    elif r < 0.04:
        bad.append((t, 7))
    elif r < 0.05:
        bad.append((t, 1.5))
    elif r < 0.06:
        bad.append(("nan", 2))
    elif r < 0.07:
        bad.append((t, -1))
write("invalid", bad)
PYEOF

cat > "$OUT/small.yaml" <<'YAML'
window_size: 10
min_measurements: 5
max_age_s: 3.0
ratio_threshold: 0.6
cooldown_s: 2.0
rearm: repeat
YAML
cat > "$OUT/distance5.yaml" <<'YAML'
window_size: 12
min_measurements: 8
max_age_s: 6.0
ratio_threshold: 0.7
cooldown_s: 1.5
leader: {beta_deg: 0, gamma_deg: 20, distance_m: 12}
followers:
  - {beta_deg: 72, gamma_deg: 10, distance_m: 9}
  - {beta_deg: 144, gamma_deg: -10, distance_m: 9}
  - {beta_deg: -144, gamma_deg: 5, distance_m: 10}
  - {beta_deg: -72, gamma_deg: 0, distance_m: 11}
limits: {gamma_min_deg: -10, gamma_max_deg: 45, distance_min_m: 6, distance_max_m: 14, safety_distance_m: 3}
mapping:
  1: {parameter: all.distance_m, increment: 1.5}
  2: {parameter: followers.distance_m, increment: -2}
  3: {parameter: leader.gamma_deg, increment: 7.5}
  4: {parameter: follower3.gamma_deg, increment: -6}
YAML
cat > "$OUT/events3.yaml" <<'YAML'
window_size: 15
max_age_s: 10.0
ratio_threshold: 0.5
cooldown_s: 0.0
followers:
  # follower 1 sweeps all round (beta +45 per command) at its own distance: at 8 m like the
  # others it was put on follower 2's point, a command the formation now refuses (formation.md 4)
  - {beta_deg: 90, gamma_deg: 0, distance_m: 15}
  - {beta_deg: 180, gamma_deg: 0, distance_m: 8}
  - {beta_deg: -90, gamma_deg: 5, distance_m: 8}
mapping:
  1: {parameter: follower1.beta_deg, increment: 45}
  2: {event: assist_requested}
  3: {parameter: leader.gamma_deg, increment: -20}
  4: {event: abort}
YAML
# The same sweep at 8 m: follower 1 reaches follower 2's point (beta 180, 8 m) — refused by the
# formation (docs/formation.md §4: two slots closer than safety_distance_m), a row with value nan,
# nothing changed, and the sweep goes on from where it stood.
sed 's/{beta_deg: 90, gamma_deg: 0, distance_m: 15}/{beta_deg: 90, gamma_deg: 0, distance_m: 8}/' "$OUT/events3.yaml" > "$OUT/slots8.yaml"
cat > "$OUT/boundary.yaml" <<'YAML'
window_size: 8
min_measurements: 4
max_age_s: 1.0
ratio_threshold: 0.75
cooldown_s: 2.5
rearm: repeat
YAML
# The same held gesture with the default re-arming (release): one performance, one command.
cat > "$OUT/boundary_release.yaml" <<'YAML'
window_size: 8
min_measurements: 4
max_age_s: 1.0
ratio_threshold: 0.75
cooldown_s: 2.5
release_s: 0.5
YAML
# Sparse at 1.5 s: with max_age_s 6 the window holds exactly 5 entries only because an
# entry exactly t_c old is kept (t_i >= t - t_c); min_measurements 5 makes that decisive.
cat > "$OUT/sparse.yaml" <<'YAML'
window_size: 10
min_measurements: 5
max_age_s: 6.0
ratio_threshold: 0.75
cooldown_s: 3.0
rearm: repeat
YAML

fails=0
run() {  # name config input
  "$GFCTL" gesture-filter --config "$2" --in "$OUT/$3.csv" --out "$OUT/$1_gfctl.csv" > "$OUT/$1.log" 2> "$OUT/$1.err" \
    || { echo "gfctl failed on $1"; cat "$OUT/$1.err"; exit 1; }
  $PY "$SRC/tools/reference/gesture_filter_reference.py" --config "$2" --in "$OUT/$3.csv" --out "$OUT/$1_ref.csv"
  local n
  n=$(($(wc -l < "$OUT/$1_ref.csv") - 1))
  if diff "$OUT/$1_gfctl.csv" "$OUT/$1_ref.csv" > "$OUT/$1.diff"; then
    echo "ok: $1: $n identical fired rows; $(cat "$OUT/$1.log")"
  else
    echo "FAIL: $1: fired rows differ (gfctl < > reference):"; head -20 "$OUT/$1.diff"; fails=$((fails + 1))
  fi
  echo "$n" > "$OUT/$1.count"
}
run default_bursty "$SRC/config/gestures.yaml" bursty
run default_noisy "$SRC/config/gestures.yaml" noisy
run default_ties "$SRC/config/gestures.yaml" ties
run default_sparse "$SRC/config/gestures.yaml" sparse
run small_bursty "$OUT/small.yaml" bursty
run small_ties "$OUT/small.yaml" ties
run small_sparse "$OUT/small.yaml" sparse
run sparse_age_boundary "$OUT/sparse.yaml" sparse
run distance5_noisy "$OUT/distance5.yaml" noisy
run distance5_bursty "$OUT/distance5.yaml" bursty
run events3_noisy "$OUT/events3.yaml" noisy
run boundary_exact "$OUT/boundary.yaml" boundary
run boundary_release "$OUT/boundary_release.yaml" boundary
run events3_bursty "$OUT/events3.yaml" bursty
run slots8_noisy "$OUT/slots8.yaml" noisy
run slots8_bursty "$OUT/slots8.yaml" bursty
run default_invalid "$SRC/config/gestures.yaml" invalid
run small_invalid "$OUT/small.yaml" invalid

# The scenarios must exercise what they claim.
[ "$(cat "$OUT/default_bursty.count")" -ge 3 ] || { echo "FAIL: bursty stream fired too little"; fails=$((fails + 1)); }
grep -q "values clamped" "$OUT/distance5_noisy.log" && ! grep -q " 0 values clamped" "$OUT/distance5_noisy.log" \
  || { echo "FAIL: distance5 never clamped"; fails=$((fails + 1)); }
[ "$(cat "$OUT/sparse_age_boundary.count")" -ge 3 ] || { echo "FAIL: sparse stream at the age boundary never fired"; fails=$((fails + 1)); }
grep -q "abort\|assist_requested" "$OUT/events3_noisy_gfctl.csv" || { echo "FAIL: no event fired"; fails=$((fails + 1)); }
grep -q "^[^,]*,1,follower1.beta_deg,45,nan$" "$OUT/slots8_noisy_gfctl.csv" "$OUT/slots8_bursty_gfctl.csv" \
  && grep -q "command refused: .*safety_distance_m" "$OUT/slots8_noisy.err" "$OUT/slots8_bursty.err" \
  || { echo "FAIL: slots8: no command refused by the slot rule"; fails=$((fails + 1)); }
grep -q "measurement rejected: out of order" "$OUT/default_invalid.err" || { echo "FAIL: no out-of-order row"; fails=$((fails + 1)); }
grep -q "measurement rejected: unknown gesture id" "$OUT/default_invalid.err" || { echo "FAIL: no unknown id"; fails=$((fails + 1)); }
# boundary: 4 Hz of gesture 1, t_d = 2.5 s exactly representable → commands exactly 2.5 s apart.
$PY - "$OUT/boundary_exact_gfctl.csv" <<'PYEOF' || fails=$((fails + 1))
import csv, sys
t = [float(r["t"]) for r in csv.DictReader(open(sys.argv[1]))]
gaps = {b - a for a, b in zip(t, t[1:])}
if t[0] != 0.75 or gaps != {2.5}:
    print(f"FAIL: boundary: first command at {t[0]} (want 0.75: 4th row), gaps {gaps} (want exactly 2.5)")
    sys.exit(1)
print(f"ok: boundary: first command at 0.75 s, then every 2.5 s ({len(t)} commands)")
PYEOF
[ "$(cat "$OUT/boundary_release.count")" -eq 1 ] \
  || { echo "FAIL: a held gesture fired $(cat "$OUT/boundary_release.count") times with rearm: release (want 1)"; fails=$((fails + 1)); }
[ "$(cat "$OUT/default_bursty.count")" -lt "$(cat "$OUT/small_bursty.count")" ] \
  || echo "note: release fired no less than repeat on the bursty stream"
exit $fails
