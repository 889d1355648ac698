#!/usr/bin/env bash
# Installs what is missing, builds everything and runs every test (unit + integration).
# This is the README's test command and what CI (.ci/run) runs.
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -eo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
tools/build.sh
cd "${GF_BUILD_DIR:-build}"
ctest --output-on-failure -j"${GF_JOBS:-$(nproc)}"
