#!/usr/bin/env bash
# gfctl simulate --camera rendered (docs/simulation.md §8): the closed loop on rendered images
# through the real perception pipeline, on test/data/sim/rendered_gestures.yaml (58 s: the worker
# 6-9 m from the leader performs the four near-misses of docs/design.md §2, then each gesture once;
# about 2.5 minutes with three cameras on 2 cores).
# Asserts: bad inputs exit 2 naming the option / the missing asset and how to get it; the safety
# figures (mutual >= 2.5 m, obstacle >= 0.5 m, human >= 2.5 m, no collision); the gestures that fire
# on pixels; the perception section against the truth; perception.csv; a short run's videos.
# Exit 77 (ctest: skipped) only when this machine has no EGL display / OpenGL 3.3 context.
# Usage: gfctl_simulate_rendered.sh GFCTL SRC
set -euo pipefail
GFCTL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
M=$SRC/test/data/sim/rendered_gestures.yaml

expect_bad() {  # expect_bad "needle" args...
  local needle=$1; shift
  set +e
  "$GFCTL" simulate "$@" >"$TMP/stdout" 2>"$TMP/stderr"
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || fail "exit $rc (expected 2) for: $*; stderr: $(cat "$TMP/stderr")"
  grep -q -- "$needle" "$TMP/stderr" || fail "stderr lacks '$needle' for: $*; got: $(cat "$TMP/stderr")"
}
expect_bad "\-\-camera: expected synthetic or rendered, got 'pixels'" --scenario "$M" --out "$TMP/x" --camera pixels
expect_bad "\-\-camera-video needs --camera rendered" --scenario "$M" --out "$TMP/x" --camera-video "$TMP/v"
expect_bad "\-\-camera-rate: expected frames/s in \[3, 15\]" --scenario "$M" --out "$TMP/x" --camera rendered --camera-rate 30
expect_bad "\-\-camera-rate: expected frames/s" --scenario "$M" --out "$TMP/x" --camera rendered --camera-rate fast

# A missing asset (or no EGL device) stops the command: never a fall-back to synthetic inputs.
set +e
"$GFCTL" simulate --scenario "$M" --out "$TMP/x" --camera rendered --models "$TMP/none" --no-plot >"$TMP/stdout" 2>"$TMP/stderr"
rc=$?
set -e
if [ "$rc" -eq 1 ] && grep -q "EGL\|OpenGL" "$TMP/stderr"; then echo "SKIP: no EGL here: $(cat "$TMP/stderr")"; exit 77; fi
[ "$rc" -eq 2 ] || fail "missing asset: exit $rc (expected 2): $(cat "$TMP/stderr")"
grep -q "wooden_mannequin.glb" "$TMP/stderr" && grep -q "convert_mannequin.py" "$TMP/stderr" \
  || fail "missing asset: the error names neither the file nor how to get it: $(cat "$TMP/stderr")"
[ ! -e "$TMP/x/metrics.json" ] || fail "missing asset: a mission was flown anyway"

# Videos: a 2 s run writes each UAV's annotated stream.
"$GFCTL" simulate --scenario "$M" --out "$TMP/short" --camera rendered --duration 2 --camera-video "$TMP/video" --no-plot \
  >"$TMP/short.log" 2>&1 || fail "short run exited $?: $(cat "$TMP/short.log")"
for f in uav0_leader uav1_follower1 uav2_follower2; do
  [ "$(stat -c %s "$TMP/video/$f.avi" 2>/dev/null || echo 0)" -gt 100000 ] || fail "video $f.avi missing or empty"
done

# The mission.
"$GFCTL" simulate --scenario "$M" --out "$TMP/run" --seed 1 --camera rendered --no-plot >"$TMP/run.log" 2>&1 \
  || fail "mission exited $?: $(cat "$TMP/run.log")"
cat "$TMP/run.log"
/usr/bin/python3 - "$TMP/run" <<'PY' || exit 1
import csv, json, sys
d = sys.argv[1]
m = json.load(open(d + "/metrics.json"))
events = list(csv.DictReader(open(d + "/events.csv")))
rows = list(csv.DictReader(open(d + "/perception.csv")))
problems = []
def need(ok, what):
    if not ok:
        problems.append(what)
need(m["collisions"] == 0, f"collisions {m['collisions']}")
need(m["min_mutual_distance_m"] >= 2.5, f"min_mutual_distance_m {m['min_mutual_distance_m']:.3f} < 2.5")
need(m["min_obstacle_distance_m"] >= 0.5, f"min_obstacle_distance_m {m['min_obstacle_distance_m']:.3f} < 0.5")
need(m["min_human_distance_m"] >= 2.5, f"min_human_distance_m {m['min_human_distance_m']:.3f} < 2.5")
need(m["gestures_performed"] == 4, f"gestures_performed {m['gestures_performed']} != 4")
# On pixels, through MoveNet, the LSTM, the 2-of-3 vote and the 3-D check of every voted gesture
# (view_fusion.require_3d, the default; issue 33): raise an arm (4) fires, matched in time. Crossed
# arms and palms together are read by too few views for the filter (the skeleton network's
# systematic errors on rendered figures); "extend an arm" (2) passes the 2-D vote but its
# triangulated arm is not abducted to the side in enough frames, so the 3-D check refuses it —
# the price of the check, which also refuses the near-miss that fired before it (seed 1: "extend"
# at 18.8 s while follower 1 read an arm partway/pointing as extended). Measured on seed 1 with
# the check: gesture 4 fired, 1, 2 and 3 missed, no false adaptation (without it: 2 and 4 fired,
# one false adaptation).
fired_ok = {e["gesture_id"] for e in events if e["source"] == "gesture" and e["status"] == "applied"
            and e["gesture_start_t"] not in ("", "nan")}
need("4" in fired_ok, f"gestures fired in time {sorted(fired_ok)}, expected 4 among them")
need(m["gestures_successful"] >= 1, f"gestures_successful {m['gestures_successful']} < 1")
# No near-miss fires a command on pixels.
need(m["false_adaptations"] == 0, f"false_adaptations {m['false_adaptations']} > 0")
p = m.get("perception")
need(p is not None, "metrics.json has no perception section")
if p:
    need(p["frames"] == len(rows) and p["frames"] > 2000, f"perception frames {p['frames']} vs perception.csv {len(rows)}")
    need(p["detection_rate"] >= 0.95, f"detection_rate {p['detection_rate']} < 0.95")
    need(p["keypoint_error_fraction_median"] <= 0.05, f"keypoint_error_fraction_median {p['keypoint_error_fraction_median']} > 0.05")
    need(p["iou_median"] >= 0.7, f"iou_median {p['iou_median']} < 0.7")
    need(p["identity_switches"] == 0, f"identity_switches {p['identity_switches']} (one person in the scene)")
    dist = {b["bin"]: b for b in p["by_distance_m"]}
    need(dist["6-9"]["frames"] > 0.5 * p["frames_in_view"], f"the worker is not mostly 6-9 m away: {dist}")
    need(set(r["uav"] for r in rows) == {"0", "1", "2"}, "perception.csv lacks a UAV's frames")
print(("FAIL: " if problems else "ok: ") + ("; ".join(problems) if problems else
      f"gestures fired in time {sorted(fired_ok)}, false adaptations {m['false_adaptations']}, "
      f"detection {p['detection_rate']:.3f}, keypoint error {p['keypoint_error_fraction_median']:.3f} of the figure, "
      f"wall {m['wall_time_s']:.0f} s for {m['sim_time_s']:.0f} s"))
sys.exit(1 if problems else 0)
PY
