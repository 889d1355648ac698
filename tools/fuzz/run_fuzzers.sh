#!/usr/bin/env bash
# Builds the libFuzzer targets in fuzz/ with clang (-fsanitize=fuzzer,address,undefined) in
# their own build directory and runs each for a bounded time. Exit 1 if any target crashed
# (the crashing input is left in <build>/artifacts/ and named in the output).
#
#   tools/fuzz/run_fuzzers.sh                         # every target, 60 s each
#   tools/fuzz/run_fuzzers.sh --time 600 config csv   # chosen targets, 10 min each
#   tools/fuzz/run_fuzzers.sh --smoke --time 15       # CI (test/integration/fuzz_smoke.sh): every
#                                                     # committed input (seeds + crash regressions)
#                                                     # runs first; a target without corpus fails
#   tools/fuzz/run_fuzzers.sh --merge                 # also minimise new inputs into fuzz/corpus/
#   tools/fuzz/run_fuzzers.sh --seeds                 # (re)write the generated seeds into fuzz/corpus/
#
# Environment: GF_FUZZ_BUILD_DIR (default <repo>/build-fuzz), GF_FUZZ_JOBS (default 2).
# Targets: envelope envelope_v2 payloads lcm_envelope key_file config csv (fuzz/fuzz_<name>.cpp).
set -eo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
export PATH=/usr/bin:/bin:$PATH
BUILD=${GF_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}
TIME=60
SMOKE=0
MERGE=0
SEEDS=0
TARGETS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --time) TIME=$2; shift 2 ;;
    --smoke) SMOKE=1; shift ;;
    --merge) MERGE=1; shift ;;
    --seeds) SEEDS=1; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    -*) echo "run_fuzzers: unknown option '$1'" >&2; exit 2 ;;
    *) TARGETS+=("$1"); shift ;;
  esac
done
if [ ${#TARGETS[@]} -eq 0 ]; then
  TARGETS=(envelope envelope_v2 payloads lcm_envelope key_file config csv)
fi
command -v clang++ >/dev/null || { echo "run_fuzzers: clang++ not found; run tools/setup.sh (installs clang, libclang-rt-14-dev)" >&2; exit 2; }

# --- build -----------------------------------------------------------------------------
mkdir -p "$BUILD"
if [ ! -f "$BUILD/build.ninja" ]; then
  cmake -S "$ROOT/fuzz" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_COMPILER=clang++ \
    > "$BUILD/configure.log" 2>&1 || { cat "$BUILD/configure.log"; exit 2; }
fi
ninja -C "$BUILD" -j"${GF_FUZZ_JOBS:-2}" > "$BUILD/build.log" 2>&1 || { tail -50 "$BUILD/build.log"; exit 2; }
if [ "$SEEDS" = 1 ]; then
  mkdir -p "$ROOT/fuzz/corpus/payloads" "$ROOT/fuzz/corpus/lcm_envelope" "$ROOT/fuzz/corpus/envelope"
  "$BUILD/gf_fuzz_make_seeds" "$ROOT/fuzz/corpus"
fi

# --- run -------------------------------------------------------------------------------
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
mkdir -p "$BUILD/artifacts"
failed=()
printf '%-14s %10s %8s %8s %7s %6s %s\n' target execs exec/s cov ft corpus result
for t in "${TARGETS[@]}"; do
  bin="$BUILD/fuzz_$t"
  [ -x "$bin" ] || { echo "run_fuzzers: no target fuzz_$t" >&2; exit 2; }
  corpus="$ROOT/fuzz/corpus/$t"
  work="$BUILD/corpus/$t"      # new inputs go here, not into the committed corpus
  mkdir -p "$corpus" "$work"
  if [ "$SMOKE" = 1 ] && [ -z "$(ls -A "$corpus")" ]; then
    echo "run_fuzzers: committed corpus $corpus is empty" >&2
    failed+=("$t")
    continue
  fi
  args=(-max_total_time="$TIME" -print_final_stats=1 -timeout=10 -rss_limit_mb=2048
        -artifact_prefix="$BUILD/artifacts/${t}-" -max_len=8192)
  [ -f "$ROOT/fuzz/dict/$t.dict" ] && args+=(-dict="$ROOT/fuzz/dict/$t.dict")
  log="$BUILD/fuzz_$t.log"
  rc=0
  "$bin" "${args[@]}" "$work" "$corpus" > "$log" 2>&1 || rc=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  cov=$(grep -oE '(INITED|DONE|#[0-9]+.*) cov: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$' || true)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$' || true)
  units=$(find "$work" "$corpus" -type f | wc -l)
  if [ "$rc" = 0 ]; then
    result=ok
  else
    result="CRASH (exit $rc; see $log; input in $BUILD/artifacts/${t}-*)"
    failed+=("$t")
    grep -m5 -E 'ERROR|runtime error|fuzz invariant|SUMMARY' "$log" >&2 || true
  fi
  printf '%-14s %10s %8s %8s %7s %6s %s\n' "$t" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "$units" "$result"
  if [ "$MERGE" = 1 ] && [ "$rc" = 0 ]; then
    "$bin" -merge=1 -max_len=8192 "$corpus" "$work" > "$BUILD/merge_$t.log" 2>&1 || true
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "run_fuzzers: crashes in: ${failed[*]}" >&2
  exit 1
fi
