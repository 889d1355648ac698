#!/usr/bin/python3
"""Check the converted ONNX files with Debian's OpenCV 4.6 DNN (python3-opencv), the
runtime the product uses: load, run on the committed input, compare every output with
the source framework's reference (test/data/perception/<model>/*.f32), decode MoveNet
lightning with the documented algorithm and compare with the TF graph's own decoding
(final.csv), and time inference (cv2.setNumThreads(2), median of --runs).

Run with /usr/bin/python3 (not the conversion venv: it has no cv2).
  check_opencv.py [--runs 50] [--models DIR] [--json OUT.json]
Exit code 1 when a model fails to load or an output differs by more than its tolerance.
"""
import argparse
import json
import os
import sys
import time

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "../.."))
DATA = os.path.join(ROOT, "test/data/perception")

# (model dir, onnx file, reference dir, input png, size, scale, mean, tolerance on max abs diff
#  relative to max |reference| of that output)
MODELS = [
    ("blazepose_detector", "pose_detection.onnx", "blazepose_detector", "pose_det_224.png", 224, 1 / 127.5, 127.5),
    ("blazepose_landmark_full", "pose_landmark_full.onnx", "blazepose_landmark_full", "pose_crop_256.png", 256, 1 / 255.0, 0.0),
    ("movenet_lightning", "movenet_lightning.onnx", "movenet_lightning", "pose_crop_192.png", 192, 1.0, 0.0),
    ("movenet_multipose", "movenet_multipose.onnx", "movenet_multipose", "multipose_256.png", 256, 1.0, 0.0),
]
REL_TOL = 1e-3


def read_ref(d):
    out = {}
    for line in open(os.path.join(d, "manifest.txt")):
        f, dims = line.split()
        shape = [int(x) for x in dims.split("x")]
        out[f[:-4]] = np.fromfile(os.path.join(d, f), "<f4").reshape(shape)
    return out


def decode_movenet_lightning(heat, center_w, regress, offset):
    """heat [17,H,W], center_w [H,W], regress/offset [34,H,W] (NCHW, batch dropped) ->
    [17,3] (y, x, score), y/x normalised to the input. Mirrors the TF.js graph."""
    H, W = center_w.shape
    c = int(np.argmax(center_w.reshape(-1)))
    cy, cx = c // W, c % W
    reg = regress[:, cy, cx].reshape(17, 2)
    ry = cy + reg[:, 0]
    rx = cx + reg[:, 1]
    yy, xx = np.meshgrid(np.arange(H, dtype=np.float32), np.arange(W, dtype=np.float32), indexing="ij")
    out = np.zeros((17, 3), np.float32)
    for k in range(17):
        dist = np.sqrt((yy - ry[k]) ** 2 + (xx - rx[k]) ** 2) + np.float32(1.7998047)
        idx = int(np.argmax((heat[k] / dist).reshape(-1)))
        ky, kx = idx // W, idx % W
        out[k, 0] = (ky + offset[2 * k, ky, kx]) * np.float32(0.020828247)
        out[k, 1] = (kx + offset[2 * k + 1, ky, kx]) * np.float32(0.020828247)
        out[k, 2] = heat[k, ky, kx]
    return out


