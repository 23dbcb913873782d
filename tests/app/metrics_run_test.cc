// `penumbra run` with a world-file `metrics:` section: the metrics sink is part of the run,
// its summaries are the last key of run.json, and a run without the section is unchanged.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "penumbra/app/runner.h"
#include "penumbra/core/error.h"
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
  fs::path dir_;
};

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
