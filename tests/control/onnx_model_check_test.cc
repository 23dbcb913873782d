// the ONNX checks before OpenCV's importer (control/onnx_model_check.h) on the crafted files
// of tests/control/make_crafted_onnx.py, generated into each test's temporary folder: each
// is refused with a ConfigError naming the file and the tensor, node or limit, and nothing
// crashes; the shipped policies and fixtures pass.

#include "penumbra/control/onnx_model_check.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/control/onnx_policy_network.h"
#include "penumbra/core/error.h"

extern char** environ;

namespace penumbra {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

class OnnxModelCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // the generator, run without a shell
    std::vector<std::string> args = {
        "/usr/bin/python3", PENUMBRA_SOURCE_DIR "/tests/control/make_crafted_onnx.py", dir_.str()};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&fa);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "make_crafted_onnx.py failed";
  }

  std::string Path(const std::string& name) const { return (dir_.path() / name).string(); }

  // the error LoadOnnxPolicy gives for the crafted file `name` ("" if it loads)
  std::string LoadError(const std::string& name, int in = 4, int out = 2) {
    try {
      LoadOnnxPolicy(Path(name), in, out);
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(Path(name), 0), 0u) << "the message starts with the file: " << m;
      return m;
    }
    return "";
  }

  testing::TempDir dir_;
};

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

TEST_F(OnnxModelCheckTest, TheValidControlLoadsAndRuns) {
  auto net = LoadOnnxPolicy(Path("valid.onnx"), 4, 2);
  std::vector<float> x = {1, 2, 3, 4}, y(2);
  net->Run(x, y);
  EXPECT_FLOAT_EQ(y[0], 0.5f);
  EXPECT_FLOAT_EQ(y[1], 1.0f);
}

TEST_F(OnnxModelCheckTest, HugeDimsAreRefusedBeforeOpenCv) {
  // was SIGFPE in OpenCV's InnerProductLayer::create
  const std::string e = LoadError("dims_2p62.onnx");
  EXPECT_HAS(e, "initializer 0 'w' has dims [4611686018427387904, 4]");
  EXPECT_HAS(e, "more than 16777216 elements (kOnnxMaxTensorElements)");
  // was SIGSEGV in cv::Mat::copyTo
  const std::string e2 = LoadError("dims_2p20x48_raw4.onnx");
  EXPECT_HAS(e2, "'w' has dims [1048576, 48]");
  EXPECT_HAS(e2, "kOnnxMaxTensorElements");
}

TEST_F(OnnxModelCheckTest, DataShorterThanTheDimsIsRefused) {
  // was SIGSEGV in cv::Mat::copyTo
  EXPECT_HAS(LoadError("float_data3_2p22.onnx"),
             "'w' has dims [4194304] (4194304 elements) but holds 3 float_data values; expected "
             "exactly 4194304");
  EXPECT_HAS(LoadError("raw_short.onnx"),
             "'w' has dims [2, 4] (8 elements, 32 bytes) but its raw_data holds 4 bytes; "
             "expected exactly 32");
  EXPECT_HAS(LoadError("negative_dim.onnx"), "expected every dim >= 1");
}

TEST_F(OnnxModelCheckTest, TinyFilesWithHugeActivationsAreRefused) {
  // the 4.2 GB RSS model: 278 bytes whose ConstantOfShape OpenCV folds into 2^32 floats
  EXPECT_HAS(LoadError("constant_of_shape_bomb.onnx"),
             "node 0 'fill' (ConstantOfShape): operator 'ConstantOfShape' is not supported");
  // a 0.2 KB graph expanding to 2^34 values
  EXPECT_HAS(LoadError("expand_bomb.onnx"), "operator 'Expand' is not supported; expected one of");
  const std::string e = LoadError("broadcast_bomb.onnx");
  EXPECT_HAS(e, "node 0 'add' (Add)");
  EXPECT_HAS(e, "more than 4194304 elements (kOnnxMaxActivationElements)");
}

TEST_F(OnnxModelCheckTest, OperatorsOpsetsAndControlFlowOutsideTheSupportedSetAreRefused) {
  // the out-of-bounds read behind "non-finite action -inf"
  EXPECT_HAS(LoadError("gather_oob.onnx"), "node 0 'gather' (Gather): operator 'Gather' is not");
  EXPECT_HAS(LoadError("opset_999.onnx"), "opset 999; expected an opset of 7 .. 17");
  EXPECT_HAS(LoadError("loop_graph.onnx"), "node 0 'if' (If): operator 'If' is not supported");
  EXPECT_HAS(LoadError("graph_attr.onnx"), "attribute 'body' holds a graph (control flow");
  EXPECT_HAS(LoadError("external_data.onnx"), "uses external data");
  EXPECT_HAS(LoadError("truncated.onnx"), "not a valid ONNX (protobuf) file");
  EXPECT_HAS(LoadError("gemm_omitted_b.onnx"),
             "node 0 'fc' (Gemm) omits its required input 1; expected a tensor name");
}

TEST_F(OnnxModelCheckTest, InputAndOutputShapesMustMatchTheConfiguredSizes) {
  EXPECT_HAS(LoadError("input_5.onnx"),
             "graph input 'obs' has shape [1, 5] (-1: symbolic); expected [1, 4]");
  EXPECT_HAS(LoadError("output_3.onnx"),
             "graph output 'actions' declares shape [1, 3]; expected 2 values");
  EXPECT_HAS(LoadError("valid.onnx", 4, 3), "expected 3 values (one per policy joint)");
}

TEST_F(OnnxModelCheckTest, EveryPrefixOfAValidFileIsRefusedCleanly) {
  const std::string bytes = ReadAll(Path("valid.onnx"));
  ASSERT_GT(bytes.size(), 100u);
  for (size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(CheckOnnxModel(std::string_view(bytes).substr(0, n), "cut.onnx", 4, 2),
                 ConfigError)
        << n;
  // and every single flipped byte either passes the checks or is refused with a ConfigError
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::string b = bytes;
    b[i] = static_cast<char>(b[i] ^ 0xff);
    try {
      LoadOnnxPolicyFromBytes(b, "flip.onnx", 4, 2);
    } catch (const ConfigError&) {
    }
  }
}

TEST_F(OnnxModelCheckTest, TheShippedPoliciesAndFixturesPass) {
  const std::string root = PENUMBRA_SOURCE_DIR;
  struct Case {
    std::string path;
    int in, out;
  };
  for (const Case& c : {Case{root + "/worlds/models/policies/go1_velocity.onnx", 48, 12},
                        Case{root + "/worlds/policies/stand_48x12.onnx", 48, 12},
                        Case{root + "/tests/control/fixtures/mlp_48x12.onnx", 48, 12},
                        Case{root + "/tests/control/fixtures/gemm_15x12.onnx", 15, 12}}) {
    const OnnxModelSummary s = CheckOnnxModel(ReadAll(c.path), c.path, c.in, c.out);
    EXPECT_EQ(s.output_shape, (std::vector<int64_t>{1, c.out})) << c.path;
    EXPECT_GT(s.weight_bytes, 0) << c.path;
  }
}

}  // namespace
}  // namespace penumbra
