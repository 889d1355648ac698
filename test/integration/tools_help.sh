#!/bin/bash
# Every shell script in tools/ answers --help (and -h) with what it does, exit 0, before
# doing anything: no install, no build, no build directory created.
set -uo pipefail
SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
fails=0
scripts=("$SRC"/tools/*.sh)
[ ${#scripts[@]} -ge 9 ] || { echo "FAIL: expected the 9+ scripts of tools/, found ${#scripts[@]}"; exit 1; }
for path in "${scripts[@]}"; do
  s=$(basename "$path")
  for flag in --help -h; do
    GF_BUILD_DIR=$T/build GF_PREFIX=$T/prefix timeout 10 bash "$SRC/tools/$s" $flag > "$T/out" 2> "$T/err"
    rc=$?
    lines=$(wc -l < "$T/out")
    if [ $rc != 0 ] || [ "$lines" -lt 1 ] || [ -e "$T/build" ] || [ -e "$T/prefix" ]; then
      echo "FAIL: tools/$s $flag -> exit $rc, $lines line(s) on stdout, build dir created: $([ -e "$T/build" ] && echo yes || echo no)"
      head -5 "$T/out" "$T/err"
      fails=$((fails + 1))
    else
      echo "ok: tools/$s $flag -> 0: $(head -1 "$T/out" | cut -c1-70)"
    fi
  done
done
exit $fails
