#!/bin/bash
# gfctl render end to end (docs/rendering.md §6): bad input exits 2 naming the option (a missing
# asset names the conversion command); one frame of the power-tower mission is written (colour
# 640x480, 16-bit depth, truth CSV with 17 keypoints and a non-empty worker box, the worker's
# visible pixels equal to the box's count). Exit 77 (ctest: skipped) only when this machine has no
# EGL display / OpenGL 3.3 context.
set -euo pipefail
GFCTL=$1
SRC=$2
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
S=$SRC/config/scenarios/power_towers.yaml

expect_bad() {  # expect_bad "needle" args...
  local needle=$1; shift
  set +e
  "$GFCTL" render "$@" >"$OUT/stdout" 2>"$OUT/stderr"
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || fail "exit $rc (expected 2) for: $*; stderr: $(cat "$OUT/stderr")"
  grep -q -- "$needle" "$OUT/stderr" || fail "stderr lacks '$needle' for: $*; got: $(cat "$OUT/stderr")"
}
expect_bad "missing required option --uav" --scenario "$S" --t 1 --out "$OUT/a.png"
expect_bad "\-\-t: expected a time" --scenario "$S" --t -1 --uav 0 --out "$OUT/a.png"
expect_bad "has 3 UAVs" --scenario "$S" --t 1 --uav 7 --out "$OUT/a.png"
expect_bad "\-\-outfit" --scenario "$S" --t 1 --uav 0 --out "$OUT/a.png" --outfit tuxedo
expect_bad "\-\-motion: unknown motion" --scenario "$S" --t 1 --uav 0 --out "$OUT/a.png" --motion moonwalk
expect_bad "/nonexistent.yaml" --scenario /nonexistent.yaml --t 1 --uav 0 --out "$OUT/a.png"
expect_bad "convert_mannequin.py" --scenario "$S" --t 1 --uav 0 --out "$OUT/a.png" --models "$OUT/none"

set +e
"$GFCTL" render --scenario "$S" --t 75 --uav 0 --seed 2 --out "$OUT/f.png" --depth "$OUT/d.png" --truth "$OUT/t.csv" \
  >"$OUT/stdout" 2>"$OUT/stderr"
rc=$?
set -e
if [ "$rc" -eq 1 ] && grep -q "EGL\|OpenGL" "$OUT/stderr"; then echo "SKIP: no EGL here: $(cat "$OUT/stderr")"; exit 77; fi
[ "$rc" -eq 0 ] || fail "render exit $rc: $(cat "$OUT/stderr")"
grep -q "10 m from the worker" "$OUT/stdout" || fail "unexpected summary: $(cat "$OUT/stdout")"
/usr/bin/python3 - "$OUT" <<'PY' || fail "outputs"
import csv, struct, sys
d = sys.argv[1]
def ihdr(path):  # width, height, bit depth, colour type of a PNG
    b = open(path, "rb").read(33)
    assert b[:8] == b"\x89PNG\r\n\x1a\n" and b[12:16] == b"IHDR", path
    return struct.unpack(">IIBB", b[16:26])
assert ihdr(d + "/f.png") == (640, 480, 8, 2), ihdr(d + "/f.png")    # RGB, 8 bit
assert ihdr(d + "/d.png") == (640, 480, 16, 0), ihdr(d + "/d.png")   # grey, 16 bit
rows = list(csv.reader(open(d + "/t.csv")))
assert rows[0] == ["keypoint", "u_px", "v_px", "depth_m", "in_image", "visible"], rows[0]
assert len(rows) == 19 and rows[1][0] == "nose" and rows[17][0] == "right_ankle", len(rows)
box = dict(kv.split("=") for kv in rows[18][1:])
u, v, w, h = (int(box[k]) for k in "uvwh")
assert w > 10 and h > 60, box
for r in rows[1:18]:
    if r[5] == "1":
        x, y = float(r[1]), float(r[2])
        assert u - 1 <= x <= u + w and v - 1 <= y <= v + h, (r, box)
        assert abs(float(r[3]) - 10.0) < 1.0, r   # the leader is 10 m from the worker
print("gfctl_render: outputs ok", box)
PY
# the depth image holds both nothing (0: sky) and surfaces (> 0)
range=$(identify -format "%[min] %[max]" "$OUT/d.png")
[ "${range%% *}" = "0" ] && [ "${range##* }" != "0" ] || fail "depth range '$range' lacks sky or surface"
echo "gfctl_render: ok"
