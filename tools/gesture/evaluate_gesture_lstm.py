#!/usr/bin/env python3
"""Evaluates the trained gesture LSTM through the product's own code paths (gfctl classify =
OpenCV DNN in C++, gfctl gesture-filter = the C++ GestureFilter) on held-out data that the
training never saw: unseen seeds, and body heights, proportions, viewpoints, tempi and
noise outside the training ranges (tools/gesture/heldout_*.yaml).

    /opt/gesture_formation/venv/bin/python tools/gesture/evaluate_gesture_lstm.py \
        --gfctl build/devel/lib/gesture_formation/gfctl

Writes third_party_models/gesture_lstm/evaluation.json, docs/images/gesture_confusion.png,
docs/images/gesture_filter_sweep.png and (with --write-test-set) the fixed held-out test
set test/data/gesture/heldout_skeletons.csv used by the C++ accuracy test.

Definitions (docs/gestures.md):
- window label = the label of the window's newest frame (the synthesizer labels a frame
  with its gesture while the pose is ≥ 85 % reached);
- a gesture sequence succeeds when the filter fires the right command while the worker
  still performs the gesture (motion_start_s ≤ t_fire ≤ motion_end_s); latency =
  t_fire − motion_start_s; any command fired during a "none" sequence is a false adaptation.

Every set is also seen by the formation's two followers (cameras at ±60° azimuth from the
leader's, Table II; `synth-gestures --views 60,-60`, the leader's file unchanged by it): each
view is classified, `gfctl fuse-views` (gesture::ViewFusion, config/gestures.yaml) votes, and
the fused ids go through the same filter — "filter_three_views" (the product's configuration),
"filter_three_views_no_envelope" (the same without the envelope gate), next to the single-camera
"filter_paper_parameters".
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gesture_data  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CLASSES = ["none", "cross_arms", "extend_arm_side", "palms_together", "raise_arm_up"]
SEQ_GAP_S = 100.0
FOLLOWER_OFFSETS_DEG = (60, -60)  # Table II: followers at ±60° from the leader  # sequences are laid end to end this far apart (> max_age_s + cooldown_s)

# name, seed, sequences, config (None: the training distribution)
CLASSIFIER_SETS = [
    ("unseen_seed", 2001, 600, None),
    ("far_high_tall", 2002, 400, "tools/gesture/heldout_far_high_tall.yaml"),
    ("near_low_short", 2003, 400, "tools/gesture/heldout_near_low_short.yaml"),
]
FILTER_SET = ("filter_protocol", 2004, 600, "tools/gesture/heldout_filter_protocol.yaml")
TEST_SET_SEQUENCES = 40  # per classifier set, into test/data/gesture/heldout_skeletons.csv


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def laid_out(data_dir, fps):
    """Rewrites skeletons.csv with t += SEQ_GAP_S·sequence; returns the path, per-row
    (sequence, frame index, label) and the sequences' metadata."""
    header, rows = read_csv(os.path.join(data_dir, "skeletons.csv"))
    it, iseq, ilab = header.index("t"), header.index("sequence"), header.index("label")
    mheader, mrows = read_csv(os.path.join(data_dir, "sequences.csv"))
    meta = {int(r[0]): dict(zip(mheader, r)) for r in mrows}
    out = os.path.join(data_dir, "laid_out.csv")
    keys = {}
    with open(out, "w") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            seq = int(r[iseq])
            t = float(r[it])
            frame = int(round(t * fps))
            r = list(r)
            r[it] = repr(SEQ_GAP_S * seq + t)
            keys[(seq, frame)] = int(r[ilab])
            f.write(",".join(r) + "\n")
    return out, keys, meta


