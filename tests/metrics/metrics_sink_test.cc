// MetricsSink: a scripted collision (the rover driven into a wall) counted through the whole
// pipeline, CSV columns and units, run.json summaries, kinematic mode, and name errors.
#include "penumbra/metrics/metrics_sink.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string ReadText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string line; std::getline(s, line);) out.push_back(line);
  return out;
}

// a floor and a wall whose face is at x = 1.15 m; the rover (worlds/models/rover.xml, bumper
// 0.184 m ahead of its origin) starts at the origin heading +x and is steered at 0.5 m/s to a
// waypoint behind the wall, so it drives into the wall and keeps pushing against it
constexpr const char* kArena = R"(<mujoco model="arena">
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <geom name="wall" type="box" pos="1.2 0 0.25" size="0.05 1 0.25"/>
  </worldbody>
</mujoco>)";

std::string CollisionWorld(const std::string& extra_metrics = "") {
  return std::string(R"(seed: 1
duration_sec: 4
physics: {timestep_sec: 0.002}
mjcf_cameras: {enabled: false}
robots:
  - name: rover
    file: )") +
         PENUMBRA_SOURCE_DIR + R"(/worlds/models/rover.xml
    controller:
      type: waypoint_follower
      base_body: chassis
      left_actuator: left_wheel
      right_actuator: right_wheel
      wheel_radius_m: 0.05
      track_width_m: 0.3
      speed_m_s: 0.5
      waypoints: [[3.0, 0.0]]
      loop: false
models:
  - {name: arena, file: arena.xml}
metrics:
  rate_hz: 20
  series:
    - name: bumps
      type: contacts
      min_force_N: 1
      debounce_sec: 0.2
      exclude: [{a: "rover/*", b: "arena/floor"}]
    - {name: all_contacts, type: contacts, min_force_N: 1, debounce_sec: 0.2}
    - {name: chassis, type: body_pose, bodies: [rover/chassis]}
    - {name: twist, type: body_twist, bodies: [rover/chassis]}
    - {name: wheels, type: joint_torque, joints: ["rover/*_wheel"]}
    - {name: wheel_q, type: joint_position, joints: ["rover/left_wheel"], rate_hz: 10}
    - {name: wall, type: distance, body: rover/chassis, to_point: [1.15, 0, 0]}
    - {name: track, type: tracking_error, robot: rover}
    - {name: wheel_speed, type: sensor, sensors: ["rover/*_vel"]}
)" + extra_metrics;
}

// runs `world_text` (in `dir`) for its duration with one metrics sink in `mode`
std::string RunMetrics(const testing::TempDir& dir, const std::string& world_text,
                       const std::string& out, MetricsMode mode, bool controllers = true) {
  std::ofstream(dir.path() / "arena.xml") << kArena;
  const WorldConfig world = ParseWorld(world_text, (dir.path() / "world.yaml").string());
  SessionOptions options;
  options.build_renderer = false;
  options.add_controllers = controllers;
  Session session(world, options);
  std::unique_ptr<MetricsSink> sink =
      MakeMetricsSink(world, session.sim(), (dir.path() / out).string(), mode);
  EXPECT_TRUE(sink);
  PhysicsSource source(&session.sim());
  const LoopFinish f = testing::RunLoop(&source, {sink.get()}, world.duration_sec);
  EXPECT_FALSE(f.error);
  return sink->SummaryJson();
}