def decode_movenet_multipose(center, box_scale, box_offset, heat, regress, offset, in_h, in_w):
    """center [H,W], box_scale/box_offset [2,H,W], heat [17,H,W], regress/offset [34,H,W]
    (NCHW, batch dropped) -> [6,56] rows (y,x,score)*17, ymin,xmin,ymax,xmax, score.
    Mirrors the TF.js graph's post-processing step by step (docs/perception_models.md)."""
    H, W = center.shape
    f32 = np.float32
    # 1. centre NMS: 5x5 max-pool (SAME, stride 1), keep local maxima, top 6
    pad = np.pad(center, 2, constant_values=-np.inf)
    pooled = np.max([pad[dy:dy + H, dx:dx + W] for dy in range(5) for dx in range(5)], axis=0)
    c = center * (np.abs(center - pooled) < f32(1.013279e-06)).astype(f32)
    flat = c.reshape(-1)
    order = np.argsort(-flat, kind="stable")[:6]
    top_val, cy, cx = flat[order], order // W, order % W
    # 2. boxes in grid units, clipped to [0, H] / [0, W]
    sh = np.maximum(box_scale[0, cy, cx], 0) * f32(0.5)
    sw = np.maximum(box_scale[1, cy, cx], 0) * f32(0.5)
    by = cy + box_offset[0, cy, cx]
    bx = cx + box_offset[1, cy, cx]
    ymin, ymax = np.clip(by - sh, 0, H), np.clip(by + sh, 0, H)
    xmin, xmax = np.clip(bx - sw, 0, W), np.clip(bx + sw, 0, W)
    # 3. regressed keypoints, Gaussian-weighted heatmap inside the box
    ry = cy[:, None] + regress[0::2, cy, cx].T  # [6,17]
    rx = cx[:, None] + regress[1::2, cy, cx].T
    yy, xx = np.meshgrid(np.arange(H, dtype=f32), np.arange(W, dtype=f32), indexing="ij")
    d2 = (yy[:, :, None, None] - ry[None, None]) ** 2 + (xx[:, :, None, None] - rx[None, None]) ** 2
    w = heat.transpose(1, 2, 0)[:, :, None, :] * np.exp(-d2 / (f32(min(H, W)) * f32(0.300048828125)))
    inside = ((yy[:, :, None] >= ymin) & (yy[:, :, None] < ymax) & (xx[:, :, None] >= xmin) & (xx[:, :, None] < xmax))
    w = w * inside[:, :, :, None]  # [H,W,6,17]
    wmax = w.max(axis=2)  # [H,W,17] (max over the 6 candidates)
    idx = np.argmax(w.reshape(H * W, 6 * 17), axis=0).reshape(6, 17)
    ky, kx = idx // W, idx % W
    k = np.arange(17)[None, :].repeat(6, 0)
    kp_y = (ky + offset[2 * k, ky, kx]) * f32((in_h / H) / in_h)  # (grid + offset) * stride / input size
    kp_x = (kx + offset[2 * k + 1, ky, kx]) * f32((in_w / W) / in_w)
    kp_s = wmax[ky, kx, k]
    # 4. person score: mean of centre score * keypoint score over keypoints scoring > 0.127
    good = kp_s > f32(0.126953125)
    score = (top_val[:, None] * np.where(good, kp_s, 0)).sum(1) / np.maximum(good.sum(1), 1)
    out = np.zeros((6, 56), f32)
    out[:, 0:51:3], out[:, 1:51:3], out[:, 2:51:3] = kp_y, kp_x, kp_s
    stride_y, stride_x = in_h / H, in_w / W
    out[:, 51] = np.clip(ymin * stride_y / in_h, 0, 1)
    out[:, 52] = np.clip(xmin * stride_x / in_w, 0, 1)
    out[:, 53] = np.clip(ymax * stride_y / in_h, 0, 1)
    out[:, 54] = np.clip(xmax * stride_x / in_w, 0, 1)
    out[:, 55] = score
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=50)
    ap.add_argument("--models", default=os.path.join(ROOT, "third_party_models"))
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    cv2.setNumThreads(2)
    ok = True
    results = {}
    for mdir, fname, rdir, png, size, scale, mean in MODELS:
        path = os.path.join(a.models, mdir, fname)
        r = {"onnx": os.path.relpath(path, ROOT), "opencv": cv2.__version__}
        try:
            net = cv2.dnn.readNetFromONNX(path)
        except cv2.error as e:
            print(f"{mdir}: LOAD FAILED: {e}")
            ok = False
            results[mdir] = {"loads": False}
            continue
        net.setPreferableBackend(cv2.dnn.DNN_BACKEND_OPENCV)
        net.setPreferableTarget(cv2.dnn.DNN_TARGET_CPU)
        img = cv2.imread(os.path.join(DATA, png))
        blob = cv2.dnn.blobFromImage(img, scale, (size, size), (mean, mean, mean), swapRB=True, crop=False)
        names = list(net.getUnconnectedOutLayersNames())
        net.setInput(blob)
        outs = dict(zip(names, net.forward(names)))
        ref = read_ref(os.path.join(DATA, rdir))
        r["loads"] = True
        r["outputs"] = {}
        for k, v in ref.items():
            got = outs[k].reshape(v.shape)
            diff = float(np.abs(got - v).max())
            scale_ref = float(np.abs(v).max())
            passed = diff <= REL_TOL * max(scale_ref, 1.0)
            ok &= passed
            r["outputs"][k] = {"shape": list(v.shape), "max_abs_diff": diff, "max_abs_ref": scale_ref, "pass": passed}
            print(f"{mdir}: {k} {list(v.shape)} max|diff| {diff:.3g} (max|ref| {scale_ref:.3g}) {'ok' if passed else 'FAIL'}")
        if mdir == "movenet_lightning":
            dec = decode_movenet_lightning(outs["kpt_heatmap"][0], outs["center_weighted"][0, 0],
                                           outs["kpt_regress"][0], outs["kpt_offset"][0])
            fin = np.loadtxt(os.path.join(DATA, rdir, "final.csv"), delimiter=",", skiprows=1)
            diff = float(np.abs(dec - fin).max())
            ok &= diff < 1e-3
            r["decoded_vs_tf_max_abs_diff"] = diff
            print(f"{mdir}: decoded keypoints vs TF graph output max|diff| {diff:.3g} {'ok' if diff < 1e-3 else 'FAIL'}")
        if mdir == "movenet_multipose":
            dec = decode_movenet_multipose(outs["center_heatmap"][0, 0], outs["box_scale"][0], outs["box_offset"][0],
                                           outs["kpt_heatmap"][0], outs["kpt_regress"][0], outs["kpt_offset"][0], size, size)
            fin = np.loadtxt(os.path.join(DATA, rdir, "final.csv"), delimiter=",", skiprows=1)
            diff = float(np.abs(dec - fin).max())
            ok &= diff < 1e-3
            r["decoded_vs_tf_max_abs_diff"] = diff
            print(f"{mdir}: decoded [6,56] vs TF graph output max|diff| {diff:.3g} {'ok' if diff < 1e-3 else 'FAIL'}")
        for _ in range(3):
            net.setInput(blob)
            net.forward(names)
        ts = []
        for _ in range(a.runs):
            t0 = time.perf_counter()
            net.setInput(blob)
            net.forward(names)
            ts.append((time.perf_counter() - t0) * 1e3)
        r["ms_median"] = float(np.median(ts))
        r["ms_p90"] = float(np.percentile(ts, 90))
        print(f"{mdir}: {size}x{size} median {r['ms_median']:.1f} ms, p90 {r['ms_p90']:.1f} ms ({a.runs} runs, 2 threads)")
        results[mdir] = r
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)
    print("check_opencv:", "all ok" if ok else "FAILURES")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
