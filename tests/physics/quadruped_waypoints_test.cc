// trot_gait in waypoint mode on the bundled quadruped (worlds/models/quadruped.xml): it walks
// a square of waypoints with the pure-pursuit law shared with waypoint_follower, and the
// command sources keep their precedence (programmatic > waypoints > script).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "quadruped_test_util.h"

namespace penumbra {
namespace {

using namespace quadruped_test;

constexpr double kToleranceM = 0.15;

// trot_gait config with waypoints (and optional extra keys, e.g. a script)
std::string WaypointConfig(const std::string& waypoints, bool loop, const std::string& extra = "") {
  return "base_body: trunk\n" + LegsYaml() + "waypoints: " + waypoints +
         "\nloop: " + (loop ? "true" : "false") +
         "\nspeed_m_s: 0.5\nmax_yaw_rate_deg_s: 60\ntolerance_m: " + std::to_string(kToleranceM) +
         "\n" + extra;
}

// a 1.5 m square counter-clockwise from the start (origin, heading +x): each waypoint is
// reached in order, within the tolerance, in bounded time; the trunk never touches the
// ground; after the last one the (script-less) robot trots in place there. pure pursuit with
// the waypoint as goal point takes a 90 deg corner (goal 1.5 m away, 90 deg off the
// heading) on the arc of radius 1.5 / (2 sin 90 deg) = 0.75 m through the goal, which bulges
// up to 0.75 m outside the square; a goal behind (> 90 deg) is turned to in place.
TEST(QuadrupedWaypoints, WalksASquareReachingEveryWaypoint) {
  const std::vector<Eigen::Vector2d> wps = {{1.5, 0}, {1.5, 1.5}, {0, 1.5}, {0, 0}};
  Rig rig = MakeRig("quadruped", Ground::kFlat,
                    WaypointConfig("[[1.5, 0], [1.5, 1.5], [0, 1.5], [0, 0]]", false));
  ASSERT_NE(rig.gait->route(), nullptr);
  size_t next = 0;  // next waypoint the trunk has to come within tolerance of
  std::vector<double> reached_at;
  double finished_at = -1, path_m = 0, max_speed = 0;
  Eigen::Vector2d last = Trunk(rig).translation().head<2>();
  Eigen::Vector2d lo = last, hi = last;
  WorldSnapshot snap;
  while (rig.sim.time() < 30.0 - 1e-9) {
    rig.sim.Step();
    rig.sim.Snapshot(&snap);
    const Eigen::Vector2d p = snap.X_WB[rig.trunk].translation().head<2>();
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    // path length sampled every 0.1 s (without the trot's sway within each stride)
    if (rig.sim.step_count() % 50 == 0) {
      path_m += (p - last).norm();
      last = p;
    }
    max_speed = std::max(max_speed, rig.gait->command().vx);
    if (next < wps.size() && (p - wps[next]).norm() < kToleranceM) {
      reached_at.push_back(rig.sim.time());
      ++next;
    }
    if (rig.gait->route()->finished() && finished_at < 0) finished_at = rig.sim.time();
    if (finished_at >= 0 && rig.sim.time() > finished_at + 2.0) break;
  }
  std::printf("[ measured ] square: waypoints reached at");
  for (double t : reached_at) std::printf(" %.2f", t);
  std::printf(" s; path %.2f m (trunk origin); x in [%.2f, %.2f], y in [%.2f, %.2f] m\n", path_m,
              lo.x(), hi.x(), lo.y(), hi.y());
  ASSERT_EQ(reached_at.size(), wps.size()) << "reached " << reached_at.size() << " waypoints";
  EXPECT_EQ(rig.gait->route()->reached(), 4);
  EXPECT_TRUE(rig.gait->route()->finished());
  EXPECT_LE(max_speed, 0.5);
  // about 7.5 m of edges and arcs at 0.5 m/s (15 s) and one turn in place: within 20 s
  EXPECT_LT(reached_at.back(), 20.0);
  EXPECT_GT(path_m, 6.0);
  EXPECT_LT(path_m, 8.5);
  // within the square grown by the arcs' bulge (0.75 m) and the trot's sway
  EXPECT_GT(lo.x(), -0.8);
  EXPECT_GT(lo.y(), -0.8);
  EXPECT_LT(hi.x(), 1.5 + 0.8);
  EXPECT_LT(hi.y(), 1.5 + 0.8);
  // after the route the command is the (empty) script's zero: it trots in place near the
  // last waypoint
  EXPECT_EQ(rig.gait->command().vx, 0.0);
  EXPECT_EQ(rig.gait->command().yaw_rate, 0.0);
  const Eigen::Vector2d p_end = Trunk(rig).translation().head<2>();
  EXPECT_LT(p_end.norm(), 0.3) << p_end.transpose();
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0)
      << "trunk touched at t = " << rig.probe->first_trunk_touch_sec;
  EXPECT_GT(rig.probe->min_up_z, 0.95);
}

// looping: the route starts again after the last waypoint.
TEST(QuadrupedWaypoints, LoopKeepsGoing) {
  Rig rig = MakeRig("quadruped", Ground::kFlat, WaypointConfig("[[1.0, 0], [0, 0]]", true));
  RunUntil(&rig, 12.0);
  std::printf("[ measured ] loop of 2 waypoints 1 m apart: %lld reached in 12 s\n",
              static_cast<long long>(rig.gait->route()->reached()));
  EXPECT_FALSE(rig.gait->route()->finished());
  // 2 s per leg and a 3 s turn in place at each end: the first waypoint again by 12 s
  EXPECT_GE(rig.gait->route()->reached(), 3);
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
}

// two runs in waypoint mode are bit-identical at every step.
TEST(QuadrupedWaypoints, TwoRunsAreBitIdentical) {
  const std::string cfg = WaypointConfig("[[0.6, 0.4], [0, 0.8]]", true);
  Rig a = MakeRig("quadruped", Ground::kFlat, cfg);
  Rig b = MakeRig("quadruped", Ground::kFlat, cfg);
  ASSERT_TRUE(StepInLockstep(a.sim, b.sim, 1500));
  EXPECT_GT(std::hypot(a.sim.qpos()[0], a.sim.qpos()[1]), 0.5);  // and it did walk
}

// precedence: SetCommand overrides the waypoints (the route pauses) until cleared; the
// script applies only once a non-looping route is finished.
TEST(QuadrupedWaypoints, CommandSourcesKeepTheirPrecedence) {
  // the script says turn left; the route says walk straight to (1, 0) first
  Rig rig = MakeRig("quadruped", Ground::kFlat,
                    WaypointConfig("[[1.0, 0]]", false, "commands: [{t: 0, yaw_rate: 0.5}]\n"));
  RunUntil(&rig, 1.0);
  EXPECT_EQ(rig.gait->command().vx, 0.5);  // waypoints beat the script
  EXPECT_NEAR(rig.gait->command().yaw_rate, 0.0, 0.05);
  // programmatic beats waypoints: walk backwards for 2 s, the route pauses (slewing from
  // +0.5 to -0.3 m/s takes 0.53 s: about -0.39 m in all)
  rig.gait->SetTwist({-0.3, 0, 0});
  const double x1 = Trunk(rig).translation().x();
  RunUntil(&rig, 3.0);
  EXPECT_EQ(rig.gait->command().vx, -0.3);
  std::printf("[ measured ] precedence: %.3f m in 2 s of vx = -0.3 m/s\n",
              Trunk(rig).translation().x() - x1);
  EXPECT_LT(Trunk(rig).translation().x(), x1 - 0.25);
  EXPECT_EQ(rig.gait->route()->reached(), 0);
  // cleared: the route resumes and finishes, then the script turns the robot in place
  rig.gait->ClearTwist();
  while (!rig.gait->route()->finished() && rig.sim.time() < 10.0) rig.sim.Step();
  ASSERT_TRUE(rig.gait->route()->finished());
  const double t_done = rig.sim.time();
  const Pose X_done = Trunk(rig);
  std::printf("[ measured ] precedence: route to (1, 0) finished at %.2f s at (%.3f, %.3f)\n",
              t_done, X_done.translation().x(), X_done.translation().y());
  RunUntil(&rig, t_done + 3.0);
  EXPECT_EQ(rig.gait->command().yaw_rate, 0.5);
  EXPECT_EQ(rig.gait->command().vx, 0.0);
  const double turned = Yaw(Trunk(rig)) - Yaw(X_done);
  EXPECT_GT(turned, 0.8);  // about 1.5 rad less the slew-limited start
  EXPECT_EQ(rig.probe->max_trunk_touch_n, 0.0);
}

// route keys without waypoints, or bad waypoints, fail at load naming the key.
TEST(QuadrupedWaypoints, BadWaypointConfigFailsNamingTheKey) {
  auto error_of = [](const std::string& yaml) -> std::string {
    try {
      MakeController(ControllerConfig{"trot_gait", ParseYaml(yaml), 4}, "", "world.yaml");
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string base = "base_body: trunk\n" + LegsYaml();
  std::string m = error_of(base + "speed_m_s: 0.4\n");
  EXPECT_NE(m.find("world.yaml:4"), std::string::npos) << m;
  EXPECT_NE(m.find("speed_m_s"), std::string::npos) << m;
  EXPECT_NE(m.find("waypoint mode"), std::string::npos) << m;
  m = error_of(base + "waypoints: []\n");
  EXPECT_NE(m.find("waypoints"), std::string::npos) << m;
  m = error_of(base + "waypoints: [[1, 2, 3]]\n");
  EXPECT_NE(m.find("waypoints"), std::string::npos) << m;
  m = error_of(base + "waypoints: [[1, 2]]\ntolerance_m: 0\n");
  EXPECT_NE(m.find("tolerance_m"), std::string::npos) << m;
  m = error_of(base + "waypoints: [[1, 2]]\nmax_yaw_rate_deg_s: -5\n");
  EXPECT_NE(m.find("max_yaw_rate_deg_s"), std::string::npos) << m;
}

}  // namespace
}  // namespace penumbra
