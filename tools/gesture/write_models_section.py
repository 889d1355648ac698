#!/usr/bin/env python3
"""Rewrites the `## gesture_lstm (ours)` section of third_party_models/MODELS.md (from that
heading to the next `## ` heading; the sections after it are kept) from the trained file's sha256,
third_party_models/gesture_lstm/training.json and evaluation.json. Run after
tools/train_gesture_lstm.py and tools/gesture/evaluate_gesture_lstm.py."""
import hashlib
import json
import os

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DIR = os.path.join(ROOT, "third_party_models", "gesture_lstm")
MD = os.path.join(ROOT, "third_party_models", "MODELS.md")
HEADING = "## gesture_lstm (ours)"


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def main():
    onnx = os.path.join(DIR, "gesture_lstm.onnx")
    tr = json.load(open(os.path.join(DIR, "training.json")))
    ev = json.load(open(os.path.join(DIR, "evaluation.json")))
    fp = ev["sets"]["filter_protocol"]["filter_paper_parameters"]
    extra = tr["train"].get("extra", {})
    lines = [
        HEADING,
        "",
        "Trained by this project on synthetic skeleton sequences (no third-party weights, no "
        "labelled footage). Licence: the project's own. Details and evaluation: `docs/gestures.md`.",
        "",
        f"- file: `third_party_models/gesture_lstm/gesture_lstm.onnx` — {os.path.getsize(onnx) / 1024:.0f} KiB",
        f"- sha256: `{sha256(onnx)}`",
        f"- source: `tools/train_gesture_lstm.py` (PyTorch {tr['torch']} CPU from PyPI in the venv of "
        "`tools/gesture/setup_train_env.sh`), data from `gfctl synth-gestures`",
        f"- command: `{tr['command']}` (build gfctl first: `tools/build.sh`)",
        f"- data seeds: train {tr['train']['seed']} ({tr['train']['sequences']} sequences)"
        + (f" + {extra['seed']} ({extra['sequences']} sequences, `{extra['config']}`)" if extra else "")
        + f", validation {tr['validation']['seed']} ({tr['validation']['sequences']} sequences); "
        f"torch seed {tr['torch_seed']}, {tr['epochs']} epochs, hidden {tr['hidden']}, class weights "
        f"{tr.get('class_weights', 'balanced')}",
        "- input: `skeletons` [1,9,51] float32: 9 frames (oldest first) × 17 COCO keypoints × "
        "(x', y', c), x' = (x − u)/w, y' = (y − v)/h in the worker's box, (0,0,0) for a missing keypoint",
        "- output: `probabilities` [1,5] softmax over none, cross_arms, extend_arm_side, palms_together, "
        "raise_arm_up",
        f"- validation accuracy (PyTorch, windows): {tr['validation']['accuracy']:.4f}; held-out accuracy "
        f"(OpenCV DNN, unseen seeds and out-of-range bodies/viewpoints): {ev['held_out_accuracy']:.4f}; "
        f"through the filter (paper parameters): success {fp['success_rate']:.3f}, mean latency "
        f"{fp['mean_latency_s']:.2f} s, false adaptations {fp['false_adaptations']} in "
        f"{fp['none_minutes']:.1f} min of work motions",
        "- checked: loads in OpenCV 4.6.0 DNN; equals PyTorch to 1e-4 on `test/data/gesture/lstm_reference.csv` "
        "(test_gesture: GestureClassifierTest.OpenCvMatchesPyTorchOnCommittedInputs)",
        "- reproducibility: deterministic torch (fixed seeds, 2 threads, deterministic algorithms); "
        "a second training run is compared in docs/gestures.md §5 (Done-when of issue 6: within 1 %)",
        "",
    ]
    with open(MD) as f:
        text = f.read()
    head, _, rest = text.partition(HEADING)
    # the sections after this one (e.g. the mannequin's) stay as they are
    following = rest[rest.find("\n## ") + 1:] if "\n## " in rest else ""
    with open(MD, "w") as f:
        f.write(head.rstrip("\n") + "\n\n" + "\n".join(lines) + ("\n" + following if following else ""))
    print("wrote", MD)


if __name__ == "__main__":
    main()
