#!/usr/bin/env bash
# The main job (README): installs what is missing, builds gfctl and replays the worker
# position estimator on the sample flight log shipped in test/data/flights/, then prints a
# summary against the ground truth and draws build/demo/estimate.png.
# (It grows into the simulated power-tower mission when that lands.)
set -eo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh > /dev/null
tools/build.sh gfctl > /dev/null
BUILD_DIR=${GF_BUILD_DIR:-build}
GFCTL=$BUILD_DIR/devel/lib/gesture_formation/gfctl
mkdir -p "$BUILD_DIR/demo"
echo "== gfctl estimate on test/data/flights/sample_flight.csv (75 s, 15 Hz, leader at Table II view)"
"$GFCTL" estimate --config config/estimator.yaml --in test/data/flights/sample_flight.csv \
  --out "$BUILD_DIR/demo/states.csv"
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || PY=/usr/bin/python3
"$PY" tools/summarize_estimate.py --states "$BUILD_DIR/demo/states.csv" \
  --truth test/data/flights/sample_flight_truth.csv --plot "$BUILD_DIR/demo/estimate.png"
echo "states: $BUILD_DIR/demo/states.csv   gfctl: $GFCTL"
