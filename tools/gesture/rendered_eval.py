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
DATA_DIR = "/work/gestrend_data"  # default cache of the rendered sets (--data)
SKELETON = "movenet_lightning"  # the pipeline's skeleton network (--skeleton); others render into their own directory
SKELETON_NAMES = {"movenet_lightning": "MoveNet lightning", "blazepose_landmark": "BlazePose landmark full"}
CLASSES = ev.CLASSES


def load_protocol(path):
    with open(path) as f:
        return yaml.safe_load(f)


def set_dir(data, name, spec):
    tag = "" if SKELETON == "movenet_lightning" else f"_{SKELETON}"
    return os.path.join(data, f"{name}_seed{spec['seed']}_n{spec['count']}{tag}")


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
    if SKELETON != "movenet_lightning":
        cmd += ["--skeleton", SKELETON]
    if spec.get("window_only"):  # training data: the skeleton network alone on the worker's window
        cmd += ["--window-only"]
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
        e["passed"] += int(int(r[ig]) != 0) + int(r[ir])  # the output id is after the 3-D check
        e["rejected_3d"] += int(r[ir])
    return out


def with_labels(view_csv):
    """A copy of a classified view (classify_view's CSV) whose gesture_id is each frame's label: the classifier
    replaced by the truth, to measure what the vote, the 3-D check and the filter leave of perfect readings."""
    vdir = os.path.dirname(view_csv)
    header, rows = ev.read_csv(os.path.join(vdir, "laid_out.csv"))
    it, il = header.index("t"), header.index("label")
    label = {round(float(r[it]), 6): r[il] for r in rows}
    header, rows = ev.read_csv(view_csv)
    ig = header.index("gesture_id")
    out = os.path.join(vdir, "gestures_geometry_labels.csv")
    with open(out, "w") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            r = list(r)
            r[ig] = label[round(float(r[0]), 6)]
            f.write(",".join(r) + "\n")
    return out


def evaluate(gfctl, protocol, name, data, model, config, tag="shipped", labels_as_classifier=False):
    """classify per view -> fuse-views -> gesture-filter on a rendered set; the figures of protocol v2.
    labels_as_classifier: every view's classifications replaced by the frames' labels (a diagnostic)."""
    spec = protocol["sets"][name]
    d = set_dir(data, name, spec)
    fps, gap = protocol["fps"], protocol["sequence_gap_s"]
    he.set_paths(he.PROTOCOL, config)
    _, keys, meta = ev.laid_out(d, fps)
    views = [ev.classify_view(gfctl, model, d, sfx, fps, d) for sfx in VIEW_SUFFIXES(spec)]
    if labels_as_classifier:
        views = [with_labels(v) for v in views]
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
    return {"set": name, "seed": spec["seed"], "sequences": spec["count"], "skeleton": SKELETON,
            "model": "the frames' labels (diagnostic)" if labels_as_classifier else os.path.relpath(model, ROOT),
            "model_sha256": "n/a" if labels_as_classifier else he.sha256(model), "config": os.path.relpath(config, ROOT), "config_sha256": he.sha256(config),
            "worker_found_share": {k: round(v, 4) for k, v in found.items()},
            "leader_window_accuracy": round(float(np.trace(m) / m.sum()), 4) if m.sum() else None,
            "leader_per_class": ev.per_class(m), "leader_confusion": m.tolist(),
            "three_cameras": three, "leader_camera_only": leader, "fired_by_gesture": fired_by_gesture,
            "per_motion_vote_and_3d": per_motion}


def csv_rows(path):
    """The rows of a CSV file; a last line still being written (fewer fields) is left out."""
    import csv
    with open(path) as f:
        return [r for r in csv.DictReader(f) if None not in r.values()]



# ---- the networks' systematic errors against the renderer's truth (tuning data only) ----------------
LS, RS, LE, RE, LW, RW, LH, RH = 5, 6, 7, 8, 9, 10, 11, 12
SEPARATE = 0.05  # truth joints closer than this (fraction of the box height) are not told apart in the swap counts
MIN_CONF = 0.3  # as the triangulation (view_triangulation.hpp TriangulationConfig::min_confidence)


def camera_of(md):
    q = [float(md[c]) for c in ("cam_qw", "cam_qx", "cam_qy", "cam_qz")]
    w, x, y, z = q
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    p = np.array([float(md[c]) for c in ("cam_x", "cam_y", "cam_z")])
    K = [float(md[c]) for c in ("cam_fx", "cam_fy", "cam_cx", "cam_cy")]
    return R, p, K


