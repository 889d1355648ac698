#!/usr/bin/env bash
# Installs what is missing, builds everything and runs every test (unit + integration).
# This is the README's test command and what CI (.ci/run) runs.
set -eo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
tools/build.sh
cd "${GF_BUILD_DIR:-build}"
ctest --output-on-failure -j"${GF_JOBS:-$(nproc)}"