def classify(gfctl, model, laid_out_csv, keys, fps, work):
    out = os.path.join(work, "gestures.csv")
    run([gfctl, "classify", "--in", laid_out_csv, "--out", out, "--model", model])
    header, rows = read_csv(out)
    res = []  # (sequence, frame, t, true, predicted, probabilities)
    for r in rows:
        t = float(r[0])
        seq = int(t // SEQ_GAP_S)
        frame = int(round((t - SEQ_GAP_S * seq) * fps))
        res.append((seq, frame, t, keys[(seq, frame)], int(r[1]), [float(x) for x in r[2:7]]))
    return out, res


KEYPOINT_COLUMNS = [f"{p}{k}" for p in "xyc" for k in range(17)]
CAMERA_COLUMNS = ["cam_x", "cam_y", "cam_z", "cam_qw", "cam_qx", "cam_qy", "cam_qz",
                  "cam_fx", "cam_fy", "cam_cx", "cam_cy", "cam_width", "cam_height"]


def frame_skeletons(laid_out_csv):
    """{round(t, 6): [x0..x16, y0..y16, c0..c16]} of a laid-out skeletons file."""
    header, rows = read_csv(laid_out_csv)
    it, ik = header.index("t"), [header.index(c) for c in KEYPOINT_COLUMNS]
    return {round(float(r[it]), 6): [r[i] for i in ik] for r in rows}


def classify_view(gfctl, model, data_dir, suffix, fps, work):
    """Classifies the view `suffix` ("_view1", …) and adds per row its camera geometry
    (distance_m, elevation_deg of its sequence) for the envelope gate and, when the sequences
    file has the camera's pose (gfctl synth-gestures: cam_* columns), the frame's keypoints and
    that pose: the calibrated skeleton `gfctl fuse-views` triangulates (view_fusion.require_3d)."""
    vdir = os.path.join(work, "view" + suffix)
    os.makedirs(vdir, exist_ok=True)
    for name in ("skeletons", "sequences"):
        src = os.path.join(data_dir, name + suffix + ".csv")
        dst = os.path.join(vdir, name + ".csv")
        if os.path.abspath(src) != os.path.abspath(dst):
            with open(src) as fi, open(dst, "w") as fo:
                fo.write(fi.read())
    laid, keys, meta = laid_out(vdir, fps)
    gcsv, _ = classify(gfctl, model, laid, keys, fps, vdir)
    header, rows = read_csv(gcsv)
    calibrated = all(c in next(iter(meta.values())) for c in CAMERA_COLUMNS)
    skeletons = frame_skeletons(laid) if calibrated else {}
    out = os.path.join(vdir, "gestures_geometry.csv")
    with open(out, "w") as f:
        extra = "," + ",".join(KEYPOINT_COLUMNS + CAMERA_COLUMNS) if calibrated else ""
        f.write(",".join(header) + ",distance_m,elevation_deg" + extra + "\n")
        for r in rows:
            seq = int(float(r[0]) // SEQ_GAP_S)
            line = ",".join(r) + f",{meta[seq]['distance_m']},{meta[seq]['elevation_deg']}"
            if calibrated:
                line += "," + ",".join(skeletons[round(float(r[0]), 6)] + [meta[seq][c] for c in CAMERA_COLUMNS])
            f.write(line + "\n")
    return out


def fuse(gfctl, view_csvs, config, out):
    run([gfctl, "fuse-views", "--in", ",".join(view_csvs), "--out", out, "--config", config])
    return out


def confusion(res):
    m = np.zeros((5, 5), dtype=np.int64)
    for _, _, _, y, p, _ in res:
        m[y, p] += 1
    return m


def per_class(m):
    out = {}
    for c in range(5):
        tp = m[c, c]
        prec = tp / m[:, c].sum() if m[:, c].sum() else float("nan")
        rec = tp / m[c, :].sum() if m[c, :].sum() else float("nan")
        out[CLASSES[c]] = {"precision": round(float(prec), 4), "recall": round(float(rec), 4),
                           "support": int(m[c, :].sum())}
    return out


def none_false_positives(res, meta, fps):
    """Windows of non-gesture sequences classified as a gesture, per minute, per motion."""
    by_motion = {}
    for seq, _, _, _, p, _ in res:
        md = meta[seq]
        if int(md["gesture_id"]) != 0:
            continue
        d = by_motion.setdefault(md["motion"], [0, 0])
        d[0] += 1
        d[1] += int(p != 0)
    total_w = sum(v[0] for v in by_motion.values())
    total_fp = sum(v[1] for v in by_motion.values())
    per_min = lambda fp, w: fp / (w / fps / 60.0) if w else float("nan")  # noqa: E731
    return {"per_minute": round(per_min(total_fp, total_w), 3), "windows": total_w, "false_windows": total_fp,
            "by_motion": {k: {"per_minute": round(per_min(v[1], v[0]), 3), "windows": v[0]} for k, v in
                          sorted(by_motion.items())}}


def write_filter_config(path, window, min_meas, ratio, gate_envelope=True):
    with open(os.path.join(ROOT, "config", "gestures.yaml")) as f:
        base = f.read()
    import yaml  # tools venv
    cfg = yaml.safe_load(base)
    cfg["window_size"] = window
    cfg["min_measurements"] = min_meas
    cfg["ratio_threshold"] = ratio
    cfg["view_fusion"]["gate_envelope"] = gate_envelope
    with open(path, "w") as f:
        yaml.safe_dump(cfg, f)


def filter_eval(gfctl, gestures_csv, meta, config, work):
    """Runs gfctl gesture-filter on the laid-out classifier output; scores per sequence."""
    out = os.path.join(work, "commands.csv")
    # gesture-filter wants t,gesture_id
    inp = os.path.join(work, "filter_in.csv")
    _, rows = read_csv(gestures_csv)
    with open(inp, "w") as f:
        f.write("t,gesture_id\n")
        for r in rows:
            f.write(f"{r[0]},{r[1]}\n")
    run([gfctl, "gesture-filter", "--config", config, "--in", inp, "--out", out])
    _, fired = read_csv(out)
    fires = {}
    for r in fired:
        t = float(r[0])
        seq = int(t // SEQ_GAP_S)
        fires.setdefault(seq, []).append((t - SEQ_GAP_S * seq, int(r[1])))
    n_g = succ = wrong = false_adapt = n_none = 0
    latencies = []
    none_minutes = 0.0
    for seq, md in meta.items():
        gid = int(md["gesture_id"])
        fs = fires.get(seq, [])
        if gid == 0:
            n_none += 1
            none_minutes += int(md["frames"]) / 15.0 / 60.0
            false_adapt += len(fs)
            continue
        n_g += 1
        t0, t1 = float(md["motion_start_s"]), float(md["motion_end_s"])
        wrong += sum(1 for _, g in fs if g != gid)
        ok = [t for t, g in fs if g == gid and t0 <= t <= t1]
        if ok:
            succ += 1
            latencies.append(ok[0] - t0)
    return {"gesture_sequences": n_g, "successes": succ,
            "success_rate": round(succ / n_g, 4) if n_g else float("nan"),
            "mean_latency_s": round(float(np.mean(latencies)), 3) if latencies else float("nan"),
            "median_latency_s": round(float(np.median(latencies)), 3) if latencies else float("nan"),
            "max_latency_s": round(float(np.max(latencies)), 3) if latencies else float("nan"),
            "wrong_commands": wrong, "none_sequences": n_none, "none_minutes": round(none_minutes, 2),
            "false_adaptations": false_adapt}


def plot_confusion(m, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    norm = m / np.maximum(1, m.sum(axis=1, keepdims=True))
    fig, ax = plt.subplots(figsize=(6.4, 5.4))
    im = ax.imshow(norm, cmap="Blues", vmin=0, vmax=1)
    for i in range(5):
        for j in range(5):
            ax.text(j, i, f"{norm[i, j]:.3f}\n({m[i, j]})", ha="center", va="center", fontsize=7,
                    color="white" if norm[i, j] > 0.6 else "black")
    ax.set_xticks(range(5), CLASSES, rotation=30, ha="right")
    ax.set_yticks(range(5), CLASSES)
    ax.set_xlabel("predicted")
    ax.set_ylabel("true (newest frame of the window)")
    ax.set_title(title, fontsize=9)
    fig.colorbar(im, ax=ax, fraction=0.046)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def plot_sweep(sweep, path, label):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for K in sorted({s["K"] for s in sweep}):
        pts = sorted([s for s in sweep if s["K"] == K], key=lambda s: s["ratio"])
        a1.plot([s["false_per_hour"] for s in pts], [100 * s["success_rate"] for s in pts], "o-", label=f"K = {K}")
        for s in pts:
            a1.annotate(f"{s['ratio']:.2f}", (s["false_per_hour"], 100 * s["success_rate"]), fontsize=6,
                        xytext=(2, 2), textcoords="offset points")
        a2.plot([s["ratio"] for s in pts], [s["mean_latency_s"] for s in pts], "o-", label=f"K = {K}")
    a1.set_xlabel("false commands per hour of work motions")
    a1.set_ylabel("gesture → command success [%]")
    a1.set_title(f"{label}: success vs false commands (labels: Π_d)", fontsize=9)
    a1.grid(alpha=0.3)
    a1.legend(fontsize=8)
    a2.set_xlabel("ratio threshold Π_d")
    a2.set_ylabel("mean latency [s]")
    a2.set_title("latency from gesture start to command", fontsize=9)
    a2.grid(alpha=0.3)
    a2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def write_test_set(data_dirs, path, per_set):
    """The first `per_set` sequences of each classifier set, renumbered, 6 significant digits."""
    out_rows, header = [], None
    next_id = 0
    for d in data_dirs:
        header, rows = read_csv(os.path.join(d, "skeletons.csv"))
        iseq = header.index("sequence")
        remap = {}
        for r in rows:
            s = int(r[iseq])
            if s >= per_set:
                continue
            if s not in remap:
                remap[s] = next_id
                next_id += 1
            vals = ["%.6g" % float(x) for x in r[:iseq - 1]]
            out_rows.append(vals + [r[iseq - 1], str(remap[s])])
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for r in out_rows:
            f.write(",".join(r) + "\n")
    return next_id, len(out_rows)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gfctl", required=True)
    ap.add_argument("--model", default=os.path.join(ROOT, "third_party_models/gesture_lstm/gesture_lstm.onnx"))
    ap.add_argument("--work", default=None)
    ap.add_argument("--json", default=os.path.join(ROOT, "third_party_models/gesture_lstm/evaluation.json"))
    ap.add_argument("--images", default=os.path.join(ROOT, "docs/images"))
    ap.add_argument("--write-test-set", action="store_true")
    a = ap.parse_args()
    work = a.work or tempfile.mkdtemp(prefix="gf_eval_")
    fps = 15.0
    report = {"model": os.path.relpath(a.model, ROOT), "sets": {}}
    all_m = np.zeros((5, 5), dtype=np.int64)
    dirs = []
    for name, seed, count, cfg in CLASSIFIER_SETS + [FILTER_SET]:
        d = gesture_data.synthesize(a.gfctl, seed, count, os.path.join(work, name),
                                    os.path.join(ROOT, cfg) if cfg else None, FOLLOWER_OFFSETS_DEG)
        laid, keys, meta = laid_out(d, fps)
        gcsv, res = classify(a.gfctl, a.model, laid, keys, fps, d)
        m = confusion(res)
        acc = float(np.trace(m) / m.sum())
        entry = {"seed": seed, "sequences": count, "config": cfg, "windows": int(m.sum()),
                 "accuracy": round(acc, 4), "per_class": per_class(m), "confusion": m.tolist(),
                 "none_false_positives": none_false_positives(res, meta, fps),
                 "filter_paper_parameters": filter_eval(a.gfctl, gcsv, meta, os.path.join(ROOT, "config/gestures.yaml"), d)}
        # The formation's three cameras: classify each, vote, filter.
        views = [classify_view(a.gfctl, a.model, d, "", fps, d)]
        views += [classify_view(a.gfctl, a.model, d, f"_view{i + 1}", fps, d) for i in range(len(FOLLOWER_OFFSETS_DEG))]
        gesture_cfg = os.path.join(ROOT, "config/gestures.yaml")
        fused = fuse(a.gfctl, views, gesture_cfg, os.path.join(d, "fused.csv"))
        entry["filter_three_views"] = filter_eval(a.gfctl, fused, meta, gesture_cfg, d)
        open_cfg = os.path.join(d, "gestures_no_envelope.yaml")
        write_filter_config(open_cfg, 20, 20, 0.8, gate_envelope=False)
        fused_open = fuse(a.gfctl, views, open_cfg, os.path.join(d, "fused_no_envelope.csv"))
        entry["filter_three_views_no_envelope"] = filter_eval(a.gfctl, fused_open, meta, gesture_cfg, d)
        report["sets"][name] = entry
        print(f"{name}: accuracy {acc:.4f} on {m.sum()} windows; filter {entry['filter_paper_parameters']}")
        print(f"{name}: three views {entry['filter_three_views']}")
        print(f"{name}: three views, no envelope gate {entry['filter_three_views_no_envelope']}")
        if name != FILTER_SET[0]:
            all_m += m
            dirs.append(d)
        if name == FILTER_SET[0]:
            sweep, sweep3 = [], []
            none_minutes = entry["filter_paper_parameters"]["none_minutes"]
            for K in (5, 10, 15, 20, 30):
                for ratio in (0.5, 0.6, 0.7, 0.8, 0.9):
                    cfgp = os.path.join(d, f"filter_K{K}_r{ratio}.yaml")
                    write_filter_config(cfgp, K, K, ratio)
                    for src, lst in ((gcsv, sweep), (fused, sweep3)):
                        fe = filter_eval(a.gfctl, src, meta, cfgp, d)
                        lst.append({"K": K, "ratio": ratio, "success_rate": fe["success_rate"],
                                    "mean_latency_s": fe["mean_latency_s"], "false_adaptations": fe["false_adaptations"],
                                    "false_per_hour": round(60.0 * fe["false_adaptations"] / none_minutes, 2),
                                    "wrong_commands": fe["wrong_commands"]})
            report["filter_sweep"] = sweep
            report["filter_sweep_three_views"] = sweep3
            plot_sweep(sweep, os.path.join(a.images, "gesture_filter_sweep.png"), "one camera (the leader's)")
            plot_sweep(sweep3, os.path.join(a.images, "gesture_filter_sweep_three_views.png"),
                       "three cameras (leader, followers at ±60°), 2-of-3 vote")
    report["held_out_accuracy"] = round(float(np.trace(all_m) / all_m.sum()), 4)
    report["held_out_confusion"] = all_m.tolist()
    report["held_out_per_class"] = per_class(all_m)
    plot_confusion(all_m, os.path.join(a.images, "gesture_confusion.png"),
                   f"held-out windows (unseen seed + out-of-range bodies/viewpoints), accuracy "
                   f"{report['held_out_accuracy']:.3f}")
    if a.write_test_set:
        path = os.path.join(ROOT, "test/data/gesture/heldout_skeletons.csv")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        n, rows = write_test_set(dirs, path, TEST_SET_SEQUENCES)
        report["test_set"] = {"path": os.path.relpath(path, ROOT), "sequences": n, "rows": rows}
    with open(a.json, "w") as f:
        json.dump(report, f, indent=1)
    print(f"held-out accuracy {report['held_out_accuracy']:.4f}; wrote {a.json}")


if __name__ == "__main__":
    main()
