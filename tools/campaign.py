#!/usr/bin/env python3
"""Campaigns of simulated missions on Dask, results in one SQLite store (docs/campaigns.md).

A campaign is a YAML file: scenarios x fault profiles x seeds x config variants. Each mission
is one Dask task running `gfctl simulate` in a subprocess; each finished mission is one row of
the store, keyed by (source commit, gfctl sha256, model sha256, scenario, profile, seed, config
hash). A mission already stored is never run again, so any run resumes where the last stopped.

  campaign.py run CAMPAIGN.yaml [--store FILE] [--workers N | --scheduler tcp://HOST:8786]
  campaign.py report [CAMPAIGN.yaml] [--commit C] [--out MD] [--plot PNG]   fault-matrix report
  campaign.py compare A B [--campaign CAMPAIGN.yaml]                        commit A vs commit B
  campaign.py bench CAMPAIGN.yaml [--workers-list 1,2]                      throughput, overhead
  campaign.py cameras [CAMPAIGN.yaml] [--commit C]                          synthetic vs rendered camera
  campaign.py import-csv RUNS.csv ...                                       legacy runs files
  campaign.py failures [--commit C]                                         failed attempts, log tails

Run with the tools venv's Python (/opt/gesture_formation/venv/bin/python; tools/setup.sh).
Exit codes: 0 ok, 1 missions failed, 2 bad input (campaign file, store, gfctl not found).
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

TOOLS = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(TOOLS)
sys.path.insert(0, TOOLS)

import campaign_store  # noqa: E402
import campaign_worker  # noqa: E402
from campaign_store import Store, StoreError  # noqa: E402

DEFAULT_STORE = os.path.join(ROOT, "docs", "results", "campaigns.sqlite")
DIRTY_PATHS = ["src", "include", "config", "third_party_models", "CMakeLists.txt"]
NAME_RE = re.compile(r"^[a-z0-9_-]+$")
KEY_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_0-9][A-Za-z0-9_]*)*$")
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


class BadInput(Exception):
    """Bad input: the message names the field and the value."""


def log(msg):
    print(f"campaign: {msg}", file=sys.stderr, flush=True)


# ---- the campaign file ----------------------------------------------------------------
def parse_seeds(v):
    """seeds: [1, 2, 5] | {from: A, to: B} | "A..B"."""
    if isinstance(v, str) and ".." in v:
        a, _, b = v.partition("..")
        v = {"from": a.strip(), "to": b.strip()}
    if isinstance(v, dict):
        if set(v) != {"from", "to"}:
            raise BadInput(f"seeds: expected {{from: A, to: B}}, got {v!r}")
        try:
            a, b = int(v["from"]), int(v["to"])
        except (TypeError, ValueError):
            raise BadInput(f"seeds: from/to must be integers, got {v!r}") from None
        if a < 0 or b < a:
            raise BadInput(f"seeds: expected 0 <= from <= to, got {v!r}")
        return list(range(a, b + 1))
    if isinstance(v, list) and v and all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in v):
        if len(set(v)) != len(v):
            raise BadInput(f"seeds: duplicate seeds in {v!r}")
        return v
    raise BadInput(f"seeds: expected a list of non-negative integers, {{from: A, to: B}} or 'A..B', got {v!r}")


def positive_number(c, field, default):
    v = c.get(field, default)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0:
        raise BadInput(f"{field}: expected a number > 0, got {v!r}")
    return v


def load_campaign(path, root=ROOT):
    """The campaign file, validated: every field checked, files resolved (relative to root)."""
    import yaml
    try:
        with open(path) as f:
            c = yaml.safe_load(f)
    except OSError as e:
        raise BadInput(f"{path}: {e.strerror}") from None
    except yaml.YAMLError as e:
        raise BadInput(f"{path}: not valid YAML: {e}") from None
    if not isinstance(c, dict):
        raise BadInput(f"{path}: expected a mapping of campaign fields, got {type(c).__name__}")
    known = {"name", "scenarios", "profiles", "seeds", "duration_s", "timeout_s", "threads_per_mission", "model",
             "variants", "camera", "description"}
    for k in c:
        if k not in known:
            raise BadInput(f"{path}: {k}: unknown field (known: {', '.join(sorted(known))})")
    for k in ("name", "scenarios", "profiles", "seeds"):
        if k not in c:
            raise BadInput(f"{path}: {k}: missing")
    try:
        return _validate(c, root)
    except BadInput as e:
        raise BadInput(f"{path}: {e}") from None


def campaign_from_args(args, root=ROOT):
    """The campaign file with --seeds / --profiles (if given) in place of its own."""
    import yaml
    c = load_campaign(args.campaign, root)
    if getattr(args, "seeds", None) is None and getattr(args, "profiles", None) is None:
        return c
    with open(args.campaign) as f:
        raw = yaml.safe_load(f)
    if args.seeds is not None:
        raw["seeds"] = args.seeds
        if ".." not in args.seeds:
            try:
                raw["seeds"] = [int(x) for x in re.split(r"[,\s]+", args.seeds.strip("[] ")) if x]
            except ValueError:
                raise BadInput(f"--seeds: expected A..B or a list of integers, got {args.seeds!r}") from None
    if args.profiles is not None:
        raw["profiles"] = [p for p in re.split(r"[,\s]+", args.profiles) if p]
    try:
        return _validate(raw, root)
    except BadInput as e:
        raise BadInput(f"{args.campaign} with --seeds/--profiles: {e}") from None


def _validate(c, root):
    name = c["name"]
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise BadInput(f"name: expected [a-z0-9_-]+, got {name!r}")
    scenarios = c["scenarios"]
    if not isinstance(scenarios, list) or not scenarios or not all(isinstance(s, str) for s in scenarios):
        raise BadInput(f"scenarios: expected a non-empty list of scenario files, got {scenarios!r}")
    for s in scenarios:
        if not os.path.isfile(os.path.join(root, s)):
            raise BadInput(f"scenarios: {s!r}: no such file (paths are relative to {root})")
    profiles = c["profiles"]
    if not isinstance(profiles, list) or not profiles or not all(isinstance(p, str) for p in profiles):
        raise BadInput(f"profiles: expected a non-empty list of fault profile names, got {profiles!r}")
    if len(set(profiles)) != len(profiles):
        raise BadInput(f"profiles: duplicate names in {profiles!r}")
    for p in profiles:
        if not NAME_RE.match(p):
            raise BadInput(f"profiles: {p!r}: expected a name of [a-z0-9_-] (config/faults/NAME.yaml, or none)")
        for s in scenarios:
            if p != "none" and not os.path.isfile(faults_file(root, s, p)):
                raise BadInput(f"profiles: {p!r}: {faults_file(root, s, p)} does not exist")
    seeds = parse_seeds(c["seeds"])
    duration = positive_number(c, "duration_s", None)
    timeout = positive_number(c, "timeout_s", 3600)
    threads = c.get("threads_per_mission", 1)
    if isinstance(threads, bool) or not isinstance(threads, int) or not 1 <= threads <= 16:
        raise BadInput(f"threads_per_mission: expected an integer 1..16, got {threads!r}")
    model = c.get("model")
    if model is not None and (not isinstance(model, str) or not os.path.isfile(os.path.join(root, model))):
        raise BadInput(f"model: {model!r}: no such file (relative to {root})")
    variants = c.get("variants") or {}
    if not isinstance(variants, dict):
        raise BadInput(f"variants: expected a mapping KEY: [values], got {variants!r}")
    for k, vals in variants.items():
        if not isinstance(k, str) or not KEY_RE.match(k) or not (k.startswith("mission.") or k.startswith("faults.")):
            raise BadInput(f"variants: {k!r}: expected a dotted key under mission. or faults. "
                           "(e.g. mission.links.uav.delay_s)")
        if not isinstance(vals, list) or not vals:
            raise BadInput(f"variants: {k}: expected a non-empty list of values, got {vals!r}")
        if k.startswith("faults.") and "none" in profiles:
            raise BadInput(f"variants: {k}: a faults. key needs a fault profile; profiles has 'none'")
    cameras = c.get("camera", ["synthetic"])
    if (not isinstance(cameras, list) or not cameras or len(set(map(str, cameras))) != len(cameras)
            or not all(m in ("synthetic", "rendered") for m in cameras)):
        raise BadInput(f"camera: expected a list of distinct modes from [synthetic, rendered] (gfctl simulate --camera), "
                       f"got {cameras!r}")
    return {"name": name, "scenarios": scenarios, "profiles": profiles, "seeds": seeds, "duration_s": duration,
            "timeout_s": timeout, "threads": threads, "model": model, "variants": variants, "cameras": cameras}


def faults_file(root, scenario, profile):
    """gfctl simulate --fault-profile NAME: <scenario dir>/../faults/NAME.yaml."""
    return os.path.normpath(os.path.join(root, os.path.dirname(scenario), "..", "faults", profile + ".yaml"))


def variant_configs(c):
    """Every combination of the variants' values (cartesian product), each a config dict."""
    combos = [{}]
    for k, vals in c["variants"].items():
        combos = [dict(combo, **{k: v}) for combo in combos for v in vals]
    # A camera other than the default one is part of the config (and of its hash); the synthetic
    # camera's configs keep the hashes they always had.
    return [dict({"duration_s": c["duration_s"], "overrides": combo}, **({} if cam == "synthetic" else {"camera": cam}))
            for combo in combos for cam in c.get("cameras", ["synthetic"])]


