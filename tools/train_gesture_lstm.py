#!/usr/bin/env python3
"""Trains the gesture LSTM on synthetic skeleton windows and exports ONNX for OpenCV 4.6.

    tools/gesture/setup_train_env.sh
    /opt/gesture_formation/venv-train/bin/python tools/train_gesture_lstm.py \
        --gfctl build/devel/lib/gesture_formation/gfctl --out third_party_models/gesture_lstm

Data: `gfctl synth-gestures` with the training seed (default 1001, 6000 sequences, the
default distribution), an extra training set (seed 1003, 4000 sequences,
tools/gesture/train_extra.yaml: more work motions, longer holds) and a validation seed
(1002, 600 sequences, default distribution). Model: LSTM(51 → 128) over N = 9 frames, the final hidden state h_n (not output[:, -1]:
OpenCV 4.6 rejects the negative-index Slice that exports) → Linear(128 → 5) → softmax.
Deterministic: fixed torch seed, 2 threads, deterministic algorithms. Writes
<out>/gesture_lstm.onnx, <out>/training.json (command, seeds, figures) and the C++/OpenCV
equality reference test/data/gesture/lstm_reference.csv.
"""
import argparse
import json
import os
import sys
import tempfile
import time

import numpy as np
import torch
from torch import nn

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "gesture"))
import gesture_data  # noqa: E402

CLASSES = ["none", "cross_arms", "extend_arm_side", "palms_together", "raise_arm_up"]


