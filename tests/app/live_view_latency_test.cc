// the live view of a run at real-time pacing (command/bridge_set.h): with a camera that fires
// every physics step, so that rendering is far slower than the step rate, no frame captured
// before a command is still waiting for the renderer when the command applies: the live view
// holds at most the one frame it is given, the first frame delivered after a teleop twist was
// captured at or after the step the twist applied at, and the files on disk still hold every
// frame. real components: RunWorld, the bundled default world, the run's dispatcher.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>

#include "common/temp_dir.h"
#include "penumbra/command/command_dispatcher.h"
#include "penumbra/command/run_bridge.h"
#include "penumbra/run/runner.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// what the live-view probe saw (outlives the bridge, which ends with the run)
struct LiveViewProbeLog {
  std::mutex mu;
  int frames = 0;
  int max_pending = 0;  // frames captured and not yet delivered, at each delivery
  std::set<int64_t> indices;
  bool command_applied = false;
  double command_time_sec = -1;
  int64_t command_step = -1;
  double first_after_time_sec = -1;  // the first frame delivered after the command applied
  int64_t first_after_step = -1;
  std::string error;
};

// a live view stand-in: counts the frames captured (its Wants runs at every step, the camera
// fires at every step) against the frames delivered, and sends one teleop twist from the render
// thread after `twist_after` frames, as a page's key press would arrive mid-render
class LiveViewProbe : public RunBridge {
 public:
  LiveViewProbe(const RunBridgeContext& ctx, LiveViewProbeLog* log, int twist_after)
      : dispatcher_(ctx.dispatcher), log_(log), twist_after_(twist_after) {}

  SnapshotContent Wants(int64_t step, double) override {
    last_step_.store(step);
    return SnapshotContent::kNone;
  }

  void OnCameraFrame(const std::shared_ptr<const CameraFrame>& frame) override {
    bool send = false;
    {
      std::lock_guard<std::mutex> lock(log_->mu);
      ++log_->frames;
      log_->indices.insert(frame->index);
      const int pending = static_cast<int>(last_step_.load() - frame->step + 1);
      log_->max_pending = std::max(log_->max_pending, pending);
      if (log_->command_applied && log_->first_after_step < 0) {
        log_->first_after_step = frame->step;
        log_->first_after_time_sec = frame->time_sec;
      }
      send = log_->frames == twist_after_;
    }
    if (!send) return;
    dispatcher_.Dispatch({{"cmd", "twist"}, {"id", 1}, {"vx", 0.3}}, [this](nlohmann::json r) {
      std::lock_guard<std::mutex> lock(log_->mu);
      if (!r.value("ok", false)) {
        log_->error = r.dump();
        return;
      }
      log_->command_applied = true;
      log_->command_step = r.value("step", int64_t{-1});
      log_->command_time_sec = r.value("time_sec", -1.0);
    });
  }

 private:
  CommandDispatcher& dispatcher_;
  LiveViewProbeLog* log_;
  int twist_after_;
  std::atomic<int64_t> last_step_{-1};
};

TEST(LiveViewLatencyTest, ATeleopCommandShowsOnTheNextRenderedFrameAndFilesKeepEveryFrame) {
  testing::TempDir tmp;
  WorldConfig world = LoadWorldFile(fs::path(PENUMBRA_SOURCE_DIR) / "worlds" / "default.yaml");
  ASSERT_EQ(world.cameras.size(), 1u);
  // rgb only at 160 x 120, one frame per 0.002 s physics step: the render is far slower than
  // the steps it should keep up with
  world.cameras[0].width = 160;
  world.cameras[0].height = 120;
  world.cameras[0].outputs = CameraOutputs{};
  // the ideal camera: a frame is due at its capture step (a real profile's exposure and readout
  // would hold each frame back until its span ended)
  world.cameras[0].sensor = CameraSensorConfig();
  ASSERT_EQ(world.timestep_sec.value_or(0), 0.002);
  world.cameras[0].rate_hz = 500;
  world.sensors.clear();
  LiveViewProbeLog log;
  RunOptions options;
  options.out_dir = (tmp.path() / "run").string();
  options.progress = false;
  options.realtime = true;
  options.duration_sec = 0.1;  // 51 frames, steps 0..50
  options.bridges.push_back([&log](const RunBridgeContext& ctx) -> std::unique_ptr<RunBridge> {
    return std::make_unique<LiveViewProbe>(ctx, &log, 15);
  });
  const RunSummary summary = RunWorld(world, options);

  ASSERT_EQ(log.error, "");
  ASSERT_TRUE(log.command_applied);
  ASSERT_GE(log.first_after_step, 0) << "no frame after the twist";
  // the live view never has a stale frame behind the one it is given
  EXPECT_LE(log.max_pending, 1);
  // the first frame after the twist was captured at or after the step it applied at
  EXPECT_GE(log.first_after_step, log.command_step);
  EXPECT_GE(log.first_after_time_sec, log.command_time_sec - 1e-12);
  // every frame was delivered and written
  EXPECT_EQ(summary.physics_steps, 50);
  EXPECT_EQ(log.frames, 51);
  ASSERT_EQ(log.indices.size(), 51u);
  EXPECT_EQ(*log.indices.begin(), 0);
  EXPECT_EQ(*log.indices.rbegin(), 50);
  EXPECT_EQ(summary.frames_per_camera.at("front"), 51);
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(tmp.path() / "run" / "front" / "rgb"))
    pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, 51);
}

}  // namespace
}  // namespace penumbra
