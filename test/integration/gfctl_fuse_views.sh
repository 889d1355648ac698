#!/usr/bin/env bash
# gfctl fuse-views (gesture::ViewFusion, docs/gestures.md §6): the 2-of-3 vote over three
# cameras' classifications, the envelope gate, the single-camera configuration, and bad input
# (exit 2 naming file, line and field).  Usage: gfctl_fuse_views.sh GFCTL SOURCE_DIR
set -euo pipefail
GFCTL=$1
SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# Leader sees "extend arm" (2) all along; follower 1 agrees from t = 0.1 (in its 1 s vote window:
# half its frames at t = 0.1, two thirds at 0.2: it votes, view_fusion.vote_min_fraction 0.5);
# follower 2 sees none, and at t = 0.3 "raise arm" (4) in one frame of four (no vote).
cat > "$T/g0.csv" <<CSV
t,gesture_id,p0,p1,p2,p3,p4,distance_m,elevation_deg
0.0,2,0,0,1,0,0,10,20
0.1,2,0,0,1,0,0,10,20
0.2,2,0,0,1,0,0,10,20
0.3,2,0,0,1,0,0,10,20
CSV
cat > "$T/g1.csv" <<CSV
t,gesture_id,distance_m,elevation_deg
0.0,0,8,20
0.1,2,8,20
0.2,2,8,20
0.3,2,30,20
CSV
cat > "$T/g2.csv" <<CSV
t,gesture_id,distance_m,elevation_deg
0.0,0,8,20
0.1,0,8,20
0.2,0,8,20
0.3,4,8,20
CSV
"$GFCTL" fuse-views --in "$T/g0.csv,$T/g1.csv,$T/g2.csv" --out "$T/f.csv" --config "$SRC/config/gestures.yaml" > /dev/null
got=$(cut -d, -f2 "$T/f.csv" | tail -n +2 | tr '\n' ' ')
# t=0.3: follower 1 is 30 m away (outside the envelope): only the leader votes 2 → 0.
[ "$got" = "0 2 2 0 " ] || fail "fused ids '$got', expected '0 2 2 0 '"
[ "$(sed -n 5p "$T/f.csv")" = "0.3,0,2,1" ] || fail "t=0.3 row: $(sed -n 5p "$T/f.csv") (expected 2 voting views, 1 agreeing)"

# Single camera (the paper): the leader's ids pass unchanged.
sed 's/min_agreeing_views: 2/min_agreeing_views: 1/' "$SRC/config/gestures.yaml" > "$T/single.yaml"
"$GFCTL" fuse-views --in "$T/g0.csv" --out "$T/s.csv" --config "$T/single.yaml" > /dev/null
[ "$(cut -d, -f2 "$T/s.csv" | tail -n +2 | tr '\n' ' ')" = "2 2 2 2 " ] || fail "single view: $(cat "$T/s.csv")"

# Without geometry columns a view is of unknown geometry: it votes only without the gate.
printf 't,gesture_id\n0.0,2\n' > "$T/n0.csv"
printf 't,gesture_id\n0.0,2\n' > "$T/n1.csv"
"$GFCTL" fuse-views --in "$T/n0.csv,$T/n1.csv" --out "$T/n.csv" --config "$SRC/config/gestures.yaml" > /dev/null
[ "$(sed -n 2p "$T/n.csv")" = "0,0,0,0" ] || fail "unknown geometry voted: $(sed -n 2p "$T/n.csv")"
sed 's/gate_envelope: true/gate_envelope: false/' "$SRC/config/gestures.yaml" > "$T/open.yaml"
"$GFCTL" fuse-views --in "$T/n0.csv,$T/n1.csv" --out "$T/n.csv" --config "$T/open.yaml" > /dev/null
[ "$(sed -n 2p "$T/n.csv")" = "0,2,2,2" ] || fail "no gate: $(sed -n 2p "$T/n.csv")"

# Bad input: exit 2, the message names the file, line and field.
expect_error() {  # expect_error PATTERN ARGS...
  local pattern=$1; shift
  set +e
  "$GFCTL" fuse-views "$@" > /dev/null 2> "$T/err"
  local rc=$?
  set -e
  [ $rc -eq 2 ] || fail "exit $rc (expected 2) for $*"
  grep -q -- "$pattern" "$T/err" || fail "message '$(cat "$T/err")' lacks '$pattern'"
}
printf 't,gesture_id\n0.0,2\n0.1,9\n' > "$T/bad_id.csv"
expect_error "bad_id.csv:3.*gesture_id" --in "$T/bad_id.csv" --out "$T/x.csv"
printf 't,gesture_id\n0.2,2\n0.1,2\n' > "$T/bad_order.csv"
expect_error "time order" --in "$T/bad_order.csv" --out "$T/x.csv"
printf 't,label\n0.0,2\n' > "$T/bad_cols.csv"
expect_error "gesture_id" --in "$T/g0.csv,$T/bad_cols.csv" --out "$T/x.csv"
printf 'view_fusion: {min_agreeing_views: 0, elevation_max_deg: -10}\n' > "$T/bad.yaml"
expect_error "view_fusion.min_agreeing_views" --in "$T/g0.csv" --out "$T/x.csv" --config "$T/bad.yaml"
grep -q "view_fusion.elevation_max_deg" "$T/err" || fail "config report lists only the first problem: $(cat "$T/err")"
echo "gfctl fuse-views: vote, envelope gate, single camera and bad input OK"
