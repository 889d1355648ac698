#!/usr/bin/env python3
"""The synthetic mission's speed, two gfctl builds side by side, and whether they fly the same.

    tools/bench_simulate.py --baseline OTHER/gfctl [--candidate build/devel/lib/gesture_formation/gfctl]
                            [--runs 3] [--seed 1] [--scenario config/scenarios/power_towers.yaml]
                            [--check] [--report docs/results/simulate_speed.md]
                            [--baseline-label TEXT] [--candidate-label TEXT]

Speed: `gfctl simulate --scenario S --seed N --no-plot --out TMP` (the synthetic camera, the
default), `--runs` times per build, alternating baseline and candidate so that both see the same
machine load; per run the real-time factor gfctl prints (simulated seconds / wall seconds of the
mission loop: metrics.json real_time_factor), the process's wall and CPU seconds and peak RSS, and
the 1-minute load average at its start. Prints the medians side by side. A loaded machine lowers
every figure: read them as lower bounds and compare builds only within one invocation.

--check: the two builds must give the same results on the power-tower mission, seeds 1-3 and
seed 1 under the fault profiles `harsh` and `loss30`: metrics.json identical but for the keys it
lists in wall_clock_keys, timeline.csv, events.csv and modes.csv byte-identical, plans.csv
identical but for its wall-clock planning_ms column. Exit code 1 when they differ.

--report FILE writes the figures as a dated markdown page (docs/results/), naming the builds by
--baseline-label / --candidate-label (e.g. the commits they were built from; default: their paths).
Exit code: 0 done (and identical with --check), 1 results differ or a run failed, 2 bad arguments.
"""
import argparse
import csv
import datetime
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def simulate(gfctl, scenario, seed, out, extra=()):
    """Runs one mission; returns (metrics dict, wall s, cpu s, max rss MB, load before)."""
    load = os.getloadavg()[0]
    cmd = ["/usr/bin/time", "-f", "%e %U %S %M", "-o", out + ".time", gfctl, "simulate", "--scenario", scenario,
           "--seed", str(seed), "--no-plot", "--out", out, *extra]
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode != 0:
        sys.exit(f"bench_simulate: {' '.join(cmd[6:])} failed ({proc.returncode}):\n{proc.stdout[-2000:]}")
    wall, user, system, rss_kb = open(out + ".time").read().split()[-4:]
    metrics = json.load(open(os.path.join(out, "metrics.json")))
    return metrics, float(wall), float(user) + float(system), int(rss_kb) / 1024, load


def speed(args, tmp):
    rows = []
    for r in range(args.runs):
        row = {}
        for name, gfctl in (("baseline", args.baseline), ("candidate", args.candidate)):
            m, wall, cpu, rss, load = simulate(gfctl, args.scenario, args.seed, os.path.join(tmp, f"{name}_{r}"))
            row[name] = {"rtf": m["real_time_factor"], "loop_s": m["wall_time_s"], "wall": wall, "cpu": cpu,
                         "rss": rss, "load": load, "sim_s": m["sim_time_s"]}
            print(f"run {r + 1} {name:<9}: {m['sim_time_s']:.2f} s simulated in {m['wall_time_s']:.2f} s "
                  f"(real-time factor {m['real_time_factor']:.1f}x); process {wall:.1f} s wall, {cpu:.1f} s CPU, "
                  f"peak RSS {rss:.0f} MB; load {load:.1f}", flush=True)
        rows.append(row)
    return rows


def median(rows, name, key):
    return statistics.median(r[name][key] for r in rows)


def same_csv_but(path_a, path_b, skip_column):
    with open(path_a) as fa, open(path_b) as fb:
        a, b = list(csv.reader(fa)), list(csv.reader(fb))
    if len(a) != len(b) or not a:
        return False
    skip = a[0].index(skip_column) if skip_column in a[0] else -1
    strip = lambda row: [v for i, v in enumerate(row) if i != skip]
    return all(strip(x) == strip(y) for x, y in zip(a, b))


def compare(dir_a, dir_b):
    """The differences between two mission outputs, apart from the wall-clock figures."""
    problems = []
    ma = json.load(open(os.path.join(dir_a, "metrics.json")))
    mb = json.load(open(os.path.join(dir_b, "metrics.json")))
    wall = set(ma.get("wall_clock_keys", [])) | set(mb.get("wall_clock_keys", []))
    for k in sorted(set(ma) | set(mb)):
        if k not in wall and ma.get(k) != mb.get(k):
            problems.append(f"metrics.json {k}: {ma.get(k)!r} != {mb.get(k)!r}")
    for f in ("timeline.csv", "events.csv", "modes.csv"):
        if open(os.path.join(dir_a, f), "rb").read() != open(os.path.join(dir_b, f), "rb").read():
            problems.append(f"{f} differs")
    if not same_csv_but(os.path.join(dir_a, "plans.csv"), os.path.join(dir_b, "plans.csv"), "planning_ms"):
        problems.append("plans.csv differs (beyond planning_ms)")
    return problems


