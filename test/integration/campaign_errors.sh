#!/usr/bin/env bash
# tools/campaign.py refuses bad input with exit 2 and an error naming the field and the value,
# before it starts a cluster or touches a store: unknown field, bad seeds, a missing scenario or
# fault profile, a variant key outside mission./faults., bad --seeds/--profiles, a missing store.
# Skipped (77) without the tools venv.
# Usage: campaign_errors.sh GFCTL SRC
set -uo pipefail
SRC=$2
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || { echo "SKIP: no tools venv ($PY): tools/setup.sh"; exit 77; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$SRC"
passes=0
fails=0
base='name: t
scenarios: [config/scenarios/open_field.yaml]
profiles: [nominal]
seeds: 1..2'
expect() {  # expect WHAT YAML_TEXT MESSAGE [extra args]
  local what=$1 text=$2 msg=$3
  shift 3
  printf '%s\n' "$text" > "$T/c.yaml"
  out=$("$PY" tools/campaign.py --store "$T/s.sqlite" run "$T/c.yaml" --dry-run "$@" 2>&1)
  rc=$?
  if [ $rc = 2 ] && grep -qF -- "$msg" <<<"$out" && [ ! -e "$T/s.sqlite" ]; then
    echo "PASS: $what: $out"; passes=$((passes + 1))
  else
    echo "FAIL: $what: exit $rc, '$out' (want 2 and '$msg', no store created)"; fails=$((fails + 1))
  fi
}
expect "unknown field" "$base
sed: 3" "sed: unknown field"
expect "seeds reversed" "${base/1..2/9..2}" "seeds: expected 0 <= from <= to, got {'from': '9', 'to': '2'}"
expect "seeds not integers" "${base/1..2/[1, x]}" "seeds: expected a list of non-negative integers"
expect "missing scenario" "${base/open_field/nowhere}" "scenarios: 'config/scenarios/nowhere.yaml': no such file"
expect "missing profile" "${base/nominal/nosuch}" "profiles: 'nosuch':"
expect "variant key outside mission./faults." "$base
variants: {planner.horizon: [1, 2]}" "variants: 'planner.horizon': expected a dotted key under mission. or faults."
expect "variant without values" "$base
variants: {mission.links.uav.delay_s: []}" "variants: mission.links.uav.delay_s: expected a non-empty list of values"
expect "timeout not positive" "$base
timeout_s: 0" "timeout_s: expected a number > 0, got 0"
expect "name" "${base/name: t/name: Big Name}" "name: expected [a-z0-9_-]+, got 'Big Name'"
expect "--seeds" "$base" "--seeds: expected A..B or a list of integers, got '1,x'" --seeds 1,x
expect "--profiles" "$base" "profiles: 'bogus':" --profiles nominal,bogus
out=$("$PY" tools/campaign.py --store "$T/none.sqlite" report 2>&1)
rc=$?
[ $rc = 2 ] && grep -q "none.sqlite: no such campaign store" <<<"$out" && [ ! -e "$T/none.sqlite" ] \
  && { echo "PASS: report on a missing store: $out"; passes=$((passes + 1)); } \
  || { echo "FAIL: report on a missing store: exit $rc, '$out'"; fails=$((fails + 1)); }
echo "campaign_errors: $passes passed, $fails failed"
exit $((fails > 0))
