#!/usr/bin/env python3
"""Scores candidate numbers of the network-tolerant 3-D regions (view_fusion.tolerant_3d, require_3d;
docs/gestures.md §6) on rendered TRAINING sets through the product's own fuse-views and gesture-filter,
with two stand-ins for the classifier, so that the regions are chosen on what they must pass and refuse,
not on one model's mistakes:

  - truth: every view's classification is the frame's label — the gestures the 3-D check lets through
    when the classifier is right (`fired` per gesture);
  - adversary g (g = 1..4): in every work-motion sequence each frame between the motion's start and end
    is read as gesture g by every view — the commands the 3-D check alone lets through when the
    classifier mistakes a work motion for g (`false` per g and per motion). A near-miss the regions
    refuse never fires whatever the network says.

    python3 tools/gesture/fit_3d_regions.py --gfctl build/devel/lib/gesture_formation/gfctl \
        --sets rendered_train_1,rendered_train_2 --candidates CANDIDATES.yaml --out FIT.json
    # the page of one or more runs (docs/results/gestures_3d_regions.md)
    python3 tools/gesture/fit_3d_regions.py --report docs/results/gestures_3d_regions.md --from-json LABEL=A.json \
        [--from-json LABEL=B.json …]

CANDIDATES.yaml: {name: {key: value, …}, …}, keys relative to view_fusion (e.g. tolerant_3d.palms_max_height_H,
require_3d_min_fraction, geometry_3d), each applied over config/gestures.yaml; the name `shipped` with no keys is
the file as it is. Refuses the held-out sets and the tuning sets (they judge the choice; docs/gestures.md §8).
"""
import argparse
import copy
import datetime
import json
import os
import sys

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import evaluate_gesture_lstm as ev  # noqa: E402
import heldout_eval as he  # noqa: E402
import rendered_eval as re_  # noqa: E402

WORK = "/work/fit3d"


def prepared_views(gfctl, model, d, spec, fps, work):
    """Per view: (rows of the classified CSV with the frame's label, sequence and time in the sequence); the
    classifier's output is replaced below, only its rows (frames with a full window) and columns are kept."""
    out = []
    for sfx in re_.VIEW_SUFFIXES(spec):
        vdir = os.path.join(work, "view" + sfx)
        csv = os.path.join(vdir, "gestures_geometry.csv")
        if not os.path.exists(csv):
            csv = ev.classify_view(gfctl, model, d, sfx, fps, work)
        header, rows = ev.read_csv(os.path.join(vdir, "laid_out.csv"))
        it, il = header.index("t"), header.index("label")
        label = {round(float(r[it]), 6): int(r[il]) for r in rows}
        header, rows = ev.read_csv(csv)
        out.append((header, [(label[round(float(r[0]), 6)], list(r)) for r in rows]))
    return out


