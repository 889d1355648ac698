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


def load_frames(data_dir):
    """Returns dict sequence (or (sequence, segment) when the file has a `segment` column) -> (features [T, 51]
    float32, labels [T] int, t [T])."""
    seqs = {}
    with open(os.path.join(data_dir, "skeletons.csv")) as f:
        reader = csv.reader(f)
        header = next(reader)
        idx = {n: i for i, n in enumerate(header)}
        for row in reader:
            v = np.array([float(x) for x in row[:-2]], dtype=np.float64)
            u, vv, w, h = v[idx["u"]], v[idx["v"]], v[idx["w"]], v[idx["h"]]
            feat = np.zeros(N_FEATURES, dtype=np.float32)
            for k in range(17):
                x, y, c = v[idx[f"x{k}"]], v[idx[f"y{k}"]], v[idx[f"c{k}"]]
                if c > 0 and w > 0 and h > 0:
                    feat[3 * k:3 * k + 3] = ((x - u) / w, (y - vv) / h, c)
            # `gfctl render-gestures` adds a `segment` column: a window never spans the frames in which the
            # pipeline lost the worker (as its FIFO and `gfctl classify` restart), so each segment is a sequence.
            key = int(row[idx["sequence"]]) if "segment" not in idx else (int(row[idx["sequence"]]), int(row[idx["segment"]]))
            seqs.setdefault(key, []).append((feat, int(row[idx["label"]]), v[idx["t"]]))
    out = {}
    for sid, frames in seqs.items():
        out[sid] = (np.stack([f[0] for f in frames]), np.array([f[1] for f in frames]), np.array([f[2] for f in frames]))
    return out


def windows(seqs):
    """All windows of N_FRAMES consecutive frames; label = the last frame's label."""
    xs, ys, sid_of = [], [], []
    for sid, (feat, lab, _) in sorted(seqs.items()):
        for end in range(N_FRAMES, len(feat) + 1):
            xs.append(feat[end - N_FRAMES:end])
            ys.append(lab[end - 1])
            sid_of.append(sid)
    return np.stack(xs).astype(np.float32), np.array(ys, dtype=np.int64), np.array(sid_of)