def check(args, tmp):
    cases = [(f"seed {s}", s, ()) for s in (1, 2, 3)]
    cases += [(f"seed 1 --fault-profile {p}", 1, ("--fault-profile", p)) for p in ("harsh", "loss30")]
    results = []
    for label, seed, extra in cases:
        dirs = []
        for name, gfctl in (("baseline", args.baseline), ("candidate", args.candidate)):
            d = os.path.join(tmp, f"check_{name}_{seed}_{'_'.join(extra) or 'nominal'}")
            simulate(gfctl, args.scenario, seed, d, extra)
            dirs.append(d)
        problems = compare(*dirs)
        results.append((label, problems))
        print(f"check {label}: {'identical' if not problems else 'DIFFERENT: ' + '; '.join(problems[:5])}", flush=True)
    return results


def report(args, rows, checks, path):
    scenario = os.path.relpath(os.path.abspath(args.scenario), ROOT)
    lines = [f"## {datetime.date.today().isoformat()}, {os.uname().nodename}, {os.cpu_count()} cores", "",
             f"Command: `tools/bench_simulate.py --baseline <{args.baseline_label}> --candidate "
             f"<{args.candidate_label}> --runs {args.runs}{' --check' if checks else ''}` "
             f"(`gfctl simulate --scenario {scenario} --seed {args.seed}`, synthetic camera).", "",
             "| run | baseline RTF | candidate RTF | baseline CPU s | candidate CPU s | load (1 min) |",
             "|---|---|---|---|---|---|"]
    for i, r in enumerate(rows):
        b, c = r["baseline"], r["candidate"]
        lines.append(f"| {i + 1} | {b['rtf']:.1f}x | {c['rtf']:.1f}x | {b['cpu']:.1f} | {c['cpu']:.1f} | "
                     f"{b['load']:.1f} / {c['load']:.1f} |")
    lines.append(f"| median | {median(rows, 'baseline', 'rtf'):.1f}x | {median(rows, 'candidate', 'rtf'):.1f}x | "
                 f"{median(rows, 'baseline', 'cpu'):.1f} | {median(rows, 'candidate', 'cpu'):.1f} | |")
    if checks:
        lines += ["", "Same results (metrics.json but its wall_clock_keys; timeline, events, modes byte-identical; "
                  "plans.csv but planning_ms): " + ", ".join(f"{label} {'yes' if not p else 'NO'}" for label, p in checks) + "."]
    lines.append("")
    header = ("# Results: the synthetic mission's speed (`tools/bench_simulate.py`)\n\n"
              "Real-time factor = simulated seconds / wall seconds of the mission loop (metrics.json "
              "`real_time_factor`); CPU = user + system seconds of the whole process. Under load the figures "
              "are lower bounds; compare the two builds within one table. Method: "
              "[simulation.md](../simulation.md) §3.\n\n")
    old = open(path).read() if os.path.exists(path) else header
    if not old.startswith("# "):
        old = header + old
    head, sep, rest = old.partition("\n## ")
    with open(path, "w") as f:
        f.write(head.rstrip("\n") + "\n\n" + "\n".join(lines) + ("\n## " + rest if sep else ""))
    print(f"wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", required=True, help="the gfctl to compare against (e.g. main's build)")
    ap.add_argument("--candidate", default=os.path.join(ROOT, "build/devel/lib/gesture_formation/gfctl"))
    ap.add_argument("--baseline-label", help="what the baseline is in the report (default: its path)")
    ap.add_argument("--candidate-label", help="what the candidate is in the report (default: its path)")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scenario", default=os.path.join(ROOT, "config/scenarios/power_towers.yaml"))
    ap.add_argument("--check", action="store_true", help="also check that both builds give the same results")
    ap.add_argument("--report", help="write the figures into this markdown page")
    args = ap.parse_args()
    for name in ("baseline", "candidate"):
        if not os.access(getattr(args, name), os.X_OK):
            ap.error(f"--{name}: not an executable: {getattr(args, name)}")
    args.baseline_label = args.baseline_label or args.baseline
    args.candidate_label = args.candidate_label or args.candidate
    if args.runs < 1:
        ap.error(f"--runs: expected at least 1, got {args.runs}")
    with tempfile.TemporaryDirectory(prefix="bench_simulate_") as tmp:
        rows = speed(args, tmp)
        print(f"median real-time factor: baseline {median(rows, 'baseline', 'rtf'):.1f}x, candidate "
              f"{median(rows, 'candidate', 'rtf'):.1f}x; median CPU: baseline {median(rows, 'baseline', 'cpu'):.1f} s, "
              f"candidate {median(rows, 'candidate', 'cpu'):.1f} s; load {min(r['baseline']['load'] for r in rows):.1f}-"
              f"{max(r['candidate']['load'] for r in rows):.1f}")
        checks = check(args, tmp) if args.check else []
        if args.report:
            report(args, rows, checks, args.report)
    return 1 if any(p for _, p in checks) else 0


if __name__ == "__main__":
    sys.exit(main())
