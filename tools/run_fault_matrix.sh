#!/usr/bin/env bash
# Monte Carlo over the fault matrix (issue 9 item 4): the power-tower mission under every fault
# profile of config/faults/ for seeds 1..N, then the table of docs/reliability.md
# (faults × min mutual distance, min obstacle distance, collisions, requests applied, worker-
# estimate error; min / median / max over seeds).
#
#   tools/run_fault_matrix.sh                 # 100 seeds (the issue's figure), every profile
#   GF_SEEDS=10 tools/run_fault_matrix.sh     # 10 seeds
#   GF_PROFILES="loss50 harsh" tools/run_fault_matrix.sh
#   tools/run_fault_matrix.sh --report-only   # rewrite docs/reliability.md from the runs file
#
# Every finished mission appends one row (profile, seed, source commit, model sha256, metrics) to
# the committed runs file docs/data/fault_matrix_runs.csv (GF_RUNS), and the report is computed
# from that file: the ~1400 missions (≈ 4–10 CPU-hours) can be spread over sessions and machines. A
# (profile, seed) already in the file is skipped, so the script resumes; start afresh after a change
# that can move the figures (planner, simulator, model) by removing the file (the report lists the
# commits its rows come from; older runs files kept as docs/data/fault_matrix_runs_<commit>.csv are
# listed, and a newer matrix still running, kept as docs/data/fault_matrix_runs_next*.csv, is
# reported by its safety figures so far, not in the tables). Seeds are the outer loop, so a run stopped early covers every profile
# evenly. GF_JOBS missions run at once (default: the number of cores), each classifying its camera
# views on one thread when the jobs fill the cores (gfctl simulate --threads; results do not depend
# on it); GFCTL overrides the binary,
# GF_MATRIX_DIR the missions' output (default build-faults/fault_matrix), GF_REPORT the table
# (default docs/reliability.md), GF_PLOT its figure (default docs/images/fault_matrix.png, drawn by
# tools/plot_fault_matrix.py with the tools venv's matplotlib).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac  # the comment above
set -euo pipefail
cd "$(dirname "$0")/.."
SEEDS=${GF_SEEDS:-100}
GFCTL=${GFCTL:-build-faults/devel/lib/gesture_formation/gfctl}
OUT=${GF_MATRIX_DIR:-build-faults/fault_matrix}
REPORT=${GF_REPORT:-docs/reliability.md}
RUNS=${GF_RUNS:-docs/data/fault_matrix_runs.csv}
JOBS=${GF_JOBS:-$(nproc)}
THREADS=()
[ "$JOBS" -ge "$(nproc)" ] && THREADS=(--threads 1)
SCENARIO=config/scenarios/power_towers.yaml
PROFILES=${GF_PROFILES:-"nominal loss10 loss30 loss50 delay_jitter dup_reorder follower_dropout worker_lost_5s worker_lost_60s sensor_dropouts range_outliers gusts planner_outage harsh"}
COLUMNS_CSV="profile,seed,commit,model_sha256,min_mutual_distance_m,min_obstacle_distance_m,min_obstacle_uav,min_obstacle_t_s,collisions,requests_applied,requests_total,false_adaptations,human_estimate_error_rms_m,min_human_distance_m,plans_hold,plans_fallback_brake,commands_stale,distance_error_rms_m,wall_time_s"

