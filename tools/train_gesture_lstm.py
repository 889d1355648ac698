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
Deterministic: fixed torch seed, --threads threads, deterministic algorithms. Writes
<out>/gesture_lstm.onnx, <out>/training.json (command, seeds, figures) and the C++/OpenCV
equality reference (--reference, default test/data/gesture/lstm_reference.csv).

The skeleton network's systematic errors (docs/gestures.md §2, §9): --error-model FILE applies
tools/gesture/error_model.py with the measured ranges of FILE (tools/gesture/error_model_movenet.yaml)
to a share of the training and extra sequences (seeded by --error-model-seed; validation stays
clean), and --rendered DIR,... adds the skeletons MoveNet extracted from rendered sets — the
training sets of protocol version 5 (seeds 3800-3899, `gfctl render-gestures --window-only`) or a
tuning set (then no longer judged out-of-sample on it) — all their views; sets of the held-out
protocol's seed range are refused,
each window --rendered-repeat times (those labelled none --rendered-none-repeat times more).
--init-onnx FILE fine-tunes from an exported model's weights (e.g. the shipped one) instead of a
random start.
"""
import re
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
import error_model  # noqa: E402
import gesture_data  # noqa: E402

HELDOUT_SEEDS = range(9000, 10000)  # tools/gesture/heldout/protocol*.yaml: never trained on

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


def load_onnx_weights(model, path):
    """Copies the weights of an ONNX export of GestureLstm (LSTM W, R, B; Gemm head) into model. ONNX orders
    the gates i, o, f, c; torch i, f, g (= c), o."""
    import onnx
    from onnx import numpy_helper
    g = onnx.load(path).graph
    init = {i.name: numpy_helper.to_array(i) for i in g.initializer}
    lstm = next(n for n in g.node if n.op_type == "LSTM")
    w, r, b = (init[lstm.input[i]][0] for i in (1, 2, 3))  # inputs: X, W, R, B, …
    hidden = r.shape[1]
    if hidden != model.lstm.hidden_size or w.shape[1] != gesture_data.N_FEATURES:
        raise ValueError(f"--init-onnx {path}: LSTM hidden {hidden}, input {w.shape[1]}; the model has "
                         f"hidden {model.lstm.hidden_size} (--hidden), input {gesture_data.N_FEATURES}")
    order = lambda m: np.concatenate([m[k * hidden:(k + 1) * hidden] for k in (0, 2, 3, 1)])  # noqa: E731
    gemm = next(n for n in g.node if n.op_type == "Gemm")
    with torch.no_grad():
        model.lstm.weight_ih_l0.copy_(torch.from_numpy(order(w)))
        model.lstm.weight_hh_l0.copy_(torch.from_numpy(order(r)))
        model.lstm.bias_ih_l0.copy_(torch.from_numpy(order(b[:4 * hidden])))
        model.lstm.bias_hh_l0.copy_(torch.from_numpy(order(b[4 * hidden:])))
        model.head.weight.copy_(torch.from_numpy(np.array(init[gemm.input[1]])))
        model.head.bias.copy_(torch.from_numpy(np.array(init[gemm.input[2]])))


def rendered_windows(dirs, repeat, none_repeat=1):
    """Windows of rendered training or tuning sets (every view's skeletons*.csv), each repeated `repeat` times,
    those labelled none `repeat` x `none_repeat` times."""
    xs, ys, info = [], [], []
    for d in dirs:
        m = re.search(r"_seed(\d+)_", os.path.basename(os.path.normpath(d)) + "_")
        if m is None:
            raise ValueError(f"--rendered {d}: no _seed<N>_ in the directory name (rendered_eval.py's cache names)")
        if int(m.group(1)) in HELDOUT_SEEDS:
            raise ValueError(f"--rendered {d}: seed {m.group(1)} belongs to the held-out protocol (9000-9999)")
        for f in sorted(n for n in os.listdir(d) if re.fullmatch(r"skeletons(_view\d+)?\.csv", n)):
            x, y, _ = gesture_data.windows(gesture_data.load_frames(d, f))
            xs += [x] * repeat + [x[y == 0]] * (repeat * (none_repeat - 1))
            ys += [y] * repeat + [y[y == 0]] * (repeat * (none_repeat - 1))
            info.append({"dir": os.path.basename(os.path.normpath(d)), "file": f, "windows": int(len(x))})
    return np.concatenate(xs), np.concatenate(ys), info


def training_windows(data_dir, em_cfg, em_seed, set_index):
    """Windows of a synthesized set, with the error model applied when em_cfg is given."""
    if em_cfg is None:
        return gesture_data.windows(gesture_data.load_frames(data_dir))[:2] + (0,)
    raw, changed = error_model.augment(gesture_data.load_raw(data_dir), gesture_data.load_motions(data_dir),
                                       em_cfg, em_seed, set_index)
    frames = {sid: (gesture_data.features(kp, box), lab, t) for sid, (kp, box, lab, t) in raw.items()}
    return gesture_data.windows(frames)[:2] + (changed,)


def sha256(path):
    import hashlib
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


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
    ap.add_argument("--threads", type=int, default=2, help="torch threads (1 on a shared machine)")
    ap.add_argument("--lr", type=float, default=2e-3, help="Adam's initial learning rate (cosine to 0)")
    ap.add_argument("--init-onnx", default=None, help="fine-tune from this exported model's weights")
    ap.add_argument("--error-model", default=None,
                    help="apply the skeleton network's errors (tools/gesture/error_model_movenet.yaml) to the training sets")
    ap.add_argument("--error-model-seed", type=int, default=11)
    ap.add_argument("--rendered", default=None, help="rendered training (3800-3899) or tuning sets to train on, comma-separated directories")
    ap.add_argument("--rendered-repeat", type=int, default=1)
    ap.add_argument("--rendered-none-repeat", type=int, default=1,
                    help="the rendered windows labelled none (work motions, the moves into and out of a gesture) this many times more")
    ap.add_argument("--reference", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "test", "data",
                                                       "gesture", "lstm_reference.csv"),
                    help="where the C++/OpenCV equality reference is written")
    a = ap.parse_args()
    em_cfg = error_model.load(a.error_model) if a.error_model else None
    torch.manual_seed(a.torch_seed)
    np.random.seed(a.torch_seed)
    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    work = a.work or tempfile.mkdtemp(prefix="gf_lstm_")
    t0 = time.time()
    train_dir = gesture_data.synthesize(a.gfctl, a.train_seed, a.train_count, os.path.join(work, f"train_{a.train_seed}"))
    extra_dir = None
    if a.extra_count > 0:
        extra_dir = gesture_data.synthesize(a.gfctl, a.extra_seed, a.extra_count,
                                            os.path.join(work, f"extra_{a.extra_seed}"), a.extra_config)
    val_dir = gesture_data.synthesize(a.gfctl, a.val_seed, a.val_count, os.path.join(work, f"val_{a.val_seed}"))
    xtr, ytr, changed = training_windows(train_dir, em_cfg, a.error_model_seed, 0)
    if extra_dir:
        xex, yex, changed_ex = training_windows(extra_dir, em_cfg, a.error_model_seed, 1)
        xtr, ytr, changed = np.concatenate([xtr, xex]), np.concatenate([ytr, yex]), changed + changed_ex
    rendered_info = []
    if a.rendered:
        if a.rendered_none_repeat < 1:
            sys.exit(f"--rendered-none-repeat must be >= 1, got {a.rendered_none_repeat}")
        xre, yre, rendered_info = rendered_windows(a.rendered.split(","), a.rendered_repeat, a.rendered_none_repeat)
        xtr, ytr = np.concatenate([xtr, xre]), np.concatenate([ytr, yre])
    xva, yva, _ = gesture_data.windows(gesture_data.load_frames(val_dir))
    print(f"windows: train {len(xtr)} {np.bincount(ytr, minlength=5).tolist()}, val {len(xva)} "
          f"{np.bincount(yva, minlength=5).tolist()} ({time.time() - t0:.0f} s)")
    counts = np.bincount(ytr, minlength=5).astype(np.float64)
    # "balanced" up-weights the gestures (the minority) and buys recall with false gestures
    # on work motions; "none" (default) keeps the data's prior.
    weights = (torch.tensor(counts.sum() / (5 * counts), dtype=torch.float32) if a.class_weights == "balanced"
               else torch.ones(5))
    model = GestureLstm(a.hidden)
    if a.init_onnx:
        load_onnx_weights(model, a.init_onnx)
    opt = torch.optim.Adam(model.parameters(), lr=a.lr)
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
    os.makedirs(os.path.dirname(os.path.abspath(a.reference)), exist_ok=True)
    pick = np.linspace(0, len(xva) - 1, 20).astype(int)
    with torch.no_grad():
        probs = model(torch.from_numpy(xva[pick])).numpy()
    with open(a.reference, "w") as f:
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
        "init_onnx": ({"path": os.path.basename(a.init_onnx), "sha256": sha256(a.init_onnx)} if a.init_onnx else None),
        "learning_rate": a.lr, "threads": a.threads,
        "error_model": ({"file": os.path.basename(a.error_model), "sha256": sha256(a.error_model), "seed": a.error_model_seed,
                         "sequences_changed": int(changed)} if em_cfg else None),
        "rendered": ({"sets": rendered_info, "repeat": a.rendered_repeat, "none_repeat": a.rendered_none_repeat}
                     if a.rendered else None),
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
