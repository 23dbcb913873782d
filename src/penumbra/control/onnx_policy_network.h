#pragma once
// ONNX policies through OpenCV's dnn module (OpenCV 4.6, Debian's libopencv-dnn-dev): the
// PolicyNetwork (control/policy_network.h) of the policy controller.
//
// why OpenCV dnn: it is a maintained Debian package the project already depends on (OpenCV's
// core), reads ONNX files directly (no Python, no exporter at run time), runs MLPs on the CPU
// in-process and needs no download; ONNX Runtime and LibTorch are not packaged in Debian 12.
// what it cannot run (OpenCV 4.6's ONNX importer): graphs with control flow (Loop, If, Scan),
// recurrent policies whose hidden state is a graph input/output pair (only one input is fed),
// inputs whose shape is only known at run time (dynamic shapes other than the batch), and
// operators the importer does not know (the load fails naming them); docs/policies.md lists
// what exporters should produce (opset <= 13 MLPs: Gemm/MatMul/Add, Relu/Elu/Tanh/Sigmoid).
//
// determinism: OpenCV dnn's CPU layers split their work over OpenCV's thread pool by output
// elements; each output element's reduction runs in one thread in a fixed order, so results
// are bit-identical for any cv::setNumThreads (tests/control/policy_network_test.cc checks 1,
// 2 and 8 threads on an ELU MLP). the net uses the OpenCV backend on the CPU target only.

#include <memory>
#include <string>
#include <string_view>

#include "penumbra/control/policy_network.h"

namespace penumbra {

/// loads the ONNX graph at `path` (a regular file of at most kOnnxMaxFileBytes, read once)
/// and checks that it takes one float input of `input_size` values (shape [1, input_size] or
/// [input_size]) and returns one output of `output_size` values: first the file's protobuf
/// by CheckOnnxModel (control/onnx_model_check.h: tensor sizes against their data, caps on
/// weights and activations, opset and operators, input/output shapes), only then OpenCV's
/// importer on the checked bytes, and a run on zeros.
/// @throws ConfigError(path, ...) when the file is missing, not a regular file, unreadable or
///         too large, fails CheckOnnxModel (the message names the tensor, node or field and
///         the limit), is not an ONNX graph OpenCV can import (OpenCV's message is included),
///         has more than one output, rejects an input of `input_size` values, or returns a
///         different number of values than `output_size`; each message says what was expected.
std::unique_ptr<PolicyNetwork> LoadOnnxPolicy(const std::string& path, int input_size,
                                              int output_size);

/// LoadOnnxPolicy on the file contents `bytes`; `path` names them in errors.
/// @throws ConfigError as LoadOnnxPolicy.
std::unique_ptr<PolicyNetwork> LoadOnnxPolicyFromBytes(std::string_view bytes,
                                                       const std::string& path, int input_size,
                                                       int output_size);

}  // namespace penumbra
