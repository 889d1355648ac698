#!/usr/bin/env bash
# Monte Carlo over the fault matrix (issue 9 item 4): the power-tower mission under every fault
# profile of config/faults/ for seeds 1..N, then the table of docs/reliability.md
# (faults × min mutual distance, min obstacle distance, collisions, requests applied, worker-
# estimate error; min / median / max over seeds).
#
#   tools/run_fault_matrix.sh                 # 100 seeds (the issue's figure), every profile
#   GF_SEEDS=10 tools/run_fault_matrix.sh     # 10 seeds
#   GF_PROFILES="loss50 harsh" tools/run_fault_matrix.sh
#   tools/run_fault_matrix.sh --report-only   # rewrite docs/reliability.md from what is in GF_MATRIX_DIR
#
# Seeds are the outer loop, so a run stopped early covers every profile evenly; a seed already
# done (its metrics.json exists) is skipped, so the script resumes. One mission at a time
# (~8-25 s wall each on 2 shared cores); GFCTL overrides the binary, GF_MATRIX_DIR the output
# (default build-faults/fault_matrix), GF_REPORT the table (default docs/reliability.md).
set -euo pipefail
cd "$(dirname "$0")/.."
SEEDS=${GF_SEEDS:-100}
GFCTL=${GFCTL:-build-faults/devel/lib/gesture_formation/gfctl}
OUT=${GF_MATRIX_DIR:-build-faults/fault_matrix}
REPORT=${GF_REPORT:-docs/reliability.md}
SCENARIO=config/scenarios/power_towers.yaml
PROFILES=${GF_PROFILES:-"nominal loss10 loss30 loss50 delay_jitter dup_reorder follower_dropout worker_lost_5s worker_lost_60s sensor_dropouts range_outliers gusts planner_outage harsh"}

if [ "${1:-}" != "--report-only" ]; then
  [ -x "$GFCTL" ] || { echo "run_fault_matrix.sh: $GFCTL not built (GF_BUILD_DIR=build-faults tools/build.sh gfctl)" >&2; exit 2; }
  mkdir -p "$OUT"
  for seed in $(seq 1 "$SEEDS"); do
    for p in $PROFILES; do
      dir="$OUT/$p/seed_$seed"
      [ -s "$dir/metrics.json" ] && continue
      "$GFCTL" simulate --scenario "$SCENARIO" --fault-profile "$p" --seed "$seed" --out "$dir" --no-plot \
        > "$OUT/$p.seed_$seed.log" 2>&1 || { echo "FAIL $p seed $seed (see $OUT/$p.seed_$seed.log)"; continue; }
      python3 -c "import json,sys; m=json.load(open(sys.argv[1])); print(f\"{sys.argv[2]:18s} seed {sys.argv[3]:>3s}: mutual {m['min_mutual_distance_m']:.2f} obstacle {m['min_obstacle_distance_m']:.2f} collisions {m['collisions']} applied {m['requests_applied']} est {m['human_estimate_error_rms_m']:.2f} wall {m['wall_time_s']:.1f}s\")" \
        "$dir/metrics.json" "$p" "$seed"
    done
  done
fi

python3 - "$OUT" "$REPORT" $PROFILES <<'PY'
import glob, json, os, statistics, sys, datetime
out, report, profiles = sys.argv[1], sys.argv[2], sys.argv[3:]
desc = {}
for p in profiles:
    path = f"config/faults/{p}.yaml"
    lines = []
    for line in (open(path) if os.path.exists(path) else []):
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("# ").strip())
    desc[p] = " ".join(lines)
cols = [("min_mutual_distance_m", "min mutual [m]", "{:.2f}"), ("min_obstacle_distance_m", "min obstacle [m]", "{:.2f}"),
        ("collisions", "collisions", "{:.0f}"), ("requests_applied", "requests applied", "{:.0f}"),
        ("human_estimate_error_rms_m", "estimate error RMS [m]", "{:.2f}")]
extra = [("min_human_distance_m", "min human [m]", "{:.2f}"), ("plans_hold", "hold plans", "{:.0f}"),
         ("plans_fallback_brake", "brake fallbacks", "{:.0f}"), ("commands_stale", "stale commands", "{:.0f}"),
         ("distance_error_rms_m", "distance error RMS [m]", "{:.2f}"), ("wall_time_s", "wall time [s]", "{:.1f}")]
rows, extra_rows, runs, violations = [], [], {}, []
def cell(vals, fmt):
    if not vals:
        return "–"
    return " / ".join(fmt.format(v) for v in (min(vals), statistics.median(vals), max(vals)))
