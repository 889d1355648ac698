#!/usr/bin/env bash
# gfctl bench <name>: dispatches to the gf_bench_<name> programs next to gfctl (a quick run of
# one, options passed through), lists the names on a bad call (exit 2). Timings are not checked.
set -euo pipefail
GFCTL=$1
out=$("$GFCTL" bench 2>&1) && { echo "FAIL: no name accepted"; exit 1; } || rc=$?
[ "$rc" = 2 ] || { echo "FAIL: exit $rc without a name"; exit 1; }
grep -q "planner" <<< "$out" || { echo "FAIL: names not listed: $out"; exit 1; }
out=$("$GFCTL" bench no_such 2>&1) && { echo "FAIL: unknown name accepted"; exit 1; } || rc=$?
[ "$rc" = 2 ] && grep -q "no benchmark 'no_such'" <<< "$out" || { echo "FAIL: unknown name: rc $rc: $out"; exit 1; }
out=$("$GFCTL" bench formation --benchmark_min_time=0.01 "--benchmark_filter=.*" 2>&1) || { echo "FAIL: bench formation: $out"; exit 1; }
grep -q "gf_bench_formation" <<< "$out" && grep -qE "^BM_|[0-9]+ ns" <<< "$out" || { echo "FAIL: no benchmark table: $out"; exit 1; }
echo ok
