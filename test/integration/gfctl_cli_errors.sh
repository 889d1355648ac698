#!/bin/bash
# gfctl's error contract (docs/design.md §8): exit 2 on bad arguments or input, with a message that
# names the file, line and field; nothing written that looks like a result.
set -uo pipefail
GFCTL=$1
SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
fails=0
expect() {  # expected_code expected_stderr_substring -- args...
  local code=$1 msg=$2
  shift 3
  "$GFCTL" "$@" > "$T/stdout" 2> "$T/stderr"
  local got=$?
  if [ "$got" != "$code" ] || ! grep -qF -- "$msg" "$T/stderr"; then
    echo "FAIL: gfctl $* -> exit $got (want $code), stderr:"; cat "$T/stderr"; echo "(wanted: $msg)"
    fails=$((fails + 1))
  else
    echo "ok: gfctl $* -> $code: $(head -1 "$T/stderr")"
  fi
}
CFG=$SRC/config/estimator.yaml
IN=$SRC/test/data/flights/sample_flight.csv
expect 2 "usage: gfctl" --
expect 2 "unknown command 'nope'" -- nope
# Help: one command's usage on stdout, exit 0 (--help, -h anywhere after it, or `help <command>`).
for form in "simulate --help" "simulate --scenario x -h" "help simulate"; do
  # shellcheck disable=SC2086
  "$GFCTL" $form > "$T/stdout" 2> "$T/stderr"
  got=$?
  if [ "$got" != 0 ] || ! grep -q "^usage: gfctl simulate --scenario FILE --out DIR" "$T/stdout" || [ -s "$T/stderr" ]; then
    echo "FAIL: gfctl $form -> exit $got, stdout: $(head -c 200 "$T/stdout"), stderr: $(cat "$T/stderr")"; fails=$((fails + 1))
  else
    echo "ok: gfctl $form -> 0: $(head -c 60 "$T/stdout")"
  fi
done
expect 2 "unknown command 'nope'" -- help nope
expect 2 "unknown command 'nope'" -- nope --help
expect 2 "missing required option --in" -- estimate --config "$CFG" --out "$T/o.csv"
expect 2 "unknown option --bogus" -- estimate --config "$CFG" --in "$IN" --out "$T/o.csv" --bogus 1
expect 2 "$T/none.csv: cannot open file" -- estimate --config "$CFG" --in "$T/none.csv" --out "$T/o.csv"
printf 't,cam_x\n0,1\n' > "$T/cols.csv"
expect 2 "cols.csv:1: header lacks column(s): cam_y" -- estimate --config "$CFG" --in "$T/cols.csv" --out "$T/o.csv"
head -5 "$IN" > "$T/bad.csv"
sed -i '4s/^\([^,]*\),[^,]*,/\1,oops,/' "$T/bad.csv"
expect 2 "bad.csv:4: field 'cam_x': cannot parse 'oops' as a number" -- estimate --config "$CFG" --in "$T/bad.csv" --out "$T/o.csv"
head -3 "$IN" > "$T/short.csv"; echo "1,2,3" >> "$T/short.csv"
expect 2 "short.csv:4: expected 14 fields, got 3" -- estimate --config "$CFG" --in "$T/short.csv" --out "$T/o.csv"
printf 'gate_chi2: -1\nprocess_noise: {sigma_v_mps: abc}\ncamera: {fx: 0}\n' > "$T/bad.yaml"
expect 2 "gate_chi2: value -1 is out of range" -- estimate --config "$T/bad.yaml" --in "$IN" --out "$T/o.csv"
grep -q "process_noise.sigma_v_mps: expected a number, got 'abc'" "$T/stderr" || { echo "FAIL: not every config problem listed"; fails=$((fails+1)); }
grep -q "camera.fx: value 0 is out of range" "$T/stderr" || { echo "FAIL: camera.fx not listed"; fails=$((fails+1)); }
expect 2 "cannot open for writing" -- estimate --config "$CFG" --in "$IN" --out /nonexistent/dir/o.csv
# Valid but garbage rows are rejected with a warning, not fatal.
head -3 "$IN" > "$T/nan.csv"; sed -n 4p "$IN" | sed 's/^\([^,]*\),/\1,nan,/;s/,nan,[^,]*,/,nan,/' >> "$T/nan.csv"
"$GFCTL" estimate --config "$CFG" --in "$T/nan.csv" --out "$T/o.csv" > /dev/null 2> "$T/stderr" || { echo "FAIL: NaN row fatal"; fails=$((fails+1)); }
grep -q "nan.csv:4: measurement rejected: camera pose has a non-finite value" "$T/stderr" || { echo "FAIL: NaN row not reported"; cat "$T/stderr"; fails=$((fails+1)); }
[ "$(wc -l < "$T/o.csv")" = 4 ] || { echo "FAIL: one output row per input row expected"; fails=$((fails+1)); }
exit $fails
