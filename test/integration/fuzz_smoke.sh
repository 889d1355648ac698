#!/usr/bin/env bash
# ctest: builds the libFuzzer targets (fuzz/) with clang and runs each for a short bounded
# time over its committed corpus (seeds and the crash inputs kept as regressions), failing
# on any crash, sanitizer report or broken invariant. Budget: 6 targets × 15 s.
#   usage: fuzz_smoke.sh GFCTL SOURCE_DIR
# The fuzz build lives next to the ctest build (<build>/fuzz), override with GF_FUZZ_BUILD_DIR.
set -eo pipefail
GFCTL=$1
SRC=${2:-$(cd "$(dirname "$0")/../.." && pwd)}
BUILD_ROOT=$(cd "$(dirname "$GFCTL")/../../.." && pwd)
export GF_FUZZ_BUILD_DIR=${GF_FUZZ_BUILD_DIR:-$BUILD_ROOT/fuzz}
exec "$SRC/tools/fuzz/run_fuzzers.sh" --smoke --time "${GF_FUZZ_SMOKE_SECONDS:-15}"
