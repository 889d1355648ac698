"""Reports from the campaign store (tools/campaign.py report | compare | bench; docs/campaigns.md).

report: the fault-matrix tables and figure (docs/results/reliability.md, fault_matrix.png),
        the same figures the former tools/run_fault_matrix.sh computed from its runs file.
compare: commit A against commit B, per scenario, config and fault profile, on the missions
        both ran: every safety figure side by side, regressions flagged, differing missions listed.
bench:  the same small batch with 1, 2, ... local workers: missions per hour, speed-up and the
        scheduler's overhead per mission, appended with the date and the machine's load to
        docs/results/campaigns.md.
"""
import datetime
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from campaign_store import BASE_CONFIG_HASH, UNKNOWN_BINARY, Store

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Gamma_dis between UAVs, the planner's verification clearance to obstacles, and to the worker (UAV
# centre to his mid-body) the planner's worker safety distance 3.0 m (> Gamma_dis 2.5 m; issue 36:
# "0 violations of Gamma_dis to the worker"; docs/simulation.md's acceptance table, plot_fault_matrix.py).
# Rows of older stores without a figure are not judged on it.
THRESHOLDS = {"min_mutual_distance_m": 2.5, "min_obstacle_distance_m": 0.5, "min_human_distance_m": 3.0}

# ---- report -------------------------------------------------------------------------------
COLS = [("min_mutual_distance_m", "min mutual [m]", "{:.2f}"), ("min_obstacle_distance_m", "min obstacle [m]", "{:.2f}"),
        ("collisions", "collisions", "{:.0f}"), ("requests_applied", "requests applied", "{:.0f}"),
        ("human_estimate_error_rms_m", "estimate error RMS [m]", "{:.2f}")]
EXTRA = [("min_human_distance_m", "min human [m]", "{:.2f}"), ("plans_hold", "hold plans", "{:.0f}"),
         ("plans_fallback_brake", "brake fallbacks", "{:.0f}"), ("commands_stale", "stale commands", "{:.0f}"),
         ("false_adaptations", "false adaptations", "{:.0f}"), ("distance_error_rms_m", "distance error RMS [m]", "{:.2f}"),
         ("wall_time_s", "wall time [s]", "{:.1f}")]


def cell(vals, fmt):
    if not vals:
        return "–"
    return " / ".join(fmt.format(v) for v in (min(vals), statistics.median(vals), max(vals)))


def is_violation(m):
    return (any(m[k] < t for k, t in THRESHOLDS.items() if m.get(k) is not None) or m["collisions"] != 0)


def commit_time(commit):
    """Committer time of a commit (seconds) from git, None when git does not know it."""
    c = commit.split("-modified")[0]
    try:
        out = subprocess.run(["git", "-C", ROOT, "log", "-1", "--format=%ct", c], capture_output=True, text=True,
                             timeout=10)
        return int(out.stdout.strip()) if out.returncode == 0 and out.stdout.strip() else None
    except (OSError, ValueError, subprocess.TimeoutExpired):
        return None


def matrix_rows(store, scenario, profiles, commits=None):
    """Rows of the base config for the scenario and profiles; per commit and (profile, seed) one
    row (a commit run by two binaries: the row with a recorded binary, then the latest)."""
    marks = ",".join("?" * len(profiles))
    rows = store.rows(f"scenario = ? AND config_hash = ? AND profile IN ({marks})", [scenario, BASE_CONFIG_HASH] + profiles)
    if commits is not None:
        rows = [r for r in rows if any(r["source_commit"].startswith(c) for c in commits)]
    rows.sort(key=lambda r: (r["gfctl_sha256"] != UNKNOWN_BINARY, r["finished_utc"] or ""), reverse=True)
    seen, out = set(), []
    for r in rows:
        k = (r["source_commit"], r["profile"], r["seed"])
        if k not in seen:
            seen.add(k)
            out.append(r)
    return out