if [ "${1:-}" != "--report-only" ]; then
  [ -x "$GFCTL" ] || { echo "run_fault_matrix.sh: $GFCTL not built (GF_BUILD_DIR=build-faults tools/build.sh gfctl)" >&2; exit 2; }
  mkdir -p "$OUT" "$(dirname "$RUNS")"
  [ -s "$RUNS" ] || echo "$COLUMNS_CSV" > "$RUNS"
  [ "$(head -1 "$RUNS")" = "$COLUMNS_CSV" ] || { echo "run_fault_matrix.sh: $RUNS has other columns; move it away to start afresh" >&2; exit 2; }
  COMMIT=$(git rev-parse --short=10 HEAD 2>/dev/null || echo unknown)
  git diff --quiet HEAD -- src include config third_party_models 2>/dev/null || COMMIT="$COMMIT-modified"
  MODEL_SHA=$(sha256sum third_party_models/gesture_lstm/gesture_lstm.onnx | cut -c1-16)
  one() {  # one PROFILE SEED: run the mission, append its row (under a lock: jobs run in parallel)
    local p=$1 seed=$2 dir="$OUT/$1/seed_$2"
    rm -rf "$dir"
    "$GFCTL" simulate --scenario "$SCENARIO" --fault-profile "$p" --seed "$seed" --out "$dir" --no-plot "${THREADS[@]}" \
      > "$OUT/$p.seed_$seed.log" 2>&1 || { echo "FAIL $p seed $seed (see $OUT/$p.seed_$seed.log)"; return 0; }
    python3 - "$dir/metrics.json" "$p" "$seed" "$COMMIT" "$MODEL_SHA" "$COLUMNS_CSV" "$RUNS" <<'ROW'
import fcntl, json, sys
m = json.load(open(sys.argv[1]))
p, seed, commit, sha, cols, runs = sys.argv[2:8]
m.update(profile=p, seed=seed, commit=commit, model_sha256=sha)
row = ",".join("" if m.get(c) is None else str(m[c]) for c in cols.split(","))
with open(runs, "a") as f:
    fcntl.flock(f, fcntl.LOCK_EX)
    f.write(row + "\n")
print(f"{p:18s} seed {seed:>3s}: mutual {m['min_mutual_distance_m']:.2f} obstacle {m['min_obstacle_distance_m']:.2f} "
      f"collisions {m['collisions']} applied {m['requests_applied']} est {m['human_estimate_error_rms_m']:.2f} "
      f"wall {m['wall_time_s']:.1f}s", flush=True)
ROW
  }
  done_pairs=$(python3 -c "import csv, sys; print(' '.join(r['profile'] + ':' + r['seed'] for r in csv.DictReader(open(sys.argv[1]))))" "$RUNS")
  running=0
  for seed in $(seq 1 "$SEEDS"); do
    for p in $PROFILES; do
      case " $done_pairs " in *" $p:$seed "*) continue ;; esac
      one "$p" "$seed" &
      running=$((running + 1))
      if [ "$running" -ge "$JOBS" ]; then wait -n || true; running=$((running - 1)); fi
    done
  done
  wait
fi

PLOT=${GF_PLOT:-$(dirname "$REPORT")/images/fault_matrix.png}
PY_VENV=/opt/gesture_formation/venv/bin/python
PLOT_REL=""
if [ -x "$PY_VENV" ]; then
  mkdir -p "$(dirname "$PLOT")"
  "$PY_VENV" tools/plot_fault_matrix.py "$RUNS" "$PLOT" $PROFILES && PLOT_REL=$(realpath --relative-to="$(dirname "$REPORT")" "$PLOT")
fi
GF_PLOT_REL="$PLOT_REL" python3 - "$RUNS" "$REPORT" $PROFILES <<'PY'
import csv, json, os, statistics, sys, datetime
runs_file, report, profiles = sys.argv[1], sys.argv[2], sys.argv[3:]
def number(v):
    try:
        return float(v)
    except ValueError:
        return None
all_rows = [{k: (v if k in ("profile", "commit", "model_sha256") else number(v)) for k, v in r.items()}
            for r in csv.DictReader(open(runs_file))]
commits = sorted({(r["commit"], r["model_sha256"]) for r in all_rows})
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
         ("false_adaptations", "false adaptations", "{:.0f}"), ("distance_error_rms_m", "distance error RMS [m]", "{:.2f}"),
         ("wall_time_s", "wall time [s]", "{:.1f}")]
rows, extra_rows, runs, violations = [], [], {}, []
def cell(vals, fmt):
    if not vals:
        return "–"
    return " / ".join(fmt.format(v) for v in (min(vals), statistics.median(vals), max(vals)))
