#pragma once
// the inference seam of the policy controller (control/policy_controller.h): a feed-forward
// network mapping one observation vector to one action vector. the policy controller only
// calls it through this interface; control/onnx_policy_network.h implements it with OpenCV's
// dnn module over ONNX files, and another runtime (e.g. a GPU one) would implement it beside.

#include <span>

namespace penumbra {

/// a loaded policy network: (input_size) float32 observations -> (output_size) float32
/// actions, batch 1. Run must be deterministic: the same input gives bit-identical outputs,
/// whatever the process's thread count. not thread-safe (one controller owns one network).
class PolicyNetwork {
 public:
  virtual ~PolicyNetwork() = default;
  /// length of the observation vector the network takes.
  virtual int input_size() const = 0;
  /// length of the action vector it returns.
  virtual int output_size() const = 0;
  /// writes the actions for `observation` into `action`.
  /// @throws Error if the spans' lengths differ from input_size() / output_size() or the
  ///         runtime fails.
  virtual void Run(std::span<const float> observation, std::span<float> action) = 0;
};

}  // namespace penumbra
