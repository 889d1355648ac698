#!/bin/bash
# gfctl formation-ref against the independent Python implementation
# (tools/reference/formation_ref_reference.py) to 1e-9 absolute (gfctl
# prints 15 significant digits; headings modulo 2π and checked wrapped to (−π, π]) on a
# random worker trajectory (fixed seed) with headings far outside (−π, π], under the
# shipped config/formation.yaml, 3 and 5 followers, other parameter values and a config
# with only some keys; plus: a config outside the limits is an error (exit 2), not clamped.
set -euo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
PY=/usr/bin/python3
REF=$SRC/tools/reference/formation_ref_reference.py

$PY - "$OUT/walk.csv" <<'PYEOF'
import math, random, sys
rng = random.Random(42)
x = y = 0.0
z = 12.0
with open(sys.argv[1], "w") as f:
    f.write("t,hx,hy,hz,h_heading\n")
    for k in range(500):
        t = 0.2 * k
        x += rng.gauss(0, 0.3); y += rng.gauss(0, 0.3); z += rng.gauss(0, 0.1)
        # headings: mostly in (−π, π], some far outside, some exactly ±π and 0
        h = rng.choice([rng.uniform(-math.pi, math.pi), rng.uniform(-20, 20), math.pi, -math.pi, 0.0])
        f.write(f"{t!r},{x!r},{y!r},{z!r},{h!r}\n")
PYEOF

cat > "$OUT/three.yaml" <<'YAML'
leader: {beta_deg: -45, gamma_deg: 25, distance_m: 14}
followers:
  - {beta_deg: 120, gamma_deg: -10, distance_m: 9}
  - {beta_deg: -120, gamma_deg: 15, distance_m: 6.5}
  - {beta_deg: 180, gamma_deg: 0, distance_m: 20}
YAML
cat > "$OUT/five.yaml" <<'YAML'
leader: {beta_deg: 180, gamma_deg: -5, distance_m: 7}
followers:
  - {beta_deg: 72, gamma_deg: 10, distance_m: 9}
  - {beta_deg: 144, gamma_deg: 40, distance_m: 9}
  - {beta_deg: -144, gamma_deg: 5, distance_m: 10}
  - {beta_deg: -72, gamma_deg: -20, distance_m: 11}
  - {beta_deg: 0.5, gamma_deg: 0, distance_m: 24}
limits: {gamma_min_deg: -25, gamma_max_deg: 45, distance_min_m: 5, distance_max_m: 30, safety_distance_m: 3}
YAML
cat > "$OUT/partial.yaml" <<'YAML'
leader: {gamma_deg: 30}
followers:
  - {distance_m: 12}
YAML

fails=0
run() {  # name config
  "$GFCTL" formation-ref --config "$2" --in "$OUT/walk.csv" --out "$OUT/$1_gfctl.csv" > "$OUT/$1.log" 2>&1 \
    || { echo "gfctl failed on $1"; cat "$OUT/$1.log"; exit 1; }
  $PY "$REF" --config "$2" --in "$OUT/walk.csv" --out "$OUT/$1_ref.csv"
  if $PY "$REF" --compare "$OUT/$1_gfctl.csv" "$OUT/$1_ref.csv" --tol 1e-9 > "$OUT/$1.cmp"; then
    echo "ok: $1: $(cat "$OUT/$1.log"); $(tail -1 "$OUT/$1.cmp")"
  else
    echo "FAIL: $1:"; cat "$OUT/$1.cmp"; fails=$((fails + 1))
  fi
}
run default "$SRC/config/formation.yaml"
run three "$OUT/three.yaml"
run five "$OUT/five.yaml"
run partial "$OUT/partial.yaml"
[ "$(grep -c ',5,' "$OUT/five_gfctl.csv")" = 500 ] || { echo "FAIL: five followers expected"; fails=$((fails + 1)); }

# Out of the limits: an error naming every problem, never silently clamped.
cat > "$OUT/bad.yaml" <<'YAML'
leader: {gamma_deg: 55, distance_m: 2}
followers:
  - {beta_deg: 60, gamma_deg: 10, distance_m: 8}
  - {gamma_deg: 0, distance_m: 30}
limits: {gamma_max_deg: 60}
YAML
if "$GFCTL" formation-ref --config "$OUT/bad.yaml" --in "$OUT/walk.csv" --out "$OUT/bad.csv" 2> "$OUT/bad.err"; then
  echo "FAIL: out-of-limit config accepted"; fails=$((fails + 1))
else
  code=$?
  for want in "leader.distance_m" "followers[0].gamma_deg" "followers[1].distance_m"; do
    grep -qF "$want" "$OUT/bad.err" || { echo "FAIL: '$want' not reported:"; cat "$OUT/bad.err"; fails=$((fails + 1)); }
  done
  [ "$code" = 2 ] || { echo "FAIL: exit $code, want 2"; fails=$((fails + 1)); }
  echo "ok: out-of-limit config rejected (exit $code): $(tr '\n' ' ' < "$OUT/bad.err")"
fi
# Bad input rows: exit 2 naming file, line and field.
printf 't,hx,hy,hz,h_heading\n0,1,2,3,0\n1,1,nan,3,0\n' > "$OUT/nan.csv"
if "$GFCTL" formation-ref --config "$SRC/config/formation.yaml" --in "$OUT/nan.csv" --out "$OUT/o.csv" 2> "$OUT/nan.err"; then
  echo "FAIL: nan row accepted"; fails=$((fails + 1))
else
  grep -qF "nan.csv:3: field 'hy'" "$OUT/nan.err" || { echo "FAIL: nan row message:"; cat "$OUT/nan.err"; fails=$((fails + 1)); }
  echo "ok: nan row rejected: $(cat "$OUT/nan.err")"
fi
exit $fails
