#!/usr/bin/env bash
# Writes docs/images/gesture_rendered_skeletons.png (docs/gestures.md §9): the four gestures rendered
# (`gfctl render-gestures --frames-every 1`, seed 3999 of the tuning range, the rendered protocol's
# viewpoints and bodies; of each performance's three views the nearest) at the middle of the hold, the truth's stick figure in green and the skeleton network's in red
# (left side thick): MoveNet lightning (the default, top row) and BlazePose landmark full (bottom
# row) on the same pixels. What the chain's failures on rendered frames look like.
#   tools/make_gesture_frames_figure.sh   # needs gfctl built (tools/build.sh gfctl) and the tools venv
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GF_BUILD_DIR:-build}
GFCTL=$(find "$BUILD_DIR" -name gfctl -type f -perm -u+x | head -1)
[ -n "$GFCTL" ] || { echo "make_gesture_frames_figure: build gfctl first (tools/build.sh gfctl)" >&2; exit 1; }
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || { echo "make_gesture_frames_figure: the tools venv is missing (tools/setup.sh)" >&2; exit 1; }
TMP=$(mktemp -d /tmp/gf-gesture-fig.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
# the protocol's synth keys (tools/gesture/heldout/protocol_v2_rendered.yaml)
"$PY" -c "import yaml, sys; p = yaml.safe_load(open('tools/gesture/heldout/protocol_v2_rendered.yaml')); yaml.safe_dump(dict(p['synth']), open(sys.argv[1], 'w'))" "$TMP/synth.yaml"
for sk in movenet_lightning blazepose_landmark; do
  "$GFCTL" render-gestures --seed 3999 --count 4 --out "$TMP/$sk" --views 60,-60 --config "$TMP/synth.yaml" \
    --motions cross_arms,palms_together,extend_arm_side,raise_arm_up --skeleton $sk --frames-every 1 > "$TMP/$sk.log"
done
mkdir -p docs/images
"$PY" - "$TMP" docs/images/gesture_rendered_skeletons.png <<'PY'
import csv, sys
from PIL import Image, ImageDraw
tmp, out = sys.argv[1], sys.argv[2]
FPS, SIDE = 15.0, 300
rows = []
for sk in ("movenet_lightning", "blazepose_landmark"):
    views = [list(csv.DictReader(open(f"{tmp}/{sk}/sequences{sfx}.csv"))) for sfx in ("", "_view1", "_view2")]
    tiles = []
    for i in range(len(views[0])):
        v = min(range(3), key=lambda j: float(views[j][i]["distance_m"]))
        s = views[v][i]
        k = round(0.5 * (float(s["motion_start_s"]) + float(s["motion_end_s"])) * FPS)
        im = Image.open(f"{tmp}/{sk}/frames/seq{s['sequence']}_view{v}_f{k}.png").convert("RGB")
        im.thumbnail((SIDE, SIDE))
        tile = Image.new("RGB", (SIDE, SIDE + 18), "white")
        tile.paste(im, ((SIDE - im.width) // 2, 18))
        ImageDraw.Draw(tile).text((4, 3), f"{s['motion']} ({sk.split('_')[0]}), {float(s['distance_m']):.1f} m", fill="black")
        tiles.append(tile)
    row = Image.new("RGB", (len(tiles) * (SIDE + 4), SIDE + 18), "white")
    for i, t in enumerate(tiles):
        row.paste(t, (i * (SIDE + 4), 0))
    rows.append(row)
m = Image.new("RGB", (rows[0].width, sum(r.height + 4 for r in rows)), "white")
for i, r in enumerate(rows):
    m.paste(r, (0, i * (r.height + 4)))
m.save(out, optimize=True)
PY
echo "make_gesture_frames_figure: wrote docs/images/gesture_rendered_skeletons.png"
