#!/usr/bin/env python3
"""docs/results/leader_handover.md from the leader-dropout missions of a campaign store
(tools/campaign.py run config/campaigns/mission_safety.yaml --profiles leader_dropout_5s,...).

Per profile (leader_dropout_5s, leader_dropout_60s, leader_dropout_for_good) over the stored seeds,
from each mission's metrics.json `leadership` section and its safety figures: the time from the
silence to a new acting leader (distribution, and against the limit silence_limit_s +
candidacy_stagger_s + 2 election_timeout_s), which UAV took over, the most UAVs acting at one step
(must be 1) and the steps with two acting (must be 0), the operator requests sent after the
hand-over and how many were applied, the worker's gestures applied and the false adaptations, collisions, the least mutual distance (Gamma_dis 2.5 m), the
least worker distance (Gamma_dis) and obstacle distance (0.5 m), the tracking errors, the wall time
per mission.

With --baseline STORE (and --baseline-commit PREFIX), a last section compares, per profile over the
seeds both stores hold, the medians and extremes of the tracking and safety figures of the two
(e.g. before / after a planner change).

  tools/handover_report.py --store FILE [--out docs/results/leader_handover.md] [--commit PREFIX]
                           [--seeds A..B] [--title TEXT] [--load "2 workers at a time, 1-min load 8-12 on 2 cores"]
                           [--baseline FILE --baseline-commit PREFIX]
"""
import argparse
import datetime
import json
import os
import sqlite3
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from campaign import BadInput, parse_seeds  # noqa: E402  the campaign file's seeds rule ("A..B")

PROFILES = ["leader_dropout_5s", "leader_dropout_60s", "leader_dropout_for_good"]
GAMMA_DIS_M = 2.5
CLEARANCE_M = 0.5
LIMIT_S = 2.0 + 0.5 + 2 * 1.0  # formation::LeadershipConfig defaults (the power-tower mission sets none)


def dist(values, fmt="{:.2f}"):
    vals = sorted(v for v in values if v is not None)
    if not vals:
        return "none"
    pick = lambda q: vals[min(len(vals) - 1, int(q * (len(vals) - 1) + 0.5))]
    return " / ".join(fmt.format(v) for v in (vals[0], pick(0.5), pick(0.95), vals[-1]))


def load(store, commit, seeds=None):
    con = sqlite3.connect(f"file:{store}?mode=ro", uri=True)
    con.row_factory = sqlite3.Row
    q = "SELECT profile, seed, source_commit, finished_utc, mission_s, metrics_json FROM missions WHERE profile LIKE 'leader_dropout%'"
    params = ()
    if commit:
        q += " AND source_commit LIKE ?"
        params = (commit + "%",)
    if seeds:
        q += f" AND seed IN ({','.join('?' * len(seeds))})"
        params += tuple(seeds)
    rows = [dict(r) for r in con.execute(q + " ORDER BY profile, seed", params)]
    fails = [dict(r) for r in con.execute(
        "SELECT profile, seed, status, exit_code FROM failures WHERE profile LIKE 'leader_dropout%'")]
    con.close()
    return rows, fails


