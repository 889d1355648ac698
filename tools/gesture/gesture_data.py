"""Loading `gfctl synth-gestures` datasets into classifier windows (shared by training and
evaluation). Features per frame: 17 × (x', y', c) with x' = (x − u)/w, y' = (y − v)/h and
(0, 0, 0) for a missing keypoint — exactly gesture::boxNormalizedFeatures in C++."""
import csv
import os
import subprocess

import numpy as np

N_FRAMES = 9
N_FEATURES = 51


def synthesize(gfctl, seed, count, out_dir, config=None, views=None):
    """views: azimuth offsets [deg] of further cameras (skeletons_view1.csv, …); the primary
    skeletons.csv is the same with or without them."""
    last = "skeletons_view%d.csv" % len(views) if views else "skeletons.csv"
    if not os.path.exists(os.path.join(out_dir, last)):
        cmd = [gfctl, "synth-gestures", "--seed", str(seed), "--count", str(count), "--out", out_dir]
        if config:
            cmd += ["--config", config]
        if views:
            cmd += ["--views", ",".join(str(v) for v in views)]
        subprocess.run(cmd, check=True)
    return out_dir


def load_raw(data_dir, filename="skeletons.csv"):
    """Returns dict sequence (or (sequence, segment) when the file has a `segment` column) -> (keypoints
    [T, 17, 3] float64 in pixels (x, y, c), box [T, 4] (u, v, w, h), labels [T] int, t [T])."""
    seqs = {}
    with open(os.path.join(data_dir, filename)) as f:
        reader = csv.reader(f)
        header = next(reader)
        idx = {n: i for i, n in enumerate(header)}
        cols = [idx[f"{a}{k}"] for k in range(17) for a in ("x", "y", "c")]
        box = [idx[n] for n in ("u", "v", "w", "h")]
        for row in reader:
            v = np.array([float(x) for x in row], dtype=np.float64)
            # `gfctl render-gestures` adds a `segment` column: a window never spans the frames in which the
            # pipeline lost the worker (as its FIFO and `gfctl classify` restart), so each segment is a sequence.
            key = int(row[idx["sequence"]]) if "segment" not in idx else (int(row[idx["sequence"]]), int(row[idx["segment"]]))
            seqs.setdefault(key, []).append((v[cols].reshape(17, 3), v[box], int(row[idx["label"]]), v[idx["t"]]))
    return {sid: (np.stack([f[0] for f in fr]), np.stack([f[1] for f in fr]), np.array([f[2] for f in fr]),
                  np.array([f[3] for f in fr])) for sid, fr in seqs.items()}


def features(keypoints, box):
    """Box-normalised features [T, 51] float32 of raw keypoints [T, 17, 3] and boxes [T, 4] (as
    gesture::boxNormalizedFeatures: a keypoint with c <= 0, or a degenerate box, gives (0, 0, 0))."""
    u, v, w, h = (box[:, i:i + 1] for i in range(4))
    c = keypoints[:, :, 2]
    present = (c > 0) & (w > 0) & (h > 0)
    x = np.where(present, (keypoints[:, :, 0] - u) / np.where(w > 0, w, 1), 0.0)
    y = np.where(present, (keypoints[:, :, 1] - v) / np.where(h > 0, h, 1), 0.0)
    return np.stack([x, y, np.where(present, c, 0.0)], axis=2).reshape(len(keypoints), N_FEATURES).astype(np.float32)


def load_frames(data_dir, filename="skeletons.csv"):
    """Returns dict sequence (or (sequence, segment)) -> (features [T, 51] float32, labels [T] int, t [T])."""
    return {sid: (features(kp, box), lab, t) for sid, (kp, box, lab, t) in load_raw(data_dir, filename).items()}


def load_motions(data_dir, filename="sequences.csv"):
    """sequence -> motion name (sequences.csv of synth-gestures / render-gestures)."""
    with open(os.path.join(data_dir, filename)) as f:
        return {int(r["sequence"]): r["motion"] for r in csv.DictReader(f)}


def windows(seqs):
    """All windows of N_FRAMES consecutive frames; label = the last frame's label."""
    xs, ys, sid_of = [], [], []
    for sid, (feat, lab, _) in sorted(seqs.items()):
        for end in range(N_FRAMES, len(feat) + 1):
            xs.append(feat[end - N_FRAMES:end])
            ys.append(lab[end - 1])
            sid_of.append(sid)
    return np.stack(xs).astype(np.float32), np.array(ys, dtype=np.int64), np.array(sid_of)