def triangulate(obs):
    """obs: [(R_world_camera, p_world_camera, (fx, fy, cx, cy), u, v, weight)] -> least-squares point (>= 2 views)."""
    if len(obs) < 2:
        return None
    A, b = [], []
    for R, p, (fx, fy, cx, cy), u, v, w in obs:
        Rt = R.T  # world -> camera rows
        xn, yn = (u - cx) / fx, (v - cy) / fy
        for row in (Rt[0] - xn * Rt[2], Rt[1] - yn * Rt[2]):
            A.append(w * row)
            b.append(w * row @ p)
    X, *_ = np.linalg.lstsq(np.array(A), np.array(b), rcond=None)
    return X


def reprojection_error(X, obs):
    e = 0.0
    for R, p, (fx, fy, cx, cy), u, v, w in obs:
        c = R.T @ (X - p)
        if c[2] <= 0:
            return float("inf")
        e += w * ((fx * c[0] / c[2] + cx - u) ** 2 + (fy * c[1] / c[2] + cy - v) ** 2)
    return e


def reassociated_wrists(obs_l, obs_r):
    """The two wrists triangulated with each view's left/right labels taken as they are or exchanged, whichever
    reprojects best (the first view's labels fixed): what the views show without trusting the network's sides."""
    views = sorted({id(o[0]) for o in obs_l} & {id(o[0]) for o in obs_r})
    by_view = {vid: ([o for o in obs_l if id(o[0]) == vid][0], [o for o in obs_r if id(o[0]) == vid][0]) for vid in views}
    if len(views) < 2:
        return None
    best = None
    for mask in range(1 << (len(views) - 1)):
        a, b = [], []
        for i, vid in enumerate(views):
            ol, orr = by_view[vid]
            swap = i > 0 and (mask >> (i - 1)) & 1
            a.append(orr if swap else ol)
            b.append(ol if swap else orr)
        XA, XB = triangulate(a), triangulate(b)
        err = reprojection_error(XA, a) + reprojection_error(XB, b)
        if best is None or err < best[0]:
            best = (err, XA, XB)
    return best[1], best[2]


def body_measures(P):
    """design.md §2 measures of a 3-D skeleton {keypoint: xyz} as gesture_geometry.hpp defines them."""
    if any(P.get(k) is None for k in (LS, RS, LH, RH)):
        return None
    sm, hm = 0.5 * (P[LS] + P[RS]), 0.5 * (P[LH] + P[RH])
    y = P[LS] - P[RS]
    y /= np.linalg.norm(y)
    z = sm - hm
    z -= (z @ y) * y
    z /= np.linalg.norm(z)
    torso = (sm - hm) @ z
    if torso < 0.1:
        return None
    H = torso / 0.30
    m = {"H": H}
    if P.get(LW) is not None and P.get(RW) is not None:
        m["wrist_sep_H"] = np.linalg.norm(P[LW] - P[RW]) / H
        m["crossed"] = bool((P[LW] - sm) @ y < 0 and (P[RW] - sm) @ y > 0)
        m["wrist_h_H"] = 0.52 + 0.30 * 0.5 * ((P[LW] - hm) @ z + (P[RW] - hm) @ z) / torso
        m["wrist_lateral_H"] = max(abs((P[LW] - sm) @ y), abs((P[RW] - sm) @ y)) / H
    arms = []
    for sh, el, wr in ((LS, LE, LW), (RS, RE, RW)):
        if P.get(el) is not None and P.get(wr) is not None:
            up, fore = P[el] - P[sh], P[wr] - P[el]
            elev = np.degrees(np.arccos(np.clip(-(up @ z) / np.linalg.norm(up), -1, 1)))
            elbow = np.degrees(np.arccos(np.clip(-(up @ fore) / (np.linalg.norm(up) * np.linalg.norm(fore)), -1, 1)))
            whole = P[wr] - P[sh]
            whole_elev = np.degrees(np.arccos(np.clip(-(whole @ z) / np.linalg.norm(whole), -1, 1)))
            arms.append((elev, elbow, whole_elev))
    if arms:
        m["arm_elevation_deg"], m["arm_elbow_deg"], m["arm_whole_elevation_deg"] = max(arms)  # the more raised arm
    return m