def default_commits(store, scenario, profiles, seeds):
    """The newest commit (git time) whose missions cover the campaign's profiles x seeds; else
    the commit with the most missions."""
    rows = matrix_rows(store, scenario, profiles)
    by_commit = {}
    for r in rows:
        by_commit.setdefault(r["source_commit"], set()).add((r["profile"], r["seed"]))
    if not by_commit:
        return []
    need = {(p, s) for p in profiles for s in seeds}
    complete = [c for c, got in by_commit.items() if need <= got]
    if complete:
        return [max(complete, key=lambda c: (commit_time(c) or 0, c))]
    return [max(by_commit, key=lambda c: len(by_commit[c]))]


def profile_description(scenario, profile):
    path = os.path.join(ROOT, os.path.dirname(scenario), "..", "faults", profile + ".yaml")
    lines = []
    for line in (open(path) if os.path.exists(path) else []):
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("# ").strip())
    return " ".join(lines)


def report(args, campaign):
    if campaign is None:
        raise SystemExit("campaign.py report: needs the campaign file (default config/campaigns/fault_matrix.yaml)")
    scenario, profiles, seeds = campaign["scenarios"][0], campaign["profiles"], campaign["seeds"]
    store = Store(args.store, create=False)
    try:
        commits = args.commit or default_commits(store, scenario, profiles, seeds)
        # --seeds selects the seeds of the tables too (the store may hold more of the same commit)
        wanted = set(seeds)
        all_rows = [r for r in matrix_rows(store, scenario, profiles, commits) if r["seed"] in wanted] if commits else []
        every = [r for r in matrix_rows(store, scenario, profiles) if r["seed"] in wanted]
        fails = [f for f in store.failures("scenario = ? AND config_hash = ?", (scenario, BASE_CONFIG_HASH))
                 if any(f["source_commit"].startswith(c) for c in commits)]
    finally:
        store.close()
    out = args.out
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    plot = args.plot or os.path.join(os.path.dirname(out), "fault_matrix.png")
    plot_rel = None
    try:
        import plot_fault_matrix
        if all_rows:
            plot_fault_matrix.draw(all_rows, profiles, plot)
            plot_rel = os.path.relpath(plot, os.path.dirname(os.path.abspath(out)))
    except ImportError as e:
        print(f"campaign.py report: no figure ({e}; the tools venv has matplotlib: tools/setup.sh)", file=sys.stderr)
    text, violations, total = render_report(all_rows, every, fails, commits, scenario, profiles, out, plot_rel,
                                            args.store)
    with open(out, "w") as f:
        f.write(text)
    print(f"wrote {out}: {total} missions, {len(violations)} with a safety violation")
    for v in violations:
        print("  VIOLATION", v)
    return 0


