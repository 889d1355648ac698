"""Load a TF.js graph model (model.json + weight shards) into a TensorFlow GraphDef.

Used by tfjs2onnx.py and reference_outputs.py. Needs only tensorflow (no tensorflowjs).

- model.json's `modelTopology` is a GraphDef in protobuf-JSON form; Const nodes lost
  their `value` (the weights live in the .bin shards described by `weightsManifest`).
  Weights are decoded here (float16-quantized float32 weights are widened back to fp32,
  exactly as TF.js does at load time) and put back into the Const nodes.
- TF.js's converter fuses ops into `_FusedConv2D` (a TF-internal op) and
  `FusedDepthwiseConv2dNative` (an op that only exists in TF.js). Both are unfused here
  into standard Conv2D / DepthwiseConv2dNative + BiasAdd + Relu/Relu6, keeping the
  original node name on the last op so consumers stay wired; dtype/format attributes
  the converter stripped (T, data_format, dilations) are restored.
"""
import json
import os

import numpy as np
import tensorflow as tf
from google.protobuf import json_format
from tensorflow.core.framework import attr_value_pb2, graph_pb2, node_def_pb2

DTYPES = {"float32": np.float32, "int32": np.int32, "bool": np.bool_, "uint8": np.uint8}
QDTYPES = {"float16": np.float16, "uint8": np.uint8, "uint16": np.uint16}


def load_weights(model_dir, manifest):
    weights = {}
    for group in manifest:
        buf = b"".join(open(os.path.join(model_dir, p), "rb").read() for p in group["paths"])
        off = 0
        for w in group["weights"]:
            shape = [int(s) for s in w["shape"]]
            n = int(np.prod(shape)) if shape else 1
            q = w.get("quantization")
            if q:
                qdt = np.dtype(QDTYPES[q["dtype"]])
                raw = np.frombuffer(buf, qdt.newbyteorder("<"), n, off)
                off += n * qdt.itemsize
                if q["dtype"] == "float16":
                    arr = raw.astype(np.float32)
                else:
                    arr = raw.astype(np.float32) * q["scale"] + q["min"]
                arr = arr.astype(DTYPES[w["dtype"]])
            else:
                dt = np.dtype(DTYPES[w["dtype"]])
                arr = np.frombuffer(buf, dt.newbyteorder("<"), n, off).astype(dt)
                off += n * dt.itemsize
            weights[w["name"]] = arr.reshape(shape)
        if off != len(buf):
            raise ValueError(f"weight shard size mismatch: used {off} of {len(buf)} bytes")
    return weights


def _attr_list_s(node, key):
    return [s.decode() for s in node.attr[key].list.s] if key in node.attr else []


def _unfuse(node):
    """Return replacement nodes for a fused conv node (or [node] if not fused)."""
    if node.op not in ("_FusedConv2D", "FusedDepthwiseConv2dNative"):
        return [node]
    fused = _attr_list_s(node, "fused_ops")
    if not fused or fused[0] != "BiasAdd" or len(node.input) != 3:
        raise NotImplementedError(f"{node.name}: fused_ops {fused} with {len(node.input)} inputs")
    conv = node_def_pb2.NodeDef()
    conv.name = node.name + "/_conv"
    conv.op = "Conv2D" if node.op == "_FusedConv2D" else "DepthwiseConv2dNative"
    conv.input.extend(node.input[:2])
    for k in ("strides", "padding", "dilations", "data_format", "explicit_paddings"):
        if k in node.attr:
            conv.attr[k].CopyFrom(node.attr[k])
    conv.attr["T"].type = tf.float32.as_datatype_enum
    if "data_format" not in conv.attr:
        conv.attr["data_format"].s = b"NHWC"
    if "dilations" not in conv.attr:
        conv.attr["dilations"].list.i.extend([1, 1, 1, 1])
    if conv.op == "Conv2D" and "use_cudnn_on_gpu" in node.attr:
        conv.attr["use_cudnn_on_gpu"].CopyFrom(node.attr["use_cudnn_on_gpu"])
    if conv.op == "DepthwiseConv2dNative" and "explicit_paddings" in conv.attr and not conv.attr["explicit_paddings"].list.i:
        del conv.attr["explicit_paddings"]
    bias = node_def_pb2.NodeDef()
    bias.name = node.name + "/_bias" if len(fused) > 1 else node.name
    bias.op = "BiasAdd"
    bias.input.extend([conv.name, node.input[2]])
    bias.attr["T"].type = tf.float32.as_datatype_enum
    bias.attr["data_format"].s = conv.attr["data_format"].s
    out = [conv, bias]
    if len(fused) == 2:
        act = node_def_pb2.NodeDef()
        act.name = node.name
        if fused[1] not in ("Relu", "Relu6", "Elu", "Sigmoid", "Tanh"):
            raise NotImplementedError(f"{node.name}: activation {fused[1]}")
        act.op = fused[1]
        act.input.append(bias.name)
        act.attr["T"].type = tf.float32.as_datatype_enum
        out.append(act)
    elif len(fused) > 2:
        raise NotImplementedError(f"{node.name}: fused_ops {fused}")
    return out


