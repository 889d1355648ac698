#!/usr/bin/env python3
"""Run the SOURCE frameworks on the committed test inputs and write their raw outputs as
reference data for the C++ tests (test/data/perception/<model>/).

Runs in the conversion venv (tools/models/setup_env.sh):
  - BlazePose detector / landmark: TensorFlow Lite interpreter (tf.lite.Interpreter of
    tensorflow-cpu, with its default XNNPACK delegate) on the original .tflite files;
  - MoveNet lightning / multipose: the TF.js graph executed by TensorFlow (weights and
    ops as in tfjs_graph.py), full graph including its post-processing, int32 input.

Files written per model (all little-endian float32, C order, no header):
  <output>.f32   one file per ONNX output, in the ONNX output's layout (4-D: NCHW;
                 TFLite / TF produce NHWC, transposed here)
  manifest.txt   one line per file: `<file> <dim0>x<dim1>x...`
  final.csv      (MoveNet) the TF graph's own decoded output (see docs/perception_models.md)

Usage: reference_outputs.py SRC_DIR OUT_DIR
  SRC_DIR holds the unpacked packages (mediapipe wheel in SRC_DIR/mediapipe-0.10.21,
  npm package in SRC_DIR/human-models-3.0.4), as convert_all.sh leaves them.
"""
import os
import sys

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")

import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.normpath(os.path.join(HERE, "../../test/data/perception"))


def rgb(png):
    return np.asarray(Image.open(os.path.join(DATA, png)).convert("RGB"))


def write(outdir, tensors):
    os.makedirs(outdir, exist_ok=True)
    lines = []
    for name, arr in tensors:
        arr = np.ascontiguousarray(np.asarray(arr, np.float32))
        arr.astype("<f4").tofile(os.path.join(outdir, name + ".f32"))
        lines.append(f"{name}.f32 {'x'.join(str(d) for d in arr.shape)}")
    with open(os.path.join(outdir, "manifest.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


def nchw(a):
    return a.transpose(0, 3, 1, 2) if a.ndim == 4 else a


def run_tflite(path, x):
    import tensorflow as tf

    it = tf.lite.Interpreter(model_path=path)
    it.allocate_tensors()
    it.set_tensor(it.get_input_details()[0]["index"], x)
    it.invoke()
    return {d["name"]: it.get_tensor(d["index"]) for d in it.get_output_details()}


def blazepose(src):
    mp = os.path.join(src, "mediapipe-0.10.21/mediapipe/modules")
    x = rgb("pose_det_224.png").astype(np.float32)[None] / 127.5 - 1.0
    o = run_tflite(os.path.join(mp, "pose_detection/pose_detection.tflite"), x)
    write(os.path.join(DATA, "blazepose_detector"), [("regressors", o["Identity"]), ("classificators", o["Identity_1"])])
    x = rgb("pose_crop_256.png").astype(np.float32)[None] / 255.0
    o = run_tflite(os.path.join(mp, "pose_landmark/pose_landmark_full.tflite"), x)
    write(os.path.join(DATA, "blazepose_landmark_full"), [
        ("landmarks", o["Identity"]), ("pose_flag", o["Identity_1"]), ("segmentation", nchw(o["Identity_2"])),
        ("heatmap", nchw(o["Identity_3"])), ("world_landmarks", o["Identity_4"])])


def movenet(src, name, png, heads, final_cols):
    import tfjs_graph

    gd, _ = tfjs_graph.load_graph_def(os.path.join(src, f"human-models-3.0.4/models/{name}.json"))
    x = rgb(png).astype(np.int32)[None]
    fetches = ["Identity:0"] + [f"StatefulPartitionedCall/{t}:0" for t, _ in heads]
    res = tfjs_graph.run_graph(gd, {"input:0": x}, fetches)
    write(os.path.join(DATA, name.replace("-", "_")), [(n, nchw(a)) for (_, n), a in zip(heads, res[1:])])
    final = res[0].reshape(-1, res[0].shape[-1])
    with open(os.path.join(DATA, name.replace("-", "_"), "final.csv"), "w") as f:
        f.write(",".join(final_cols) + "\n")
        for row in final:
            f.write(",".join(f"{v:.9g}" for v in row) + "\n")


def main():
    if len(sys.argv) != 2 and len(sys.argv) != 3:
        sys.exit(__doc__)
    src = sys.argv[1]
    blazepose(src)
    movenet(src, "movenet-lightning", "pose_crop_192.png",
            [("Sigmoid", "kpt_heatmap"), ("truediv_2", "center_weighted"),
             ("kpt_regress_0/conv2d_6/BiasAdd", "kpt_regress"), ("kpt_offset_0/conv2d_7/BiasAdd", "kpt_offset")],
            ["y", "x", "score"])
    cols = [f"{c}{k}" for k in range(17) for c in ("y", "x", "s")] + ["ymin", "xmin", "ymax", "xmax", "score"]
    movenet(src, "movenet-multipose", "multipose_256.png",
            [("Sigmoid", "center_heatmap"), ("box_scale_0/conv2d_5/BiasAdd", "box_scale"),
             ("box_offset_0/conv2d_6/BiasAdd", "box_offset"), ("Sigmoid_1", "kpt_heatmap"),
             ("kpt_regress_0/conv2d_8/BiasAdd", "kpt_regress"), ("kpt_offset_0/conv2d_9/BiasAdd", "kpt_offset")],
            cols)
    print("reference_outputs: wrote", DATA)


if __name__ == "__main__":
    main()
