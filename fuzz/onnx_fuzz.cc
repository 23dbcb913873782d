// libFuzzer target: the ONNX policy loader (control/onnx_policy_network.h): the protobuf
// checker (control/onnx_model_check.h) on arbitrary bytes and, for what it accepts, OpenCV
// dnn's importer and one forward pass. the first two bytes pick the observation and action
// sizes (1 .. 64); the rest is the file. the documented failure is ConfigError (and Error from
// the forward pass); any other exception, a crash, a sanitizer report, or a network accepted
// for sizes other than the ones asked is a finding. docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "penumbra/control/onnx_policy_network.h"
#include "penumbra/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  if (size < 2) return 0;
  const int in = 1 + data[0] % 64, out = 1 + data[1] % 64;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 2), size - 2);
  try {
    auto net = LoadOnnxPolicyFromBytes(bytes, "fuzz.onnx", in, out);
    if (net->input_size() != in || net->output_size() != out) __builtin_trap();
    std::vector<float> obs(in, 0.5f), act(out, 0.0f);
    net->Run(obs, act);
  } catch (const Error&) {
  }
  return 0;
}