class GestureLstm(nn.Module):
    def __init__(self, hidden=64):
        super().__init__()
        self.lstm = nn.LSTM(gesture_data.N_FEATURES, hidden, batch_first=True)
        self.head = nn.Linear(hidden, len(CLASSES))

    def forward(self, x):  # x: [B, 9, 51] → probabilities [B, 5]
        _, (h_n, _) = self.lstm(x)
        return torch.softmax(self.head(h_n[0]), dim=1)

    def logits(self, x):
        _, (h_n, _) = self.lstm(x)
        return self.head(h_n[0])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gfctl", required=True)
    ap.add_argument("--out", default="third_party_models/gesture_lstm")
    ap.add_argument("--train-seed", type=int, default=1001)
    ap.add_argument("--train-count", type=int, default=6000)
    ap.add_argument("--extra-seed", type=int, default=1003,
                    help="a second training set with more work motions and longer holds")
    ap.add_argument("--extra-count", type=int, default=4000)
    ap.add_argument("--extra-config", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                           "gesture", "train_extra.yaml"))
    ap.add_argument("--class-weights", choices=["none", "balanced"], default="none")
    ap.add_argument("--val-seed", type=int, default=1002)
    ap.add_argument("--val-count", type=int, default=600)
    ap.add_argument("--torch-seed", type=int, default=7)
    ap.add_argument("--epochs", type=int, default=30)
    ap.add_argument("--hidden", type=int, default=128)
    ap.add_argument("--work", default=None, help="where datasets are cached (default: a temp dir)")
    a = ap.parse_args()
    torch.manual_seed(a.torch_seed)
    np.random.seed(a.torch_seed)
    torch.set_num_threads(2)
    torch.use_deterministic_algorithms(True)
    work = a.work or tempfile.mkdtemp(prefix="gf_lstm_")
    t0 = time.time()
    train_dir = gesture_data.synthesize(a.gfctl, a.train_seed, a.train_count, os.path.join(work, f"train_{a.train_seed}"))
    extra_dir = None
    if a.extra_count > 0:
        extra_dir = gesture_data.synthesize(a.gfctl, a.extra_seed, a.extra_count,
                                            os.path.join(work, f"extra_{a.extra_seed}"), a.extra_config)
    val_dir = gesture_data.synthesize(a.gfctl, a.val_seed, a.val_count, os.path.join(work, f"val_{a.val_seed}"))
    xtr, ytr, _ = gesture_data.windows(gesture_data.load_frames(train_dir))
    if extra_dir:
        xex, yex, _ = gesture_data.windows(gesture_data.load_frames(extra_dir))
        xtr, ytr = np.concatenate([xtr, xex]), np.concatenate([ytr, yex])
    xva, yva, _ = gesture_data.windows(gesture_data.load_frames(val_dir))
    print(f"windows: train {len(xtr)} {np.bincount(ytr, minlength=5).tolist()}, val {len(xva)} "
          f"{np.bincount(yva, minlength=5).tolist()} ({time.time() - t0:.0f} s)")
    counts = np.bincount(ytr, minlength=5).astype(np.float64)
    # "balanced" up-weights the gestures (the minority) and buys recall with false gestures
    # on work motions; "none" (default) keeps the data's prior.
    weights = (torch.tensor(counts.sum() / (5 * counts), dtype=torch.float32) if a.class_weights == "balanced"
               else torch.ones(5))
    model = GestureLstm(a.hidden)
    opt = torch.optim.Adam(model.parameters(), lr=2e-3)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, a.epochs)
    loss_fn = nn.CrossEntropyLoss(weight=weights)
    xtr_t, ytr_t = torch.from_numpy(xtr), torch.from_numpy(ytr)
    xva_t = torch.from_numpy(xva)
    g = torch.Generator().manual_seed(a.torch_seed)
    history = []
    for epoch in range(a.epochs):
        model.train()
        perm = torch.randperm(len(xtr_t), generator=g)
        total = 0.0
        for i in range(0, len(perm), 256):
            b = perm[i:i + 256]
            opt.zero_grad()
            loss = loss_fn(model.logits(xtr_t[b]), ytr_t[b])
            loss.backward()
            opt.step()
            total += float(loss) * len(b)
        sched.step()
        model.eval()
        with torch.no_grad():
            acc = float((model(xva_t).argmax(1).numpy() == yva).mean())
        history.append({"epoch": epoch + 1, "train_loss": total / len(perm), "val_accuracy": acc})
        print(f"epoch {epoch + 1:2d}: loss {total / len(perm):.4f}, val accuracy {acc:.4f}")
    os.makedirs(a.out, exist_ok=True)
    onnx_path = os.path.join(a.out, "gesture_lstm.onnx")
    model.eval()
    dummy = torch.zeros(1, gesture_data.N_FRAMES, gesture_data.N_FEATURES)
    kwargs = dict(input_names=["skeletons"], output_names=["probabilities"], opset_version=11)
    try:
        torch.onnx.export(model, dummy, onnx_path, dynamo=False, **kwargs)
    except TypeError:
        torch.onnx.export(model, dummy, onnx_path, **kwargs)
    # Reference for the C++/OpenCV equality test: 20 validation windows and PyTorch's output.
    ref_dir = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "test", "data", "gesture")
    os.makedirs(ref_dir, exist_ok=True)
    pick = np.linspace(0, len(xva) - 1, 20).astype(int)
    with torch.no_grad():
        probs = model(torch.from_numpy(xva[pick])).numpy()
    with open(os.path.join(ref_dir, "lstm_reference.csv"), "w") as f:
        f.write(",".join([f"f{i}" for i in range(gesture_data.N_FRAMES * gesture_data.N_FEATURES)] +
                         [f"p{c}" for c in range(5)]) + "\n")
        for x, p in zip(xva[pick], probs):
            f.write(",".join("%.9g" % v for v in list(x.reshape(-1)) + list(p)) + "\n")
    report = {
        "command": " ".join(sys.argv),
        "train": {"seed": a.train_seed, "sequences": a.train_count, "windows": int(len(xtr)),
                  "extra": {"seed": a.extra_seed, "sequences": a.extra_count,
                            "config": os.path.relpath(a.extra_config, os.path.join(os.path.dirname(__file__), ".."))}},
        "class_weights": a.class_weights,
        "validation": {"seed": a.val_seed, "sequences": a.val_count, "windows": int(len(xva)),
                       "accuracy": history[-1]["val_accuracy"]},
        "torch_seed": a.torch_seed, "epochs": a.epochs, "hidden": a.hidden, "torch": torch.__version__,
        "history": history, "seconds": round(time.time() - t0, 1),
    }
    with open(os.path.join(a.out, "training.json"), "w") as f:
        json.dump(report, f, indent=1)
    print(f"wrote {onnx_path} (val accuracy {history[-1]['val_accuracy']:.4f}, {time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
