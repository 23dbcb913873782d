#include "penumbra/effects/agent_path.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

AgentConfig Square() {
  AgentConfig a;
  a.name = "walker";
  a.waypoints = {{0, 0}, {4, 0}, {4, 3}, {0, 3}};
  a.speed_m_s = 2.0;
  a.pause_sec = 0.5;
  a.start_delay_sec = 1.0;
  return a;
}

// the analytic position of Square() at time t: legs of 2 s, 1.5 s, 2 s, 1.5 s, each
// followed by a 0.5 s pause, after a 1 s start delay
Eigen::Vector2d Expected(double t) {
  const Eigen::Vector2d w[5] = {{0, 0}, {4, 0}, {4, 3}, {0, 3}, {0, 0}};
  double u = t - 1.0;
  if (u <= 0) return w[0];
  u = std::fmod(u, 2 + 0.5 + 1.5 + 0.5 + 2 + 0.5 + 1.5 + 0.5);
  for (int i = 0; i < 4; ++i) {
    const double travel = (w[i + 1] - w[i]).norm() / 2.0;
    if (u < travel) return w[i] + (w[i + 1] - w[i]) * (u / travel);
    u -= travel;
    if (u < 0.5) return w[i + 1];
    u -= 0.5;
  }
  return w[0];
}

TEST(AgentPath, WalksTheWaypointsAtTheSetSpeedWithPauses) {
  const AgentPath path(Square());
  EXPECT_DOUBLE_EQ(path.cycle_sec(), 9.0);
  double worst = 0;
  for (int k = 0; k <= 4000; ++k) {
    const double t = k * 0.005;  // 20 s: two cycles and a bit
    const Eigen::Vector3d p = path.Position(t);
    worst = std::max(worst, (p.head<2>() - Expected(t)).norm());
    EXPECT_EQ(p.z(), 0.0);
  }
  EXPECT_LT(worst, 1e-3) << "largest position error " << worst << " m";
  // standing still during the start delay and the pauses
  EXPECT_EQ(path.Position(0.3), path.Position(0.9));
  EXPECT_EQ(path.Position(3.1), path.Position(3.4));  // pause at (4, 0): t in [3, 3.5]
  EXPECT_NEAR((path.Position(3.2) - Eigen::Vector3d(4, 0, 0)).norm(), 0, 1e-12);
  // speed on a leg: 2 m/s
  const double v = (path.Position(2.0) - path.Position(1.5)).norm() / 0.5;
  EXPECT_NEAR(v, 2.0, 1e-9);
}

TEST(AgentPath, FacesAlongTheLegAndPoseIsConsistent) {
  const AgentPath path(Square());
  EXPECT_NEAR(path.Yaw(2.0), 0.0, 1e-12);             // along +x
  EXPECT_NEAR(path.Yaw(4.0), M_PI / 2, 1e-12);        // along +y
  EXPECT_NEAR(std::abs(path.Yaw(6.0)), M_PI, 1e-12);  // along -x
  EXPECT_NEAR(path.Yaw(3.2), 0.0, 1e-12);             // paused: heading of the arrival leg
  const Pose X = path.X_WA(4.0);
  EXPECT_NEAR((X.translation() - path.Position(4.0)).norm(), 0, 1e-15);
  EXPECT_NEAR((X.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0, 1e-12);
}

TEST(AgentPath, PingPongAndOnceRoutes) {
  AgentConfig a;
  a.name = "a";
  a.waypoints = {{0, 0}, {2, 0}, {2, 2}};
  a.speed_m_s = 1.0;
  a.route = AgentRoute::kPingPong;
  const AgentPath pp(a);
  EXPECT_DOUBLE_EQ(pp.cycle_sec(), 8.0);
  EXPECT_NEAR((pp.Position(5.0) - Eigen::Vector3d(2, 1, 0)).norm(), 0, 1e-12);  // coming back
  EXPECT_NEAR((pp.Position(7.0) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((pp.Position(8.5) - Eigen::Vector3d(0.5, 0, 0)).norm(), 0, 1e-12);  // next cycle
  a.route = AgentRoute::kOnce;
  const AgentPath once(a);
  EXPECT_NEAR((once.Position(100.0) - Eigen::Vector3d(2, 2, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(once.Yaw(100.0), M_PI / 2, 1e-12);
}

TEST(AgentPath, IsAPureFunctionOfTime) {
  const AgentPath a(Square()), b(Square());
  for (double t : {17.3, 0.0, 5.55, 17.3, 123.456}) {
    EXPECT_EQ(a.X_WA(t).matrix(), b.X_WA(t).matrix());
  }
}

TEST(AgentConfig, BadInputNamesKeyAndRange) {
  AgentConfig a = Square();
  a.waypoints = {{1, 1}};
  try {
    a.ValidateOrThrow("w.yaml", "agents[0]");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "agents[0].waypoints");
    EXPECT_NE(std::string(e.what()).find("at least 2"), std::string::npos) << e.what();
  }
  a = Square();
  a.speed_m_s = -1;
  try {
    a.ValidateOrThrow("w.yaml", "agents[3]");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "agents[3].speed_m_s");
    EXPECT_NE(std::string(e.what()).find("(0, 20]"), std::string::npos) << e.what();
  }
  a = Square();
  a.waypoints[2] = a.waypoints[1];
  EXPECT_THROW(a.ValidateOrThrow("w.yaml", "agents[0]"), ConfigError);
  EXPECT_THROW(AgentPath{a}, ConfigError);
  std::vector<AgentConfig> two = {Square(), Square()};
  try {
    ValidateAgentsOrThrow(two, "w.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "agents[1].name");
  }
}

}  // namespace
}  // namespace penumbra
