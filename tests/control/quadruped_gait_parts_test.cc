// the parts of the trot_gait controller on their own: leg kinematics, stance force
// distribution, swing trajectory and the parameter parser's errors.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/quadruped_leg_kinematics.h"
#include "penumbra/control/quadruped_stance_forces.h"
#include "penumbra/control/quadruped_swing_trajectory.h"
#include "penumbra/control/trot_gait.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

const LegGeometry kGo1Right{-0.08, 0.213, 0.213};
const LegGeometry kGo1Left{0.08, 0.213, 0.213};

TEST(QuadrupedLegKinematics, StandingPoseHasTheFootBelowTheThighAxis) {
  // thigh 0.9, calf -1.8: foot straight below the thigh axis at 2 l cos(0.9)
  const Eigen::Vector3d p = LegForwardKinematics(kGo1Right, {0, 0.9, -1.8});
  EXPECT_NEAR(p.x(), 0, 1e-12);
  EXPECT_NEAR(p.y(), -0.08, 1e-12);
  EXPECT_NEAR(p.z(), -0.426 * std::cos(0.9), 1e-12);
  // abduction by +0.2 rad rotates the whole leg about +x
  const Eigen::Vector3d q = LegForwardKinematics(kGo1Left, {0.2, 0.9, -1.8});
  const Eigen::Vector3d expected = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()) *
                                   LegForwardKinematics(kGo1Left, {0, 0.9, -1.8});
  EXPECT_LT((q - expected).norm(), 1e-12);
}

TEST(QuadrupedLegKinematics, InverseKinematicsInvertsForwardKinematics) {
  int n = 0;
  for (const LegGeometry& leg : {kGo1Right, kGo1Left, LegGeometry{0.12675, 0.35, 0.35}}) {
    for (double q1 = -0.6; q1 <= 0.6; q1 += 0.3)
      for (double q2 = -0.5; q2 <= 2.0; q2 += 0.25)
        for (double q3 = -2.6; q3 <= -0.3; q3 += 0.25) {
          const Eigen::Vector3d q(q1, q2, q3);
          const Eigen::Vector3d p = LegForwardKinematics(leg, q);
          // IK's branch keeps the foot below the thigh axis in the leg plane (z' < 0); the
          // abduction is undefined as z' -> 0, so near-degenerate poses are left out
          const double zp = -leg.thigh_m * std::cos(q2) - leg.calf_m * std::cos(q2 + q3);
          if (zp > -0.05) continue;
          Eigen::Vector3d q_ik;
          EXPECT_TRUE(LegInverseKinematics(leg, p, &q_ik)) << q.transpose();
          EXPECT_LT((LegForwardKinematics(leg, q_ik) - p).norm(), 1e-9) << q.transpose();
          EXPECT_LT((q_ik - q).norm(), 1e-7) << q.transpose() << " vs " << q_ik.transpose();
          ++n;
        }
  }
  EXPECT_GT(n, 500);
}

TEST(QuadrupedLegKinematics, UnreachableTargetsAreProjectedOntoTheWorkspace) {
  Eigen::Vector3d q;
  // far below: the leg points straight at the target, fully extended
  EXPECT_FALSE(LegInverseKinematics(kGo1Right, {0.1, -0.08, -1.0}, &q));
  const Eigen::Vector3d p = LegForwardKinematics(kGo1Right, q);
  EXPECT_NEAR(std::hypot(p.x(), p.z()), 0.426, 1e-6);
  EXPECT_NEAR(std::atan2(p.x(), -p.z()), std::atan2(0.1, 1.0), 1e-6);
  EXPECT_TRUE(q.allFinite());
  // at the hip itself
  EXPECT_FALSE(LegInverseKinematics(kGo1Left, {0, 0, 0}, &q));
  EXPECT_TRUE(q.allFinite());
}

TEST(QuadrupedLegKinematics, JacobianMatchesFiniteDifferences) {
  const Eigen::Vector3d q(0.3, 0.7, -1.5);
  const Eigen::Matrix3d J = LegJacobian(kGo1Left, q);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d dq = Eigen::Vector3d::Zero();
    dq[k] = 1e-6;
    const Eigen::Vector3d fd =
        (LegForwardKinematics(kGo1Left, q + dq) - LegForwardKinematics(kGo1Left, q - dq)) / 2e-6;
    EXPECT_LT((J.col(k) - fd).norm(), 1e-8) << k;
  }
}