def profile_section(name, rows):
    ms = [json.loads(r["metrics_json"]) for r in rows]
    ls = [m.get("leadership") or {} for m in ms]
    n = len(ms)
    out = [f"## {name}", "", f"Seeds: {n} ({', '.join(str(r['seed']) for r in rows) if n <= 30 else str(min(r['seed'] for r in rows)) + '..' + str(max(r['seed'] for r in rows))})", ""]
    if not n:
        return out + ["No missions stored.", ""]
    ho = [l.get("handover_s") for l in ls]
    within = sum(1 for h in ho if h is not None and h <= LIMIT_S)
    leaders = {}
    for l in ls:
        leaders[l.get("new_leader")] = leaders.get(l.get("new_leader"), 0) + 1
    req = sum(l.get("requests_after", 0) for l in ls)
    req_ok = sum(l.get("requests_after_applied", 0) for l in ls)
    incomplete = sum(1 for l in ls if l.get("requests_after_applied", 0) != l.get("requests_after", 0))
    performed = sum(m.get("gestures_performed", 0) for m in ms)
    fired = sum(m.get("gesture_requests_applied", 0) for m in ms)
    missed = [str(r["seed"]) for r, m in zip(rows, ms) if m.get("gesture_requests_applied", 0) < m.get("gestures_performed", 0)]
    out += [
        "| figure | value |",
        "|---|---|",
        f"| new acting leader after the silence [s] (min / median / 95 % / max) | {dist(ho)} |",
        f"| within the limit {LIMIT_S:.1f} s | {within} of {n} |",
        f"| the new leader (UAV: missions) | {', '.join(f'{k}: {v}' for k, v in sorted(leaders.items(), key=lambda kv: str(kv[0])))} |",
        f"| most UAVs acting at one step (max over seeds) | {max(l.get('max_acting', 0) for l in ls)} |",
        f"| steps with two acting (sum over seeds) | {sum(l.get('steps_two_acting', 0) for l in ls)} |",
        f"| the silent leader's last acting step after the silence [s] (max) | {max((l['silenced_last_acting_s'] - l['silent_from_s']) for l in ls if l.get('silenced_last_acting_s') is not None):.2f} |",
        f"| operator requests sent after the hand-over: applied / sent (missions with one not applied) | {req_ok} / {req} ({incomplete}) |",
        f"| the worker's gestures (whole mission): applied / performed (seeds with one not applied) | {fired} / {performed} "
        f"({', '.join(missed) if missed else 'none'}) |",
        f"| false adaptations: commands no gesture asked for (sum; seeds with one) | {sum(m.get('false_adaptations', 0) for m in ms)} "
        f"({', '.join(str(r['seed']) for r, m in zip(rows, ms) if m.get('false_adaptations', 0)) or 'none'}) |",
        f"| collisions (sum) | {sum(m['collisions'] for m in ms)} |",
        f"| min mutual distance [m] (min / median / 95 % / max over seeds; Γ_dis {GAMMA_DIS_M}) | {dist([m['min_mutual_distance_m'] for m in ms])} |",
        f"| seeds with mutual distance < Γ_dis | {sum(1 for m in ms if m['min_mutual_distance_m'] < GAMMA_DIS_M)} |",
        f"| min worker distance [m] (Γ_dis {GAMMA_DIS_M}) | {dist([m['min_human_distance_m'] for m in ms])} |",
        f"| seeds with worker distance < Γ_dis | {sum(1 for m in ms if m['min_human_distance_m'] < GAMMA_DIS_M)} |",
        f"| min obstacle distance [m] ({CLEARANCE_M}) | {dist([m['min_obstacle_distance_m'] for m in ms])} |",
        f"| distance error rms [m] | {dist([m['distance_error_rms_m'] for m in ms])} |",
        f"| angle error rms [deg] | {dist([m['angle_error_rms_deg'] for m in ms])} |",
        f"| brake fallbacks per mission | {dist([m['plans_fallback_brake'] for m in ms], '{:.0f}')} |",
        f"| wall time per mission [s] | {dist([r['mission_s'] for r in rows], '{:.0f}')} |",
        "",
    ]
    return out


COMPARED = [("distance error rms [m]", "distance_error_rms_m", "{:.2f}"),
            ("angle error rms [deg]", "angle_error_rms_deg", "{:.1f}"),
            ("min mutual distance [m]", "min_mutual_distance_m", "{:.2f}"),
            ("min worker distance [m]", "min_human_distance_m", "{:.2f}"),
            ("min obstacle distance [m]", "min_obstacle_distance_m", "{:.2f}"),
            ("collisions", "collisions", "{:.0f}"),
            ("false adaptations", "false_adaptations", "{:.0f}"),
            ("brake fallbacks per mission", "plans_fallback_brake", "{:.0f}"),
            ("gesture requests applied per mission", "gesture_requests_applied", "{:.0f}"),
            ("operator requests applied per mission", "operator_requests_applied", "{:.0f}")]


