#!/usr/bin/env python3
"""Convert a MediaPipe float TFLite model into an ONNX graph that OpenCV 4.6 DNN loads.

Only the operator subset of MediaPipe's BlazePose detector and landmark models is
supported (CONV_2D, DEPTHWISE_CONV_2D, ADD, PAD, MAX_POOL_2D, RESIZE_BILINEAR,
DEPTH_TO_SPACE, RESHAPE, CONCATENATION, LOGISTIC; DEQUANTIZE / DENSIFY only on constants).

How it works
- The graph structure and operator options are read from the .tflite flatbuffer with
  the `tflite` schema package.
- Every constant (fp16 weights behind DEQUANTIZE, sparse weights behind DENSIFY, int32
  shapes and paddings) is evaluated by TensorFlow's TFLite interpreter with
  `experimental_preserve_all_tensors=True` after one invocation on a zero input: the
  interpreter itself densifies and dequantizes, so the ONNX file holds exactly the fp32
  values TFLite computes with.
- The ONNX graph is written with the `onnx` package, opset 11, in NCHW layout: the
  network input is [1, 3, H, W] (RGB), 4-D activations stay NCHW, a RESHAPE of a 4-D
  tensor first transposes back to NHWC so that the flattened order equals TFLite's.
  4-D network outputs are NCHW (TFLite: NHWC).
- Fused RELU6 is written as `Clip` with `min`/`max` *attributes*: that is what OpenCV 4.6
  parses (it rejects opset-11 Clip with min/max inputs, and rejects Min with a constant).
  This makes the file deviate from the strict opset-11 schema (onnx.checker complains
  about Clip); it targets OpenCV 4.6 DNN only.
- TF "SAME" padding is made explicit (symmetric -> conv pads, asymmetric -> a Pad node).

Usage:
  tflite2onnx.py MODEL.tflite OUT.onnx --outputs Identity=regressors Identity_1=classificators
"""
import argparse
import sys

import numpy as np
import onnx
import tflite
from onnx import TensorProto, helper, numpy_helper

OPNAMES = {v: k for k, v in tflite.BuiltinOperator.__dict__.items() if not k.startswith("_")}
ACT_NONE, ACT_RELU, ACT_RELU6 = 0, 1, 3
PAD_SAME, PAD_VALID = 0, 1


def load_constants(path, model):
    """Run the TFLite interpreter once and return {tensor index: np.ndarray} for every
    tensor that is constant (has a buffer, or is produced by DEQUANTIZE/DENSIFY)."""
    import tensorflow as tf

    interp = tf.lite.Interpreter(model_path=path, experimental_preserve_all_tensors=True)
    interp.allocate_tensors()
    for d in interp.get_input_details():
        interp.set_tensor(d["index"], np.zeros(d["shape"], d["dtype"]))
    interp.invoke()
    g = model.Subgraphs(0)
    const_idx = set()
    for i in range(g.TensorsLength()):
        t = g.Tensors(i)
        if model.Buffers(t.Buffer()).DataLength() > 0:
            const_idx.add(i)
    for i in range(g.OperatorsLength()):
        op = g.Operators(i)
        name = opname(model, op)
        if name in ("DEQUANTIZE", "DENSIFY"):
            const_idx.add(op.Outputs(0))
    consts = {}
    for i in sorted(const_idx):
        try:
            v = np.array(interp.get_tensor(i))
        except ValueError:
            continue
        consts[i] = v
    return consts


def opname(model, op):
    oc = model.OperatorCodes(op.OpcodeIndex())
    return OPNAMES.get(max(oc.BuiltinCode(), oc.DeprecatedBuiltinCode()), "UNKNOWN")


def options(op, cls):
    o = cls()
    t = op.BuiltinOptions()
    o.Init(t.Bytes, t.Pos)
    return o


def same_pads(in_size, k, s, d):
    out = (in_size + s - 1) // s
    total = max((out - 1) * s + (k - 1) * d + 1 - in_size, 0)
    return total // 2, total - total // 2