TEST(MetricsSinkTest, RoverDrivenIntoAWallIsOneCollisionAndTheFloorIsExcluded) {
  testing::TempDir dir;
  const json j = json::parse(RunMetrics(dir, CollisionWorld(), "out", MetricsMode::kDynamics));
  // exactly one collision episode, with the wall, none with the floor (excluded by rule)
  const json& bumps = j.at("bumps");
  EXPECT_EQ(bumps.at("collisions"), 1) << bumps.dump(2);
  EXPECT_EQ(bumps.at("collisions_by_pair"), json({{"rover/chassis | arena/wall", 1}}));
  EXPECT_GT(bumps.at("peak_force_N").get<double>(), 1.0);
  // without the rule the wheels and the caster on the floor count too (from the first step)
  const json& all = j.at("all_contacts");
  EXPECT_EQ(all.at("collisions_by_pair").at("rover/chassis | arena/wall"), 1) << all.dump(2);
  EXPECT_EQ(all.at("collisions_by_pair").at("rover/left_wheel | arena/floor"), 1);
  EXPECT_EQ(all.at("collisions_by_pair").at("rover/right_wheel | arena/floor"), 1);
  EXPECT_GE(all.at("collisions").get<int>(), 3);

  // the episode file: one row, the hit between 1.5 s and 3 s, lasting to the end
  const fs::path metrics = dir.path() / "out" / "metrics";
  const std::vector<std::string> episodes = Lines(ReadText(metrics / "bumps_episodes.csv"));
  ASSERT_EQ(episodes.size(), 2u) << ReadText(metrics / "bumps_episodes.csv");
  EXPECT_EQ(episodes[0],
            "episode,a,b,start_sec,end_sec,peak_force_N,a_speed_toward_b_m_s,"
            "b_speed_toward_a_m_s");
  double start = 0, end = 0, peak = 0, rover_speed = 0, wall_speed = 0;
  ASSERT_EQ(std::sscanf(episodes[1].c_str(), "1,rover/chassis,arena/wall,%lf,%lf,%lf,%lf,%lf",
                        &start, &end, &peak, &rover_speed, &wall_speed),
            5)
      << episodes[1];
  // the rover drove into the wall at up to its 0.5 m/s (averaged over the 0.05 s between the
  // 20 Hz detections, which holds the impact: measured 0.375 m/s); the wall stands
  EXPECT_GT(rover_speed, 0.25) << episodes[1];
  EXPECT_LE(rover_speed, 0.55) << episodes[1];
  EXPECT_EQ(wall_speed, 0);
  EXPECT_GT(start, 1.5);
  EXPECT_LT(start, 3.0);
  EXPECT_NEAR(end, 4.0, 0.01) << "pushed against the wall to the end";

  // rows at 20 Hz from t = 0 (81 rows in 4 s), columns with units
  const std::vector<std::string> rows = Lines(ReadText(metrics / "bumps.csv"));
  ASSERT_EQ(rows.size(), 82u);
  EXPECT_EQ(rows[0],
            "step,time_sec,contacts,pairs_in_collision,normal_force_N,max_pair_force_N,"
            "collisions");
  EXPECT_EQ(rows[1].substr(0, 4), "0,0,");
  EXPECT_EQ(rows.back().substr(rows.back().rfind(',') + 1), "1");
  EXPECT_EQ(Lines(ReadText(metrics / "chassis.csv"))[0],
            "step,time_sec,rover/chassis_x_m,rover/chassis_y_m,rover/chassis_z_m,"
            "rover/chassis_qw,rover/chassis_qx,rover/chassis_qy,rover/chassis_qz");
  EXPECT_EQ(Lines(ReadText(metrics / "wheels.csv"))[0],
            "step,time_sec,rover/left_wheel_N_m,rover/right_wheel_N_m");
  EXPECT_EQ(Lines(ReadText(metrics / "wheel_q.csv")).size(), 42u) << "10 Hz: 41 rows";
  EXPECT_EQ(Lines(ReadText(metrics / "track.csv"))[0],
            "step,time_sec,rover/cross_track_m,rover/goal_distance_m");
  EXPECT_EQ(Lines(ReadText(metrics / "wheel_speed.csv"))[0],
            "step,time_sec,rover/left_wheel_vel_rad_s,rover/right_wheel_vel_rad_s");

  // summaries: the chassis stops at the wall (bumper at 1.15 m: origin near 0.97 m)
  const json& x = j.at("chassis").at("columns").at("rover/chassis_x_m");
  EXPECT_NEAR(x.at("min").get<double>(), 0.0, 0.01);
  EXPECT_NEAR(x.at("max").get<double>(), 1.15 - 0.184, 0.02);
  EXPECT_EQ(j.at("chassis").at("rows"), 81);
  EXPECT_EQ(j.at("chassis").at("file"), "metrics/chassis.csv");
  EXPECT_NEAR(j.at("wall").at("final_distance_m").get<double>(), 0.184, 0.02);
  // the wheels push: positive drive torque at the end of the run
  EXPECT_GT(j.at("wheels").at("columns").at("rover/left_wheel_N_m").at("max").get<double>(), 0.01);
  // the path runs along y = 0: cross-track error stays small
  EXPECT_LT(j.at("track").at("columns").at("rover/cross_track_m").at("max").get<double>(), 0.05);
}