def render_report(all_rows, every, fails, commits, scenario, profiles, out, plot_rel, store_path):
    docs = os.path.relpath(os.path.join(ROOT, "docs"), os.path.dirname(os.path.abspath(out)))
    safety = os.path.join(docs, "safety.md") if docs != "." else "safety.md"
    store_rel = os.path.relpath(os.path.abspath(store_path), ROOT)
    rows, extra_rows, runs, violations = [], [], {}, []
    for p in profiles:
        ms = sorted((r for r in all_rows if r["profile"] == p), key=lambda r: r["seed"])
        for m in ms:
            if is_violation(m):
                violations.append(f"{p} seed {m['seed']:.0f}: mutual {m['min_mutual_distance_m']:.2f} m, obstacle "
                                  f"{m['min_obstacle_distance_m']:.2f} m (UAV {m['min_obstacle_uav']:.0f} at "
                                  f"{m['min_obstacle_t_s']:.1f} s), human {float('nan') if m.get('min_human_distance_m') is None else m['min_human_distance_m']:.2f} m, "
                                  f"collisions {m['collisions']:.0f}")
        runs[p] = len(ms)
        get = lambda k: [float(m[k]) for m in ms if m.get(k) is not None]  # noqa: E731
        rows.append(f"| `{p}` | {len(ms)} | " + " | ".join(cell(get(k), fmt) for k, _, fmt in COLS) + " |")
        extra_rows.append(f"| `{p}` | " + " | ".join(cell(get(k), fmt) for k, _, fmt in EXTRA) + " |")
    n = sorted(set(runs.values())) or [0]
    total = sum(runs.values())
    pairs = sorted({(r["source_commit"], r["model_sha256"][:16]) for r in all_rows})
    w = []
    w.append("# Reliability: the power-tower mission under faults (issue 9 item 4)\n\n")
    w.append(f"Written by `tools/campaign.py report` from the campaign store `{store_rel}` (do not edit by hand) on "
             f"{datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M')} UTC. Mission: `{scenario}` "
             "(451 s, 3 UAVs, 25 requests), real planner, estimator, gesture LSTM; one fault profile "
             "(`config/faults/<name>.yaml`, `gfctl simulate --fault-profile NAME`) per row. The behaviour under each "
             f"fault is stated in [safety.md]({safety}).\n\n")
    seeds_txt = f"{n[0]}" if len(n) == 1 else f"{n[0]}–{n[-1]}"
    w.append(f"**Seeds run: {seeds_txt} per profile ({total} missions).** The issue asks for 100 seeds × the matrix; "
             "the full run is `tools/campaign.py run config/campaigns/fault_matrix.yaml` (Dask, resumes from the store; "
             "14 profiles × 100 missions of 10–25 s CPU each on a fast core, 25–120 s on a slow one ≈ 4–10 CPU-hours; "
             "[campaigns.md](" + os.path.join(docs, "campaigns.md") + ")). Rows from (commit, model sha256 prefix): "
             + ", ".join(f"`{c[:10]}` / `{h}` ({sum(1 for r in all_rows if r['source_commit'] == c and r['model_sha256'][:16] == h)})"
                         for c, h in pairs) + ".\n\n")
    w.append("Each cell: **min / median / max over seeds**. Safety thresholds: mutual ≥ Γ_dis 2.5 m, obstacle ≥ the "
             "planner's verification clearance 0.5 m (exact distance to the scenario's solids), human (UAV centre to the "
             "worker's mid-body, in the diagnostics below) ≥ the planner's worker safety distance 3.0 m, 0 collisions. "
             "Requests applied counts operator + gesture commands applied (25 performed; 26 when a work motion fires one "
             "false adaptation); estimate error is the RMS of worker estimate − truth over camera frames.\n\n")
    w.append("| faults | seeds | " + " | ".join(h for _, h, _ in COLS) + " |\n")
    w.append("|---|---|" + "---|" * len(COLS) + "\n")
    w.append("\n".join(rows) + "\n\n")
    if plot_rel:
        w.append(f"![every mission's minimum distances per fault profile]({plot_rel})\n\n"
                 "(`tools/plot_fault_matrix.py`: one dot per mission, the bar at the median, the number at the minimum; "
                 "dashed: the safety thresholds.)\n\n")
    w.append("Diagnostics (min / median / max): min human distance (UAV centre – worker mid-body), replannings in hold "
             "mode, planner brake fallbacks, operator commands rejected as stale, gesture commands fired while the worker "
             "performed no gesture (false adaptations), UAV–worker distance error, wall time "
             "of one mission (2 cores shared with other work).\n\n")
    w.append("| faults | " + " | ".join(h for _, h, _ in EXTRA) + " |\n")
    w.append("|---|" + "---|" * len(EXTRA) + "\n")
    w.append("\n".join(extra_rows) + "\n\n")
    w.append("Profiles:\n\n" + "\n".join(f"- `{p}`: {profile_description(scenario, p)}" for p in profiles) + "\n\n")
    w.append("History: the first run of this matrix (seeds 1–4, the paper's priority rule — `faults.avoid_all_plans: "
             "false`: a UAV avoids only higher-priority plans and those flagged as fallback) had **two Γ_dis violations in "
             "52 missions**: `harsh` seed 3 (1.81 m) and `delay_jitter` seed 3 (2.25 m) — a follower braked, and the "
             f"leader learned it too late over the delayed link. Cause and fix (every UAV avoids every plan, now the "
             f"default): [safety.md]({safety}) §4. The tables above are with the fix.\n\n")
    w.append(other_commits_text(every, commits, safety))
    top = int(max((r["seed"] for r in all_rows), default=0))
    have = {(r["profile"], int(r["seed"])) for r in all_rows}
    missing = [f"`{p}` seed {k}" for p in profiles for k in range(1, top + 1) if (p, k) not in have]
    if missing:
        w.append(f"**Missions without a row** (seeds 1–{top}: did not finish, or not run yet): " + ", ".join(missing)
                 + f". See [safety.md]({safety}) §4.5 for missions that hung.\n\n")
    if fails:
        kinds = {}
        for f in fails:
            kinds[f["status"]] = kinds.get(f["status"], 0) + 1
        w.append(f"**Failed attempts stored for these commits: {len(fails)}** ("
                 + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())) + "; `tools/campaign.py failures` shows "
                 "their log tails).\n\n")
    if violations:
        w.append(f"**Safety violations ({len(violations)} of {total} missions):**\n\n" + "\n".join(f"- {v}" for v in violations)
                 + f"\n\nCauses and reproduction: [safety.md]({safety}) §4 (each violation found has its subsection there, "
                 "e.g. §4.4, §4.11).\n")
    else:
        w.append(f"**No safety violation in the {total} missions** (no min mutual < 2.5 m, no obstacle distance < 0.5 m, "
                 "no UAV within 3.0 m of the worker, no collision).\n")
    false_total = sum(int(r["false_adaptations"] or 0) for r in all_rows)
    false_missions = [f"`{r['profile']}` seed {r['seed']:.0f}" for r in sorted(all_rows, key=lambda r: (
        profiles.index(r["profile"]), r["seed"])) if (r["false_adaptations"] or 0) > 0]
    w.append(f"\n**False adaptations: {false_total} in the {total} missions**"
             + (" (" + ", ".join(false_missions) + ").\n" if false_missions else ".\n"))
    return "".join(w), violations, total


