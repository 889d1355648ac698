#!/usr/bin/env bash
# Writes docs/images/site_rendered.png (docs/mapping.md §7): the construction site's obstacles that
# the prior map lacks, as the rendered cameras see them (`gfctl render`, which draws a scenario's
# unmapped_obstacles where they are at --t): follower 1's camera at t = 16 s (the crane arm across
# the route, construction yellow) and follower 2's at t = 5 s (the crane's mast and arm), each beside
# its depth image (grey: near dark, 0-40 m; black: nothing) — the image the live maps integrate
# under `gfctl simulate --camera rendered --mapping on`.
#   tools/make_site_render_figure.sh   # needs gfctl built (tools/build.sh gfctl) and ImageMagick
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GF_BUILD_DIR:-build}
GFCTL=$(find "$BUILD_DIR" -name gfctl -type f -perm -u+x | head -1)
[ -n "$GFCTL" ] || { echo "make_site_render_figure: build gfctl first (tools/build.sh gfctl)" >&2; exit 1; }
TMP=$(mktemp -d /tmp/gf-site-fig.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
S=config/scenarios/construction_site.yaml
"$GFCTL" render --scenario $S --t 16 --uav 1 --out "$TMP/a.png" --depth "$TMP/a_d.png"
"$GFCTL" render --scenario $S --t 5 --uav 2 --out "$TMP/b.png" --depth "$TMP/b_d.png"
for f in a b; do  # depth in mm (16 bit) → 8-bit grey over 0..40 m, nothing (0) stays black
  convert "$TMP/${f}_d.png" -fx 'u == 0 ? 0 : 0.15 + 0.85 * min(1, u * 65535 / 40000)' -depth 8 "$TMP/${f}_dv.png"
  convert "$TMP/$f.png" "$TMP/${f}_dv.png" +append "$TMP/${f}_row.png"
done
mkdir -p docs/images
convert "$TMP/a_row.png" "$TMP/b_row.png" -append -resize 960x -strip docs/images/site_rendered.png
echo "make_site_render_figure: wrote docs/images/site_rendered.png"
