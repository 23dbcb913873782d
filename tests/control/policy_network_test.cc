// the ONNX runtime seam of the policy controller (control/onnx_policy_network.h): outputs of
// the fixture graphs and bit-identical results for any OpenCV thread count.

#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/core.hpp>

#include "penumbra/control/onnx_policy_network.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

const std::string kFixtures = PENUMBRA_SOURCE_DIR "/tests/control/fixtures/";

TEST(OnnxPolicyNetworkTest, GemmFixtureSelectsTheJointOffsets) {
  auto net = LoadOnnxPolicy(kFixtures + "gemm_15x12.onnx", 15, 12);
  EXPECT_EQ(net->input_size(), 15);
  EXPECT_EQ(net->output_size(), 12);
  std::vector<float> x(15), y(12);
  for (int i = 0; i < 15; ++i) x[i] = 0.5f * i - 1.0f;
  net->Run(x, y);
  for (int j = 0; j < 12; ++j) EXPECT_EQ(y[j], x[3 + j]) << j;
  // wrong span sizes are an error, not a read past the buffer
  std::vector<float> short_x(14);
  EXPECT_THROW(net->Run(short_x, y), Error);
}

TEST(OnnxPolicyNetworkTest, ResultsAreBitIdenticalForAnyThreadCount) {
  const int saved = cv::getNumThreads();
  std::vector<std::vector<float>> outs;
  for (int threads : {1, 2, 8}) {
    cv::setNumThreads(threads);
    auto net = LoadOnnxPolicy(kFixtures + "mlp_48x12.onnx", 48, 12);
    std::vector<float> all;
    std::vector<float> x(48), y(12);
    for (int k = 0; k < 20; ++k) {
      for (int i = 0; i < 48; ++i) x[i] = std::sin(0.37f * i + 0.11f * k) * (1 + k % 3);
      net->Run(x, y);
      all.insert(all.end(), y.begin(), y.end());
    }
    outs.push_back(all);
  }
  cv::setNumThreads(saved);
  ASSERT_EQ(outs[0].size(), outs[1].size());
  EXPECT_EQ(std::memcmp(outs[0].data(), outs[1].data(), outs[0].size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(outs[0].data(), outs[2].data(), outs[0].size() * sizeof(float)), 0);
  // not all zero: the graph computes something
  float mag = 0;
  for (float v : outs[0]) mag = std::max(mag, std::abs(v));
  EXPECT_GT(mag, 0.1f);
}

TEST(OnnxPolicyNetworkTest, RefusesMissingFilesNamingThem) {
  try {
    LoadOnnxPolicy(kFixtures + "missing.onnx", 4, 4);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.onnx"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("no such ONNX file"), std::string::npos);
  }
}

}  // namespace
}  // namespace penumbra