def other_commits_text(every, commits, safety):
    """One line per other commit of this matrix in the store: its missions and safety figures;
    commits newer than the tables' (git time) are marked as in progress."""
    chosen = [c for c in {r["source_commit"] for r in every} if any(c.startswith(x) for x in commits)]
    newest = max((commit_time(c) or 0 for c in chosen), default=0)
    by = {}
    for r in every:
        if r["source_commit"] not in chosen:
            by.setdefault(r["source_commit"], []).append(r)
    if not by:
        return ""
    lines = []
    for c, rs in sorted(by.items(), key=lambda kv: (-(commit_time(kv[0]) or 0), kv[0])):
        worst_m = min(r["min_mutual_distance_m"] for r in rs)
        worst_o = min(r["min_obstacle_distance_m"] for r in rs)
        worst_h = min((r["min_human_distance_m"] for r in rs if r.get("min_human_distance_m") is not None), default=None)
        coll = sum(int(r["collisions"]) for r in rs)
        t = commit_time(c)
        newer = t is not None and t > newest
        verdict = ("no safety violation" if not any(is_violation(r) for r in rs) else
                   f"**a safety violation: see [safety.md]({safety}) §4**")
        lines.append(f"- `{c[:10]}`{' (newer: in progress)' if newer else ''}: {len(rs)} missions (seeds up to "
                     f"{max(r['seed'] for r in rs)}): min mutual {worst_m:.2f} m, min obstacle {worst_o:.3f} m, "
                     f"min human {'–' if worst_h is None else format(worst_h, '.2f')} m, {coll} collisions — {verdict}")
    return ("Other commits of this matrix in the store (not in the tables; `tools/campaign.py compare A B` puts two "
            "side by side):\n\n" + "\n".join(lines) + "\n\n")