def view_frames(d, sfx):
    """{(sequence, t): (truth row, skeleton row or None)} of one view, and its sequences' metadata."""
    meta = {int(r["sequence"]): r for r in csv_rows(os.path.join(d, f"sequences{sfx}.csv"))}
    sk = {(int(r["sequence"]), r["t"]): r for r in csv_rows(os.path.join(d, f"skeletons{sfx}.csv"))}
    return {(int(r["sequence"]), r["t"]): (r, sk.get((int(r["sequence"]), r["t"]))) for r in
            csv_rows(os.path.join(d, f"truth{sfx}.csv"))}, meta


def in_pose(md, t):
    """The frame is at the motion's pose: labelled frames of a gesture; the middle half of a work motion."""
    t0, t1 = float(md["motion_start_s"]), float(md["motion_end_s"])
    return t0 + 0.25 * (t1 - t0) <= float(t) <= t1 - 0.25 * (t1 - t0)


def frame_errors_2d(tr, sk):
    """2-D errors of one detected frame against the truth (fractions of the truth box height)."""
    bh = float(tr["box_h"])
    T = {k: np.array([float(tr[f"tu{k}"]), float(tr[f"tv{k}"])]) for k in range(17)}
    D = {k: np.array([float(sk[f"x{k}"]), float(sk[f"y{k}"])]) for k in range(17) if float(sk[f"c{k}"]) >= MIN_CONF}
    e = {"wrist_err": [np.linalg.norm(D[k] - T[k]) / bh for k in (LW, RW) if k in D and tr[f"tvis{k}"] == "1"]}
    # which truth joint a reported wrist sits on: only where those truth joints are apart (> SEPARATE of the box)
    apart = lambda a, b: np.linalg.norm(T[a] - T[b]) / bh > SEPARATE  # noqa: E731
    e["lr_swap"] = [int(np.linalg.norm(D[k] - T[o]) < np.linalg.norm(D[k] - T[k])) for k, o in ((LW, RW), (RW, LW))
                    if k in D and apart(LW, RW)]
    e["wrist_at_elbow"] = [int(np.linalg.norm(D[k] - T[el]) < np.linalg.norm(D[k] - T[k])) for k, el in ((LW, LE), (RW, RE))
                           if k in D and apart(k, el)]
    e["wrist_missing"] = [int(k not in D) for k in (LW, RW)]
    if LW in D and RW in D:
        e["wrist_gap_2d"] = [np.linalg.norm(D[LW] - D[RW]) / bh]
    e["wrist_gap_2d_truth"] = [np.linalg.norm(T[LW] - T[RW]) / bh]
    return e


def errors(protocol, name, data):
    if name == "rendered_heldout" or protocol["sets"][name]["seed"] in range(*protocol["seed_range"]):
        sys.exit("errors: the held-out set is never analysed for choices (docs/gestures.md §8); use the tuning set")
    spec = protocol["sets"][name]
    d = set_dir(data, name, spec)
    views = [view_frames(d, sfx) for sfx in VIEW_SUFFIXES(spec)]
    meta0 = views[0][1]
    acc = {}
    for key, (tr0, _) in views[0][0].items():
        seq, t = key
        if any(seq not in meta for _, meta in views):
            continue  # a performance still being rendered
        md = meta0[seq]
        if not in_pose(md, t):
            continue
        a = acc.setdefault(md["motion"], {"frames": 0, "found_view_frames": 0, "view_frames": 0, "tri_truth": [], "tri_net": []})
        a["frames"] += 1
        truth_obs, net_obs = {}, {}
        for frames, meta in views:
            tr, sk = frames[key]
            R, p, K = camera_of(meta[seq])
            a["view_frames"] += 1
            for k in range(17):
                truth_obs.setdefault(k, []).append((R, p, K, float(tr[f"tu{k}"]), float(tr[f"tv{k}"]), 1.0))
            if sk is None:
                continue
            a["found_view_frames"] += 1
            for k, v in frame_errors_2d(tr, sk).items():
                a.setdefault(k, []).extend(v)
            for k in range(17):
                c = float(sk[f"c{k}"])
                if c >= MIN_CONF:
                    net_obs.setdefault(k, []).append((R, p, K, float(sk[f"x{k}"]), float(sk[f"y{k}"]), c))
        for obs, out in ((truth_obs, a["tri_truth"]), (net_obs, a["tri_net"])):
            m = body_measures({k: triangulate(v) for k, v in obs.items()})
            if m is not None:
                out.append(m)
        if LW in net_obs and RW in net_obs:
            P = {k: triangulate(v) for k, v in net_obs.items()}
            pair = reassociated_wrists(net_obs[LW], net_obs[RW])
            if pair is not None:
                P[LW], P[RW] = pair
                m = body_measures(P)
                if m is not None and "wrist_sep_H" in m:
                    a.setdefault("reassoc_sep", []).append(m["wrist_sep_H"])
    return {motion: summarize(a) for motion, a in sorted(acc.items())}