for p in profiles:
    ms = []
    for f in sorted(glob.glob(f"{out}/{p}/seed_*/metrics.json")):
        m = json.load(open(f))
        ms.append(m)
        if m["min_mutual_distance_m"] < 2.5 or m["min_obstacle_distance_m"] < 0.5 or m["collisions"] != 0:
            violations.append(f"{p} seed {m['seed']}: mutual {m['min_mutual_distance_m']:.2f} m, obstacle "
                              f"{m['min_obstacle_distance_m']:.2f} m (UAV {m['min_obstacle_uav']} at {m['min_obstacle_t_s']:.1f} s), "
                              f"collisions {m['collisions']}")
    runs[p] = len(ms)
    get = lambda k: [float(m[k]) for m in ms if m.get(k) is not None]
    rows.append(f"| `{p}` | {len(ms)} | " + " | ".join(cell(get(k), fmt) for k, _, fmt in cols) + " |")
    extra_rows.append(f"| `{p}` | " + " | ".join(cell(get(k), fmt) for k, _, fmt in extra) + " |")
n = sorted(set(runs.values()))
total = sum(runs.values())
with open(report, "w") as f:
    f.write("# Reliability: the power-tower mission under faults (issue 9 item 4)\n\n")
    f.write("Written by `tools/run_fault_matrix.sh` (do not edit by hand) on "
            f"{datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M')} UTC. Mission: `config/scenarios/power_towers.yaml` "
            "(451 s, 3 UAVs, 25 requests), real planner, estimator, gesture LSTM; one fault profile "
            "(`config/faults/<name>.yaml`, `gfctl simulate --fault-profile NAME`) per row. The behaviour under each fault "
            "is stated in [safety.md](safety.md).\n\n")
    seeds = f"{n[0]}" if len(n) == 1 else f"{n[0]}–{n[-1]}"
    f.write(f"**Seeds run: {seeds} per profile (seeds 1..N; {total} missions).** The issue asks for 100 seeds "
            "× the matrix; the full run is `GF_SEEDS=100 tools/run_fault_matrix.sh` (resumes where a previous run stopped; "
            "~14 profiles × 100 × 8–25 s ≈ 3–10 h on one core).\n\n")
    f.write("Each cell: **min / median / max over seeds**. Safety thresholds: mutual ≥ Γ_dis 2.5 m, obstacle ≥ the "
            "planner's verification clearance 0.5 m (exact distance to the scenario's solids), 0 collisions. "
            "Requests applied counts operator + gesture commands applied (25 performed; 26 when a work motion fires one "
            "false adaptation); estimate error is the RMS of worker estimate − truth over camera frames.\n\n")
    f.write("| faults | seeds | " + " | ".join(h for _, h, _ in cols) + " |\n")
    f.write("|---|---|" + "---|" * len(cols) + "\n")
    f.write("\n".join(rows) + "\n\n")
    f.write("Diagnostics (min / median / max): min human distance (UAV centre – worker mid-body), replannings in hold "
            "mode, planner brake fallbacks, operator commands rejected as stale, UAV–worker distance error, wall time "
            "of one mission (2 cores shared with other work).\n\n")
    f.write("| faults | " + " | ".join(h for _, h, _ in extra) + " |\n")
    f.write("|---|" + "---|" * len(extra) + "\n")
    f.write("\n".join(extra_rows) + "\n\n")
    f.write("Profiles:\n\n" + "\n".join(f"- `{p}`: {desc[p]}" for p in profiles) + "\n\n")
    f.write("History: the first run of this matrix (seeds 1–4, the paper's priority rule — `faults.avoid_all_plans: "
            "false`: a UAV avoids only higher-priority plans and those flagged as fallback) had **two Γ_dis violations in "
            "52 missions**: `harsh` seed 3 (1.81 m) and `delay_jitter` seed 3 (2.25 m) — a follower braked, and the "
            "leader learned it too late over the delayed link. Cause and fix (every UAV avoids every plan, now the "
            "default): [safety.md](safety.md) §4. The tables above are with the fix.\n\n")
    if violations:
        f.write(f"**Safety violations ({len(violations)} of {total} missions):**\n\n" + "\n".join(f"- {v}" for v in violations)
                + "\n\nCauses and reproduction: [safety.md](safety.md) §4.\n")
    else:
        f.write(f"**No safety violation in the {total} missions** (no min mutual < 2.5 m, no obstacle distance < 0.5 m, "
                "no collision).\n")
print(f"wrote {report}: {total} missions, {len(violations)} with a safety violation")
for v in violations:
    print("  VIOLATION", v)
PY
