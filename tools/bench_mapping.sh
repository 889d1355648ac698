#!/usr/bin/env bash
# Runs the online-mapping benchmark (bench/bench_mapping.cpp) and writes its figures, with the
# machine's load, to docs/results/mapping.md (issue 35: map update per 640×480 depth frame plus the
# incremental distance-field update <= 10 ms median on 2 cores).
#
#   tools/bench_mapping.sh [--frames N]     # builds gf_bench_mapping into build/ if needed
# Environment: GF_BUILD_DIR (default build).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GF_BUILD_DIR:-build}
GF_BUILD_DIR=$BUILD_DIR GF_JOBS=${GF_JOBS:-1} tools/build.sh gf_bench_mapping >/dev/null
BENCH=$(find "$BUILD_DIR" -name gf_bench_mapping -type f -perm -u+x | head -1)
[ -n "$BENCH" ] || { echo "bench_mapping: gf_bench_mapping not built" >&2; exit 1; }
OUT=$(mktemp /tmp/gf-mapping-md.XXXXXX)
trap 'rm -f "$OUT"' EXIT
"$BENCH" "$@" --markdown "$OUT" --commit "$(git rev-parse --short HEAD)"
mkdir -p docs/results
cp "$OUT" docs/results/mapping.md
echo "bench_mapping: wrote docs/results/mapping.md"