def summarize(a):
    med = lambda v: round(float(np.median(v)), 4) if len(v) else None  # noqa: E731
    mean = lambda v: round(float(np.mean(v)), 4) if len(v) else None  # noqa: E731
    out = {"frames_at_pose": a["frames"], "found_share": round(a["found_view_frames"] / max(1, a["view_frames"]), 4),
           "wrist_error_box_median": med(a.get("wrist_err", [])), "wrist_lr_swap_share": mean(a.get("lr_swap", [])),
           "wrist_at_elbow_share": mean(a.get("wrist_at_elbow", [])), "wrist_missing_share": mean(a.get("wrist_missing", [])),
           "wrist_gap_2d_box_median": {"net": med(a.get("wrist_gap_2d", [])), "truth": med(a.get("wrist_gap_2d_truth", []))}}
    for tag in ("truth", "net"):
        ms = [m for m in a[f"tri_{tag}"] if "wrist_sep_H" in m]
        out[f"3d_{tag}"] = {"frames": len(ms), "wrist_sep_H_median": med([m["wrist_sep_H"] for m in ms]),
                            "wrist_sep_H_p90": round(float(np.percentile([m["wrist_sep_H"] for m in ms], 90)), 4) if ms else None,
                            "wrists_crossed_share": mean([m["crossed"] for m in ms]),
                            "wrist_height_H_median": med([m["wrist_h_H"] for m in ms]),
                            "sep_le_0.06H_share": mean([m["wrist_sep_H"] <= 0.06 for m in ms]),
                            "wrist_lateral_H_median": med([m["wrist_lateral_H"] for m in ms]),
                            "raised_arm_elevation_deg_median": med([m["arm_elevation_deg"] for m in ms if "arm_elevation_deg" in m]),
                            "raised_arm_elbow_deg_median": med([m["arm_elbow_deg"] for m in ms if "arm_elbow_deg" in m]),
                            "raised_arm_shoulder_wrist_elevation_deg_median": med([m["arm_whole_elevation_deg"] for m in ms
                                                                                   if "arm_whole_elevation_deg" in m])}
        # per frame (no median over neighbours, unlike the product's check): shares of frames in candidate regions
        arm = [m for m in ms if "arm_elevation_deg" in m]
        out[f"3d_{tag}"]["share_frames"] = {
            "raise_design_upper_arm>=150_elbow>=150": mean([m["arm_elevation_deg"] >= 150 and m["arm_elbow_deg"] >= 150 for m in arm]),
            "raise_shoulder_wrist>=150_elbow>=150": mean([m["arm_whole_elevation_deg"] >= 150 and m["arm_elbow_deg"] >= 150 for m in arm]),
            "raise_shoulder_wrist>=150_elbow>=120": mean([m["arm_whole_elevation_deg"] >= 150 and m["arm_elbow_deg"] >= 120 for m in arm]),
            "cross_design_crossed_height>=0.80": mean([m["crossed"] and m["wrist_h_H"] >= 0.80 for m in ms]),
            "cross_label_free_height>=0.80_offset<=0.10": mean([m["wrist_h_H"] >= 0.80 and m["wrist_lateral_H"] <= 0.10 for m in ms]),
            "palms_gap<=0.06": mean([m["wrist_sep_H"] <= 0.06 for m in ms]),
            "palms_gap<=0.12": mean([m["wrist_sep_H"] <= 0.12 for m in ms])}
    out["3d_net_reassociated_wrist_sep_H_median"] = med(a.get("reassoc_sep", []))
    return out



# ---- the results page ---------------------------------------------------------------------------
ERROR_MOTIONS_ORDER = ["cross_arms", "palms_together", "extend_arm_side", "raise_arm_up", "arms_folded_low", "tool_at_waist",
                       "hold_object_at_chest", "arm_partway_or_pointing", "reach_up_bolt", "balance_lunge", "walking",
                       "climbing_ladder", "idle"]


def pct(x):
    return "–" if x is None else f"{100 * x:.0f} %"


def num(x, digits=3):
    return "–" if x is None else f"{x:.{digits}f}"