TEST(MetricsSinkTest, KinematicModeRecordsPosesAndTwistsFromTheStateAlone) {
  testing::TempDir dir;
  const json dyn = json::parse(RunMetrics(dir, CollisionWorld(), "dyn", MetricsMode::kDynamics));
  const json kin = json::parse(RunMetrics(dir, CollisionWorld(), "kin", MetricsMode::kKinematic));
  for (const char* name : {"bumps", "all_contacts", "wheels", "track", "wheel_speed"}) {
    EXPECT_TRUE(kin.at(name).contains("unavailable")) << name;
    EXPECT_FALSE(fs::exists(dir.path() / "kin" / "metrics" / (std::string(name) + ".csv")));
  }
  // poses, joints and distances: the same files; twists from qvel equal MuJoCo's V_WB
  for (const char* name : {"chassis", "wheel_q", "wall"})
    EXPECT_EQ(ReadText(dir.path() / "kin" / "metrics" / (std::string(name) + ".csv")),
              ReadText(dir.path() / "dyn" / "metrics" / (std::string(name) + ".csv")))
        << name;
  const std::vector<std::string> a = Lines(ReadText(dir.path() / "kin/metrics/twist.csv"));
  const std::vector<std::string> b = Lines(ReadText(dir.path() / "dyn/metrics/twist.csv"));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), 82u);
  for (size_t r = 1; r < a.size(); ++r) {
    std::stringstream sa(a[r]), sb(b[r]);
    for (std::string va, vb; std::getline(sa, va, ',') && std::getline(sb, vb, ',');)
      EXPECT_NEAR(std::stod(va), std::stod(vb), 1e-6) << "row " << r;
  }
  EXPECT_EQ(kin.at("twist").at("columns").size(), 6u);
  EXPECT_EQ(dyn.at("chassis"), kin.at("chassis"));
}

TEST(MetricsSinkTest, WithoutControllersTheTrackingErrorIsUnavailable) {
  // a replay runs no controllers: the rover stands still, its contacts are still counted
  testing::TempDir dir;
  const json j = json::parse(
      RunMetrics(dir, CollisionWorld(), "out", MetricsMode::kDynamics, /*controllers=*/false));
  EXPECT_EQ(j.at("track").at("unavailable"),
            "the simulation runs no controllers (a replay without them)");
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "metrics" / "track.csv"));
  EXPECT_EQ(j.at("bumps").at("collisions"), 0);
  EXPECT_NEAR(j.at("wall").at("final_distance_m").get<double>(), 1.15, 0.01) << "stood still";
}

TEST(MetricsSinkTest, NamesThatMatchNothingAreConfigErrorsWithTheirLine) {
  testing::TempDir dir;
  std::ofstream(dir.path() / "arena.xml") << kArena;
  const std::string text = CollisionWorld(
      "    - {name: legs, type: joint_velocity, joints: "
      "[rover/left_wheel, \"go1/*\"]}\n");
  const WorldConfig world = ParseWorld(text, (dir.path() / "world.yaml").string());
  SessionOptions options;
  options.build_renderer = false;
  Session session(world, options);
  try {
    MakeMetricsSink(world, session.sim(), (dir.path() / "out").string(), MetricsMode::kDynamics);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "metrics.series[9].joints[1]");
    EXPECT_NE(e.problem().find("no joint matches 'go1/*'"), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find("rover/left_wheel"), std::string::npos) << "names some that exist";
    const ConfigError located = LocateInWorld(world, e);
    EXPECT_EQ(located.line(), 36) << located.what();
  }
  // a robot without a controller reporting a tracking error, and an unknown body
  const auto error_of = [&](const std::string& entry) -> std::string {
    const WorldConfig w = ParseWorld(CollisionWorld(entry), (dir.path() / "world.yaml").string());
    try {
      MakeMetricsSink(w, session.sim(), (dir.path() / "out").string(), MetricsMode::kDynamics);
    } catch (const ConfigError& e) {
      return e.key() + ": " + e.problem();
    }
    return "";
  };
  EXPECT_NE(error_of("    - {name: t2, type: tracking_error, robot: arena}\n")
                .find("metrics.series[9].robot: no robot 'arena' with a controller"),
            std::string::npos);
  EXPECT_NE(error_of("    - {name: d2, type: distance, body: rover/chasis, to_body: world}\n")
                .find("metrics.series[9].body: no body named 'rover/chasis'"),
            std::string::npos);
}

}  // namespace
}  // namespace penumbra
