#!/usr/bin/env bash
# tools/run_fault_matrix.sh --report-only on a small runs file: the report counts the missions
# per profile, names the mission that crosses a safety threshold and the one with a false
# adaptation, lists missing seeds, and (with the tools venv) draws tools/plot_fault_matrix.py's
# figure and links it; a runs file with other columns is refused when resuming.
# Usage: fault_matrix_report.sh GFCTL SRC
set -euo pipefail
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cd "$SRC"
H=$(grep -o '^COLUMNS_CSV="[^"]*"' tools/run_fault_matrix.sh | cut -d'"' -f2)
[ -n "$H" ] || { echo "FAIL: no COLUMNS_CSV in tools/run_fault_matrix.sh"; exit 1; }
row() {  # profile seed mutual obstacle collisions false_adaptations
  python3 - "$H" "$@" <<'P'
import sys
cols = sys.argv[1].split(",")
p, seed, mutual, obstacle, coll, false_ad = sys.argv[2:8]
v = dict(profile=p, seed=seed, commit="abc1234567", model_sha256="0123456789abcdef", min_mutual_distance_m=mutual,
         min_obstacle_distance_m=obstacle, min_obstacle_uav="1", min_obstacle_t_s="12.5", collisions=coll,
         requests_applied="25", requests_total="25", false_adaptations=false_ad, human_estimate_error_rms_m="0.15",
         min_human_distance_m="6.1", plans_hold="4", plans_fallback_brake="0", commands_stale="0",
         distance_error_rms_m="0.34", wall_time_s="30.0")
print(",".join(v[c] for c in cols))
P
}
{
  echo "$H"
  row nominal 1 6.50 1.05 0 0
  row nominal 2 6.10 0.98 0 1
  row loss50 1 2.40 1.00 0 0
} > "$TMP/runs.csv"
# A newer matrix in progress next to the runs file: reported by its safety figures, not in the tables.
{
  echo "$H"
  row nominal 1 5.90 0.91 0 0
  row loss50 1 3.20 0.88 0 0
} > "$TMP/fault_matrix_runs_next.csv"
GF_RUNS="$TMP/runs.csv" GF_REPORT="$TMP/reliability.md" GF_PROFILES="nominal loss50" tools/run_fault_matrix.sh --report-only \
  > "$TMP/out.txt"
R="$TMP/reliability.md"
fails=0
check() { grep -qF -- "$2" "$3" && echo "PASS: $1" || { echo "FAIL: $1: '$2' not in $3"; fails=$((fails + 1)); }; }
check "nominal row: 2 seeds, min / median / max mutual" '| `nominal` | 2 | 6.10 / 6.30 / 6.50 |' "$R"
check "the violation is named" 'loss50 seed 1: mutual 2.40 m' "$R"
check "the violation is counted" 'Safety violations (1 of 3 missions)' "$R"
check "false adaptations counted and named" 'False adaptations: 1 in the 3 missions** (`nominal` seed 2)' "$R"
check "missing seed listed" '`loss50` seed 2' "$R"
check "the summary line" '3 missions, 1 with a safety violation' "$TMP/out.txt"
check "the matrix in progress: its safety figures" 'fault_matrix_runs_next.csv` — 2 missions of commit(s) `abc1234567` (seeds up to 1): min mutual 3.20 m, min obstacle 0.880 m, 0 collisions — no safety violation so far.' "$R"
grep -q "fault_matrix_runs_next.csv\` (2 missions)" "$R" && { echo "FAIL: the matrix in progress is listed as an earlier commit's"; fails=$((fails + 1)); } || echo "PASS: not listed as an earlier commit's runs"
if [ -x /opt/gesture_formation/venv/bin/python ]; then
  [ -s "$TMP/images/fault_matrix.png" ] && echo "PASS: figure drawn" || { echo "FAIL: no $TMP/images/fault_matrix.png"; fails=$((fails + 1)); }
  check "figure linked" '](images/fault_matrix.png)' "$R"
fi
# Resuming onto a runs file with other columns is refused (exit 2), nothing appended.
printf 'profile,seed,other\nnominal,1,3\n' > "$TMP/other.csv"
set +e
GF_RUNS="$TMP/other.csv" GF_REPORT="$TMP/x.md" GF_MATRIX_DIR="$TMP/m" GFCTL=/bin/true GF_SEEDS=1 GF_PROFILES=nominal tools/run_fault_matrix.sh \
  > "$TMP/o2.txt" 2>&1
rc=$?
set -e
[ $rc -eq 2 ] && grep -q "other columns" "$TMP/o2.txt" && [ "$(wc -l < "$TMP/other.csv")" -eq 2 ] \
  && echo "PASS: a runs file with other columns is refused" || { echo "FAIL: other columns: rc $rc"; cat "$TMP/o2.txt"; fails=$((fails + 1)); }
exit $fails
