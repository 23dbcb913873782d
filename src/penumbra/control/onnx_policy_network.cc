#include "penumbra/control/onnx_policy_network.h"

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <system_error>

#include "penumbra/control/onnx_model_check.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

// the first line of an OpenCV exception, without its source location prefix
std::string CvReason(const cv::Exception& e) {
  std::string s = e.err.empty() ? std::string(e.what()) : e.err;
  if (!e.func.empty()) s += " (in " + e.func + ")";
  return s;
}

class OnnxPolicyNetwork final : public PolicyNetwork {
 public:
  OnnxPolicyNetwork(cv::dnn::Net net, std::string path, int in, int out)
      : net_(std::move(net)),
        path_(std::move(path)),
        in_(in),
        out_(out),
        input_(cv::Mat::zeros(1, in, CV_32F)) {}

  int input_size() const override { return in_; }
  int output_size() const override { return out_; }

  void Run(std::span<const float> observation, std::span<float> action) override {
    if (static_cast<int>(observation.size()) != in_ || static_cast<int>(action.size()) != out_)
      throw Error(path_ + ": policy called with " + std::to_string(observation.size()) +
                  " observations and " + std::to_string(action.size()) + " actions; expected " +
                  std::to_string(in_) + " and " + std::to_string(out_));
    float* dst = input_.ptr<float>();
    std::copy(observation.begin(), observation.end(), dst);
    cv::Mat y;
    try {
      net_.setInput(input_);
      y = net_.forward();
    } catch (const cv::Exception& e) {
      throw Error(path_ + ": policy inference failed: " + CvReason(e));
    }
    if (y.total() != static_cast<size_t>(out_) || y.type() != CV_32F)
      throw Error(path_ + ": policy returned " + std::to_string(y.total()) + " values; expected " +
                  std::to_string(out_) + " float32");
    const cv::Mat yc = y.isContinuous() ? y : y.clone();
    std::copy(yc.ptr<float>(), yc.ptr<float>() + out_, action.begin());
  }

 private:
  cv::dnn::Net net_;
  std::string path_;
  int in_ = 0, out_ = 0;
  cv::Mat input_;  ///< (1 x in) reused input blob
};

}  // namespace

std::unique_ptr<PolicyNetwork> LoadOnnxPolicy(const std::string& path, int input_size,
                                              int output_size) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ConfigError(path, 0, "",
                      "no such ONNX file; expected a policy network exported to ONNX "
                      "(docs/policies.md)");
  // a regular file only (a FIFO does not block), its size checked before it is read
  const std::string bytes =
      ReadInputFile(path, "ONNX policy file", static_cast<size_t>(kOnnxMaxFileBytes));
  return LoadOnnxPolicyFromBytes(bytes, path, input_size, output_size);
}

std::unique_ptr<PolicyNetwork> LoadOnnxPolicyFromBytes(std::string_view bytes,
                                                       const std::string& path, int input_size,
                                                       int output_size) {
  // every size and shape checked before OpenCV's importer sees a byte
  CheckOnnxModel(bytes, path, input_size, output_size);
  const std::string expected = "expected an ONNX graph from [1, " + std::to_string(input_size) +
                               "] float32 observations to [1, " + std::to_string(output_size) +
                               "] actions";
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNetFromONNX(bytes.data(), bytes.size());
  } catch (const cv::Exception& e) {
    throw ConfigError(path, 0, "",
                      "OpenCV dnn (4.6) cannot load this ONNX graph: " + CvReason(e) + "; " +
                          expected +
                          " built from operators OpenCV dnn supports (docs/policies.md)");
  }
  if (net.empty()) throw ConfigError(path, 0, "", "the ONNX graph has no layers; " + expected);
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const std::vector<std::string> outs = net.getUnconnectedOutLayersNames();
  if (outs.size() != 1) {
    std::string names;
    for (const auto& n : outs) names += (names.empty() ? "" : ", ") + n;
    throw ConfigError(path, 0, "",
                      "the graph has " + std::to_string(outs.size()) + " outputs (" + names +
                          "); " + expected + " and exactly one output");
  }
  // probe: one forward pass on zeros of the configured size
  cv::Mat probe = cv::Mat::zeros(1, input_size, CV_32F), y;
  try {
    net.setInput(probe);
    y = net.forward();
  } catch (const cv::Exception& e) {
    throw ConfigError(path, 0, "",
                      "the graph rejects an input of [1, " + std::to_string(input_size) +
                          "] (the size of the configured observation terms): " + CvReason(e) +
                          "; " + expected);
  }
  if (y.total() != static_cast<size_t>(output_size) || y.type() != CV_32F)
    throw ConfigError(path, 0, "",
                      "the graph returns " + std::to_string(y.total()) +
                          " values for an input of [1, " + std::to_string(input_size) + "]; " +
                          expected + " (the size of the configured action)");
  return std::make_unique<OnnxPolicyNetwork>(std::move(net), path, input_size, output_size);
}

}  // namespace penumbra