def set_key(doc, dotted, value, what):
    node = doc
    parts = dotted.split(".")
    for i, part in enumerate(parts[:-1]):
        nxt = node.get(part)
        if nxt is None:
            nxt = node[part] = {}
        if not isinstance(nxt, dict):
            raise BadInput(f"variants: {dotted}: {'.'.join(parts[:i + 1])} in {what} is not a mapping")
        node = nxt
    node[parts[-1]] = value


def apply_overrides(text, overrides, prefix, what):
    """The YAML text with the overrides under `prefix` set; the text unchanged if none apply."""
    mine = {k: v for k, v in overrides.items() if k.startswith(prefix + ".")}
    if not mine:
        return text
    import yaml
    doc = yaml.safe_load(text)
    for k, v in sorted(mine.items()):
        set_key(doc, k, v, what)
    return yaml.safe_dump(doc, sort_keys=False)


def scenario_model(root, scenario):
    """The scenario's mission.gesture_model, resolved like gfctl (relative to the scenario file)."""
    import yaml
    with open(os.path.join(root, scenario)) as f:
        doc = yaml.safe_load(f) or {}
    m = (doc.get("mission") or {}).get("gesture_model")
    return os.path.normpath(os.path.join(root, os.path.dirname(scenario), m)) if m else None


