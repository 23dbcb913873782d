// the shared pure-pursuit law and waypoint progress (control/pure_pursuit.h,
// control/waypoint_route.h).

#include "penumbra/control/pure_pursuit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/control/waypoint_route.h"

namespace penumbra {
namespace {

Pose At(double x, double y, double yaw_deg) {
  return PoseFromXyzRpyDeg(Eigen::Vector3d(x, y, 0.3), Eigen::Vector3d(0, 0, yaw_deg));
}

constexpr PurePursuitLimits kLimits{0.5, M_PI / 2};

TEST(PurePursuit, StraightAheadCruises) {
  const UnicycleCommand c = PurePursuit(At(0, 0, 0), {2, 0}, kLimits);
  EXPECT_EQ(c.v_m_s, 0.5);
  EXPECT_NEAR(c.yaw_rate, 0, 1e-15);
}

TEST(PurePursuit, ArcCurvatureThroughTheGoal) {
  // alpha = 45 deg, d = sqrt(2): kappa = 2 sin(45 deg) / sqrt(2) = 1 / m
  UnicycleCommand c = PurePursuit(At(0, 0, 0), {1, 1}, kLimits);
  EXPECT_NEAR(c.v_m_s, 0.5, 1e-12);
  EXPECT_NEAR(c.yaw_rate, 0.5, 1e-12);
  // the same seen from a rotated, translated pose: goal 45 deg to the right
  c = PurePursuit(At(3, -1, 90), Eigen::Vector2d(3, -1) + Eigen::Vector2d(1, 1), kLimits);
  EXPECT_NEAR(c.v_m_s, 0.5, 1e-12);
  EXPECT_NEAR(c.yaw_rate, -0.5, 1e-12);
}

TEST(PurePursuit, YawRateLimitSlowsDown) {
  // kappa = 2 sin(45 deg) / 0.2828 = 5 / m: v kappa would be 2.5 > pi / 2 rad/s
  const UnicycleCommand c = PurePursuit(At(0, 0, 0), {0.2, 0.2}, kLimits);
  EXPECT_NEAR(c.yaw_rate, M_PI / 2, 1e-9);
  EXPECT_NEAR(c.v_m_s, (M_PI / 2) / 5.0, 1e-9);
}

TEST(PurePursuit, GoalBehindTurnsInPlaceTowardsIt) {
  UnicycleCommand c = PurePursuit(At(0, 0, 0), {-1, 0.1}, kLimits);
  EXPECT_EQ(c.v_m_s, 0);
  EXPECT_EQ(c.yaw_rate, M_PI / 2);
  c = PurePursuit(At(0, 0, 0), {-1, -0.1}, kLimits);
  EXPECT_EQ(c.v_m_s, 0);
  EXPECT_EQ(c.yaw_rate, -M_PI / 2);
}

TEST(PurePursuit, BaseXAxisVerticalStops) {
  const Pose X = PoseFromXyzRpyDeg(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -90, 0));
  const UnicycleCommand c = PurePursuit(X, {1, 0}, kLimits);
  EXPECT_EQ(c.v_m_s, 0);
  EXPECT_EQ(c.yaw_rate, 0);
}

TEST(WaypointRoute, AdvancesWithinToleranceAndFinishes) {
  WaypointRoute r({{1, 0}, {1, 1}}, false, 0.15);
  r.Advance({0.5, 0});
  EXPECT_EQ(r.target_index(), 0);
  r.Advance({0.9, 0.05});  // 0.112 m from the first
  EXPECT_EQ(r.target_index(), 1);
  EXPECT_EQ(r.reached(), 1);
  EXPECT_EQ(r.target(), Eigen::Vector2d(1, 1));
  r.Advance({1, 0.9});
  EXPECT_TRUE(r.finished());
  EXPECT_EQ(r.reached(), 2);
  r.Advance({1, 0.9});  // nothing more once finished
  EXPECT_EQ(r.reached(), 2);
  r.Reset();
  EXPECT_FALSE(r.finished());
  EXPECT_EQ(r.target_index(), 0);
  EXPECT_EQ(r.reached(), 0);
}

TEST(WaypointRoute, LoopWrapsAndAdvancesAtMostOneLapPerCall) {
  // every waypoint at the same place: one call reaches each once, then stops
  WaypointRoute r({{0, 0}, {0, 0}, {0, 0}}, true, 0.1);
  r.Advance({0, 0});
  EXPECT_EQ(r.reached(), 3);
  EXPECT_EQ(r.target_index(), 0);
  EXPECT_FALSE(r.finished());
}

}  // namespace
}  // namespace penumbra
