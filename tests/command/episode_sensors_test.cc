// `reset` restarts the sensors with the episode: their schedules on the episode's clock and
// their noise streams keyed by the sample index within the episode (the IMU's bias from the
// start of its stream), so the same actions after a reset give the first episode's IMU,
// MuJoCo sensor and LiDAR samples bit for bit, while the written sample indices go on
// increasing; and the cameras the first episode's images.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "command/live_loop.h"
#include "common/temp_dir.h"
#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/sinks/run/run_outputs.h"
#include "penumbra/sinks/sensor_sink.h"

namespace penumbra {
namespace episode_sensors_test {
namespace {

using json = nlohmann::json;
using penumbra::testing::LiveLoop;

struct Case {
  std::string name;
  std::string file;   // bundled world, relative to worlds/
  std::string robot;  // its robot's name
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// the bundled world with model paths made absolute, plus a noisy IMU and noisy MuJoCo sensors
std::string WorldWithSensors(const Case& c) {
  std::ifstream in(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + c.file);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string models = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/";
  for (const std::string key : {"file: models/", "model: models/"}) {
    for (size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + 1))
      text.replace(at + key.size() - 7, 7, models);
  }
  return text +
         "\nsensors:\n"
         "  - {name: imu, type: imu, body: " +
         c.robot +
         "/trunk, preset: consumer_mems, rate_hz: 200}\n"
         "  - {name: joints, type: mujoco, rate_hz: 100, noise: {stddev: 0.01}}\n"
         "  - {name: top, type: lidar, preset: velodyne_vlp16, columns: 90, body: " +
         c.robot +
         "/trunk, pose: {xyz: [0.1, 0, 0.15], rpy_deg: [0, 0, 0]},\n"
         "     noise: {range_stddev_m: 0.01, dropout_probability: 0.05}}\n";
}

// a sample as kept by the test: values as raw doubles
struct Kept {
  int64_t index = 0, step = 0;
  std::vector<double> values;
};

// `steps` single steps with a twist at a third and two thirds
void Episode(LiveLoop& live, int steps, int variant = 0) {
  for (int k = 0; k < steps; ++k) {
    if (k == steps / 3 || k == 2 * steps / 3) {
      const double sign = (k == steps / 3 ? 1.0 : -1.0) * (variant == 0 ? 1.0 : -0.5);
      live.CallOk({{"cmd", "twist"}, {"vx", 0.3 * std::abs(sign)}, {"yaw_rate", 0.4 * sign}});
    }
    live.CallOk({{"cmd", "step"}, {"n", 1}});
  }
}

// the samples of `sensor` with steps in (start, start + steps] (from step 0 for the first
// episode), keyed by the step within the episode
std::map<int64_t, Kept> EpisodeSamples(const std::vector<std::pair<std::string, Kept>>& all,
                                       const std::string& sensor, int64_t start, int steps) {
  std::map<int64_t, Kept> out;
  for (const auto& [name, k] : all)
    if (name == sensor && k.step >= start && (start == 0 || k.step > start) &&
        k.step <= start + steps)
      out[k.step - start] = k;
  return out;
}

class EpisodeSensorsTest : public ::testing::TestWithParam<Case> {};

TEST_P(EpisodeSensorsTest, SameActionsAfterResetGiveTheFirstEpisodesSamplesBitForBit) {
  const Case& c = GetParam();
  penumbra::testing::TempDir dir;
  const std::string world = dir.Write("world.yaml", WorldWithSensors(c));
  std::mutex mu;
  std::vector<std::pair<std::string, Kept>> samples;
  std::unique_ptr<SensorSink> sensors;
  const int steps = 120;
  std::vector<int64_t> starts = {0};
  {
    LiveLoop live(world, 1000.0, [&](Session& session, SimLoop& loop) {
      sensors = std::make_unique<SensorSink>(session.world(), session.sim(), session.scene(),
                                             dir.path().string());
      sensors->set_on_sample([&](const SensorSample& s) {
        std::lock_guard<std::mutex> lock(mu);
        Kept k{s.index, s.step, s.values};
        // a scan as its points' values (x, y, z, intensity, time, beam)
        if (s.scan)
          for (const LidarPoint& p : s.scan->points)
            k.values.insert(k.values.end(),
                            {p.x, p.y, p.z, p.intensity, p.time, static_cast<double>(p.beam)});
        samples.push_back({s.sensor, std::move(k)});
      });
      loop.AddSink(sensors.get());
    });
    Episode(live, steps);
    for (int before : {37, 61}) {
      Episode(live, before, 1);
      const json r = live.CallOk({{"cmd", "reset"}});
      starts.push_back(r.at("step").get<int64_t>());
      Episode(live, steps);
    }
    live.Stop();
  }
  for (const std::string sensor : {"imu", "joints"}) {
    // written indices increase over the whole run, episodes and resets included
    int64_t last = -1;
    int n = 0;
    for (const auto& [name, k] : samples) {
      if (name != sensor) continue;
      EXPECT_GT(k.index, last) << sensor << " at step " << k.step;
      last = k.index;
      ++n;
    }
    EXPECT_GT(n, 3 * steps / 5) << sensor;
    const std::map<int64_t, Kept> first = EpisodeSamples(samples, sensor, 0, steps);
    for (size_t e = 1; e < starts.size(); ++e) {
      const std::map<int64_t, Kept> again = EpisodeSamples(samples, sensor, starts[e], steps);
      // the step of the reset shows the state before it: an episode after a reset samples
      // from its first step on
      EXPECT_EQ(again.size() + 1, first.size()) << sensor << " episode " << e;
      int compared = 0;
      for (const auto& [j, k] : again) {
        ASSERT_TRUE(first.count(j)) << sensor << ": episode " << e << " sampled at its step " << j
                                    << ", the first episode did not";
        const Kept& f = first.at(j);
        ASSERT_EQ(k.values.size(), f.values.size());
        EXPECT_EQ(std::memcmp(k.values.data(), f.values.data(), k.values.size() * sizeof(double)),
                  0)
            << sensor << ": episode " << e << " (reset at step " << starts[e]
            << ") differs from the first at its step " << j;
        ++compared;
      }
      EXPECT_GE(compared, steps / 6);
    }
  }
  // a scan covers the time to the next one (traced with the robot's motion up to it): the
  // scans that end inside an episode are the same in every episode (noise and dropouts keyed
  // by the scan's index within it); the one open at a reset is not written
  const int scan_steps = 50;  // 10 Hz at 2 ms steps
  const std::map<int64_t, Kept> first = EpisodeSamples(samples, "top", 0, steps);
  ASSERT_TRUE(first.count(scan_steps));
  EXPECT_GT(first.at(scan_steps).values.size(), 100u);
  int64_t last = -1;
  for (const auto& [name, k] : samples) {
    if (name != "top") continue;
    EXPECT_GT(k.index, last) << "scan at step " << k.step;
    last = k.index;
  }
  for (size_t e = 1; e < starts.size(); ++e) {
    const std::map<int64_t, Kept> again = EpisodeSamples(samples, "top", starts[e], steps);
    int compared = 0;
    for (const auto& [j, k] : again) {
      if (j + scan_steps > steps) continue;
      ASSERT_TRUE(first.count(j)) << "episode " << e << " scanned at its step " << j;
      EXPECT_TRUE(k.values == first.at(j).values)
          << "the scan of episode " << e << " at its step " << j << " differs from the first's";
      ++compared;
    }
    EXPECT_EQ(compared, 1) << "episode " << e;
  }
}

// the cameras of worlds/quadruped.yaml (a RealSense D435 colour imager on the robot, a Blackfly
// S on the world: profile noise, fixed pattern and auto exposure) at a quarter of their size
TEST(EpisodeCamerasTest, SameActionsAfterResetGiveTheFirstEpisodesImagesBitForBit) {
  const Case c{"trot_gait", "quadruped.yaml", "quadruped"};
  std::string text = WorldWithSensors(c);
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"width: 640\n    height: 480",
                                                                     "width: 160\n    height: 120"},
                                 {"width: 800\n    height: 450", "width: 200\n    height: 113"}}) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  penumbra::testing::TempDir dir;
  const std::string world = dir.Write("world.yaml", text);
  struct Frame {
    std::string camera;
    int64_t index = 0, step = 0;
    std::vector<uint8_t> rgb;
  };
  std::mutex mu;
  std::vector<Frame> frames;
  std::unique_ptr<RunOutputs> outputs;
  const int steps = 120;  // 0.24 s: frames at 0, 0.1 and 0.2 s of each episode
  std::vector<int64_t> starts = {0};
  {
    LiveLoop live(
        world, 1000.0,
        [&](Session& session, SimLoop& loop) {
          // the outputs of `penumbra run` (their cameras follow the simulation's episodes)
          outputs = std::make_unique<RunOutputs>(session, session.world(), dir.path() / "out",
                                                 RunOutputsOptions{});
          outputs->cameras().set_on_frame([&](const std::shared_ptr<const CameraFrame>& f) {
            std::lock_guard<std::mutex> lock(mu);
            frames.push_back({f->camera, f->index, f->step, f->rgb.data});
          });
          outputs->AddTo(&loop);
        },
        true);
    Episode(live, steps);
    for (int before : {37, 61}) {
      Episode(live, before, 1);
      const json r = live.CallOk({{"cmd", "reset"}});
      starts.push_back(r.at("step").get<int64_t>());
      Episode(live, steps);
    }
    // steps beyond the last episode: its last exposure ends before the run does
    Episode(live, 40, 1);
    live.Stop();
  }
  for (const std::string camera : {"front", "side"}) {
    std::map<int64_t, const Frame*> first;
    int64_t last = -1;
    for (const Frame& f : frames) {
      if (f.camera != camera) continue;
      EXPECT_GT(f.index, last) << camera << " at step " << f.step;  // indices go on
      last = f.index;
      if (f.step <= steps) first[f.step] = &f;
    }
    ASSERT_EQ(first.size(), 3u) << camera;
    // the noise is on: two frames of the static side camera differ
    if (camera == "side") EXPECT_NE(first.begin()->second->rgb, first.rbegin()->second->rgb);
    for (size_t e = 1; e < starts.size(); ++e) {
      int compared = 0;
      for (const Frame& f : frames) {
        if (f.camera != camera || f.step <= starts[e] || f.step > starts[e] + steps) continue;
        const int64_t j = f.step - starts[e];
        ASSERT_TRUE(first.count(j)) << camera << ": episode " << e << " rendered at its step " << j
                                    << ", the first episode did not";
        EXPECT_TRUE(f.rgb == first.at(j)->rgb)
            << camera << ": episode " << e << " (reset at step " << starts[e]
            << ") differs from the first at its step " << j;
        ++compared;
      }
      // the frame at the episode's step 0 is not rendered (the reset step shows the episode
      // before it): 0.1 and 0.2 s are
      EXPECT_EQ(compared, 2) << camera << " episode " << e;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Controllers, EpisodeSensorsTest,
                         ::testing::Values(Case{"trot_gait", "quadruped.yaml", "quadruped"},
                                           Case{"policy", "quadruped_policy.yaml", "go1"}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace episode_sensors_test
}  // namespace penumbra