# ---- the build and the source -----------------------------------------------------------
def find_gfctl(flag=None, root=ROOT):
    """--gfctl, then $GFCTL, then build*/devel/lib/gesture_formation/gfctl under the source tree
    (newest first), then a catkin workspace above it (devel/lib/gesture_formation/gfctl), then PATH."""
    for path, origin in ((flag, "--gfctl"), (os.environ.get("GFCTL"), "$GFCTL")):
        if path:
            if not (os.path.isfile(path) and os.access(path, os.X_OK)):
                raise BadInput(f"{origin}: {path!r} is not an executable file")
            return os.path.abspath(path)
    rel = os.path.join("devel", "lib", "gesture_formation", "gfctl")
    candidates = []
    for d in sorted(os.listdir(root)):
        if d == "build" or d.startswith("build-") or d.startswith("build_"):
            candidates.append(os.path.join(root, d, rel))
    up = os.path.dirname(root)
    for _ in range(3):  # catkin: WS/src/gesture_formation -> WS/devel
        candidates.append(os.path.join(up, rel))
        up = os.path.dirname(up)
    found = [p for p in candidates if os.path.isfile(p) and os.access(p, os.X_OK)]
    if found:
        return max(found, key=os.path.getmtime)
    on_path = shutil.which("gfctl")
    if on_path:
        return on_path
    raise BadInput("gfctl not found: build it (GF_JOBS=1 tools/build.sh gfctl) or pass --gfctl PATH / set GFCTL")