# ---- compare ------------------------------------------------------------------------------
# (column, label, better: "high" | "low", statistic of the worst case, regression tolerance)
SAFETY = [("min_mutual_distance_m", "min mutual [m]", "high", "min", 0.01),
          ("min_obstacle_distance_m", "min obstacle [m]", "high", "min", 0.01),
          ("collisions", "collisions", "low", "sum", 0),
          ("min_human_distance_m", "min human [m]", "high", "min", 0.01),
          ("requests_applied", "requests applied", "high", "min", 0),
          ("false_adaptations", "false adaptations", "low", "sum", 0),
          ("human_estimate_error_rms_m", "estimate error RMS [m]", "low", "max", 0.01),
          ("distance_error_rms_m", "distance error RMS [m]", "low", "max", 0.01),
          ("plans_fallback_brake", "brake fallbacks", "low", "sum", "5%"),
          ("commands_stale", "stale commands", "low", "sum", 0)]


def _tol(tol, a):
    """A tolerance: absolute, or "N%" of A's value."""
    if isinstance(tol, str):
        return abs(a) * float(tol.rstrip("%")) / 100.0
    return tol


def _stat(vals, how):
    if not vals:
        return None
    return {"min": min, "max": max, "sum": sum}[how](vals)


def _fmt(v):
    if v is None:
        return "–"
    return f"{v:.0f}" if float(v).is_integer() else f"{v:.2f}"


def _commit_rows(store, prefix, campaign):
    """(rows of the one commit named by prefix, restricted to the campaign, or an error message)."""
    rows = store.rows("source_commit LIKE ?", (prefix + "%",))
    full = sorted({r["source_commit"] for r in rows})
    if len(full) > 1:
        return None, f"{prefix!r} names several commits: {', '.join(full)}"
    if campaign:
        rows = [r for r in rows if r["scenario"] in campaign["scenarios"] and r["profile"] in campaign["profiles"]
                and r["seed"] in campaign["seeds"]]
    if not rows:
        return None, f"no missions of commit {prefix!r} in {store.path}" + (" for this campaign" if campaign else "")
    return rows, None


def _index(rows):
    """(scenario, config hash, profile, seed) -> row; of two binaries, the known one, then the latest."""
    out = {}
    for r in sorted(rows, key=lambda r: (r["gfctl_sha256"] != UNKNOWN_BINARY, r["finished_utc"] or "")):
        out[(r["scenario"], r["config_hash"], r["profile"], r["seed"])] = r
    return out


def _profile_cells(keys, ia, ib, prof, regressions):
    """The table cells of one profile: each SAFETY figure A → B, then the violations."""
    cells = []
    for col, label, better, how, tol in SAFETY:
        va = [ia[k][col] for k in keys if ia[k][col] is not None]
        vb = [ib[k][col] for k in keys if ib[k][col] is not None]
        sa, sb = _stat(va, how), _stat(vb, how)
        flag = ""
        if sa is not None and sb is not None:
            worse = (sa - sb) if better == "high" else (sb - sa)
            if worse > _tol(tol, sa) + 1e-12:
                flag = " ▼"
                regressions.append(f"{prof}: {label} {_fmt(sa)} → {_fmt(sb)}")
            elif -worse > _tol(tol, sa) + 1e-12:
                flag = " ▲"
        med = "" if how == "sum" or not va or not vb else \
            f" ({_fmt(statistics.median(va))} → {_fmt(statistics.median(vb))})"
        cells.append(f"{_fmt(sa)} → {_fmt(sb)}{flag}{med}")
    viol_a = sum(1 for k in keys if is_violation(ia[k]))
    viol_b = sum(1 for k in keys if is_violation(ib[k]))
    if viol_b > viol_a:
        regressions.append(f"{prof}: safety violations {viol_a} → {viol_b}")
    cells.append(f"{viol_a} → {viol_b}{' ▼' if viol_b > viol_a else (' ▲' if viol_b < viol_a else '')}")
    return cells


