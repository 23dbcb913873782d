// the bundled robots' example worlds (docs/robots/*.md) run through their world files, physics
// and controllers only, and do what their pages say: the quadruped and the quadruped with arm
// climb the ramp, stop on the platform and turn 90 degrees; the rover drives its loop through
// the room; the quadrotor flies its square and lands on its pad; the arm carries the cube to the
// marker.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

double DistanceToRouteSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

double TrunkYaw(const Pose& X) { return std::atan2(X.linear()(1, 0), X.linear()(0, 0)); }

// runs worlds/<name>.yaml for its duration without a renderer, calling `each` after every
// step with the pose of `body`; returns that pose at the end.
Pose RunExampleWorld(const std::string& name, const std::string& body,
                     const std::function<void(double, const Pose&)>& each) {
  const WorldConfig world = LoadWorldFile(PENUMBRA_SOURCE_DIR "/worlds/" + name + ".yaml");
  SessionOptions options;
  options.build_renderer = false;
  Session session(world, options);
  Simulation& sim = session.sim();
  const int b = sim.scene().FindBody(body);
  EXPECT_GE(b, 0) << body;
  WorldSnapshot snap;
  while (sim.time() < world.duration_sec - 1e-9) {
    sim.Step();
    sim.Snapshot(&snap);
    each(sim.time(), snap.X_WB[b]);
  }
  sim.Snapshot(&snap);
  return snap.X_WB[b];
}

// the ramp course (models/ramp.xml): the ramp rises 0.35 m over x = 1.5 .. 3.5 m, the platform
// is x = 3.5 .. 6.0 m; the trunk ends on the platform turned 90 degrees (to the left: +90)
void ExpectRampCourse(const std::string& name, const std::string& trunk, double turn_deg,
                      double stand_height_m) {
  double min_up = 1;
  const Pose X = RunExampleWorld(
      name, trunk, [&](double, const Pose& p) { min_up = std::min(min_up, p.linear()(2, 2)); });
  const double yaw_deg = TrunkYaw(X) * 180 / M_PI;
  std::printf(
      "[ measured ] %s: trunk ends at (%.2f, %.2f, %.3f) m, yaw %.1f deg, up-axis z >= %.3f\n",
      name.c_str(), X.translation().x(), X.translation().y(), X.translation().z(), yaw_deg, min_up);
  EXPECT_GT(X.translation().x(), 3.7);
  EXPECT_LT(X.translation().x(), 5.8);
  EXPECT_NEAR(X.translation().z(), 0.35 + stand_height_m, 0.06);  // standing on the platform
  EXPECT_NEAR(yaw_deg, turn_deg, 5.0);
  EXPECT_GT(min_up, 0.9);
}

TEST(RobotWorlds, QuadrupedClimbsTheRampStopsAndTurns) {
  ExpectRampCourse("quadruped", "quadruped/trunk", 90, 0.285);
}

TEST(RobotWorlds, QuadrupedArmClimbsTheRampStopsAndTurns) {
  ExpectRampCourse("quadruped_arm", "carrier/trunk", -90, 0.52);
}

TEST(RobotWorlds, RoverDrivesItsLoopThroughTheRoom) {
  // the route of the world file, from the start pose (-0.2, -1.45); the world runs 20 s
  const std::vector<Eigen::Vector2d> route = {{1.3, -1.0},  {1.9, 0.0},   {1.4, 1.0},
                                              {0.0, 1.6},   {-1.6, 1.35}, {-2.5, 0.1},
                                              {-1.8, -1.2}, {-0.2, -1.45}};
  size_t next = 0;
  double path_m = 0, max_off_m = 0, min_up = 1, last_at = -1;
  Eigen::Vector2d last(-0.2, -1.45);
  RunExampleWorld("rover", "rover/chassis", [&](double t, const Pose& X) {
    const Eigen::Vector2d p = X.translation().head<2>();
    path_m += (p - last).norm();
    last = p;
    min_up = std::min(min_up, X.linear()(2, 2));
    double off = 1e9;
    for (size_t k = 0; k < route.size(); ++k)
      off = std::min(off, DistanceToRouteSegment(p, route[k], route[(k + 1) % route.size()]));
    max_off_m = std::max(max_off_m, off);
    if (next < route.size() && (p - route[next]).norm() < 0.15) {
      ++next;
      last_at = t;
    }
  });
  std::printf(
      "[ measured ] rover: %zu of %zu waypoints in order in 20 s (the %zuth at %.2f s), chassis "
      "path %.2f m (%.3f m/s), max %.3f m off the waypoint polygon, up-axis z >= %.4f\n",
      next, route.size(), next, last_at, path_m, path_m / 20.0, max_off_m, min_up);
  EXPECT_GE(next, 6u);  // 12 m in 24 s: six or seven of the eight in the world's 20 s
  EXPECT_NEAR(path_m / 20.0, 0.45, 0.06);
  EXPECT_LT(max_off_m, 0.35);  // pure pursuit rounds each corner
  EXPECT_GT(min_up, 0.99);     // level floor, never tipping
}

TEST(RobotWorlds, QuadrotorFliesItsSquareAndLandsOnThePad) {
  const std::vector<Eigen::Vector3d> c = {
      {0, 0, 1.5}, {4, 0, 1.5}, {4, 4, 1.5}, {0, 4, 1.5}, {0, 0, 1.5}};
  double max_off_m = 0;
  const Pose X = RunExampleWorld("quadrotor", "drone/base", [&](double t, const Pose& p) {
    if (t < 4.0 || t > 24.0) return;  // the square is flown from t = 4 s
    double off = 1e9;
    for (size_t k = 0; k + 1 < c.size(); ++k) {
      const Eigen::Vector3d ab = c[k + 1] - c[k];
      const double s = std::clamp((p.translation() - c[k]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      off = std::min(off, (p.translation() - (c[k] + s * ab)).norm());
    }
    max_off_m = std::max(max_off_m, off);
  });
  std::printf(
      "[ measured ] quadrotor world: square flown within %.1f mm of its sides; landed at (%.4f, "
      "%.4f, %.4f) m\n",
      1000 * max_off_m, X.translation().x(), X.translation().y(), X.translation().z());
  EXPECT_LT(max_off_m, 0.03);
  EXPECT_LT(X.translation().head<2>().norm(), 0.02);  // on the pad it took off from
  EXPECT_NEAR(X.translation().z(), 0.095, 0.01);      // standing on its legs
}

TEST(RobotWorlds, ArmPutsTheCubeOnTheMarker) {
  // the table scene is placed 0.75 m up; the marker is at (0.5, 0.15) in the arm's base frame
  const Pose X = RunExampleWorld("arm", "arm/cube", [](double, const Pose&) {});
  const Eigen::Vector2d marker(0.5, 0.15);
  const double off = (X.translation().head<2>() - marker).norm();
  std::printf(
      "[ measured ] arm world: cube ends %.1f mm from the marker, z %.4f m, up-axis z %.4f\n",
      1000 * off, X.translation().z(), X.linear()(2, 2));
  EXPECT_LT(off, 0.01);
  EXPECT_NEAR(X.translation().z(), 0.75 + 0.025, 0.005);  // resting on the table top
  EXPECT_GT(X.linear()(2, 2), 0.99);
}

}  // namespace
}  // namespace penumbra
