#!/usr/bin/env python3
"""The rendered sets of the held-out gesture protocol, version 2
(tools/gesture/heldout/protocol_v2_rendered.yaml; docs/gestures.md §9): renders them and runs the
product's chain on the skeletons the real networks extracted from the pixels.

    # 1. render a set once (cached: slow; gfctl render-gestures, one process, nice it)
    nice -n 10 python3 tools/gesture/rendered_eval.py render --gfctl build/devel/lib/gesture_formation/gfctl \
        --set rendered_tuning --data /work/gestrend_data
    # 2. the chain on a rendered set (fast): classify per view -> fuse-views -> gesture-filter
    python3 tools/gesture/rendered_eval.py evaluate --gfctl … --set rendered_heldout --data /work/gestrend_data \
        [--model FILE] [--config FILE] [--out docs/results/gestures_rendered]
    # 3. the networks' systematic errors against the renderer's truth (tuning set only)
    python3 tools/gesture/rendered_eval.py errors --set rendered_tuning --data /work/gestrend_data [--out FILE.json]

Nothing here chooses anything. `evaluate` on the held-out set is run once per candidate model and
only reported; `errors` refuses the held-out set.
"""
import argparse
import datetime
import json
import os
import subprocess
import sys

import numpy as np
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import evaluate_gesture_lstm as ev  # noqa: E402
import heldout_eval as he  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PROTOCOL = os.path.join(ROOT, "tools/gesture/heldout/protocol_v2_rendered.yaml")
CLASSES = ev.CLASSES


def load_protocol(path):
    with open(path) as f:
        return yaml.safe_load(f)


def set_dir(data, name, spec):
    return os.path.join(data, f"{name}_seed{spec['seed']}_n{spec['count']}")


def render(gfctl, protocol, name, data, models=None):
    spec = protocol["sets"][name]
    d = set_dir(data, name, spec)
    os.makedirs(d, exist_ok=True)
    cfg = os.path.join(d, "synth.yaml")
    with open(cfg, "w") as f:
        yaml.safe_dump(dict(spec["synth"]), f)
    cmd = [gfctl, "render-gestures", "--seed", str(spec["seed"]), "--count", str(spec["count"]), "--out", d,
           "--config", cfg, "--views", ",".join(str(v) for v in spec["views_deg"]), "--motions", ",".join(spec["motions"])]
    if models:
        cmd += ["--models", models]
    with open(os.path.join(d, "render.log"), "w") as log:
        log.write(f"# {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC load {os.getloadavg()}\n")
        log.flush()
        r = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT)
        log.write(f"# exit {r.returncode}, load {os.getloadavg()}\n")
    if r.returncode != 0:
        sys.exit(f"render-gestures failed (exit {r.returncode}): see {d}/render.log")
    return d



VIEW_SUFFIXES = lambda spec: [""] + [f"_view{i + 1}" for i in range(len(spec["views_deg"]))]  # noqa: E731


def vote_and_3d(fused_csv, meta, gap):
    """Per sequence: fused frames whose 2-D vote passed a gesture (before the 3-D check) and of them the
    ones the 3-D check refused (gfctl fuse-views columns)."""
    header, rows = ev.read_csv(fused_csv)
    out = {}
    if "rejected_3d" not in header:
        return out
    it, ig, ir = header.index("t"), header.index("gesture_id"), header.index("rejected_3d")
    for r in rows:
        seq = int(float(r[it]) // gap)
        e = out.setdefault(seq, {"passed": 0, "rejected_3d": 0})
        e["passed"] += int(int(r[ig]) != 0)
        e["rejected_3d"] += int(r[ir])
    return out


def evaluate(gfctl, protocol, name, data, model, config, tag="shipped"):
    """classify per view -> fuse-views -> gesture-filter on a rendered set; the figures of protocol v2."""
    spec = protocol["sets"][name]
    d = set_dir(data, name, spec)
    fps, gap = protocol["fps"], protocol["sequence_gap_s"]
    he.set_paths(he.PROTOCOL, config)
    _, keys, meta = ev.laid_out(d, fps)
    views = [ev.classify_view(gfctl, model, d, sfx, fps, d) for sfx in VIEW_SUFFIXES(spec)]
    # window accuracy of the leader's view (label = the newest frame's)
    laid, keys, _ = ev.laid_out(os.path.join(d, "view"), fps)
    _, res = ev.classify(gfctl, model, laid, keys, fps, os.path.join(d, "view"))
    m = ev.confusion(res)
    fused = ev.fuse(gfctl, views, config, os.path.join(d, f"fused_{tag}.csv"))
    three = he.score(he.run_filter(gfctl, fused, config, d, f"fused_{tag}"), meta, gap, fps)
    leader = he.score(he.run_filter(gfctl, views[0], config, d, f"leader_{tag}"), meta, gap, fps)
    votes = vote_and_3d(fused, meta, gap)
    per_motion = {}
    for seq, md in meta.items():
        e = per_motion.setdefault(md["motion"], {"sequences": 0, "fused_frames_vote_passed": 0, "rejected_3d": 0})
        e["sequences"] += 1
        e["fused_frames_vote_passed"] += votes.get(seq, {}).get("passed", 0)
        e["rejected_3d"] += votes.get(seq, {}).get("rejected_3d", 0)
    fired_by_gesture = {}
    for seq, md in meta.items():
        gid = int(md["gesture_id"])
        if gid:
            e = fired_by_gesture.setdefault(CLASSES[gid], [0, 0])
            e[1] += 1
            e[0] += int(not any(x["sequence"] == seq for x in three["missed_list"]))
    found = {sfx or "_leader": sum(int(r["frames_found"]) for r in csv_rows(os.path.join(d, f"sequences{sfx}.csv"))) /
             sum(int(r["frames"]) for r in csv_rows(os.path.join(d, f"sequences{sfx}.csv"))) for sfx in VIEW_SUFFIXES(spec)}
    return {"set": name, "seed": spec["seed"], "sequences": spec["count"], "model": os.path.relpath(model, ROOT),
            "model_sha256": he.sha256(model), "config": os.path.relpath(config, ROOT), "config_sha256": he.sha256(config),
            "worker_found_share": {k: round(v, 4) for k, v in found.items()},
            "leader_window_accuracy": round(float(np.trace(m) / m.sum()), 4) if m.sum() else None,
            "leader_per_class": ev.per_class(m), "leader_confusion": m.tolist(),
            "three_cameras": three, "leader_camera_only": leader, "fired_by_gesture": fired_by_gesture,
            "per_motion_vote_and_3d": per_motion}


def csv_rows(path):
    import csv
    with open(path) as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("action", choices=["render", "evaluate", "errors"])
    ap.add_argument("--gfctl")
    ap.add_argument("--set", required=True)
    ap.add_argument("--data", required=True, help="cache of the rendered sets (not in git)")
    ap.add_argument("--protocol", default=PROTOCOL)
    ap.add_argument("--models", default=None)
    ap.add_argument("--model", default=he.MODEL)
    ap.add_argument("--config", default=he.GESTURES_YAML)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    protocol = load_protocol(a.protocol)
    if a.action == "render":
        print(render(a.gfctl, protocol, a.set, a.data, a.models))


if __name__ == "__main__":
    main()
