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

# Calibrated views (view_fusion.require_3d, docs/gestures.md 6): synth-gestures writes each view's camera
# pose (cam_* of sequences*.csv); joined to every frame's keypoints they give fuse-views the calibrated
# skeletons it triangulates. Every frame of work motions read as "palms together" (3) by all three
# views: the vote alone passes it, the 3-D check (design.md 2's geometry) refuses it; real palms
# together read as 3 pass.
calibrated_views() {  # calibrated_views DIR ID: DIR/c0.csv.. with every row read as ID (label rows: ID = label)
  python3 - "$1" "$2" <<'PY'
import csv, sys
d, gid = sys.argv[1], sys.argv[2]
for v, suffix in enumerate(["", "_view1", "_view2"]):
    seqs = {r["sequence"]: r for r in csv.DictReader(open(f"{d}/sequences{suffix}.csv"))}
    cam = [c for c in next(iter(seqs.values())) if c.startswith("cam_")]
    kp = [f"{p}{k}" for p in "xyc" for k in range(17)]
    with open(f"{d}/c{v}.csv", "w") as out:
        out.write(",".join(["t", "gesture_id", "distance_m", "elevation_deg"] + kp + cam) + "\n")
        for r in csv.DictReader(open(f"{d}/skeletons{suffix}.csv")):
            m = seqs[r["sequence"]]
            t = 100.0 * int(r["sequence"]) + float(r["t"])
            g = r["label"] if gid == "label" else gid
            out.write(",".join([repr(t), g, m["distance_m"], m["elevation_deg"]] + [r[k] for k in kp] + [m[c] for c in cam]) + "\n")
PY
}
printf 'gesture_fraction: 0.0\ndistance_min_m: 6\ndistance_max_m: 12\nelevation_max_deg: 30\n' > "$T/work.yaml"
"$GFCTL" synth-gestures --seed 3301 --count 6 --out "$T/w" --config "$T/work.yaml" --views 60,-60 > /dev/null
head -1 "$T/w/sequences_view1.csv" | grep -q "cam_qw" || fail "sequences_view1.csv has no camera pose: $(head -1 "$T/w/sequences_view1.csv")"
calibrated_views "$T/w" 3
sed 's/require_3d: true/require_3d: false/' "$SRC/config/gestures.yaml" > "$T/no3d.yaml"
"$GFCTL" fuse-views --in "$T/w/c0.csv,$T/w/c1.csv,$T/w/c2.csv" --out "$T/w/off.csv" --config "$T/no3d.yaml" > /dev/null
"$GFCTL" fuse-views --in "$T/w/c0.csv,$T/w/c1.csv,$T/w/c2.csv" --out "$T/w/on.csv" --config "$SRC/config/gestures.yaml" > /dev/null
head -1 "$T/w/on.csv" | grep -q "checked_3d,rejected_3d" || fail "no 3-D columns: $(head -1 "$T/w/on.csv")"
rows=$(tail -n +2 "$T/w/on.csv" | wc -l)
off=$(tail -n +2 "$T/w/off.csv" | awk -F, '$2 == 3' | wc -l)
on=$(tail -n +2 "$T/w/on.csv" | awk -F, '$2 == 3' | wc -l)
rejected=$(tail -n +2 "$T/w/on.csv" | awk -F, '$6 == 1' | wc -l)
[ "$off" -ge $((rows * 9 / 10)) ] || fail "without the 3-D check only $off of $rows work frames fused as 3"
[ "$on" -le $((rows / 50)) ] || fail "with the 3-D check $on of $rows work frames still fused as palms together"
[ "$rejected" -ge $((off * 9 / 10)) ] || fail "only $rejected of $off rejected_3d"
printf 'gesture_fraction: 1.0\ndistance_min_m: 6\ndistance_max_m: 12\nelevation_max_deg: 30\nhold_min_s: 3\nhold_max_s: 4\n' > "$T/g.yaml"
"$GFCTL" synth-gestures --seed 3302 --count 8 --out "$T/g" --config "$T/g.yaml" --views 60,-60 > /dev/null
calibrated_views "$T/g" label
"$GFCTL" fuse-views --in "$T/g/c0.csv,$T/g/c1.csv,$T/g/c2.csv" --out "$T/g/on.csv" --config "$SRC/config/gestures.yaml" > /dev/null
voted=$(tail -n +2 "$T/g/on.csv" | awk -F, '$4 >= 2' | wc -l)
kept=$(tail -n +2 "$T/g/on.csv" | awk -F, '$4 >= 2 && $2 != 0' | wc -l)
[ "$voted" -gt 100 ] && [ "$kept" -ge $((voted * 8 / 10)) ] || fail "gestures: $kept of $voted voted frames passed the 3-D check"
# A broken camera pose: exit 2 naming the field.
awk -F, -v OFS=, 'NR == 2 { for (i = 1; i <= NF; ++i) if (h[i] == "cam_qw") $i = 2 } NR == 1 { for (i = 1; i <= NF; ++i) h[i] = $i } 1' \
  "$T/w/c1.csv" > "$T/w/bad_q.csv"
expect_error "bad_q.csv:2.*cam_qw" --in "$T/w/c0.csv,$T/w/bad_q.csv" --out "$T/x.csv" --config "$SRC/config/gestures.yaml"
echo "gfctl fuse-views: vote, envelope gate, single camera, bad input and the 3-D check OK"