def load_graph_def(model_json):
    """GraphDef of a TF.js graph model with weights restored and fused ops unfused."""
    model_dir = os.path.dirname(os.path.abspath(model_json))
    j = json.load(open(model_json))
    if j.get("format") != "graph-model":
        raise ValueError(f"{model_json}: not a TF.js graph model")
    gd = json_format.ParseDict(j["modelTopology"], graph_pb2.GraphDef(), ignore_unknown_fields=True)
    weights = load_weights(model_dir, j["weightsManifest"])
    out = graph_pb2.GraphDef()
    out.versions.CopyFrom(gd.versions)
    for node in gd.node:
        if node.op == "Const" and node.name in weights:
            arr = weights[node.name]
            node.attr["value"].CopyFrom(attr_value_pb2.AttrValue(tensor=tf.make_tensor_proto(arr)))
            node.attr["dtype"].type = tf.as_dtype(arr.dtype).as_datatype_enum
        out.node.extend(_unfuse(node))
    return out, j


def replace_with_placeholder(graph_def, node_name, shape, new_name="input"):
    """Cut the graph at `node_name`: its consumers read a new float32 Placeholder instead
    (used to drop the int32 input + Cast so that the network takes float pixels 0..255)."""
    out = graph_pb2.GraphDef()
    out.versions.CopyFrom(graph_def.versions)
    ph = node_def_pb2.NodeDef()
    ph.name = new_name
    ph.op = "Placeholder"
    ph.attr["dtype"].type = tf.float32.as_datatype_enum
    ph.attr["shape"].shape.CopyFrom(tf.TensorShape(shape).as_proto())
    out.node.append(ph)
    for node in graph_def.node:
        if node.name in (node_name, new_name):
            continue
        n = node_def_pb2.NodeDef()
        n.CopyFrom(node)
        for i, inp in enumerate(n.input):
            if inp == node_name or inp == node_name + ":0":
                n.input[i] = new_name
        out.node.append(n)
    return out


def run_graph(graph_def, feeds, fetches):
    """Run a GraphDef in a TF1-style session; feeds/fetches are tensor names."""
    g = tf.Graph()
    with g.as_default():
        tf.compat.v1.import_graph_def(graph_def, name="")
    with tf.compat.v1.Session(graph=g) as s:
        return s.run(fetches, feed_dict=feeds)


def fold_static_shapes(graph_def):
    """Replace every Shape node whose input has a fully known static shape (after the
    input placeholder got a fixed size) with a Const, so that the resize-size arithmetic
    (Shape -> StridedSlice -> Mul -> ResizeBilinear) folds to constants. OpenCV 4.6
    cannot import the dynamic Shape/Gather/Slice/Concat chain."""
    g = tf.Graph()
    with g.as_default():
        tf.compat.v1.import_graph_def(graph_def, name="")
    out = graph_pb2.GraphDef()
    out.versions.CopyFrom(graph_def.versions)
    folded = 0
    for node in graph_def.node:
        n = node_def_pb2.NodeDef()
        n.CopyFrom(node)
        if node.op == "Shape":
            shape = g.get_operation_by_name(node.name).inputs[0].shape
            if shape.is_fully_defined():
                dt = tf.as_dtype(node.attr["out_type"].type) if "out_type" in node.attr else tf.int32
                n = node_def_pb2.NodeDef()
                n.name = node.name
                n.op = "Const"
                n.attr["dtype"].type = dt.as_datatype_enum
                n.attr["value"].CopyFrom(attr_value_pb2.AttrValue(
                    tensor=tf.make_tensor_proto(np.array(shape.as_list(), dt.as_numpy_dtype))))
                folded += 1
        out.node.append(n)
    return out, folded
