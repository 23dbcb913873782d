#!/usr/bin/python3
"""Writes the crafted (hostile) ONNX policy files the ONNX checker must refuse
(control/onnx_model_check.h; tests/control/onnx_model_check_test.cc runs this script into its
temporary folder), as protobuf bytes by hand (onnx.proto field numbers): no onnx package.

Every file is for a policy of 4 observations and 2 actions (input "obs" [1, 4], output
"actions" [1, 2]) unless its name says otherwise:

  valid.onnx              Gemm obs [1, 4] x W^T [2, 4] + b: accepted (the control).
  dims_2p62.onnx          an initializer with dims [2^62, 4] and 16 raw bytes (was SIGFPE in
                          OpenCV's InnerProductLayer::create).
  dims_2p20x48_raw4.onnx  dims [2^20, 48] with 4 raw bytes (was SIGSEGV in cv::Mat::copyTo).
  float_data3_2p22.onnx   dims [2^22] with 3 float_data values (was SIGSEGV).
  raw_short.onnx          dims [2, 4] (32 bytes) with 4 raw bytes (the old loader accepted it,
                          reading 28 bytes past the data).
  negative_dim.onnx       dims [-1, 4].
  expand_bomb.onnx        a 0.3 KB graph whose Expand makes a [65536, 65536, 4] tensor (the
                          4.2 GB RSS model's kind: a tiny file, a huge activation).
  constant_of_shape_bomb.onnx  278 bytes whose ConstantOfShape fills [16384, 16384, 4]: OpenCV
                          folds it at import into a 4.3 GB tensor (the 4.2 GB RSS model; a
                          [8192, 8192, 4] variant measured 1.06 GB RSS under the old loader).
  broadcast_bomb.onnx     Add of initializers [4096, 1] and [1, 4096]: 16.7 M elements from
                          supported operators (over the activation cap).
  gather_oob.onnx         Gather of index 1000 from obs (the out-of-bounds read behind
                          "non-finite action -inf").
  opset_999.onnx          the valid graph under opset 999.
  loop_graph.onnx         an If node holding a graph attribute (control flow).
  graph_attr.onnx         a Relu node carrying a graph attribute.
  external_data.onnx      an initializer whose data lives in an external file.
  input_5.onnx            the valid graph declaring input [1, 5] (mismatched observation size).
  output_3.onnx           a graph computing [1, 3] actions (mismatched action size).
  gemm_omitted_b.onnx     a Gemm whose required input B is the empty name (an omitted input;
                          found by fuzzing the checker).
  truncated.onnx          valid.onnx cut in the middle of a field.
  huge_action.onnx        accepted by the checker; returns 3e38 for every output on obs = 1.
  inf_action.onnx         accepted by the checker; returns -inf for output 0 on obs = 1.

usage: /usr/bin/python3 tests/control/make_crafted_onnx.py OUT_DIR
(fuzz/make_corpus.py imports crafted() for the onnx seed corpus.)
"""

import os
import struct
import sys


# the protobuf wire helpers are the policy fixtures' (one writer of onnx.proto's encoding)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures"))
from make_policy_fixtures import field_bytes as fb  # noqa: E402
from make_policy_fixtures import field_float as ff  # noqa: E402
from make_policy_fixtures import field_varint as fv  # noqa: E402
from make_policy_fixtures import varint  # noqa: E402,F401


FLOAT, INT64 = 1, 7


def tensor(name, dims, values=None, raw=None, dtype=FLOAT, float_data=None, extra=b""):
    # TensorProto: dims 1, data_type 2, float_data 4 (packed), name 8, raw_data 9
    t = b"".join(fv(1, d) for d in dims) + fv(2, dtype) + fb(8, name)
    if values is not None:
        fmt = "<%d%s" % (len(values), "f" if dtype == FLOAT else "q")
        raw = struct.pack(fmt, *values)
    if raw is not None:
        t += fb(9, raw)
    if float_data is not None:
        t += fb(4, struct.pack("<%df" % len(float_data), *float_data))
    return t + extra


def value_info(name, dims):
    shape = b"".join(fb(1, fv(1, d)) for d in dims)
    return fb(1, name) + fb(2, fb(1, fv(1, FLOAT) + fb(2, shape)))


def attr_int(name, value):
    return fb(1, name) + fv(3, value) + fv(20, 2)


def node(op, inputs, outputs, name, attrs=()):
    n = b"".join(fb(1, i) for i in inputs) + b"".join(fb(2, o) for o in outputs)
    n += fb(3, name) + fb(4, op)
    return n + b"".join(fb(5, a) for a in attrs)


def graph(nodes, inits, inputs, outputs):
    g = b"".join(fb(1, n) for n in nodes) + fb(2, "policy")
    g += b"".join(fb(5, t) for t in inits)
    g += b"".join(fb(11, v) for v in inputs) + b"".join(fb(12, v) for v in outputs)
    return g


def model(nodes, inits, inputs=None, outputs=None, opset=13):
    inputs = inputs if inputs is not None else [value_info("obs", [1, 4])]
    outputs = outputs if outputs is not None else [value_info("actions", [1, 2])]
    return (fv(1, 7) + fb(2, "make_crafted_onnx.py") +
            fb(7, graph(nodes, inits, inputs, outputs)) + fb(8, fb(1, "") + fv(2, opset)))