class Builder:
    def __init__(self, model, consts, output_names):
        self.m = model
        self.g = model.Subgraphs(0)
        self.consts = consts
        self.nodes = []
        self.inits = []
        self.names = {}  # tflite tensor index -> onnx name
        self.counter = 0
        self.output_names = output_names

    def shape(self, i):
        t = self.g.Tensors(i)
        return [int(x) for x in t.ShapeAsNumpy()] if t.ShapeLength() else []

    def tname(self, i):
        return self.g.Tensors(i).Name().decode()

    def fresh(self, base):
        self.counter += 1
        return f"{base}__{self.counter}"

    def const(self, name, arr):
        self.inits.append(numpy_helper.from_array(np.ascontiguousarray(arr), name))
        return name

    def value(self, i):
        """ONNX name of tensor i; constants become initializers (4-D ones in NCHW)."""
        if i in self.names:
            return self.names[i]
        if i in self.consts:
            arr = self.consts[i].astype(np.float32)
            if arr.ndim == 4:
                arr = arr.transpose(0, 3, 1, 2)
            name = self.const(self.fresh("const"), arr)
            self.names[i] = name
            return name
        raise KeyError(f"tensor {i} ({self.tname(i)}) has no producer")

    def out_name(self, i):
        n = self.tname(i)
        if n in self.output_names:
            name = self.output_names[n]
        else:
            name = f"t{i}"
        self.names[i] = name
        return name

    def activation(self, x, act, out):
        if act == ACT_NONE:
            return x
        if act == ACT_RELU:
            self.nodes.append(helper.make_node("Relu", [x], [out], name=out + "_relu"))
        elif act == ACT_RELU6:
            self.nodes.append(helper.make_node("Clip", [x], [out], name=out + "_relu6", min=0.0, max=6.0))
        else:
            raise NotImplementedError(f"fused activation {act}")
        return out

    def emit(self, i, op):
        name = opname(self.m, op)
        ins = [op.Inputs(j) for j in range(op.InputsLength())]
        outs = [op.Outputs(j) for j in range(op.OutputsLength())]
        if name in ("DEQUANTIZE", "DENSIFY"):
            if outs[0] not in self.consts:
                raise NotImplementedError(f"op {i} {name} on a non-constant tensor")
            return
        o = outs[0]
        y = self.out_name(o)
        if name in ("CONV_2D", "DEPTHWISE_CONV_2D"):
            dw = name == "DEPTHWISE_CONV_2D"
            opt = options(op, tflite.DepthwiseConv2DOptions if dw else tflite.Conv2DOptions)
            x = self.value(ins[0])
            w = self.consts[ins[1]].astype(np.float32)
            in_shape = self.shape(ins[0])
            if dw:
                # [1, kh, kw, C*mult] -> [C*mult, 1, kh, kw], group = C_in
                w = w.transpose(3, 0, 1, 2)
                group = in_shape[3]
            else:
                # [O, kh, kw, I] -> [O, I, kh, kw]
                w = w.transpose(0, 3, 1, 2)
                group = 1
            kh, kw = w.shape[2], w.shape[3]
            sh, sw = opt.StrideH(), opt.StrideW()
            dh, dwl = opt.DilationHFactor(), opt.DilationWFactor()
            pads = [0, 0, 0, 0]
            if opt.Padding() == PAD_SAME:
                pt, pb = same_pads(in_shape[1], kh, sh, dh)
                pl, pr = same_pads(in_shape[2], kw, sw, dwl)
                if pt == pb and pl == pr:
                    pads = [pt, pl, pb, pr]
                else:
                    padded = self.fresh(y + "_pad")
                    pc = self.const(self.fresh("pads"), np.array([0, 0, pt, pl, 0, 0, pb, pr], np.int64))
                    self.nodes.append(helper.make_node("Pad", [x, pc], [padded], name=padded, mode="constant"))
                    x = padded
            wn = self.const(self.fresh("W"), w)
            inputs = [x, wn]
            if len(ins) > 2 and ins[2] >= 0:
                inputs.append(self.const(self.fresh("B"), self.consts[ins[2]].astype(np.float32).reshape(-1)))
            act = opt.FusedActivationFunction()
            conv_out = y if act == ACT_NONE else self.fresh(y + "_conv")
            self.nodes.append(helper.make_node(
                "Conv", inputs, [conv_out], name=conv_out, kernel_shape=[kh, kw], strides=[sh, sw],
                dilations=[dh, dwl], pads=pads, group=group))
            self.activation(conv_out, act, y)
        elif name == "ADD":
            opt = options(op, tflite.AddOptions)
            act = opt.FusedActivationFunction()
            add_out = y if act == ACT_NONE else self.fresh(y + "_add")
            self.nodes.append(helper.make_node("Add", [self.value(ins[0]), self.value(ins[1])], [add_out], name=add_out))
            self.activation(add_out, act, y)
        elif name == "PAD":
            p = self.consts[ins[1]].astype(np.int64)  # [[n0,n1],[h0,h1],[w0,w1],[c0,c1]] (NHWC)
            if len(ins) > 2 and ins[2] >= 0 and np.any(self.consts[ins[2]] != 0):
                raise NotImplementedError("PAD with a non-zero value")
            order = [0, 3, 1, 2]
            pads = [int(p[a, 0]) for a in order] + [int(p[a, 1]) for a in order]
            pc = self.const(self.fresh("pads"), np.array(pads, np.int64))
            self.nodes.append(helper.make_node("Pad", [self.value(ins[0]), pc], [y], name=y, mode="constant"))
        elif name == "MAX_POOL_2D":
            opt = options(op, tflite.Pool2DOptions)
            in_shape = self.shape(ins[0])
            kh, kw, sh, sw = opt.FilterHeight(), opt.FilterWidth(), opt.StrideH(), opt.StrideW()
            pads = [0, 0, 0, 0]
            if opt.Padding() == PAD_SAME:
                pt, pb = same_pads(in_shape[1], kh, sh, 1)
                pl, pr = same_pads(in_shape[2], kw, sw, 1)
                if (pt, pl) != (pb, pr):
                    raise NotImplementedError("asymmetric SAME max-pool")
                pads = [pt, pl, pb, pr]
            act = opt.FusedActivationFunction()
            pool_out = y if act == ACT_NONE else self.fresh(y + "_pool")
            self.nodes.append(helper.make_node("MaxPool", [self.value(ins[0])], [pool_out], name=pool_out,
                                               kernel_shape=[kh, kw], strides=[sh, sw], pads=pads))
            self.activation(pool_out, act, y)
        elif name == "RESIZE_BILINEAR":
            opt = options(op, tflite.ResizeBilinearOptions)
            in_shape, out_shape = self.shape(ins[0]), self.shape(o)
            if opt.AlignCorners():
                mode = "align_corners"
            elif opt.HalfPixelCenters():
                mode = "half_pixel"
            else:
                mode = "asymmetric"
            scales = np.array([1.0, 1.0, out_shape[1] / in_shape[1], out_shape[2] / in_shape[2]], np.float32)
            roi = self.const(self.fresh("roi"), np.zeros(0, np.float32))
            sc = self.const(self.fresh("scales"), scales)
            self.nodes.append(helper.make_node("Resize", [self.value(ins[0]), roi, sc], [y], name=y,
                                               mode="linear", coordinate_transformation_mode=mode))
        elif name == "DEPTH_TO_SPACE":
            opt = options(op, tflite.DepthToSpaceOptions)
            # TF's channel order (i*bs + j)*C' + c equals ONNX mode DCR
            self.nodes.append(helper.make_node("DepthToSpace", [self.value(ins[0])], [y], name=y,
                                               blocksize=opt.BlockSize(), mode="DCR"))
        elif name == "RESHAPE":
            in_shape, out_shape = self.shape(ins[0]), self.shape(o)
            x = self.value(ins[0])
            if len(in_shape) == 4 and not (in_shape[1] == 1 and in_shape[2] == 1):
                nhwc = self.fresh(y + "_nhwc")
                self.nodes.append(helper.make_node("Transpose", [x], [nhwc], name=nhwc, perm=[0, 2, 3, 1]))
                x = nhwc
            if len(out_shape) == 4:
                raise NotImplementedError("RESHAPE to 4-D")
            sc = self.const(self.fresh("shape"), np.array(out_shape, np.int64))
            self.nodes.append(helper.make_node("Reshape", [x, sc], [y], name=y))
        elif name == "CONCATENATION":
            opt = options(op, tflite.ConcatenationOptions)
            rank = len(self.shape(o))
            axis = opt.Axis() % rank
            if rank == 4:
                axis = [0, 2, 3, 1][axis]
            act = opt.FusedActivationFunction()
            cat_out = y if act == ACT_NONE else self.fresh(y + "_cat")
            self.nodes.append(helper.make_node("Concat", [self.value(t) for t in ins], [cat_out], name=cat_out, axis=axis))
            self.activation(cat_out, act, y)
        elif name == "LOGISTIC":
            self.nodes.append(helper.make_node("Sigmoid", [self.value(ins[0])], [y], name=y))
        else:
            raise NotImplementedError(f"op {i}: {name}")

    def build(self, graph_name):
        g = self.g
        inputs = []
        for j in range(g.InputsLength()):
            i = g.Inputs(j)
            s = self.shape(i)
            name = "input" if g.InputsLength() == 1 else self.tname(i)
            self.names[i] = name
            inputs.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, [s[0], s[3], s[1], s[2]]))
        for i in range(g.OperatorsLength()):
            self.emit(i, g.Operators(i))
        outputs = []
        for j in range(g.OutputsLength()):
            i = g.Outputs(j)
            s = self.shape(i)
            if len(s) == 4:
                s = [s[0], s[3], s[1], s[2]]
            outputs.append(helper.make_tensor_value_info(self.names[i], TensorProto.FLOAT, s))
        graph = helper.make_graph(self.nodes, graph_name, inputs, outputs, self.inits)
        model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 11)],
                                  producer_name="gesture_formation/tools/models/tflite2onnx.py",
                                  producer_version="1")
        model.ir_version = 6
        return model


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tflite")
    ap.add_argument("onnx")
    ap.add_argument("--outputs", nargs="*", default=[], help="TFLITE_NAME=ONNX_NAME renames of graph outputs")
    ap.add_argument("--graph-name", default=None)
    a = ap.parse_args()
    buf = open(a.tflite, "rb").read()
    model = tflite.Model.GetRootAsModel(buf, 0)
    if model.SubgraphsLength() != 1:
        sys.exit("only single-subgraph models are supported")
    consts = load_constants(a.tflite, model)
    renames = dict(kv.split("=", 1) for kv in a.outputs)
    b = Builder(model, consts, renames)
    m = b.build(a.graph_name or a.onnx.rsplit("/", 1)[-1].rsplit(".", 1)[0])
    # shape-inference would reject the attribute-style Clip; the file is saved as built
    with open(a.onnx, "wb") as f:
        f.write(m.SerializeToString())
    print(f"tflite2onnx: wrote {a.onnx} ({len(m.graph.node)} nodes, {len(m.graph.initializer)} initializers)")


if __name__ == "__main__":
    main()