def _print_tables(common, ia, ib, order):
    """One table per (scenario, config); returns the regressions."""
    groups = {}
    for k in common:
        groups.setdefault(k[:3], []).append(k)
    rank = lambda p: (order.index(p) if order and p in order else len(order or []), p)  # noqa: E731
    header = "| profile | n | " + " | ".join(label for _, label, *_ in SAFETY) + " | violations |"
    regressions, last = [], None
    for (sc, cfg, prof), keys in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1], rank(kv[0][2]))):
        if (sc, cfg) != last:
            print(f"\n{sc}, config {cfg[:8]}:\n\n{header}\n|---|---|" + "---|" * (len(SAFETY) + 1))
            last = (sc, cfg)
        print(f"| `{prof}` | {len(keys)} | " + " | ".join(_profile_cells(keys, ia, ib, prof, regressions)) + " |")
    return regressions


def _worse_missions(common, ia, ib):
    """(number of missions differing in a safety figure, those worse in B: new violations first,
    then by the first SAFETY figure that got worse, most first)."""
    differing, worse = 0, []
    for k in common:
        a, b = ia[k], ib[k]
        changes = []
        for i, (col, label, better, how, tol) in enumerate(SAFETY):
            if a[col] is None or b[col] is None or abs(a[col] - b[col]) <= 1e-9:
                continue
            d = (a[col] - b[col]) if better == "high" else (b[col] - a[col])
            changes.append((d, i, label, a[col], b[col], _tol(tol, a[col])))
        if not changes:
            continue
        differing += 1
        bad = [c for c in changes if c[0] > c[5] + 1e-12]
        if bad or is_violation(b) != is_violation(a):
            first = bad[0] if bad else changes[0]
            worse.append((is_violation(b) and not is_violation(a), first[1], -first[0], k, bad))
    worse.sort(key=lambda t: (not t[0], t[1], t[2]))
    return differing, worse


def compare(args, campaign):
    store = Store(args.store, create=False)
    try:
        (rows_a, err_a), (rows_b, err_b) = _commit_rows(store, args.a, campaign), _commit_rows(store, args.b, campaign)
    finally:
        store.close()
    if err_a or err_b:
        print(f"campaign.py compare: {err_a or err_b}", file=sys.stderr)
        return 2
    ia, ib = _index(rows_a), _index(rows_b)
    common = sorted(set(ia) & set(ib))
    print(f"compare A = {rows_a[0]['source_commit'][:10]} ({len(ia)} missions) vs B = {rows_b[0]['source_commit'][:10]} "
          f"({len(ib)} missions): {len(common)} missions in both, {len(set(ia) - set(ib))} only in A, "
          f"{len(set(ib) - set(ia))} only in B")
    print("each cell: A → B over the missions both ran (worst case: the minimum of a distance, the sum of a count, "
          "the maximum of an error; median in brackets); ▼ a regression beyond the tolerance, ▲ an improvement")
    regressions = _print_tables(common, ia, ib, campaign["profiles"] if campaign else None)
    print(f"\nregressions: {len(regressions)}" + (":\n" + "\n".join(f"  ▼ {r}" for r in regressions) if regressions else ""))
    differing, worse = _worse_missions(common, ia, ib)
    print(f"\nmissions that differ in a safety figure: {differing} of {len(common)}; worse in B beyond the tolerance: "
          f"{len(worse)}" + (f" (the {min(args.limit, len(worse))} worst):" if worse else ""))
    for new_violation, _, _, k, bad in worse[:args.limit]:
        what = ", ".join(f"{label} {_fmt(va)} → {_fmt(vb)}" for _, _, label, va, vb, _ in bad)
        print(f"  {os.path.basename(k[0])} {k[2]} seed {k[3]} config {k[1][:8]}: {what}"
              + ("  NEW SAFETY VIOLATION" if new_violation else ""))
    return 0


# ---- cameras: synthetic vs rendered ------------------------------------------------------------
CAMERA_FIGURES = [  # (metrics.json key, label, format)
    ("collisions", "collisions", "d"), ("min_mutual_distance_m", "min mutual [m]", ".2f"),
    ("min_obstacle_distance_m", "min obstacle [m]", ".2f"), ("min_human_distance_m", "min human [m]", ".2f"),
    ("requests_applied", "requests applied", "d"), ("gestures_successful", "gestures successful", "d"),
    ("gestures_performed", "of performed", "d"), ("gesture_mean_latency_s", "latency [s]", ".2f"),
    ("false_adaptations", "false adaptations", "d"), ("human_estimate_error_rms_m", "estimate error [m]", ".2f"),
]


