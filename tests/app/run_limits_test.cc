// `penumbra run` (the real binary) on worlds with too many cameras or agents, and a SIGTERM
// while a run is being set up: a world of 5,000 cameras did not see a SIGTERM for more than
// 10 s, and 10,000 agents ran 339 s before MuJoCo ended the run. counts are refused at once with
// the file, line and limit (scene/scene_limits.h); a signal during the set-up ends it within
// about a second, with nothing written.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using testing::ChildProcess;

constexpr char kFloorMjcf[] = R"(<mujoco model="floor">
  <worldbody>
    <geom name="floor" type="plane" size="50 50 0.1"/>
    <body name="ball" pos="0 0 1"><freejoint/><geom type="sphere" size="0.2"/></body>
  </worldbody>
</mujoco>)";

// a world with `cameras` cameras of `width` x `height` on the world and `agents` people
std::string WorldText(int cameras, int width, int height, int agents) {
  std::string w =
      "duration_sec: 0.2\nmodels: [{name: scene, file: floor.xml}]\n"
      "mjcf_cameras: {enabled: false}\n";
  if (cameras > 0) w += "cameras:\n";
  for (int i = 0; i < cameras; ++i)
    w += "  - {name: c" + std::to_string(i) + ", attach: world, width: " + std::to_string(width) +
         ", height: " + std::to_string(height) + ", fovy_deg: 60, rate_hz: 10, outputs: [rgb], " +
         "pose: {xyz: [" + std::to_string(i % 50) + ", -5, 1]}}\n";
  if (agents > 0) w += "agents:\n";
  for (int i = 0; i < agents; ++i) {
    const std::string x = std::to_string(i % 40 - 20), y = std::to_string(i / 40 * 2 - 10);
    w += "  - {name: p" + std::to_string(i) + ", waypoints: [[" + x + ", " + y + "], [" + x +
         ".5, " + y + "]]}\n";
  }
  return w;
}

class RunLimitsTest : public ::testing::Test {
 protected:
  void SetUp() override { tmp_.Write("floor.xml", kFloorMjcf); }

  // runs `world` to its end (at most 60 s); returns the exit code and the seconds it took
  std::pair<int, double> Run(const std::string& world, ChildProcess** out = nullptr) {
    const auto t0 = Clock::now();
    ChildProcess p({"run", world, "--out", (tmp_.path() / "out").string(), "-q"}, tmp_.path());
    const int code = p.WaitFor(60);
    if (code < 0) p.Signal(SIGKILL);
    err_ = p.err();
    return {code, std::chrono::duration<double>(Clock::now() - t0).count()};
  }

  penumbra::testing::TempDir tmp_;
  std::string err_;
};

TEST_F(RunLimitsTest, ACameraCountBeyondTheLimitIsRefusedBeforeAnythingIsSetUp) {
  const std::string world = tmp_.Write("many.yaml", WorldText(5000, 16, 16, 0));
  const auto [code, seconds] = Run(world);
  EXPECT_EQ(code, 2) << err_;
  EXPECT_LT(seconds, 10) << err_;
  EXPECT_NE(err_.find(world + ":4: cameras: 5000 cameras; expected at most " +
                      std::to_string(kMaxCameras)),
            std::string::npos)
      << err_;
  EXPECT_FALSE(fs::exists(tmp_.path() / "out"));
}

TEST_F(RunLimitsTest, AnAgentCountBeyondTheLimitIsRefusedBeforeAnythingIsSetUp) {
  const std::string world = tmp_.Write("crowd.yaml", WorldText(0, 16, 16, 10000));
  const auto [code, seconds] = Run(world);
  EXPECT_EQ(code, 2) << err_;
  EXPECT_LT(seconds, 10) << err_;
  EXPECT_NE(
      err_.find(world + ":4: agents: 10000 agents; expected at most " + std::to_string(kMaxAgents)),
      std::string::npos)
      << err_;
}

TEST_F(RunLimitsTest, AsManyAgentsAsTheLimitAllowsRun) {
  // the limit keeps MuJoCo's collision arena small: at the limit the run completes
  const std::string world = tmp_.Write("limit.yaml", WorldText(0, 16, 16, kMaxAgents));
  const auto [code, seconds] = Run(world);
  EXPECT_EQ(code, 0) << err_;
}

TEST_F(RunLimitsTest, ASigtermDuringTheSetUpEndsItWithinASecond) {
  // the most cameras a world may have: set-up and first frames take seconds on this machine
  const std::string world = tmp_.Write("cams.yaml", WorldText(kMaxCameras, 320, 240, 100));
  const fs::path out = tmp_.path() / "out";
  ChildProcess p({"run", world, "--out", out.string(), "-q"}, tmp_.path());
  // composed.xml is written once the models are composed, after the handlers are installed
  bool composed = false;
  for (int i = 0; i < 6000 && !composed; ++i) {
    composed = fs::exists(out / "composed.xml");
    if (!composed) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(composed) << p.err();
  const auto t0 = Clock::now();
  p.Signal(SIGTERM);
  const int code = p.WaitFor(30);
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (code < 0) p.Signal(SIGKILL);
  EXPECT_EQ(code, 143) << p.err();
  EXPECT_LT(seconds, 1.5) << p.err();
  EXPECT_NE(p.err().find("interrupted by SIGTERM while"), std::string::npos) << p.err();
  EXPECT_NE(p.err().find("before the run started; no outputs written"), std::string::npos)
      << p.err();
  // nothing half-made is left: the folder the run created is gone
  EXPECT_FALSE(fs::exists(out / "run.json"));
  EXPECT_FALSE(fs::exists(out)) << p.err();
}

}  // namespace
}  // namespace penumbra