// four feet at the corners of a 0.38 x 0.25 m rectangle, 0.27 m below the COM
std::array<Eigen::Vector3d, 4> Feet() {
  return {Eigen::Vector3d(0.19, -0.125, -0.27), Eigen::Vector3d(0.19, 0.125, -0.27),
          Eigen::Vector3d(-0.19, -0.125, -0.27), Eigen::Vector3d(-0.19, 0.125, -0.27)};
}

TEST(QuadrupedStanceForces, StandingOnFourFeetSharesTheWeight) {
  const double mg = 12 * 9.81;
  Eigen::Matrix<double, 6, 1> w;
  w << 0, 0, mg, 0, 0, 0;
  std::array<Eigen::Vector3d, 4> f;
  DistributeStanceForces(Feet(), {true, true, true, true}, w, Eigen::Vector3d::UnitZ(),
                         StanceForceLimits{}, &f);
  for (const auto& fi : f) {
    EXPECT_NEAR(fi.z(), mg / 4, 1e-3 * mg);
    EXPECT_NEAR(fi.head<2>().norm(), 0, 1e-3 * mg);
  }
}

TEST(QuadrupedStanceForces, FeasibleWrenchIsMetOnTwoDiagonalFeet) {
  // a wrench two diagonal feet can produce exactly (no moment about their diagonal)
  const auto r = Feet();
  const std::array<bool, 4> stance = {true, false, false, true};  // FR, RL
  const Eigen::Vector3d f1(3, 1, 50), f4(-1, 2, 70);
  Eigen::Matrix<double, 6, 1> w;
  w.head<3>() = f1 + f4;
  w.tail<3>() = r[0].cross(f1) + r[3].cross(f4);
  StanceForceLimits lim;
  lim.regularization = 1e-9;
  std::array<Eigen::Vector3d, 4> f;
  DistributeStanceForces(r, stance, w, Eigen::Vector3d::UnitZ(), lim, &f);
  Eigen::Matrix<double, 6, 1> got;
  got.head<3>() = f[0] + f[3];
  got.tail<3>() = r[0].cross(f[0]) + r[3].cross(f[3]);
  EXPECT_LT((got - w).norm(), 1e-5 * w.norm());
  EXPECT_EQ(f[1], Eigen::Vector3d::Zero());
  EXPECT_EQ(f[2], Eigen::Vector3d::Zero());
}

TEST(QuadrupedStanceForces, ForcesStayInsideTheFrictionCones) {
  // a large sideways push: the solution must be clipped to |f_t| <= mu f_n, f_n in bounds
  Eigen::Matrix<double, 6, 1> w;
  w << 0, 300, 100, 0, 0, 0;
  StanceForceLimits lim;
  lim.mu = 0.5;
  lim.min_normal_n = 2;
  lim.max_normal_n = 60;
  const Eigen::Vector3d n = Eigen::Vector3d(0.1, 0, 1).normalized();  // a slope
  std::array<Eigen::Vector3d, 4> f;
  DistributeStanceForces(Feet(), {true, true, true, true}, w, n, lim, &f);
  for (const auto& fi : f) {
    const double fn = fi.dot(n);
    EXPECT_GE(fn, 2 - 1e-12);
    EXPECT_LE(fn, 60 + 1e-12);
    EXPECT_LE((fi - fn * n).norm(), 0.5 * fn + 1e-9);
  }
}

TEST(QuadrupedSwingTrajectory, StartsAndEndsAtRestAndPeaksAtMidSwing) {
  const Eigen::Vector3d p0(0, 0, 0.02), p1(0.12, -0.03, 0.05);
  const double h = 0.08, T = 0.18;
  const SwingSample a = CycloidSwing(p0, p1, h, 0, T);
  const SwingSample b = CycloidSwing(p0, p1, h, 1, T);
  EXPECT_LT((a.p - p0).norm(), 1e-15);
  EXPECT_LT((b.p - p1).norm(), 1e-15);
  EXPECT_LT(a.v.norm(), 1e-12);
  EXPECT_LT(b.v.norm(), 1e-12);
  const SwingSample m = CycloidSwing(p0, p1, h, 0.5, T);
  EXPECT_NEAR(m.p.z(), (p0.z() + p1.z()) / 2 + h, 1e-12);
  EXPECT_LT((m.p.head<2>() - (p0 + p1).head<2>() / 2).norm(), 1e-12);
  // velocity is the time derivative of position
  for (double s : {0.1, 0.37, 0.8}) {
    const double ds = 1e-6;
    const Eigen::Vector3d fd =
        (CycloidSwing(p0, p1, h, s + ds, T).p - CycloidSwing(p0, p1, h, s - ds, T).p) /
        (2 * ds * T);
    EXPECT_LT((CycloidSwing(p0, p1, h, s, T).v - fd).norm(), 1e-6) << s;
  }
}

