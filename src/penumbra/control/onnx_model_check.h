#pragma once
// the checks an ONNX policy file passes before any library reads it
// (control/onnx_policy_network.h loads it through OpenCV dnn afterwards). a policy file is
// something users download and share: OpenCV 4.6's importer trusts the file's tensor shapes
// and sizes (a crafted initializer crashed it), so the model's protobuf is read here by a
// small bounded wire-format reader of the ONNX subset a feed-forward policy uses, and
// refused unless:
//   - it is well-formed protobuf of at most kOnnxMaxFileBytes, IR version 3 .. 10, with one
//     opset of the default domain ("" / "ai.onnx") in kOnnxMinOpset .. kOnnxMaxOpset and no
//     other domain, no functions, training info or sparse initializers;
//   - every tensor (initializer or Constant value) has a supported data type (float32; int64
//     for Reshape shapes), at most 8 dims, each >= 0, an element count of at
//     most kOnnxMaxTensorElements (overflow-checked), its data inside the file (no external
//     data) and exactly as many values / raw bytes as its dims say; all tensors together hold
//     at most kOnnxMaxWeightBytes;
//   - every node is one of the supported operators (OnnxSupportedOperators(): the MLP
//     operators OpenCV 4.6 dnn imports), of the default domain, with no graph attributes
//     (no control flow), its inputs defined before it (topological order), its outputs named
//     once; the shapes are inferred from the declared input (batch 1) node by node, and every
//     intermediate tensor holds at most kOnnxMaxActivationElements values, all of them
//     together at most kOnnxMaxTotalActivationElements;
//   - the graph has one float32 input of shape [input_size] or [1|batch, input_size] and one
//     float32 output of output_size values, both declared and inferred.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

inline constexpr int64_t kOnnxMaxFileBytes = 64ll << 20;  ///< 64 MiB
inline constexpr int64_t kOnnxMaxTensorElements = 1ll << 24;
inline constexpr int64_t kOnnxMaxWeightBytes = 64ll << 20;  ///< all tensors of the file
inline constexpr int64_t kOnnxMaxActivationElements = 1ll << 22;
inline constexpr int64_t kOnnxMaxTotalActivationElements = 1ll << 24;
inline constexpr int64_t kOnnxMaxNodes = 10000;
inline constexpr int64_t kOnnxMinOpset = 7;
inline constexpr int64_t kOnnxMaxOpset = 17;

/// what CheckOnnxModel found in an accepted file.
struct OnnxModelSummary {
  int64_t ir_version = 0;
  int64_t opset = 0;
  std::string input_name, output_name;
  std::vector<int64_t> input_shape;   ///< as inferred (batch 1)
  std::vector<int64_t> output_shape;  ///< as inferred
  int64_t nodes = 0;
  int64_t weight_bytes = 0;             ///< all tensors' data
  int64_t activation_elements = 0;      ///< all nodes' outputs together
  int64_t max_activation_elements = 0;  ///< the largest node output
};

/// the supported operators, comma-separated (for messages and docs).
std::string OnnxSupportedOperators();

/// checks the ONNX model `bytes` (the file's contents; `path` names it in errors) against the
/// limits of the file comment, for a policy taking `input_size` observations and returning
/// `output_size` actions.
/// @throws ConfigError(path, 0, "", ...) naming the tensor, node or field and the limit it
///         breaks (malformed protobuf: the byte offset).
OnnxModelSummary CheckOnnxModel(std::string_view bytes, const std::string& path, int input_size,
                                int output_size);

}  // namespace penumbra
