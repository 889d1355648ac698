#!/bin/bash
# replay.launch under Xvfb: rviz loads config/rviz/gesture_formation.rviz and renders a bag
# replay (rosbag play --clock); the screenshot must show the Visualizer's colours: leader red,
# follower 1 green, follower 2 blue, the worker's covariance yellow, the map grey.
# Optional fourth argument (after SRC BUILD DEVEL): a bag to replay instead of the synthetic one
# (e.g. a mission bag);
# GF_RVIZ_SHOT=path keeps the screenshot; GF_RVIZ_SCENARIO=scenario.yaml replays a bag without
# markers (record.launch) through the Visualizer with that site's map.
set -o pipefail
source "$(dirname "$0")/common.bash"
BAG=${4:+$(realpath "$4")}
START=${GF_RVIZ_START:-0}
if [ -z "$BAG" ]; then
  BAG=$T/markers.bag
  python3 "$SRC/test/ros/make_marker_bag.py" "$BAG" || { echo "FAIL: cannot write the bag"; exit 1; }
fi
# roslaunch starts the master (-p PORT)
SHOT=${GF_RVIZ_SHOT:-$T/shot.png}
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || PY=python3
cat > "$T/colours.py" <<'PY'
import sys
import numpy as np
from PIL import Image
img = np.asarray(Image.open(sys.argv[1]).convert("RGB")).astype(int)
H, W = img.shape[:2]
img = img[int(0.1 * H):int(0.95 * H), int(0.02 * W):int(0.98 * W)]  # the 3D view only (no menus, status bar)
r, g, b = img[..., 0], img[..., 1], img[..., 2]
checks = {
    "leader red": (r > 150) & (g < 90) & (b < 90),
    "follower 1 green": (g > 130) & (r < 90) & (b < 90),
    "follower 2 blue": (b > 150) & (r < 90) & (g < 140),
    # semi-transparent (alpha 0.6) and shaded over the dark background: median (143, 132, 21),
    # lit side up to (166, 153, 21), dark side (107, 100, 21) — r ≈ g, both far above b
    "worker covariance yellow": (r > 100) & (g > 90) & (b < 60) & (abs(r - g) < 40),
}
bad = 0
for name, mask in checks.items():
    n = int(mask.sum())
    ok = n >= 20
    bad += 0 if ok else 1
    print(f"{'PASS' if ok else 'FAIL'}: {name}: {n} pixels")
sys.exit(bad)
PY
# rviz needs a few seconds to load and draw (longer on a busy computer): a screenshot every 2 s
# from GF_RVIZ_WAIT (10 s) on, until the colours are there or 40 s have passed; the last one is judged.
xvfb-run -a -s "-screen 0 1200x800x24" bash -c "
  roslaunch -p $PORT gesture_formation replay.launch bag:=$BAG start:=$START loop:=true ${GF_RVIZ_SCENARIO:+scenario_file:=$GF_RVIZ_SCENARIO} > '$T/replay.log' 2>&1 &
  l=\$!
  sleep ${GF_RVIZ_WAIT:-10}
  for _ in \$(seq 16); do
    import -window root '$SHOT' && '$PY' '$T/colours.py' '$SHOT' > /dev/null 2>&1 && break
    sleep 2
  done
  kill -INT \$l; wait \$l" || true
[ -s "$SHOT" ] || { echo "FAIL: no screenshot"; tail -20 "$T/replay.log"; exit 1; }
grep -q "ERROR.*rviz\|Could not load" "$T/replay.log" && fail "rviz reported an error: $(grep -m1 ERROR "$T/replay.log")"
"$PY" "$T/colours.py" "$SHOT" || fails=$((fails + 1))
exit $fails