for p in profiles:
    ms = []
    for m in sorted((r for r in all_rows if r["profile"] == p), key=lambda r: r["seed"]):
        ms.append(m)
        if m["min_mutual_distance_m"] < 2.5 or m["min_obstacle_distance_m"] < 0.5 or m["collisions"] != 0:
            violations.append(f"{p} seed {m['seed']:.0f}: mutual {m['min_mutual_distance_m']:.2f} m, obstacle "
                              f"{m['min_obstacle_distance_m']:.2f} m (UAV {m['min_obstacle_uav']:.0f} at {m['min_obstacle_t_s']:.1f} s), "
                              f"collisions {m['collisions']:.0f}")
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
    f.write(f"**Seeds run: {seeds} per profile ({total} missions).** The issue asks for 100 seeds "
            "× the matrix; the full run is `GF_SEEDS=100 tools/run_fault_matrix.sh` (resumes from the committed runs file "
            "`docs/data/fault_matrix_runs.csv`; 14 profiles × 100 missions of 10–25 s CPU each on a fast core, 25–120 s "
            "on a slow one ≈ 4–10 CPU-hours). Rows from (commit, model "
            "sha256 prefix): " + ", ".join(f"`{c}` / `{h}` ({sum(1 for r in all_rows if r['commit'] == c and r['model_sha256'] == h)})"
                                          for c, h in commits) + ".\n\n")
    f.write("Each cell: **min / median / max over seeds**. Safety thresholds: mutual ≥ Γ_dis 2.5 m, obstacle ≥ the "
            "planner's verification clearance 0.5 m (exact distance to the scenario's solids), 0 collisions. "
            "Requests applied counts operator + gesture commands applied (25 performed; 26 when a work motion fires one "
            "false adaptation); estimate error is the RMS of worker estimate − truth over camera frames.\n\n")
    f.write("| faults | seeds | " + " | ".join(h for _, h, _ in cols) + " |\n")
    f.write("|---|---|" + "---|" * len(cols) + "\n")
    f.write("\n".join(rows) + "\n\n")
    if os.environ.get("GF_PLOT_REL"):
        f.write(f"![every mission's minimum distances per fault profile]({os.environ['GF_PLOT_REL']})\n\n"
                "(`tools/plot_fault_matrix.py`: one dot per mission, the bar at the median, the number at the minimum; "
                "dashed: the safety thresholds.)\n\n")
    f.write("Diagnostics (min / median / max): min human distance (UAV centre – worker mid-body), replannings in hold "
            "mode, planner brake fallbacks, operator commands rejected as stale, gesture commands fired while the worker "
            "performed no gesture (false adaptations), UAV–worker distance error, wall time "
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
    import glob
    runs_dir = os.path.dirname(runs_file) or "."
    pending = sorted(glob.glob(os.path.join(runs_dir, "fault_matrix_runs_next*.csv")))
    archived = sorted(a for a in glob.glob(os.path.join(runs_dir, "fault_matrix_runs_*.csv")) if a not in pending)
    for a in pending:  # the matrix of newer defaults, still running: its safety figures so far
        rows = list(csv.DictReader(open(a)))
        if not rows:
            continue
        worst_m = min(float(r["min_mutual_distance_m"]) for r in rows)
        worst_o = min(float(r["min_obstacle_distance_m"]) for r in rows)
        coll = sum(int(float(r["collisions"])) for r in rows)
        f.write(f"**In progress, not in the tables:** `{os.path.relpath(a)}` — {len(rows)} missions of commit(s) "
                + ", ".join(sorted({f"`{r['commit']}`" for r in rows})) + f" (seeds up to {max(int(r['seed']) for r in rows)}): "
                f"min mutual {worst_m:.2f} m, min obstacle {worst_o:.3f} m, {coll} collisions"
                + (" — no safety violation so far." if worst_m >= 2.5 and worst_o >= 0.5 and coll == 0 else
                   " — **a safety violation: see safety.md §4.**") + "\n\n")
    if archived:
        f.write("Runs of earlier commits (kept, not in the tables): " + ", ".join(
            f"`{os.path.relpath(a)}` ({sum(1 for _ in open(a)) - 1} missions)" for a in archived) + ".\n\n")
    top = int(max((r["seed"] for r in all_rows), default=0))
    missing = [f"`{p}` seed {k}" for p in profiles for k in range(1, top + 1)
               if not any(r["profile"] == p and int(r["seed"]) == k for r in all_rows)]
    if missing:
        f.write(f"**Missions without a row** (seeds 1–{top}: did not finish, or not run yet): " + ", ".join(missing)
                + ". See [safety.md](safety.md) §4.5 for missions that hung.\n\n")
    if violations:
        f.write(f"**Safety violations ({len(violations)} of {total} missions):**\n\n" + "\n".join(f"- {v}" for v in violations)
                + "\n\nCauses and reproduction: [safety.md](safety.md) §4 (each violation found has its subsection there, e.g. §4.4, §4.11).\n")
    else:
        f.write(f"**No safety violation in the {total} missions** (no min mutual < 2.5 m, no obstacle distance < 0.5 m, "
                "no collision).\n")
    false_total = sum(int(r["false_adaptations"] or 0) for r in all_rows)
    false_missions = [f"`{r['profile']}` seed {r['seed']:.0f}" for r in all_rows if (r["false_adaptations"] or 0) > 0]
    f.write(f"\n**False adaptations: {false_total} in the {total} missions**"
            + (" (" + ", ".join(false_missions) + ").\n" if false_missions else ".\n"))
print(f"wrote {report}: {total} missions, {len(violations)} with a safety violation")
for v in violations:
    print("  VIOLATION", v)
PY