def source_commit(root=ROOT):
    """HEAD of the source tree; -modified-<8 hex of the diff> when src/include/config/models differ."""
    def git(*a):
        return subprocess.run(["git", "-C", root, *a], capture_output=True, check=True).stdout
    try:
        head = git("rev-parse", "HEAD").decode().strip()
        status = git("status", "--porcelain", "--untracked-files=all", "--", *DIRTY_PATHS)
    except (OSError, subprocess.CalledProcessError):
        raise BadInput(f"{root}: not a git checkout: pass --commit LABEL") from None
    if not status.strip():
        return head
    h = hashlib.sha256(git("diff", "HEAD", "--", *DIRTY_PATHS))
    for line in status.decode().splitlines():  # untracked files count too
        if line.startswith("??"):
            p = os.path.join(root, line[3:].strip())
            if os.path.isfile(p):
                h.update(p.encode() + b"\0" + open(p, "rb").read())
    return f"{head}-modified-{h.hexdigest()[:8]}"


# ---- the missions ----------------------------------------------------------------------
def plan_missions(c, root, commit, gfctl, gfctl_sha, model_path, model_sha, work_root, keep_root):
    """Every mission of the campaign (seeds outer: a run stopped early covers every profile evenly)."""
    texts = {}
    for s in c["scenarios"]:
        with open(os.path.join(root, s)) as f:
            texts[s] = f.read()
    faults = {}
    for s in c["scenarios"]:
        for p in c["profiles"]:
            if p != "none":
                with open(faults_file(root, s, p)) as f:
                    faults[(s, p)] = f.read()
    configs = variant_configs(c)
    missions = []
    for seed in c["seeds"]:
        for s in c["scenarios"]:
            for p in c["profiles"]:
                for cfg in configs:
                    h = campaign_store.config_hash(cfg)
                    key = {"source_commit": commit, "gfctl_sha256": gfctl_sha, "model_sha256": model_sha,
                           "scenario": s, "profile": p, "seed": seed, "config_hash": h}
                    scenario_text = apply_overrides(texts[s], cfg["overrides"], "mission", s)
                    faults_text = None if p == "none" else apply_overrides(faults[(s, p)], cfg["overrides"], "faults", p)
                    keep = None
                    if keep_root:
                        keep = os.path.join(keep_root, os.path.splitext(os.path.basename(s))[0], p, h, f"seed_{seed}")
                    missions.append({"key": key, "config_json": json.dumps(cfg, sort_keys=True), "gfctl": gfctl,
                                     "gfctl_sha256": gfctl_sha, "model": model_path, "model_sha256": model_sha,
                                     "scenario_text": scenario_text, "faults_text": faults_text,
                                     "duration_s": cfg["duration_s"], "camera": cfg.get("camera"),
                                     "timeout_s": c["timeout_s"],
                                     "threads": c["threads"], "work_root": work_root, "keep_dir": keep})
    return missions


def short_key(k):
    return f"{os.path.basename(k['scenario'])} {k['profile']} seed {k['seed']} config {k['config_hash'][:8]}"


def fmt_duration(s):
    if s is None:
        return "–"
    s = int(round(s))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"


