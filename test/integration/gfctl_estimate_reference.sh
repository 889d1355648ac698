#!/bin/bash
# gfctl estimate against the independent Python implementation (tools/reference/), to 1e-6,
# on the committed sample flights: the clean one with the shipped config, and the nasty one
# (outliers, late and duplicated rows, invalid rows, lens distortion) with its camera and a
# tighter gate so that re-initialisation happens.
set -euo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
PY=/usr/bin/python3
run() {  # name config input
  "$GFCTL" estimate --config "$2" --in "$3" --out "$OUT/$1_gfctl.csv" > "$OUT/$1.log" 2>&1 || { cat "$OUT/$1.log"; exit 1; }
  $PY "$SRC/tools/reference/estimate_reference.py" --config "$2" --in "$3" --out "$OUT/$1_ref.csv"
  echo "== $1: $(grep "rows," "$OUT/$1.log")"
  $PY "$SRC/tools/reference/compare_csv.py" "$OUT/$1_gfctl.csv" "$OUT/$1_ref.csv" --atol 1e-6
}
run clean "$SRC/config/estimator.yaml" "$SRC/test/data/flights/sample_flight.csv"
cp "$SRC/test/data/flights/nasty_flight_camera.yaml" "$OUT/nasty.yaml"
printf 'gate_chi2: 9.0\nmax_consecutive_rejections: 2\n' >> "$OUT/nasty.yaml"
run nasty "$OUT/nasty.yaml" "$SRC/test/data/flights/nasty_flight.csv"
# Apparent distances only from row 5 on (test/data/flights/apparent_limits.csv, the clean flight's
# first 12 rows): a box 11 px tall (~98 m, over max_apparent_distance_m) and boxes clipped at the top
# and bottom edges give no measurement, in both implementations.
run limits "$SRC/config/estimator.yaml" "$SRC/test/data/flights/apparent_limits.csv"
grep -q "over max_apparent_distance_m" "$OUT/limits.log" || { echo "FAIL: no apparent distance over the limit"; cat "$OUT/limits.log"; exit 1; }
[ "$(grep -c "touches the image's top or bottom edge" "$OUT/limits.log")" -eq 2 ] \
  || { echo "FAIL: not two clipped boxes refused"; cat "$OUT/limits.log"; exit 1; }
[ "$(grep -c ',none,0,' "$OUT/limits_ref.csv")" -eq 3 ] || { echo "FAIL: the reference did not refuse the three rows"; exit 1; }
# The nasty flight must actually exercise the robust paths.
grep -q "gated [1-9]" "$OUT/nasty.log" || { echo "nasty flight gated nothing"; cat "$OUT/nasty.log"; exit 1; }
grep -q "re-initialised [1-9]" "$OUT/nasty.log" || { echo "nasty flight never re-initialised"; cat "$OUT/nasty.log"; exit 1; }
grep -q "out-of-order [1-9]" "$OUT/nasty.log" || { echo "nasty flight had no out-of-order rows"; exit 1; }
grep -q "rejected rows [1-9]" "$OUT/nasty.log" || { echo "nasty flight rejected no rows"; exit 1; }
