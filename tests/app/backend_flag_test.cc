// `--backend cpu|cuda|auto` on every verb that renders (app/backend_flag.h; run, replay,
// export, benchmark, bench render, contact-sheet, view), on the real binary: each verb takes
// `cpu` and renders, `auto` on a machine without a CUDA device renders the same bytes as `cpu`,
// `cuda` without a device is refused before anything runs (exit 2, the error names --backend),
// other values are usage errors, and `bench render --batch` / `--size` say what they need.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/render/backends/renderer_factory.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;
using testing::RunPenumbra;

constexpr char kBackendMjcf[] = R"(<mujoco model="m">
  <option timestep="0.01"/>
  <worldbody>
    <light pos="0 0 3"/>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="box" pos="0 0 0.5"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body>
  </worldbody>
</mujoco>)";

class BackendFlagTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_.Write("m.xml", kBackendMjcf);
    world_ = tmp_.Write("w.yaml",
                        "seed: 3\nduration_sec: 0.2\nmodels: [{name: m, file: m.xml}]\n"
                        "cameras: [{name: c, attach: world, pose: {xyz: [-2, 0, 1]}, width: 16, "
                        "height: 12, rate_hz: 10, outputs: [rgb, depth, segmentation]}]\n");
  }
  ProcessResult Penumbra(const std::vector<std::string>& args) {
    return RunPenumbra(args, tmp_.path());
  }
  std::string Path(const std::string& name) const { return (tmp_.path() / name).string(); }
  testing::TempDir tmp_;
  std::string world_;
};

// the bytes of every file under `dir` but run.json (which holds the command line and times)
std::map<std::string, std::string> BackendImageFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".png")
      files[fs::relative(e.path(), dir).string()] = testing::ReadAll(e.path());
  return files;
}

TEST_F(BackendFlagTest, EveryRenderingVerbTakesCpu) {
  const std::string log = Path("w.plog");
  ProcessResult r = Penumbra(
      {"run", world_, "--backend", "cpu", "--out", Path("run_cpu"), "-q", "--record", log});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(BackendImageFiles(Path("run_cpu")).empty());
  r = Penumbra({"replay", log, "--backend", "cpu", "--out", Path("replay_cpu"), "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(BackendImageFiles(Path("replay_cpu")) == BackendImageFiles(Path("run_cpu")));
  r = Penumbra({"export", log, "--backend", "cpu", "--format", "tum", "--out", Path("tum"),
                "--depth", "ground-truth"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(Path("tum/rgb.txt"))) << r.err;
  r = Penumbra({"contact-sheet", "--world", world_, "--presets", "none", "--width", "16",
                "--height", "16", "--out", Path("sheet.png"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(Path("sheet.png")));
  r = Penumbra({"bench", "render", "--world", world_, "--frames", "1", "--no-adversity",
                "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("640x480 rgb+depth"), std::string::npos) << r.out;
  // benchmark and view take the flag: their own errors come next (no spec, no world)
  r = Penumbra({"benchmark", Path("none.yaml"), "--out", Path("bench"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.find("--backend"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("none.yaml"), std::string::npos) << r.err;
  r = Penumbra({"view", Path("none.yaml"), "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.find("--backend"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("none.yaml"), std::string::npos) << r.err;
  // export of a run folder renders nothing: --backend is refused there
  r = Penumbra(
      {"export", Path("run_cpu"), "--backend", "cpu", "--format", "tum", "--out", Path("tum2")});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--backend: only for a run log (.plog) input"), std::string::npos) << r.err;
}

TEST_F(BackendFlagTest, AutoWithoutADeviceRendersTheCpuBytes) {
  if (ProbeCudaDevice().available) GTEST_SKIP() << "a CUDA device is present: auto is cuda";
  ProcessResult r = Penumbra({"run", world_, "--backend", "cpu", "--out", Path("a"), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = Penumbra({"run", world_, "--backend", "auto", "--out", Path("b"), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(BackendImageFiles(Path("a")).empty());
  EXPECT_TRUE(BackendImageFiles(Path("a")) == BackendImageFiles(Path("b")));
}

TEST_F(BackendFlagTest, CudaWithoutADeviceIsRefusedNamingTheFlag) {
  if (ProbeCudaDevice().available) GTEST_SKIP() << "a CUDA device is present";
  const std::string log = Path("x.plog");
  const std::vector<std::vector<std::string>> verbs = {
      {"run", world_, "--out", Path("o1")},
      {"replay", log, "--out", Path("o2")},
      {"export", log, "--format", "tum", "--out", Path("o3")},
      {"export", log, "--format", "rosbag", "--out", Path("o4.bag")},
      {"benchmark", Path("spec.yaml"), "--out", Path("o5")},
      {"bench", "render", "--world", world_},
      {"contact-sheet", "--world", world_, "--out", Path("o6.png")},
      {"view", world_}};
  for (std::vector<std::string> args : verbs) {
    SCOPED_TRACE(args[0]);
    args.push_back("--backend");
    args.push_back("cuda");
    const ProcessResult r = Penumbra(args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--backend: cuda needs a CUDA device"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("expected --backend cpu or auto"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(Path("o1")));
  EXPECT_FALSE(fs::exists(Path("o6.png")));
}

TEST_F(BackendFlagTest, OtherValuesAreUsageErrors) {
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"run", world_},
                                             {"replay", Path("x.plog")},
                                             {"export", Path("x.plog"), "--format", "tum"},
                                             {"benchmark", Path("s.yaml"), "--out", Path("o")},
                                             {"bench", "render"},
                                             {"contact-sheet"},
                                             {"view", world_}}) {
    SCOPED_TRACE(args[0]);
    std::vector<std::string> a = args;
    a.insert(a.end(), {"--backend", "gpu"});
    const ProcessResult r = Penumbra(a);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--backend"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
}

TEST_F(BackendFlagTest, BenchRenderBatchNeedsTheCudaBackend) {
  ProcessResult r = Penumbra({"bench", "render", "--world", world_, "--size", "64x64"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--size: applies to --batch only"), std::string::npos) << r.err;
  r = Penumbra({"bench", "render", "--world", world_, "--batch", "4", "--size", "64"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'64' is not WxH"), std::string::npos) << r.err;
  if (ProbeCudaDevice().available) return;
  r = Penumbra({"bench", "render", "--world", world_, "--batch", "4", "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--batch: batch rendering runs on the CUDA backend"), std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace penumbra
