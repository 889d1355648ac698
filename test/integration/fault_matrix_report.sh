#!/usr/bin/env bash
# The fault-matrix report from the campaign store (tools/campaign.py import-csv | report |
# compare, and tools/run_fault_matrix.sh --report-only): a small runs file in the former
# tools/run_fault_matrix.sh format is imported once; the report counts the missions per profile,
# names the mission that crosses a safety threshold and the one with a false adaptation, lists
# missing seeds, reports another commit's missions by their safety figures, and (with the tools
# venv) draws tools/plot_fault_matrix.py's figure and links it; compare flags the regression of
# a second commit and lists the mission; a runs file with other columns is refused, the store
# left untouched.
# Usage: fault_matrix_report.sh GFCTL SRC
set -uo pipefail
SRC=$2
PY=/opt/gesture_formation/venv/bin/python
[ -x "$PY" ] || { echo "SKIP: no tools venv ($PY): tools/setup.sh"; exit 77; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$SRC"
H="profile,seed,commit,model_sha256,min_mutual_distance_m,min_obstacle_distance_m,min_obstacle_uav,min_obstacle_t_s,collisions,requests_applied,requests_total,false_adaptations,human_estimate_error_rms_m,min_human_distance_m,plans_hold,plans_fallback_brake,commands_stale,distance_error_rms_m,wall_time_s"
row() {  # commit profile seed mutual obstacle collisions false_adaptations
  echo "$2,$3,$1,0123456789abcdef,$4,$5,1,12.5,$6,25,25,$7,0.15,6.1,4,0,0,0.34,30.0"
}
{
  echo "$H"
  row abc1234567 nominal 1 6.50 1.05 0 0
  row abc1234567 nominal 2 6.10 0.98 0 1
  row abc1234567 loss50 1 2.40 1.00 0 0
} > "$T/runs.csv"
{  # a newer matrix: nominal seed 1 closer to the other UAVs and to the tower
  echo "$H"
  row def7654321 nominal 1 5.90 0.91 0 0
  row def7654321 loss50 1 3.20 0.88 0 0
} > "$T/runs_next.csv"
cat > "$T/matrix.yaml" <<'EOF'
name: matrix_test
scenarios: [config/scenarios/power_towers.yaml]
profiles: [nominal, loss50]
seeds: 1..2
EOF
S=$T/store.sqlite
C="$PY tools/campaign.py --store $S"
fails=0
passes=0
check() { if grep -qF -- "$2" "$3"; then echo "PASS: $1"; passes=$((passes + 1)); else echo "FAIL: $1: '$2' not in $3"; fails=$((fails + 1)); fi; }
$C import-csv "$T/runs.csv" "$T/runs_next.csv" > "$T/import.txt" 2>&1
check "import: 3 missions" "runs.csv: 3 missions imported" "$T/import.txt"
$C import-csv "$T/runs.csv" > "$T/import2.txt" 2>&1
check "a runs file is imported once" "0 missions imported (this file was imported before)" "$T/import2.txt"

$C report "$T/matrix.yaml" --out "$T/results/reliability.md" > "$T/out.txt" 2>&1
R="$T/results/reliability.md"
check "nominal row: 2 seeds, min / median / max mutual" '| `nominal` | 2 | 6.10 / 6.30 / 6.50 |' "$R"
check "the violation is named" 'loss50 seed 1: mutual 2.40 m' "$R"
check "the violation is counted" 'Safety violations (1 of 3 missions)' "$R"
check "false adaptations counted and named" 'False adaptations: 1 in the 3 missions** (`nominal` seed 2)' "$R"
check "missing seed listed" '`loss50` seed 2' "$R"
check "the summary line" '3 missions, 1 with a safety violation' "$T/out.txt"
check "the tables' commit" '`abc1234567` / `0123456789abcdef` (3)' "$R"
check "the other commit by its safety figures" '`def7654321`: 2 missions (seeds up to 1): min mutual 3.20 m, min obstacle 0.880 m, min human 6.10 m, 0 collisions — no safety violation' "$R"
$C report "$T/matrix.yaml" --commit def7 --out "$T/r2.md" > /dev/null 2>&1
check "--commit selects the tables" '| `nominal` | 1 | 5.90 / 5.90 / 5.90 |' "$T/r2.md"
$C report "$T/matrix.yaml" --seeds 1..1 --commit abc --out "$T/r3.md" > "$T/out3.txt" 2>&1
check "--seeds selects the tables' seeds (the store holds seed 2 too)" '| `nominal` | 1 | 6.50 / 6.50 / 6.50 |' "$T/r3.md"
check "--seeds: the summary counts those seeds only" '2 missions, 1 with a safety violation' "$T/out3.txt"
if "$PY" -c "import matplotlib" 2>/dev/null; then
  [ -s "$T/results/fault_matrix.png" ] && { echo "PASS: figure drawn"; passes=$((passes + 1)); } || { echo "FAIL: no $T/results/fault_matrix.png"; fails=$((fails + 1)); }
  check "figure linked" '](fault_matrix.png)' "$R"
fi
if "$PY" - "$R" <<'P'; then echo "PASS: the report's links to docs/ resolve"; passes=$((passes + 1)); else echo "FAIL: a link of $R does not resolve"; fails=$((fails + 1)); fi
import os, re, sys
links = re.findall(r"\]\(([^)#]+\.md)\)", open(sys.argv[1]).read())
bad = [l for l in links if not os.path.exists(os.path.join(os.path.dirname(sys.argv[1]), l))]
print("links:", sorted(set(links)), "unresolved:", bad)
sys.exit(1 if bad or not links else 0)
P

# The wrapper reports from a store too.
GF_STORE=$S GF_REPORT=$T/w/reliability.md tools/run_fault_matrix.sh --report-only > "$T/w.txt" 2>&1
check "run_fault_matrix.sh --report-only: the 14-profile matrix from the store" '| `nominal` | 2 | 6.10 / 6.30 / 6.50 |' "$T/w/reliability.md"

# compare: nominal seed 1 got closer in def7654321 (6.50 -> 5.90 m mutual): flagged and listed.
$C compare abc1234567 def7654321 --campaign "$T/matrix.yaml" > "$T/cmp.txt" 2>&1
check "compare: both commits, the missions both ran" "compare A = abc1234567 (3 missions) vs B = def7654321 (2 missions): 2 missions in both, 1 only in A, 0 only in B" "$T/cmp.txt"
check "compare: nominal's min mutual regression flagged" '| `nominal` | 1 | 6.50 → 5.90 ▼' "$T/cmp.txt"
check "compare: loss50's violation gone: an improvement" '1 → 0 ▲' "$T/cmp.txt"
check "compare: the mission listed" "power_towers.yaml nominal seed 1 config" "$T/cmp.txt"
check "compare: the regressions counted" "▼ nominal: min mutual [m] 6.50 → 5.90" "$T/cmp.txt"

# A runs file with other columns is refused (exit 2), the store unchanged.
printf 'profile,seed,other\nnominal,1,3\n' > "$T/other.csv"
h0=$(sha256sum < "$S")
$C import-csv "$T/other.csv" > "$T/o2.txt" 2>&1
rc=$?
h1=$(sha256sum < "$S")
if [ $rc -eq 2 ] && grep -q "are not those of a fault-matrix runs file" "$T/o2.txt" && [ "$h0" = "$h1" ]; then
  echo "PASS: a runs file with other columns is refused, the store unchanged"; passes=$((passes + 1))
else
  echo "FAIL: other columns: rc $rc, store $([ "$h0" = "$h1" ] && echo same || echo CHANGED)"; cat "$T/o2.txt"; fails=$((fails + 1))
fi
echo "fault_matrix_report: $passes passed, $fails failed"
exit $((fails > 0))
