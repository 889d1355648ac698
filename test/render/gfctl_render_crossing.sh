#!/bin/bash
# gfctl render-crossing end to end (docs/perception.md "Identity by appearance"): bad input exits 2
# naming the option; one rendered scene (seed 2, not the report's seed) in which a second person
# walks across in front of the worker and hides it, through the real detector + tracker + MoveNet
# with the shipped tracker and the operator's choice: the choice is made, no frame's box lands on the
# walker, the worker is tracked in >= 60 % of the frames it is visible in, one row per frame.
# Exit 77 (ctest: skipped) only when this machine has no EGL display / OpenGL 3.3.
set -euo pipefail
GFCTL=$1
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
expect_bad() {  # expect_bad "needle" args...
  local needle=$1; shift
  set +e
  "$GFCTL" render-crossing "$@" >"$OUT/stdout" 2>"$OUT/stderr"
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || fail "exit $rc (expected 2) for: $*; stderr: $(cat "$OUT/stderr")"
  grep -q -- "$needle" "$OUT/stderr" || fail "stderr lacks '$needle' for: $*; got: $(cat "$OUT/stderr")"
}
expect_bad "missing required option --out" --seed 1 --count 1
expect_bad "\-\-count: expected an integer" --seed 1 --count 0 --out "$OUT/x"
expect_bad "\-\-appearance: expected 0 or 1, got 'yes'" --seed 1 --count 1 --out "$OUT/x" --appearance yes
expect_bad "\-\-choose: expected 0 or 1, got '2'" --seed 1 --count 1 --out "$OUT/x" --choose 2
set +e
"$GFCTL" render-crossing --seed 2 --count 1 --out "$OUT/run" --images "$OUT/img" > "$OUT/log" 2>&1
rc=$?
set -e
if [ "$rc" -eq 1 ] && grep -q "EGL\|OpenGL" "$OUT/log"; then echo "SKIP: no EGL here: $(cat "$OUT/log")"; exit 77; fi
[ "$rc" -eq 0 ] || fail "render-crossing exited $rc: $(cat "$OUT/log")"
cat "$OUT/log"
python3 - "$OUT/run" <<'PY'
import csv, sys
d = sys.argv[1]
scene = list(csv.DictReader(open(d + "/scenes.csv")))
frames = list(csv.DictReader(open(d + "/frames.csv")))
assert len(scene) == 1, scene
s = scene[0]
problems = []
if float(s["walker_offset_m"]) <= 0: problems.append("scene 0 should have the walker in front")
if s["chosen"] != "1": problems.append("the operator's choice was not made")
if int(s["on_walker"]) != 0: problems.append(f"{s['on_walker']} frames with the worker's box on the walker (first {s['first_on_walker']})")
if int(s["on_worker"]) < 0.6 * int(s["worker_visible"]): problems.append(f"worker tracked in {s['on_worker']} of {s['worker_visible']} visible frames")
if len(frames) != int(s["frames"]): problems.append(f"frames.csv has {len(frames)} rows, scenes.csv says {s['frames']}")
hidden = sum(1 for f in frames if int(f["walker_w"]) > 0 and int(f["worker_w"]) > 0
             and abs(int(f["walker_u"]) + int(f["walker_w"]) / 2 - int(f["worker_u"]) - int(f["worker_w"]) / 2) < int(f["worker_w"]))
if hidden == 0: problems.append("the walker never passed in front of the worker")
print(("FAIL: " + "; ".join(problems)) if problems else
      f"ok: worker tracked in {s['on_worker']}/{s['worker_visible']} visible frames, 0 on the walker, {hidden} frames crossing")
sys.exit(1 if problems else 0)
PY
[ -s "$OUT/img/scene0.png" ] || fail "no snapshot written to --images"