def gemm_model(w, w_dims=(2, 4), n_out=2, b=None, opset=13, inputs=None, w_tensor=None):
    b = b if b is not None else [0.0] * n_out
    inits = [w_tensor if w_tensor is not None else tensor("w", list(w_dims), w),
             tensor("b", [n_out], b)]
    n = node("Gemm", ["obs", "w", "b"], ["actions"], "fc", [attr_int("transB", 1)])
    return model([n], inits, inputs=inputs,
                 outputs=[value_info("actions", [1, n_out])], opset=opset)


W = [0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0]


def crafted():
    """{file name: bytes} of every crafted model (see the module comment)."""
    f = {}
    f["valid.onnx"] = gemm_model(W)
    f["dims_2p62.onnx"] = gemm_model(None, w_tensor=tensor("w", [1 << 62, 4], raw=b"\0" * 16))
    f["dims_2p20x48_raw4.onnx"] = gemm_model(
        None, w_tensor=tensor("w", [1 << 20, 48], raw=b"\0" * 4))
    f["float_data3_2p22.onnx"] = gemm_model(
        None, w_tensor=tensor("w", [1 << 22], float_data=[1.0, 2.0, 3.0]))
    f["raw_short.onnx"] = gemm_model(None, w_tensor=tensor("w", [2, 4], raw=b"\0" * 4))
    f["negative_dim.onnx"] = gemm_model(None, w_tensor=tensor("w", [-1, 4], raw=b"\0" * 16))
    shape = tensor("shape", [3], [65536, 65536, 4], dtype=INT64)
    f["expand_bomb.onnx"] = model(
        [node("Expand", ["obs", "shape"], ["big"], "expand"),
         node("ReduceSum", ["big"], ["actions"], "sum")], [shape])
    big = tensor("shape", [3], [16384, 16384, 4], dtype=INT64)
    f["constant_of_shape_bomb.onnx"] = model(
        [node("ConstantOfShape", ["shape"], ["big"], "fill"),
         node("Gemm", ["obs", "w", "b"], ["actions"], "fc", [attr_int("transB", 1)])],
        [big, tensor("w", [2, 4], W), tensor("b", [2], [0.0, 0.0])])
    f["broadcast_bomb.onnx"] = model(
        [node("Add", ["a", "b"], ["big"], "add"),
         node("Gemm", ["obs", "w", "bias"], ["actions"], "fc", [attr_int("transB", 1)])],
        [tensor("a", [4096, 1], [0.0] * 4096), tensor("b", [1, 4096], [0.0] * 4096),
         tensor("w", [2, 4], W), tensor("bias", [2], [0.0, 0.0])])
    f["gather_oob.onnx"] = model(
        [node("Gather", ["obs", "idx"], ["actions"], "gather", [attr_int("axis", 1)])],
        [tensor("idx", [2], [0, 1000], dtype=INT64)])
    f["opset_999.onnx"] = gemm_model(W, opset=999)
    # If with a then_branch graph attribute (AttributeProto.g = 6, type GRAPH = 5)
    body = graph([node("Identity", ["obs"], ["y"], "id")], [], [], [value_info("y", [1, 2])])
    cond = tensor("cond", [], [1.0])
    f["loop_graph.onnx"] = model(
        [node("If", ["cond"], ["actions"], "if", [fb(1, "then_branch") + fb(6, body) + fv(20, 5)])],
        [cond])
    f["graph_attr.onnx"] = model(
        [node("Relu", ["obs"], ["h"], "relu", [fb(1, "body") + fb(6, body) + fv(20, 5)]),
         node("Gemm", ["h", "w", "b"], ["actions"], "fc", [attr_int("transB", 1)])],
        [tensor("w", [2, 4], W), tensor("b", [2], [0.0, 0.0])])
    # TensorProto.external_data 13 {key 1, value 2}, data_location 14 = EXTERNAL (1)
    ext = fb(13, fb(1, "location") + fb(2, "/etc/passwd")) + fv(14, 1)
    f["external_data.onnx"] = gemm_model(None, w_tensor=tensor("w", [2, 4], extra=ext))
    f["input_5.onnx"] = gemm_model([0.0] * 10, w_dims=(2, 5),
                                   inputs=[value_info("obs", [1, 5])])
    f["output_3.onnx"] = gemm_model([0.0] * 12, w_dims=(3, 4), n_out=3)
    # a Gemm whose required B input is omitted ("": found by fuzzing, a null dereference)
    f["gemm_omitted_b.onnx"] = model(
        [node("Gemm", ["obs", "", "b"], ["actions"], "fc", [attr_int("transB", 1)])],
        [tensor("b", [2], [0.0, 0.0])])
    f["truncated.onnx"] = f["valid.onnx"][: len(f["valid.onnx"]) // 2 + 3]
    f["huge_action.onnx"] = gemm_model([3e38 / 4] * 8)
    f["inf_action.onnx"] = gemm_model([float("-inf")] * 4 + [0.0] * 4)
    return f


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_crafted_onnx.py OUT_DIR")
    os.makedirs(sys.argv[1], exist_ok=True)
    for name, data in sorted(crafted().items()):
        with open(os.path.join(sys.argv[1], name), "wb") as out:
            out.write(data)
        print("%s: %d bytes" % (name, len(data)))


if __name__ == "__main__":
    main()