def error_table(err):
    lines = ["| motion (frames at the pose) | found (view-frames) | wrist error / box | wrists L↔R swapped | wrist nearer its elbow | "
             "wrist missing (c < 0.3) | 2-D wrist gap / box |",
             "|---|---|---|---|---|---|---|"]
    order = [m for m in ERROR_MOTIONS_ORDER if m in err]
    for motion in order:
        e = err[motion]
        lines.append(f"| {motion} ({e['frames_at_pose']}) | {pct(e['found_share'])} | {num(e['wrist_error_box_median'])} | "
                     f"{pct(e['wrist_lr_swap_share'])} | {pct(e['wrist_at_elbow_share'])} | {pct(e['wrist_missing_share'])} | "
                     f"{num(e['wrist_gap_2d_box_median']['net'])} ({num(e['wrist_gap_2d_box_median']['truth'])}) |")
    lines += ["", "Triangulated from the three views (network, in brackets the truth's keypoints triangulated the same way; "
              "medians over the frames at the pose; the arm columns: the more raised arm):", "",
              "| motion | wrist gap / H (p90) | wrists crossed | wrists' height / H | wrists' offset from the midline / H | "
              "upper arm from hanging [°] | shoulder→wrist from hanging [°] | elbow [°] |",
              "|---|---|---|---|---|---|---|---|"]
    for motion in order:
        n, t = err[motion]["3d_net"], err[motion]["3d_truth"]
        d = lambda k, q=3: f"{num(n[k], q)} ({num(t[k], q)})"  # noqa: E731
        lines.append(f"| {motion} | {num(n['wrist_sep_H_median'])}, {num(n['wrist_sep_H_p90'])} ({num(t['wrist_sep_H_median'])}) | "
                     f"{pct(n['wrists_crossed_share'])} ({pct(t['wrists_crossed_share'])}) | {d('wrist_height_H_median')} | "
                     f"{d('wrist_lateral_H_median')} | {d('raised_arm_elevation_deg_median', 0)} | "
                     f"{d('raised_arm_shoulder_wrist_elevation_deg_median', 0)} | {d('raised_arm_elbow_deg_median', 0)} |")
    return lines


def eval_lines(r, protocol):
    t, lo = r["three_cameras"], r["leader_camera_only"]
    tg = protocol["targets"]["three_cameras"]
    ok_f = (t["fired_share"] or 0) >= tg["gestures_fired_min"]
    ok_a = t["false_adaptations"] <= tg["false_adaptations_max"]
    run = (f"Run {r['date_utc']} UTC at commit {r.get('commit', '?')}, load average "
           f"{', '.join(f'{x:.2f}' for x in r['load_average'])}. " if r.get("date_utc") and r.get("load_average") else "")
    lines = [run + f"Set {r['set']} (seed {r['seed']}, {r['sequences']} performances × 3 views, skeletons by "
             f"{SKELETON_NAMES[r.get('skeleton', 'movenet_lightning')]}); model `{r['model']}` sha256 "
             f"{r['model_sha256'][:16]}…; filter and vote `{r['config']}` sha256 {r['config_sha256'][:16]}…. Worker found "
             "(share of rendered frames, per view): " + ", ".join(f"{k.strip('_')} {pct(v)}" for k, v in r["worker_found_share"].items()) + ".",
             "",
             "| chain | gestures fired | by gesture | mean (max) latency | wrong commands | false adaptations (minutes of work motions) |",
             "|---|---|---|---|---|---|",
             f"| three cameras: classify → fuse-views → gesture-filter | {t['fired']}/{t['gestures']} = {pct(t['fired_share'])} "
             f"(target ≥ {pct(tg['gestures_fired_min'])}: {'met' if ok_f else '**not met**'}) | "
             + ", ".join(f"{g} {v[0]}/{v[1]}" for g, v in sorted(r["fired_by_gesture"].items())) +
             f" | {t['mean_latency_s']} s ({t['max_latency_s']}) | {t['wrong_commands']} | {t['false_adaptations']} "
             f"(target {tg['false_adaptations_max']}: {'met' if ok_a else '**not met**'}) ({t['work_minutes']} min) |",
             f"| the leader's camera alone into the same filter | {lo['fired']}/{lo['gestures']} = {pct(lo['fired_share'])} | | "
             f"{lo['mean_latency_s']} s ({lo['max_latency_s']}) | {lo['wrong_commands']} | {lo['false_adaptations']} ({lo['work_minutes']} min) |",
             "", f"The leader's view, every window through the LSTM: accuracy {r['leader_window_accuracy']}; recall per class: " +
             ", ".join(f"{c} {v['recall']} ({v['support']})" for c, v in r["leader_per_class"].items()) + ".",
             "", "Per motion, fused frames whose 2-D vote passed a gesture / of them refused by the 3-D check: " +
             ", ".join(f"{m} {v['fused_frames_vote_passed']}/{v['rejected_3d']}" for m, v in sorted(r["per_motion_vote_and_3d"].items())) + ".",
             "", "False adaptations: " + ("none" if not t["false_adaptation_list"] else "; ".join(
                 f"{x['gesture']} during {x['motion']} (sequence {x['sequence']}, t {x['t_s']} s)" for x in t["false_adaptation_list"])) + ".",
             "Gestures that did not fire while performed: " + ("none" if not t["missed_list"] else "; ".join(
                 f"{x['gesture']} (sequence {x['sequence']}, commands {x['commands'] or 'none'}, leader {x['distance_m']:.1f} m, "
                 f"{x['elevation_deg']:.0f}°, azimuth {x['azimuth_deg']:.0f}°)" for x in t["missed_list"])) + "."]
    return lines