class Progress:
    """One line per finished mission: done, failed, running, rate and the estimated time left."""

    def __init__(self, total, already):
        self.total, self.already = total, already
        self.done = self.failed = 0
        self.t0 = time.time()

    def line(self, running, what):
        finished = self.done + self.failed
        elapsed = time.time() - self.t0
        left = self.total - self.already - finished
        eta = elapsed / finished * left if finished else None
        rate = finished / elapsed * 3600 if finished and elapsed > 0 else 0.0
        print(f"[{self.already + self.done}/{self.total} stored, {self.done} done now, {self.failed} failed, "
              f"{running} running] {rate:.0f} missions/h, ETA {fmt_duration(eta)} | {what}", flush=True)


def start_cluster(args):
    """(client, cluster or None): a LocalCluster on 127.0.0.1 (default) or an existing scheduler."""
    from distributed import Client, LocalCluster
    if args.scheduler:
        client = Client(args.scheduler, timeout=30)
        # The scheduler unpickles the tasks and the workers run them: both import this module,
        # sent to them (and to workers that join later) so that they need no checkout of tools/.
        client.upload_file(campaign_worker.__file__)
        return client, None
    workers = args.workers or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address="127.0.0.1:0", worker_dashboard_address=None,  # health endpoints only: no bokeh
                           local_directory=os.path.join(args.work_dir, "dask"), silence_logs=40)
    return Client(cluster), cluster