def baseline_section(rows, base_rows, base_label):
    """Per profile, over the seeds both hold: min / median / max of each COMPARED figure, baseline → this."""
    out = [f"## Against the baseline ({base_label})", "",
           "Per profile, over the seeds both stores hold: min / median / max over the seeds, baseline → these missions.", ""]
    for p in PROFILES:
        mine = {r["seed"]: json.loads(r["metrics_json"]) for r in rows if r["profile"] == p}
        base = {r["seed"]: json.loads(r["metrics_json"]) for r in base_rows if r["profile"] == p}
        seeds = sorted(set(mine) & set(base))
        out += [f"### {p}", ""]
        if not seeds:
            out += ["No seed in both stores.", ""]
            continue
        out += [f"Seeds: {len(seeds)} ({seeds[0]}..{seeds[-1]})", "", "| figure | baseline | these missions |", "|---|---|---|"]
        for label, key, fmt in COMPARED:
            b = sorted(base[s][key] for s in seeds)
            m = sorted(mine[s][key] for s in seeds)
            trio = lambda v: " / ".join(fmt.format(x) for x in (v[0], statistics.median(v), v[-1]))
            out.append(f"| {label} | {trio(b)} | {trio(m)} |")
        out.append("")
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--store", required=True)
    ap.add_argument("--out", default="docs/results/leader_handover.md")
    ap.add_argument("--commit", default="", help="only missions of source commits starting with this")
    ap.add_argument("--seeds", default="", help="only these seeds, A..B (e.g. a held-out range)")
    ap.add_argument("--title", default="Leader hand-over: the leader_dropout profiles", help="the page's heading")
    ap.add_argument("--load", default="not recorded",
                    help="the machine load while the missions ran (and how many ran at a time, niced or not)")
    ap.add_argument("--baseline", default="", help="a store to compare with (its leader_dropout missions)")
    ap.add_argument("--baseline-commit", default="", help="only baseline missions of source commits starting with this")
    a = ap.parse_args(argv)
    if not os.path.exists(a.store):
        print(f"handover_report.py: --store {a.store}: no such file", file=sys.stderr)
        return 2
    try:
        seeds = parse_seeds(a.seeds) if a.seeds else None
    except BadInput as e:
        print(f"handover_report.py: --{e}", file=sys.stderr)
        return 2
    rows, fails = load(a.store, a.commit, seeds)
    commits = sorted({r["source_commit"][:10] for r in rows})
    times = sorted(r["finished_utc"] for r in rows if r["finished_utc"])
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = [
        f"# {a.title}",
        "",
        f"Written by `tools/handover_report.py` (do not edit by hand) on {now} from the campaign store "
        f"`{os.path.basename(a.store)}`, commit(s) {', '.join(commits) or 'none'}; missions finished "
        f"{times[0] if times else '-'} .. {times[-1] if times else '-'}. Mission: `config/scenarios/power_towers.yaml` with "
        "`config/faults/leader_dropout_{5s,60s,for_good}.yaml` (at 60 s the acting leader's radio dies for 5 s, 60 s, "
        "for good), run to 240 s (`config/campaigns/mission_safety.yaml`, `gfctl simulate --threads 1`). "
        f"Machine load: {a.load}. Failed attempts stored: {len(fails)}. What the UAVs do: "
        "[safety.md](../safety.md) §1.2.",
        "",
        f"Limit for a new leader: silence_limit_s + candidacy_stagger_s + 2 election_timeout_s = {LIMIT_S:.1f} s "
        "(LeadershipConfig defaults). Distributions: min / median / 95 % / max over the seeds.",
        "",
    ]
    for p in PROFILES:
        lines += profile_section(p, [r for r in rows if r["profile"] == p])
    if a.baseline:
        if not os.path.exists(a.baseline):
            print(f"handover_report.py: --baseline {a.baseline}: no such file", file=sys.stderr)
            return 2
        base_rows, _ = load(a.baseline, a.baseline_commit, seeds)
        base_commits = sorted({r["source_commit"][:10] for r in base_rows})
        lines += baseline_section(rows, base_rows, f"store `{os.path.basename(a.baseline)}`, commit(s) {', '.join(base_commits) or 'none'}")
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    with open(a.out, "w") as f:
        f.write("\n".join(lines))
    print(f"handover_report.py: {len(rows)} missions -> {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