def _camera_of(row):
    return json.loads(row["config_json"]).get("camera", "synthetic")


def cameras(args, campaign):
    """Per seed and camera (gfctl simulate --camera; the campaign field `camera`): the safety and gesture
    figures of one commit's missions side by side, and the rendered missions' perception by distance and
    by camera elevation. With --out also a results page (a header naming the store, then the same text)."""
    store = Store(args.store, create=False)
    try:
        prefix = args.commit or (store.commits()[0][0] if store.commits() else "")
        rows, err = _commit_rows(store, prefix, campaign)
    finally:
        store.close()
    if err:
        print(f"campaign.py cameras: {err}", file=sys.stderr)
        return 2
    by = {}
    for r in rows:
        by.setdefault((r["scenario"], r["profile"], r["seed"]), {})[_camera_of(r)] = json.loads(r["metrics_json"] or "{}")
    modes = sorted({_camera_of(r) for r in rows}, key=lambda m: (m != "synthetic", m))
    out = [f"commit {rows[0]['source_commit'][:10]}: {len(rows)} missions; each cell: " + " | ".join(modes), "",
           "| scenario | profile | seed | " + " | ".join(label for _, label, _ in CAMERA_FIGURES) + " |",
           "|" + " --- |" * (3 + len(CAMERA_FIGURES))]
    for (scenario, profile, seed), per in sorted(by.items()):
        cells = []
        for key, _, fmt in CAMERA_FIGURES:
            vals = [per.get(m, {}).get(key) for m in modes]
            cells.append(" / ".join("–" if v is None else format(v, fmt) for v in vals))
        out.append(f"| {os.path.basename(scenario)} | {profile} | {seed} | " + " | ".join(cells) + " |")
    rendered = [(k, per["rendered"]["perception"]) for k, per in sorted(by.items())
                if "perception" in per.get("rendered", {})]
    for key, unit, title in (("by_distance_m", "m", "distance"), ("by_elevation_deg", "deg", "camera elevation")):
        if not rendered:
            break
        out += ["", "rendered camera, perception against the truth (detection rate / keypoint error as a fraction of "
                    f"the figure (frames)) by {title}:", ""]
        for (scenario, profile, seed), p in rendered:
            bins = ", ".join(f"{b['bin']} {unit}: {_fmt(b['detection_rate'])} / {_fmt(b['keypoint_error_fraction_median'])} "
                             f"({b['frames']})" for b in p.get(key, []))
            out.append(f"- {os.path.basename(scenario)} {profile} seed {seed}: {bins}; identity switches "
                       f"{p['identity_switches']}")
    print("\n".join(out))
    if getattr(args, "out", None):
        commit = rows[0]["source_commit"][:10]
        header = ["# Camera campaign: synthetic vs rendered cameras" + (f" ({os.path.relpath(args.campaign, ROOT)})" if args.campaign else ""),
                  "",
                  f"Written by `tools/campaign.py --store {os.path.relpath(args.store, ROOT)} cameras"
                  + (f" {os.path.relpath(args.campaign, ROOT)}" if args.campaign else "")
                  + (f" --commit {args.commit}" if args.commit else "") + f" --out {os.path.relpath(args.out, ROOT)}` on "
                  f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} from the missions of commit {commit} in the store "
                  f"(one worker at nice 19 on a shared 2-core machine). Nothing was tuned on these seeds. "
                  f"Gestures on rendered pixels: docs/results/gestures_rendered.md (issue 33).", ""]
        with open(args.out, "w") as f:
            f.write("\n".join(header + out) + "\n")
    return 0


