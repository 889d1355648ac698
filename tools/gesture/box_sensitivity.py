#!/usr/bin/env python3
"""How much the gesture LSTM's reading depends on the worker's box (docs/gestures.md §6).

The classifier sees keypoints normalised to the box (design.md §8.7), so a box that moves while the
person does not changes its input. This script moves every frame's box edges of a labelled
skeleton CSV (default: the committed held-out test set) by independent normal draws of
σ × the box's width / height (seeded), classifies with `gfctl classify` (the product's C++ /
OpenCV DNN path) for each model given, and prints the window accuracy (label = the newest frame's)
and the share of "none" windows read as a gesture, per σ.

    python3 tools/gesture/box_sensitivity.py --gfctl build/devel/lib/gesture_formation/gfctl \\
        --model third_party_models/gesture_lstm/gesture_lstm.onnx --model OLD.onnx --sigma 0 0.03 0.07 0.12
"""
import argparse
import csv
import os
import random
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
WINDOW = 9


def read(path):
    with open(path) as f:
        r = csv.reader(f)
        header = next(r)
        rows = [row for row in r]
    for key in ("u", "v", "w", "h", "label", "sequence"):
        if key not in header:
            sys.exit(f"box_sensitivity.py: {path}: no column '{key}'")
    return header, rows


def perturbed(header, rows, sigma, seed):
    """The rows with each box edge moved by N(0, sigma · size); keypoints unchanged."""
    iu, iv, iw, ih = (header.index(k) for k in ("u", "v", "w", "h"))
    rng = random.Random(seed)
    out = []
    for row in rows:
        u, v, w, h = (float(row[i]) for i in (iu, iv, iw, ih))
        u0, u1 = u + sigma * w * rng.gauss(0, 1), u + w + sigma * w * rng.gauss(0, 1)
        v0, v1 = v + sigma * h * rng.gauss(0, 1), v + h + sigma * h * rng.gauss(0, 1)
        row = list(row)
        row[iu], row[iv] = f"{u0:.4f}", f"{v0:.4f}"
        row[iw], row[ih] = f"{max(2.0, u1 - u0):.4f}", f"{max(2.0, v1 - v0):.4f}"
        out.append(row)
    return out


def newest_labels(header, rows):
    """The label of the newest frame of every full window, in gfctl classify's output order."""
    il, isq = header.index("label"), header.index("sequence")
    labels, count, last = [], 0, None
    for row in rows:
        count = count + 1 if row[isq] == last else 1
        last = row[isq]
        if count >= WINDOW:
            labels.append(int(row[il]))
    return labels


def classify(gfctl, model, header, rows, tmp):
    src, dst = os.path.join(tmp, "in.csv"), os.path.join(tmp, "out.csv")
    with open(src, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    subprocess.run([gfctl, "classify", "--in", src, "--out", dst, "--model", model], check=True,
                   stdout=subprocess.DEVNULL)
    with open(dst) as f:
        return [int(r["gesture_id"]) for r in csv.DictReader(f)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--gfctl", required=True)
    ap.add_argument("--model", action="append", required=True, help="ONNX file (repeatable)")
    ap.add_argument("--in", dest="inp", default=os.path.join(ROOT, "test/data/gesture/heldout_skeletons.csv"))
    ap.add_argument("--sigma", type=float, nargs="+", default=[0.0, 0.03, 0.07, 0.12])
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    header, rows = read(a.inp)
    labels = newest_labels(header, rows)
    print(f"{a.inp}: {len(rows)} frames, {len(labels)} windows")
    print("model,sigma,accuracy,none_read_as_gesture")
    with tempfile.TemporaryDirectory() as tmp:
        for model in a.model:
            for sigma in a.sigma:
                pred = classify(a.gfctl, model, header, perturbed(header, rows, sigma, a.seed), tmp)
                if len(pred) != len(labels):
                    sys.exit(f"box_sensitivity.py: {len(pred)} classifications for {len(labels)} windows")
                acc = sum(p == l for p, l in zip(pred, labels)) / len(labels)
                none = [p for p, l in zip(pred, labels) if l == 0]
                fp = sum(p != 0 for p in none) / max(1, len(none))
                print(f"{os.path.basename(os.path.dirname(model)) or model}/{os.path.basename(model)},{sigma:g},{acc:.4f},{fp:.4f}")


if __name__ == "__main__":
    main()
