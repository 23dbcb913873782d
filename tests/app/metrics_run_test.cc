// `penumbra run` with a world-file `metrics:` section: the metrics sink is part of the run,
// its summaries are the last key of run.json, and a run without the section is unchanged.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/replay/kinematic/replay_runner.h"
#include "penumbra/replay/resimulate.h"
#include "penumbra/run/runner.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// a ball dropped onto a floor from 0.5 m
constexpr char kBallMjcf[] = R"(<mujoco model="ball">
  <option timestep="0.005"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="ball" pos="0 0 0.5"><freejoint name="free"/><geom name="ball" type="sphere" size="0.1"/></body>
  </worldbody>
</mujoco>)";

class MetricsRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("penumbra_metrics_run_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "ball.xml") << kBallMjcf;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // lines 1-8 fixed, `metrics` from line 9
  WorldConfig World(const std::string& metrics) {
    std::ofstream(dir_ / "world.yaml")
        << "seed: 3\n"
           "duration_sec: 1\n"
           "models:\n"
           "  - {name: scene, file: ball.xml}\n"
           "lights:\n"
           "  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 20000}\n"
           "cameras:\n"
           "  - {name: cam, pose: {xyz: [-3, 0, 1]}, width: 32, height: 24, rate_hz: 2}\n"
        << metrics;
    return LoadWorldFile((dir_ / "world.yaml").string());
  }
  nlohmann::ordered_json Run(const WorldConfig& world, const std::string& out) {
    RunOptions options;
    options.out_dir = (dir_ / out).string();
    options.progress = false;
    RunWorld(world, options);
    std::ifstream in(dir_ / out / "run.json");
    return nlohmann::ordered_json::parse(in);
  }
  // the run recorded to run.plog, its run.json
  nlohmann::ordered_json RunRecorded(const WorldConfig& world) {
    RunOptions options;
    options.out_dir = (dir_ / "run").string();
    options.progress = false;
    options.record_file = (dir_ / "run.plog").string();
    RunWorld(world, options);
    return Json(dir_ / "run" / "run.json");
  }
  nlohmann::ordered_json Replay(const std::string& out, const std::string& world_override = "") {
    ReplayOptions options;
    options.log_path = (dir_ / "run.plog").string();
    options.out_dir = (dir_ / out).string();
    options.world_override = world_override;
    options.progress = false;
    ReplayLog(options);
    return Json(dir_ / out / "run.json");
  }
  static nlohmann::ordered_json Json(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::ordered_json::parse(in);
  }
  static std::string Read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

constexpr char kBallMetrics[] = R"(metrics:
  series:
    - {name: ball, type: body_pose, bodies: [scene/ball], rate_hz: 10}
    - {name: joints, type: joint_position, joints: [scene/free], rate_hz: 20}
    - {name: height, type: distance, body: scene/ball, to_point: [0, 0, 0]}
    - {name: landing, type: contacts, min_force_N: 0.5}
)";

// a replay records the world's metrics on the logged motion: the kinematic ones as the run
// did, byte for byte; contacts need physics and are listed as unavailable
TEST_F(MetricsRunTest, AReplayRecordsTheKinematicMetricsOfTheRun) {
  const nlohmann::ordered_json run = RunRecorded(World(kBallMetrics));
  ASSERT_EQ(run.at("metrics").at("landing").at("collisions"), 1);
  const nlohmann::ordered_json replay = Replay("replay");
  for (const char* csv : {"ball.csv", "joints.csv", "height.csv"}) {
    const std::string recorded = Read(dir_ / "run" / "metrics" / csv);
    EXPECT_FALSE(recorded.empty()) << csv;
    EXPECT_EQ(Read(dir_ / "replay" / "metrics" / csv), recorded) << csv;
  }
  ASSERT_TRUE(replay.contains("metrics"));
  const nlohmann::ordered_json& m = replay.at("metrics");
  EXPECT_EQ(m.at("ball"), run.at("metrics").at("ball"));
  EXPECT_EQ(m.at("height").at("final_distance_m"),
            run.at("metrics").at("height").at("final_distance_m"));
  EXPECT_EQ(m.at("landing").at("type"), "contacts");
  EXPECT_TRUE(m.at("landing").contains("unavailable")) << m.at("landing").dump();
  EXPECT_FALSE(fs::exists(dir_ / "replay" / "metrics" / "landing.csv"));
  EXPECT_EQ(replay.at("replay").at("mode"), "kinematic");
}