# ---- bench --------------------------------------------------------------------------------
def _loadavg():
    try:
        return open("/proc/loadavg").read().split()[:3]
    except OSError:
        return ["?", "?", "?"]


def _cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "?"


def bench(args, run_campaign):
    counts = [int(x) for x in args.workers_list.split(",") if x.strip()]
    if not counts or min(counts) < 1:
        print(f"campaign.py bench: --workers-list: expected worker counts >= 1, got {args.workers_list!r}", file=sys.stderr)
        return 2
    scratch = tempfile.mkdtemp(prefix="bench_", dir=os.path.abspath(args.work_dir) if os.path.isdir(args.work_dir) else None)
    results = []
    try:
        for n in counts:
            load0 = _loadavg()
            args.workers, args.store, args.scheduler, args.dry_run = n, os.path.join(scratch, f"w{n}.sqlite"), None, False
            rc, summary = run_campaign(args)
            if summary is None or rc != 0:
                print(f"campaign.py bench: the run with {n} worker(s) did not finish cleanly (exit {rc})", file=sys.stderr)
                return 1
            results.append((n, summary, load0, _loadavg()))
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    base = results[0][1]["missions_per_hour"]
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M")
    from campaign import source_commit  # noqa: the CLI module (bench is only called from it)
    lines = [f"\n## {now} UTC: `{os.path.relpath(os.path.abspath(args.campaign), ROOT)}`, commit "
             f"`{source_commit()[:10]}`\n\n",
             f"Machine: {os.cpu_count()} cores ({_cpu_model()}); local Dask cluster on 127.0.0.1, one thread per worker "
             "process, one gfctl mission per worker at a time. The machine is shared with other engineers' builds and "
             "tests: the load average (1/5/15 min) before and after each run is given; figures under load are lower "
             "bounds of what the tool does on an idle machine.\n\n",
             "| workers | missions | wall [s] | missions/hour | speed-up vs first | mean mission [s] | scheduler overhead "
             "per mission [ms] | overhead [% of a mission] | gap between missions median / max [ms] | worker start-up [s] | "
             "load before | load after |\n",
             "|---|---|---|---|---|---|---|---|---|---|---|---|\n"]
    for n, s, l0, l1 in results:
        ov = s["overhead"] or {}
        lines.append(f"| {n} | {s['done']} | {s['wall_s']:.1f} | {s['missions_per_hour']:.0f} | "
                     f"{s['missions_per_hour'] / base:.2f}× | {ov.get('mean_mission_s', float('nan')):.2f} | "
                     f"{ov.get('overhead_s', float('nan')) * 1000:.0f} | {ov.get('overhead_pct', float('nan')):.2f} | "
                     f"{ov.get('gap_median_s', float('nan')) * 1000:.0f} / {ov.get('gap_max_s', float('nan')) * 1000:.0f} | "
                     f"{ov.get('startup_s', float('nan')):.2f} | "
                     f"{' '.join(l0)} | {' '.join(l1)} |\n")
    for n, s, _, _ in results:
        print(f"bench: {n} worker(s): {s['missions_per_hour']:.0f} missions/hour ({s['missions_per_hour'] / base:.2f}× the "
              f"first), overhead {(s['overhead'] or {}).get('overhead_pct', float('nan')):.2f} % of a mission")
    new = not os.path.exists(args.results)
    os.makedirs(os.path.dirname(os.path.abspath(args.results)), exist_ok=True)
    with open(args.results, "a") as f:
        if new:
            f.write("# Campaign throughput and scheduler overhead (written by `tools/campaign.py bench`)\n\n"
                    "Each section: the same missions run into a fresh scratch store once per worker count. Missions per "
                    "hour = missions / (first submission → last result); scheduler overhead per mission = the time a "
                    "worker spends between one mission's end and the next one's start plus the task's own time outside "
                    "gfctl, averaged over the missions after each worker's first; worker start-up = the first task's time "
                    "outside gfctl (hashing gfctl and its libraries once per worker process; docs/campaigns.md §6).\n")
        f.write("".join(lines))
    print(f"appended to {args.results}")
    return 0
