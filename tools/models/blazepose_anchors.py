#!/usr/bin/python3
"""Reference implementation (numpy) of the BlazePose detector decoding, for the C++ port
and its tests: MediaPipe's SSD anchor generation and box/keypoint decoding with the
parameters in third_party_models/blazepose_detector/anchors.json.

  blazepose_anchors.py            # writes test/data/perception/blazepose_detector/{anchors,detections}.csv

anchors.csv:    2254 rows `x_center,y_center,w,h` (normalised to the 224x224 input)
detections.csv: the decoded reference outputs (regressors/classificators .f32 of the
                source framework), all anchors with score >= 0.5, sorted by score
                descending: `anchor,score,xmin,ymin,xmax,ymax,kp0_x,kp0_y,...,kp3_x,kp3_y`
                (normalised to the letterboxed 224x224 input; before NMS).
Any python3 with numpy.
"""
import json
import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "../.."))


def calc_scale(min_scale, max_scale, i, n):
    return min_scale + (max_scale - min_scale) * i / (n - 1) if n > 1 else (min_scale + max_scale) * 0.5


def ssd_anchors(o):
    anchors = []
    n = o["num_layers"]
    layer = 0
    while layer < n:
        heights, widths = [], []
        last = layer
        while last < n and o["strides"][last] == o["strides"][layer]:
            scale = calc_scale(o["min_scale"], o["max_scale"], last, n)
            if last == 0 and o["reduce_boxes_in_lowest_layer"]:
                raise NotImplementedError
            for ar in o["aspect_ratios"]:
                heights.append(scale / math.sqrt(ar))
                widths.append(scale * math.sqrt(ar))
            if o["interpolated_scale_aspect_ratio"] > 0:
                nxt = 1.0 if last == n - 1 else calc_scale(o["min_scale"], o["max_scale"], last + 1, n)
                s = math.sqrt(scale * nxt)
                ar = o["interpolated_scale_aspect_ratio"]
                heights.append(s / math.sqrt(ar))
                widths.append(s * math.sqrt(ar))
            last += 1
        stride = o["strides"][layer]
        fh = math.ceil(o["input_size_height"] / stride)
        fw = math.ceil(o["input_size_width"] / stride)
        for y in range(fh):
            for x in range(fw):
                for k in range(len(heights)):
                    xc = (x + o["anchor_offset_x"]) / fw
                    yc = (y + o["anchor_offset_y"]) / fh
                    if o["fixed_anchor_size"]:
                        anchors.append((xc, yc, 1.0, 1.0))
                    else:
                        anchors.append((xc, yc, widths[k], heights[k]))
        layer = last
    return np.array(anchors, np.float32)


def decode(reg, cls, anchors, t):
    """reg [N,12], cls [N] -> (scores [N], boxes [N,4] xmin,ymin,xmax,ymax, kps [N,4,2])."""
    a = anchors
    xc = reg[:, 0] / t["x_scale"] * a[:, 2] + a[:, 0]
    yc = reg[:, 1] / t["y_scale"] * a[:, 3] + a[:, 1]
    w = reg[:, 2] / t["w_scale"] * a[:, 2]
    h = reg[:, 3] / t["h_scale"] * a[:, 3]
    boxes = np.stack([xc - w / 2, yc - h / 2, xc + w / 2, yc + h / 2], 1)
    kps = np.zeros((len(a), t["num_keypoints"], 2), np.float32)
    for k in range(t["num_keypoints"]):
        o = t["keypoint_coord_offset"] + k * t["num_values_per_keypoint"]
        kps[:, k, 0] = reg[:, o] / t["x_scale"] * a[:, 2] + a[:, 0]
        kps[:, k, 1] = reg[:, o + 1] / t["y_scale"] * a[:, 3] + a[:, 1]
    c = np.clip(cls.astype(np.float64), -t["score_clipping_thresh"], t["score_clipping_thresh"])
    scores = 1.0 / (1.0 + np.exp(-c))
    return scores, boxes, kps


def main():
    p = json.load(open(os.path.join(ROOT, "third_party_models/blazepose_detector/anchors.json")))
    anchors = ssd_anchors(p["ssd_anchors"])
    assert len(anchors) == p["ssd_anchors"]["num_anchors"], len(anchors)
    d = os.path.join(ROOT, "test/data/perception/blazepose_detector")
    np.savetxt(os.path.join(d, "anchors.csv"), anchors, fmt="%.9g", delimiter=",", header="x_center,y_center,w,h", comments="")
    reg = np.fromfile(os.path.join(d, "regressors.f32"), "<f4").reshape(-1, 12)
    cls = np.fromfile(os.path.join(d, "classificators.f32"), "<f4").reshape(-1)
    t = p["tensors_to_detections"]
    scores, boxes, kps = decode(reg, cls, anchors, t)
    keep = np.where(scores >= t["min_score_thresh"])[0]
    keep = keep[np.argsort(-scores[keep], kind="stable")]
    hdr = "anchor,score,xmin,ymin,xmax,ymax," + ",".join(f"kp{k}_x,kp{k}_y" for k in range(4))
    with open(os.path.join(d, "detections.csv"), "w") as f:
        f.write(hdr + "\n")
        for i in keep:
            vals = [scores[i], *boxes[i], *kps[i].reshape(-1)]
            f.write(f"{i}," + ",".join(f"{v:.7g}" for v in vals) + "\n")
    print(f"blazepose_anchors: {len(anchors)} anchors, {len(keep)} detections >= {t['min_score_thresh']}")
    if len(keep):
        i = keep[0]
        print("  best:", i, scores[i], boxes[i] * 224, (kps[i] * 224).round(1).tolist())


if __name__ == "__main__":
    main()