def v1_lines(runs):
    """Protocol version 1 (tools/gesture/heldout_eval.py JSONs, each with a `label`) beside the targets: a model's
    figures on the generator's own skeletons, which a candidate trained on the networks' errors must keep."""
    lines = ["| run | protocol (seeds) | model sha256 | one camera: accuracy | work windows read as a gesture | "
             "three cameras: false adaptations (minutes) | gestures fired | mean (max) latency | targets |", "|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        s = r["single_camera"]
        for mode, m in r["three_cameras"].items():
            w, g = m["work"]["three_cameras"], m["gestures"]["three_cameras"]
            met = all(all(v.values()) for v in r["meets_target"].values())
            run = r.get("label", "") + (f", rearm {mode}" if len(r["three_cameras"]) > 1 else "")
            lines.append(f"| {run} | `{r['protocol']}` ({r['single_camera']['seed']}, …) | {r['model_sha256'][:16]}… | "
                         f"{s['accuracy']:.4f} | {s['work_share_read_as_gesture']:.4f} ({s['work_windows_read_as_gesture']} of "
                         f"{s['work_windows']}) | {w['false_adaptations']} ({w['work_minutes']}) | {g['fired']}/{g['gestures']} | "
                         f"{g['mean_latency_s']} s ({g['max_latency_s']}) | {'all met' if met else '**not all met**'} |")
    return lines


def training_lines(trained):
    """The candidate models' training (tools/train_gesture_lstm.py's training.json, next to each model's ONNX)."""
    lines = []
    for label, path in trained:
        tr = json.load(open(path))
        onnx = os.path.join(os.path.dirname(path), "gesture_lstm.onnx")
        em, rd = tr.get("error_model"), tr.get("rendered")
        lines.append(f"- {label}: sha256 {he.sha256(onnx)}; `{tr['command']}` — from {tr.get('init_onnx') or 'a random start'}, "
                     f"{tr['epochs']} epochs, {tr['train']['windows']} training windows"
                     + (f", error model {em['file']} (seed {em['seed']}, {em['sequences_changed']} sequences changed)" if em else "")
                     + (f", rendered {', '.join(s['dir'] + '/' + s['file'] for s in rd['sets'])} × {rd['repeat']}" if rd else "")
                     + f"; validation accuracy {tr['validation']['accuracy']:.4f}; {tr['seconds']} s (torch {tr['torch']}, "
                     f"{tr.get('threads', 2)} thread(s), shared machine).")
    return lines


def rules_lines(rules):
    """tools/gesture/geometry_rules.py's JSON: every candidate 3-D rule's share of frames per motion (tuning set)."""
    motions = sorted(rules["share_of_frames"])
    names = list(rules["share_of_frames"][motions[0]].keys())
    lines = [f"Set {rules['set']} (seed {rules['seed']}): the three views' network keypoints triangulated per frame, each frame "
             f"read on the per-keypoint median of {rules['median_frames']} frames around it, measured in the body frame "
             "(`tools/gesture/geometry_rules.py`); share of each motion's frames (start to end of the motion) in which the rule "
             "holds. H = torso / 0.30; heights from the feet (shoulders 0.82 H); \"off\": the wrists' largest distance from the "
             "body's midline; \"whole\": the line shoulder → wrist from hanging down.", "",
             "| rule | " + " | ".join(motions) + " |", "|---|" + "---|" * len(motions)]
    for n in names:
        lines.append(f"| {n} | " + " | ".join(f"{rules['share_of_frames'][m][n]:.3f}" for m in motions) + " |")
    return lines


def report(protocol, protocol_path, tuning_errors, tuning_eval, heldout_eval, out, load_start, v1_runs=(), trained=(),
           rules=None, title=None, note=None):
    lines = [f"# {title or 'Gestures on rendered frames through the real networks (protocol version 2)'}", "",
             f"Written by `tools/gesture/rendered_eval.py report` on "
             f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, commit {he.git('rev-parse', '--short', 'HEAD')}"
             f"{'' if he.git('status', '--porcelain', '--untracked-files=no') == '' else ' (with uncommitted changes)'}; protocol "
             f"`{os.path.relpath(protocol_path, ROOT)}` version {protocol['version']} (sha256 {he.sha256(protocol_path)[:16]}…). "
             f"Machine: {he.machine()['cpu']}, {os.cpu_count()} cores; load average {', '.join(f'{x:.2f}' for x in load_start)} "
             "when the evaluation started (the renders' own logs in the data cache give theirs; shared machine).",
             "", "Sets rendered by `gfctl render-gestures` (the mannequin posed from the generator's 3-D bodies, three "
             f"formation-like views, the real MoveNet multipose + KCF + {SKELETON_NAMES[SKELETON]} on the pixels); definitions: "
             "docs/gestures.md §9 and the protocol file.", ""]
    for name, spec in protocol["sets"].items():
        log = os.path.join(DATA_DIR, os.path.basename(set_dir("", name, spec)), "render.log")
        if os.path.exists(log):
            with open(log) as f:
                text = [ln.strip() for ln in f if ln.startswith("#") or ln.startswith("gfctl render-gestures")]
            lines.append(f"Render of {name} (its log): " + " / ".join(t.lstrip("# ") for t in text) + ".")
    lines.append("")
    if note:
        with open(note) as f:
            lines += ["## What was decided, and on what", "", f.read().strip(), ""]
    if trained:
        lines += ["## Candidate models (not shipped unless third_party_models/gesture_lstm says so)", ""] + training_lines(trained) + [""]
    if tuning_errors:
        lines += ["## Tuning set: the networks' systematic errors against the renderer's truth", "",
                  "Frames at the motion's pose (gestures: labelled frames; work motions: the middle half of the motion). "
                  "2-D: the pipeline's keypoints (confidence ≥ 0.3) against the truth's projection, as fractions of the "
                  "truth box height; \"swapped\": the reported wrist lies nearer the other wrist's truth than its own; "
                  "\"nearer its elbow\": nearer its own elbow's truth (both counted only where those truth joints are more than 5 % of the box apart). 3-D: the three views' keypoints triangulated "
                  "(least squares, confidence-weighted, as view_triangulation.hpp) and measured as gesture_geometry.hpp "
                  "does (H = torso / 0.30); in brackets the same from the truth keypoints.", ""]
        lines += error_table(tuning_errors) + [""]
    if rules:
        lines += ["## Tuning set: candidate 3-D rules, share of frames per motion", ""] + rules_lines(rules) + [""]
    for r in tuning_eval:
        lines += [f"## Tuning set through the chain: {r.get('label', '')}", ""] + eval_lines(r, protocol) + [""]
    for r in heldout_eval:
        lines += [f"## Held-out set through the chain: {r.get('label', '')} (run once; nothing chosen on it)", ""] + \
                 eval_lines(r, protocol) + [""]
    if v1_runs:
        lines += ["## Protocol version 1 with the same models (the generator's own skeletons)", "",
                  "`tools/gesture/heldout_eval.py` runs (their own JSONs give every figure): a model trained on the networks' "
                  "errors must keep version 1's targets (one camera: accuracy ≥ 0.95, ≤ 2 % of work windows read as a "
                  "gesture; three cameras: 0 false adaptations, ≥ 95 % fired, mean latency ≤ 2.5 s).", ""] + v1_lines(v1_runs) + [""]
    with open(out, "w") as f:
        f.write("\n".join(lines))
    with open(os.path.splitext(out)[0] + ".json", "w") as f:
        json.dump({"protocol_version": protocol["version"], "tuning_errors": tuning_errors, "tuning_eval": tuning_eval,
                   "heldout_eval": heldout_eval, "protocol_v1": list(v1_runs)}, f, indent=1)


def set_data_dir(path, skeleton="movenet_lightning"):
    global DATA_DIR, SKELETON
    DATA_DIR, SKELETON = path, skeleton


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("action", choices=["render", "evaluate", "errors", "report"])
    ap.add_argument("--tuning-errors", default=None, help="report: the errors JSON of the tuning set")
    ap.add_argument("--tuning-eval", default=None, help="report: evaluate JSONs of the tuning set, comma-separated")
    ap.add_argument("--heldout-eval", default=None, help="report: evaluate JSONs of the held-out set, comma-separated")
    ap.add_argument("--v1", default=None, help="report: protocol version 1 JSONs (heldout_eval.py) of the same models, "
                    "comma-separated, each as LABEL=PATH")
    ap.add_argument("--trained", default=None, help="report: candidate models' training.json, comma-separated, each as LABEL=PATH")
    ap.add_argument("--rules", default=None, help="report: tools/gesture/geometry_rules.py's JSON (tuning set)")
    ap.add_argument("--title", default=None, help="report: the page's title")
    ap.add_argument("--note", default=None, help="report: a markdown file with the decision and the checks outside this tool "
                    "(unit tests, photos), placed after the header")
    ap.add_argument("--label", default="", help="evaluate: what this run is (model / rule), written into its JSON")
    ap.add_argument("--gfctl")
    ap.add_argument("--set", default=None)
    ap.add_argument("--data", default="/work/gestrend_data", help="cache of the rendered sets (not in git)")
    ap.add_argument("--protocol", default=PROTOCOL)
    ap.add_argument("--models", default=None)
    ap.add_argument("--skeleton", default="movenet_lightning", choices=["movenet_lightning", "blazepose_landmark"],
                    help="render: the pipeline's skeleton network (gfctl render-gestures --skeleton); every action "
                         "reads the set rendered with it (its own directory in --data)")
    ap.add_argument("--model", default=he.MODEL)
    ap.add_argument("--config", default=he.GESTURES_YAML)
    ap.add_argument("--out", default=None)
    ap.add_argument("--labels-as-classifier", action="store_true",
                    help="evaluate: replace every view's classifications by the frames' labels (what the vote, the 3-D "
                         "check and the filter leave of perfect readings; the leader's window figures stay the model's)")
    a = ap.parse_args()
    protocol = load_protocol(a.protocol)
    set_data_dir(a.data, a.skeleton)
    if a.action == "report":
        load = lambda p: json.load(open(p)) if p else None  # noqa: E731
        loads = lambda ps: [load(p) for p in ps.split(",")] if ps else []  # noqa: E731
        out = a.out or os.path.join(ROOT, "docs/results/gestures_rendered.md")
        v1 = []
        for item in (a.v1.split(",") if a.v1 else []):
            label, _, path = item.rpartition("=")
            if not label:
                ap.error(f"--v1 {item}: expected LABEL=PATH")
            v1.append(dict(load(path), label=label))
        trained = []
        for item in (a.trained.split(",") if a.trained else []):
            label, _, path = item.rpartition("=")
            if not label:
                ap.error(f"--trained {item}: expected LABEL=PATH")
            trained.append((label, path))
        report(protocol, a.protocol, load(a.tuning_errors), loads(a.tuning_eval), loads(a.heldout_eval), out, os.getloadavg(),
               v1, trained, load(a.rules), a.title, a.note)
        print(f"wrote {out}")
        return
    if not a.set:
        ap.error("--set is required")
    if a.action == "render":
        print(render(a.gfctl, protocol, a.set, a.data, a.models))
    elif a.action == "errors":
        r = errors(protocol, a.set, a.data)
        print(json.dumps(r, indent=1))
        if a.out:
            with open(a.out, "w") as f:
                json.dump(r, f, indent=1)
    else:
        r = evaluate(a.gfctl, protocol, a.set, a.data, a.model, os.path.abspath(a.config),
                     tag="labels" if a.labels_as_classifier else "shipped", labels_as_classifier=a.labels_as_classifier)
        r["label"] = a.label
        r["commit"] = he.git("rev-parse", "--short", "HEAD")
        r["date_utc"] = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M")
        r["load_average"] = list(os.getloadavg())
        t = r["three_cameras"]
        print(f"{a.set}: three cameras {t['fired']}/{t['gestures']} fired, mean latency {t['mean_latency_s']} s, "
              f"{t['false_adaptations']} false adaptations in {t['work_minutes']} min; by gesture {r['fired_by_gesture']}")
        if a.out:
            with open(a.out + ".json", "w") as f:
                json.dump(r, f, indent=1)


if __name__ == "__main__":
    main()