def write_view(path, header, rows, meta, gap, adversary):
    ig = header.index("gesture_id")
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for lab, r in rows:
            t = float(r[0])
            seq = int(t // gap)
            md = meta[seq]
            g = lab
            if int(md["gesture_id"]) == 0:
                rel = t - gap * seq
                g = adversary if float(md["motion_start_s"]) <= rel <= float(md["motion_end_s"]) else 0
            r[ig] = str(g)
            f.write(",".join(r) + "\n")


def config_with(base, keys, path):
    c = copy.deepcopy(base)
    for k, v in keys.items():
        node = c["view_fusion"]
        parts = k.split(".")
        for p in parts[:-1]:
            node = node[p]
        if parts[-1] not in node:
            sys.exit(f"fit_3d_regions: candidate key view_fusion.{k} is not in config/gestures.yaml")
        node[parts[-1]] = v
    with open(path, "w") as f:
        yaml.safe_dump(c, f, sort_keys=False)
    return path


def score_set(gfctl, views, meta, gap, fps, config, work):
    res = {"fired": {}, "gestures": {}, "false": {}, "false_by_motion": {}, "work_sequences": 0, "missed": [], "false_sequences": {}}
    for adversary in range(0, 5):  # 0: truth alone (work motions read as none)
        paths = []
        for i, (header, rows) in enumerate(views):
            p = os.path.join(work, f"in_{i}_{adversary}.csv")
            write_view(p, header, rows, meta, gap, adversary)
            paths.append(p)
        fused = ev.fuse(gfctl, paths, config, os.path.join(work, f"fused_{adversary}.csv"))
        s = he.score(he.run_filter(gfctl, fused, config, work, f"a{adversary}"), meta, gap, fps)
        if adversary == 0:
            missed = {x["sequence"] for x in s["missed_list"]}
            res["missed"] = sorted(missed)
            for seq, md in meta.items():
                gid = int(md["gesture_id"])
                if gid:
                    name = ev.CLASSES[gid]
                    res["gestures"][name] = res["gestures"].get(name, 0) + 1
                    res["fired"][name] = res["fired"].get(name, 0) + int(seq not in missed)
                else:
                    res["work_sequences"] += 1
            res["false"]["truth"] = s["false_adaptations"]
        else:
            res["false"][ev.CLASSES[adversary]] = s["false_adaptations"]
            res["false_sequences"][ev.CLASSES[adversary]] = sorted({int(x["sequence"]) for x in s["false_adaptation_list"]})
            for x in s["false_adaptation_list"]:
                m = meta[int(x["sequence"])]["motion"]
                res["false_by_motion"].setdefault(ev.CLASSES[adversary], {})
                res["false_by_motion"][ev.CLASSES[adversary]][m] = res["false_by_motion"][ev.CLASSES[adversary]].get(m, 0) + 1
    return res


def report(runs, out):
    """A markdown page of fit runs (each: the JSON this script writes, with its label)."""
    lines = ["# The network-tolerant 3-D regions on the rendered training sets", "",
             f"Written by `tools/gesture/fit_3d_regions.py --report` (do not edit by hand) on "
             f"{datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M')} UTC. Each row: one candidate's "
             "numbers (`view_fusion` keys over the config named) through `gfctl fuse-views` and `gesture-filter` on the "
             "three views' MoveNet skeletons of the rendered training sets, the classifier replaced by the frames' labels "
             "(gestures fired) and by an adversary that reads every work motion, start to end, as gesture g in every "
             "view (the commands the 3-D check alone lets through: 4 passes, one per g). What it is for and what was "
             "chosen: [gestures.md](../gestures.md) §6.", ""]
    for label, r in runs:
        lines += [f"## {label}", "", f"Sets: {', '.join(r['sets'])}; run {r.get('date_utc', '?')} at commit "
                  f"`{r.get('commit', '?')}`, config `{r.get('config', '?')}`.", "",
                  "| candidate | keys | fired (labels) | cross | extend | palms | raise | adversary passes: cross / extend / palms / raise | which work motions |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for cand, t in r["total"].items():
            per = r["per_set"][cand].values()
            by = {g: (sum(x["fired"].get(g, 0) for x in per), sum(x["gestures"].get(g, 0) for x in per))
                  for g in ("cross_arms", "extend_arm_side", "palms_together", "raise_arm_up")}
            motions = {}
            for x in r["per_set"][cand].values():
                for g, ms in x["false_by_motion"].items():
                    for m, n in ms.items():
                        motions[f"{m} as {g}"] = motions.get(f"{m} as {g}", 0) + n
            keys = ", ".join(f"`{k}` {v}" for k, v in (r["candidates"].get(cand) or {}).items()) or "(the config as it is)"
            f = t["false"]
            lines.append(f"| {cand} | {keys} | **{t['fired']}/{t['gestures']}** | " +
                         " | ".join(f"{a}/{b}" for a, b in by.values()) +
                         f" | **{f.get('cross_arms', 0)} / {f.get('extend_arm_side', 0)} / {f.get('palms_together', 0)} / "
                         f"{f.get('raise_arm_up', 0)}** (truth: {f.get('truth', 0)}) | " +
                         ", ".join(f"{m} {n}" for m, n in sorted(motions.items())) + " |")
        lines.append("")
    with open(out, "w") as fo:
        fo.write("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--report", default=None, help="write the page of --from-json runs to this file and stop")
    ap.add_argument("--from-json", action="append", default=[], help="--report: a run as LABEL=PATH (repeat the option)")
    ap.add_argument("--gfctl")
    ap.add_argument("--sets", help="rendered training sets, comma-separated")
    ap.add_argument("--data", default=re_.DATA_DIR)
    ap.add_argument("--candidates")
    ap.add_argument("--config", default=he.GESTURES_YAML)
    ap.add_argument("--model", default=he.MODEL, help="only to lay out the classified rows (its output is replaced)")
    ap.add_argument("--work", default=WORK)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.report:
        runs = []
        for item in a.from_json:
            label, _, path = item.rpartition("=")
            if not label or not path:
                ap.error(f"--from-json {item}: expected LABEL=PATH")
            with open(path) as f:
                runs.append((label, json.load(f)))
        report(runs, a.report)
        print(f"wrote {a.report}")
        return
    for need in ("gfctl", "sets", "candidates"):
        if getattr(a, need) is None:
            ap.error(f"--{need} is required (unless --report)")
    protocol = re_.load_protocol(re_.PROTOCOL)
    with open(a.config) as f:
        base = yaml.safe_load(f)
    with open(a.candidates) as f:
        candidates = yaml.safe_load(f)
    fps, gap = protocol["fps"], protocol["sequence_gap_s"]
    sets = a.sets.split(",")
    for name in sets:
        if not name.startswith("rendered_train_"):
            sys.exit(f"fit_3d_regions: --sets {name}: only the rendered training sets are used for choices (docs/gestures.md §8)")
    results = {n: {} for n in candidates}
    for name in sets:
        spec = protocol["sets"][name]
        d = re_.set_dir(a.data, name, spec)
        work = os.path.join(a.work, name)
        os.makedirs(work, exist_ok=True)
        _, _, meta = ev.laid_out(d, fps)
        views = prepared_views(a.gfctl, a.model, d, spec, fps, work)
        for cand, keys in candidates.items():
            cfg = config_with(base, keys or {}, os.path.join(work, "gestures_candidate.yaml"))
            r = score_set(a.gfctl, views, meta, gap, fps, cfg, work)
            results[cand][name] = r
            fired = sum(r["fired"].values())
            print(f"{name} {cand}: fired {fired}/{sum(r['gestures'].values())} {r['fired']}; false {r['false']}", flush=True)
    total = {}
    for cand, per in results.items():
        t = {"fired": 0, "gestures": 0, "false": {}}
        for r in per.values():
            t["fired"] += sum(r["fired"].values())
            t["gestures"] += sum(r["gestures"].values())
            for k, v in r["false"].items():
                t["false"][k] = t["false"].get(k, 0) + v
        total[cand] = t
        print(f"TOTAL {cand}: fired {t['fired']}/{t['gestures']}; false {t['false']}")
    if a.out:
        with open(a.out, "w") as f:
            json.dump({"sets": sets, "candidates": candidates, "per_set": results, "total": total,
                       "config": os.path.relpath(os.path.abspath(a.config), he.ROOT),
                       "commit": he.git("rev-parse", "--short", "HEAD") + (" (with uncommitted changes)" if he.git(
                           "status", "--porcelain", "--", "src", "include", "config", "tools/gesture") else ""),
                       "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
                       "gfctl": a.gfctl}, f, indent=1)


if __name__ == "__main__":
    main()