std::string Legs() {
  std::string s = "legs:\n";
  for (const char* leg : {"FR", "FL", "RR", "RL"}) {
    const std::string l = leg;
    s += "  " + l + ": {hip: " + l + "_hip, thigh: " + l + "_thigh, calf: " + l +
         "_calf, foot: " + l + "_foot}\n";
  }
  return s;
}

std::string Error(const std::string& yaml) {
  ControllerConfig cfg{"trot_gait", ParseYaml(yaml), 12};
  try {
    MakeController(cfg, "dog", "world.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(TrotGaitParams, ParsesPrefixedNamesCommandsAndHold) {
  ControllerConfig cfg{"trot_gait",
                       ParseYaml("base_body: trunk\n" + Legs() +
                                 "commands: [{t: 0}, {t: 1.5, vx: 0.5, yaw_rate: -0.2}]\n"
                                 "period_sec: 0.4\nduty: 0.6\nhold: {arm: 0.5}\n"),
                       3};
  std::unique_ptr<Controller> c = MakeController(cfg, "dog", "world.yaml");
  auto* g = dynamic_cast<TrotGait*>(c.get());
  ASSERT_NE(g, nullptr);
  const TrotGaitParams& p = g->params();
  EXPECT_EQ(p.base_body, "dog/trunk");
  EXPECT_EQ(p.legs[2].calf, "dog/RR_calf");
  EXPECT_EQ(p.legs[2].actuators[1], "dog/RR_thigh");  // defaults to the joint names
  EXPECT_EQ(p.legs[3].foot, "dog/RL_foot");
  ASSERT_EQ(p.commands.size(), 2u);
  EXPECT_EQ(p.commands[1].t_sec, 1.5);
  EXPECT_EQ(p.commands[1].command.vx, 0.5);
  EXPECT_EQ(p.commands[1].command.vy, 0);
  EXPECT_EQ(p.commands[1].command.yaw_rate, -0.2);
  EXPECT_EQ(p.duty, 0.6);
  ASSERT_EQ(p.hold.size(), 1u);
  EXPECT_EQ(p.hold[0].first, "dog/arm");
  // 1 base + 4 x (3 joints + foot + 3 actuators) + 1 held actuator
  EXPECT_EQ(g->RequiredNames().size(), 30u);
}

TEST(TrotGaitParams, BadValuesNameTheKey) {
  const std::string base = "base_body: trunk\n";
  EXPECT_NE(Error(base).find("world.yaml:12: robots[dog].controller.legs: missing"),
            std::string::npos)
      << Error(base);
  std::string legs = Legs();
  legs.replace(legs.find("  RL:"), 5, "  LH:");
  EXPECT_NE(Error(base + legs).find("controller.legs.LH: unknown leg 'LH'"), std::string::npos)
      << Error(base + legs);
  legs = Legs();
  legs.replace(legs.find("FL_foot}"), 8, "FL_foot, signs: [1, 2, 1]}");
  EXPECT_NE(Error(base + legs).find("legs.FL.signs[1]: got 2; expected 1 or -1"), std::string::npos)
      << Error(base + legs);
  legs = Legs();
  legs.replace(legs.find("FL_foot}"), 8, "FL_foot, knee: x}");
  EXPECT_NE(Error(base + legs).find("legs.FL.knee: unknown key"), std::string::npos);
  EXPECT_NE(Error(base + Legs() + "commands: [{t: 1}, {t: 1}]\n")
                .find("commands[1].t: got 1; "
                      "expected a time > the "
                      "previous entry's"),
            std::string::npos);
  EXPECT_NE(Error(base + Legs() + "commands: [{t: 0, speed: 1}]\n").find("commands[0].speed"),
            std::string::npos);
  EXPECT_NE(Error(base + Legs() + "duty: 0.9\n").find("duty: got 0.9; expected a number >= 0.3"),
            std::string::npos);
  EXPECT_NE(Error(base + Legs() + "hold: [1, 2]\n").find("hold: got a list of 2 items"),
            std::string::npos);
  EXPECT_NE(Error(base + Legs() + "gait: pace\n").find("unknown key(s) 'gait'"), std::string::npos);
}

}  // namespace
}  // namespace penumbra