def overhead_figures(results):
    """Scheduler overhead per mission: per worker, the gap between one mission's end and the next
    one's start plus the task's own time outside gfctl, averaged over the missions after each
    worker's first; the first task's time outside gfctl is the worker's start-up (hashing gfctl
    and its libraries once), given apart. None when there are no results."""
    by_worker = {}
    for r in results:
        by_worker.setdefault(r["worker"], []).append(r)
    gaps, inside, startup, mission = [], [], [], []
    for rs in by_worker.values():
        rs.sort(key=lambda r: r["t_start"])
        for a, b in zip(rs, rs[1:]):
            gaps.append(max(0.0, b["t_start"] - a["t_end"]))
        for i, r in enumerate(rs):
            (inside if i else startup).append(max(0.0, r["t_end"] - r["t_start"] - r["mission_s"]))
            mission.append(r["mission_s"])
    if not mission:
        return None
    mean_mission = sum(mission) / len(mission)
    per_mission = (sum(gaps) + sum(inside)) / len(inside) if inside else 0.0
    gaps.sort()
    return {"mean_mission_s": mean_mission, "overhead_s": per_mission,
            "overhead_pct": 100.0 * per_mission / mean_mission if mean_mission > 0 else None,
            "gap_median_s": gaps[len(gaps) // 2] if gaps else 0.0, "gap_max_s": gaps[-1] if gaps else 0.0,
            "inside_mean_s": sum(inside) / len(inside) if inside else 0.0,
            "startup_s": sum(startup) / len(startup), "steady_missions": len(inside)}


def run_campaign(args):
    c = campaign_from_args(args)
    gfctl = find_gfctl(args.gfctl)
    commit = args.commit or source_commit()
    gfctl_sha = campaign_worker.binary_sha256(gfctl)
    model_paths = {os.path.join(ROOT, c["model"]) if c["model"] else scenario_model(ROOT, s) for s in c["scenarios"]}
    if len(model_paths) != 1:
        raise BadInput(f"scenarios: they name different gesture models {sorted(map(str, model_paths))}: "
                       "set model: in the campaign file")
    model_path = model_paths.pop()
    model_sha = campaign_worker.file_sha256(model_path) if model_path else "none"
    if args.dry_run and not os.path.exists(args.store):  # count only: no store created
        log(f"{c['name']}: {len(c['seeds']) * len(c['scenarios']) * len(c['profiles']) * len(variant_configs(c))} "
            f"missions, 0 already in {args.store} (no such store yet), commit {commit[:10]}, gfctl {gfctl_sha[:12]} = "
            f"{gfctl}, model {model_sha[:12]}")
        return EXIT_OK, None
    os.makedirs(args.work_dir, exist_ok=True)
    store = Store(args.store, lock=True)
    try:
        missions = plan_missions(c, ROOT, commit, gfctl, gfctl_sha, model_path, model_sha,
                                 os.path.join(args.work_dir, "missions"), args.keep)
        stored = store.stored_keys(commit, gfctl_sha, model_sha)
        failed_before = store.failed_keys(commit, gfctl_sha, model_sha) if args.skip_failed else set()
        k4 = lambda m: (m["key"]["scenario"], m["key"]["profile"], m["key"]["seed"], m["key"]["config_hash"])  # noqa
        todo = [m for m in missions if k4(m) not in stored and k4(m) not in failed_before]
        already = len(missions) - len(todo)
        log(f"{c['name']}: {len(missions)} missions, {len(missions) - len(todo)} already in {args.store} "
            f"(commit {commit[:10]}, gfctl {gfctl_sha[:12]} = {gfctl}, model {model_sha[:12]}), {len(todo)} to run")
        if args.dry_run or not todo:
            return EXIT_OK, None
        return _run(args, c, store, todo, len(missions), already)
    finally:
        store.close()


def _run(args, c, store, todo, total, already):
    from distributed import as_completed
    client, cluster = start_cluster(args)
    progress = Progress(total, already)
    results, interrupted, mismatch = [], False, False
    t_first = time.time()

    def on_signal(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, on_signal)
    try:
        nthreads = sum(client.nthreads().values())
        log(f"cluster: {len(client.nthreads())} workers, {nthreads} threads ({args.scheduler or 'local, 127.0.0.1'})")
        queue = list(enumerate(todo))
        queue.reverse()
        ac = as_completed()
        running = {}

        def refill():
            window = 2 * max(1, sum(client.nthreads().values())) + 2
            while queue and len(running) < window:
                i, m = queue.pop()
                f = client.submit(campaign_worker.run_mission, m, key=f"mission-{i}-{os.getpid()}-{int(t_first)}",
                                  priority=-i, pure=False)
                running[f.key] = m
                ac.add(f)

        refill()
        for fut in ac:
            m = running.pop(fut.key)
            try:
                r = fut.result()
            except Exception as e:  # the task itself was lost (e.g. KilledWorker) or raised
                r = {"status": "lost", "exit_code": None, "worker": None, "mission_s": None,
                     "log_tail": f"{type(e).__name__}: {e}"}
            fut.release()
            if r["status"] == "ok":
                new = store.add_mission(m["key"], m["config_json"], c["name"], "run", r["metrics"], r["metrics_json"],
                                        worker=r["worker"], mission_s=r["mission_s"])
                progress.done += 1
                results.append(r)
                mm = r["metrics"]
                num = lambda k: float("nan") if mm.get(k) is None else mm[k]  # noqa: E731 (0.00 is a distance)
                what = (f"{short_key(m['key'])}: mutual {num('min_mutual_distance_m'):.2f} "
                        f"obstacle {num('min_obstacle_distance_m'):.2f} collisions "
                        f"{mm.get('collisions')} ({r['mission_s']:.1f} s on {r['worker']})"
                        + ("" if new else " [already stored by another run: kept the first]"))
            else:
                store.add_failure(m["key"], m["config_json"], c["name"], r["status"], r.get("exit_code"),
                                  r.get("worker"), r.get("mission_s"), r.get("log_tail", ""))
                progress.failed += 1
                tail = (r.get("log_tail") or "").strip().splitlines()
                what = f"FAILED ({r['status']}, exit {r.get('exit_code')}) {short_key(m['key'])}: " + \
                       (tail[-1][:160] if tail else "")
            progress.line(len(running), what)
            mismatch = mismatch or r["status"] == "mismatch"
            if progress.failed > args.max_failures or mismatch:
                log("stopping: " + (f"a worker's gfctl or model differs from the client's: {r.get('log_tail')}"
                                    if mismatch else f"{progress.failed} failures (> --max-failures {args.max_failures})")
                    + "; see `campaign.py failures`")
                queue.clear()
                for f in list(ac.futures):
                    f.cancel()
                break
            refill()
        t_last = time.time()
    except KeyboardInterrupt:
        interrupted = True
        t_last = time.time()
        log(f"interrupted: {progress.done} missions stored in this run; the same command resumes")
    finally:
        signal.signal(signal.SIGTERM, old)
        client.close()
        if cluster is not None:
            cluster.close()
    summary = summarize(results, t_first, t_last, progress, client_workers=args.workers or args.scheduler)
    return (EXIT_FAILED if progress.failed or interrupted else EXIT_OK), summary


def summarize(results, t_first, t_last, progress, client_workers):
    wall = max(1e-9, t_last - t_first)
    per_hour = progress.done / wall * 3600
    ov = overhead_figures(results)
    line = f"{progress.done} missions done, {progress.failed} failed in {fmt_duration(wall)}: {per_hour:.1f} missions/hour"
    if ov:
        line += (f"; mean mission {ov['mean_mission_s']:.2f} s, scheduler overhead {ov['overhead_s'] * 1000:.0f} ms "
                 f"per mission = {ov['overhead_pct']:.2f} % of a mission over the {ov['steady_missions']} missions after "
                 f"each worker's first (gap between missions on a worker: median {ov['gap_median_s'] * 1000:.0f} ms, max "
                 f"{ov['gap_max_s'] * 1000:.0f} ms; in the task outside gfctl {ov['inside_mean_s'] * 1000:.0f} ms); "
                 f"worker start-up (hashing gfctl and its libraries once) {ov['startup_s']:.2f} s")
    log(line)
    return {"done": progress.done, "failed": progress.failed, "wall_s": wall, "missions_per_hour": per_hour,
            "overhead": ov}


# ---- the other commands -----------------------------------------------------------------
def cmd_import(args):
    store = Store(args.store, lock=True)
    try:
        for path in args.csv:
            added, dup = store.import_runs_csv(path, args.campaign)
            print(f"{path}: {added} missions imported" + (f", {dup} already stored (kept the first)" if dup else "")
                  + ("" if added or dup else " (this file was imported before)"))
    finally:
        store.close()
    return EXIT_OK


def cmd_failures(args):
    store = Store(args.store, create=False)
    try:
        where, params = ("source_commit LIKE ?", (args.commit + "%",)) if args.commit else ("1", ())
        rows = store.failures(where, params)
        for r in rows[-args.limit:]:
            print(f"--- {r['finished_utc']} {r['status']} exit {r['exit_code']} {r['source_commit'][:10]} "
                  f"{short_key(r)} on {r['worker']}\n{r['log_tail'].rstrip()[-1500:]}")
        print(f"{len(rows)} failed attempts" + (f" (last {args.limit} shown)" if len(rows) > args.limit else ""))
    finally:
        store.close()
    return EXIT_OK


def cmd_report(args):
    import campaign_report
    return campaign_report.report(args, campaign_from_args(args))


def cmd_compare(args):
    import campaign_report
    return campaign_report.compare(args, load_campaign(args.campaign) if args.campaign else None)


def cmd_cameras(args):
    import campaign_report
    return campaign_report.cameras(args, load_campaign(args.campaign) if args.campaign else None)


def cmd_bench(args):
    import campaign_report
    return campaign_report.bench(args, run_campaign)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="campaign.py", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--store", default=os.environ.get("GF_CAMPAIGN_STORE", DEFAULT_STORE),
                    help="the SQLite store (default: docs/results/campaigns.sqlite; $GF_CAMPAIGN_STORE)")
    sub = ap.add_subparsers(dest="cmd", required=True)

    def selection_args(p):
        p.add_argument("--seeds", help="these seeds instead of the campaign's, e.g. 1..10 or 1,5,9")
        p.add_argument("--profiles", help="these fault profiles instead of the campaign's, e.g. nominal,harsh")

    def cluster_args(p):
        selection_args(p)
        p.add_argument("--scheduler", help="an existing Dask scheduler, e.g. tcp://127.0.0.1:8786")
        p.add_argument("--workers", type=int, help="local cluster: worker processes (default: the cores)")
        p.add_argument("--gfctl", help="the gfctl binary (default: $GFCTL, build*/devel/..., catkin devel/, PATH)")
        p.add_argument("--commit", help="the source commit label (default: git HEAD, -modified-... if changed)")
        p.add_argument("--work-dir", default=os.environ.get("GF_CAMPAIGN_WORK", os.path.join(ROOT, "build-campaign")),
                       help="scratch directory of the missions and the local cluster (default build-campaign/)")
        p.add_argument("--keep", help="keep every mission's output under this directory (default: only metrics)")
        p.add_argument("--max-failures", type=int, default=50, help="stop after this many failures (default 50)")
        p.add_argument("--skip-failed", action="store_true", help="do not retry missions that failed before")

    p = sub.add_parser("run", help="run the missions of a campaign not yet in the store")
    p.add_argument("campaign")
    cluster_args(p)
    p.add_argument("--dry-run", action="store_true", help="count the missions to run, run none")
    p.set_defaults(func=lambda a: run_campaign(a)[0])

    p = sub.add_parser("bench", help="throughput 1 -> N local workers and the scheduler overhead, "
                                     "into docs/results/campaigns.md")
    p.add_argument("campaign")
    cluster_args(p)
    p.add_argument("--workers-list", default="1,2", help="worker counts to measure (default 1,2)")
    p.add_argument("--results", default=os.path.join(ROOT, "docs", "results", "campaigns.md"))
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser("report", help="the fault-matrix report (docs/results/reliability.md) from the store")
    p.add_argument("campaign", nargs="?", default=os.path.join(ROOT, "config", "campaigns", "fault_matrix.yaml"))
    selection_args(p)
    p.add_argument("--commit", action="append", help="commit (prefix) of the tables; repeat for a matrix run over "
                                                     "several commits (default: the newest complete matrix)")
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "reliability.md"))
    p.add_argument("--plot", default=None, help="the figure (default: fault_matrix.png beside --out)")
    p.set_defaults(func=cmd_report)

    p = sub.add_parser("compare", help="commit A vs commit B per profile: safety figures, regressions, missions")
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("--campaign", default=None, help="restrict to this campaign's scenarios, profiles and seeds")
    p.add_argument("--limit", type=int, default=25, help="differing missions listed (default 25)")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("cameras", help="synthetic vs rendered camera per seed (campaign field camera) from the store")
    p.add_argument("campaign", nargs="?", default=None, help="restrict to this campaign's scenarios, profiles and seeds")
    p.add_argument("--commit", help="commit (prefix) of the missions (default: the commit with the most missions)")
    p.add_argument("--out", help="also write a results page (e.g. docs/results/camera_campaign.md)")
    p.set_defaults(func=cmd_cameras)

    p = sub.add_parser("import-csv", help="import runs files of the former tools/run_fault_matrix.sh once")
    p.add_argument("csv", nargs="+")
    p.add_argument("--campaign", default="fault_matrix")
    p.set_defaults(func=cmd_import)

    p = sub.add_parser("failures", help="failed attempts with their log tails")
    p.add_argument("--commit")
    p.add_argument("--limit", type=int, default=20)
    p.set_defaults(func=cmd_failures)

    for sp in sub.choices.values():  # --store also after the command
        sp.add_argument("--store", dest="store_after", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.store_after:
        args.store = args.store_after
    try:
        return args.func(args)
    except (BadInput, StoreError) as e:
        print(f"campaign.py: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
