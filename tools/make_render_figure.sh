#!/usr/bin/env bash
# Writes docs/images/render_example.png (docs/rendering.md): two frames of the power-tower
# mission rendered by `gfctl render` — the leader's camera at t = 75 s (the worker at height on
# the west tower extending an arm, work clothes) and follower 1's camera at t = 4 s (hi-vis vest
# and helmet, raising an arm) — each beside its depth image (grey: near dark, 0-40 m; black: nothing).
#   tools/make_render_figure.sh        # needs gfctl built (tools/build.sh gfctl) and ImageMagick
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GF_BUILD_DIR:-build}
GFCTL=$(find "$BUILD_DIR" -name gfctl -type f -perm -u+x | head -1)
[ -n "$GFCTL" ] || { echo "make_render_figure: build gfctl first (tools/build.sh gfctl)" >&2; exit 1; }
TMP=$(mktemp -d /tmp/gf-render-fig.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
S=config/scenarios/power_towers.yaml
"$GFCTL" render --scenario $S --t 75 --uav 0 --seed 2 --outfit work_clothes --out "$TMP/a.png" --depth "$TMP/a_d.png"
"$GFCTL" render --scenario $S --t 4 --uav 1 --seed 5 --outfit hivis_helmet --skin-tone 1 --motion raise_arm_up --out "$TMP/b.png" --depth "$TMP/b_d.png"
for f in a b; do  # depth in mm (16 bit) → 8-bit grey over 0..40 m, nothing (0) stays black
  convert "$TMP/${f}_d.png" -fx 'u == 0 ? 0 : 0.15 + 0.85 * min(1, u * 65535 / 40000)' -depth 8 "$TMP/${f}_dv.png"
  convert "$TMP/$f.png" "$TMP/${f}_dv.png" +append "$TMP/${f}_row.png"
done
mkdir -p docs/images
convert "$TMP/a_row.png" "$TMP/b_row.png" -append -resize 960x -strip docs/images/render_example.png
echo "make_render_figure: wrote docs/images/render_example.png"