// `metrics` is a key of the replay's --world override: the replay measures something else
TEST_F(MetricsRunTest, AReplayOverrideReplacesTheMetrics) {
  RunRecorded(World(kBallMetrics));
  std::ofstream(dir_ / "override.yaml")
      << "metrics:\n  series:\n    - {name: top, type: distance, body: scene/ball, "
         "to_point: [0, 0, 1]}\n";
  const nlohmann::ordered_json replay = Replay("replay", (dir_ / "override.yaml").string());
  EXPECT_EQ(replay.at("replay").at("override_keys"), nlohmann::ordered_json({"metrics"}));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "replay" / "metrics" / "top.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "replay" / "metrics" / "ball.csv"));
  EXPECT_NEAR(replay.at("metrics").at("top").at("final_distance_m").get<double>(), 0.9, 0.03);

  // an unknown body is the override's, on its line
  std::ofstream(dir_ / "bad.yaml")
      << "sky: {type: uniform}\nmetrics:\n  series:\n    - {name: b, type: body_pose, "
         "bodies: [scene/bal]}\n";
  try {
    Replay("bad", (dir_ / "bad.yaml").string());
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), (dir_ / "bad.yaml").string());
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(e.key(), "metrics.series[0].bodies[0]");
  }
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

// --resimulate --out: physics again, so every metric, contacts included, as the run counted
TEST_F(MetricsRunTest, AResimulationRecordsEveryMetricOfTheRun) {
  const nlohmann::ordered_json run = RunRecorded(World(kBallMetrics));
  ResimulateOptions options;
  options.log_path = (dir_ / "run.plog").string();
  options.out_dir = (dir_ / "resim").string();
  const ResimulateReport report = ResimulateLog(options);
  EXPECT_EQ(report.Describe(), "bit-exact (201 steps)");
  const nlohmann::ordered_json resim = Json(dir_ / "resim" / "run.json");
  const nlohmann::ordered_json& m = resim.at("metrics");
  EXPECT_EQ(m.at("landing").at("collisions"), 1);
  EXPECT_EQ(m.at("landing"), run.at("metrics").at("landing"));
  for (const char* csv :
       {"ball.csv", "joints.csv", "height.csv", "landing.csv", "landing_episodes.csv"})
    EXPECT_EQ(Read(dir_ / "resim" / "metrics" / csv), Read(dir_ / "run" / "metrics" / csv)) << csv;
  EXPECT_EQ(resim.at("replay").at("mode"), "resimulate");
  EXPECT_EQ(resim.at("replay").at("verdict"), "bit-exact (201 steps)");
  EXPECT_EQ(resim.at("replay").at("last_step"), 200);

  // without --out nothing is written
  options.out_dir.clear();
  EXPECT_EQ(ResimulateLog(options).Describe(), "bit-exact (201 steps)");
}

TEST_F(MetricsRunTest, SummariesAreTheLastKeyOfRunJson) {
  const nlohmann::ordered_json j = Run(World(R"(metrics:
  series:
    - {name: ball, type: body_pose, bodies: [scene/ball], rate_hz: 10}
    - {name: height, type: distance, body: scene/ball, to_point: [0, 0, 0]}
    - {name: landing, type: contacts, min_force_N: 0.5}
)"),
                                       "out");
  ASSERT_TRUE(j.contains("metrics"));
  EXPECT_EQ(j.items().begin().key(), "world_file");
  std::string last;
  for (const auto& item : j.items()) last = item.key();
  EXPECT_EQ(last, "metrics");
  const nlohmann::ordered_json& m = j.at("metrics");
  EXPECT_EQ(m.at("ball").at("rows"), 11);
  const nlohmann::ordered_json& z = m.at("ball").at("columns").at("scene/ball_z_m");
  EXPECT_NEAR(z.at("max").get<double>(), 0.5, 1e-9) << "starts at 0.5 m";
  EXPECT_NEAR(z.at("min").get<double>(), 0.1, 0.03) << "lands on the floor (soft contact)";
  EXPECT_NEAR(m.at("height").at("final_distance_m").get<double>(), 0.1, 0.03);
  EXPECT_EQ(m.at("landing").at("collisions"), 1);
  EXPECT_EQ(m.at("landing").at("collisions_by_pair"),
            nlohmann::ordered_json({{"scene/ball | scene/floor", 1}}));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / "metrics" / "ball.csv"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / "metrics" / "landing_episodes.csv"));
}

TEST_F(MetricsRunTest, WithoutTheSectionNothingChanges) {
  const nlohmann::ordered_json j = Run(World(""), "out");
  EXPECT_FALSE(j.contains("metrics"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "metrics"));
}

TEST_F(MetricsRunTest, AnUnknownBodyNamesTheWorldFileLineAndLeavesNoOutputs) {
  const WorldConfig world = World(R"(metrics:
  series:
    - {name: ball, type: body_pose, bodies: [scene/bal]}
)");
  try {
    Run(world, "out");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), (dir_ / "world.yaml").string());
    EXPECT_EQ(e.line(), 11);
    EXPECT_EQ(e.key(), "metrics.series[0].bodies[0]");
    EXPECT_NE(e.problem().find("no body matches 'scene/bal'"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "the refused run leaves no output folder";
}

}  // namespace
}  // namespace penumbra
