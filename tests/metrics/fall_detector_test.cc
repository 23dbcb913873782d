// the fall rule (metrics/fall_detector.h) on tilt sequences worked out by hand; the whole
// detector on real physics runs in tests/app/outputs_commands_test.cc.
#include "penumbra/metrics/fall_detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace penumbra {
namespace {

Eigen::Quaterniond FdRoll(double deg) {
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(deg * std::numbers::pi / 180, Eigen::Vector3d::UnitX()));
}

TEST(BaseTilt, AngleBetweenTheBodyZAndTheWorldZ) {
  EXPECT_NEAR(BaseTiltDeg(Eigen::Quaterniond::Identity()), 0.0, 1e-12);
  EXPECT_NEAR(BaseTiltDeg(FdRoll(30)), 30.0, 1e-9);
  EXPECT_NEAR(BaseTiltDeg(FdRoll(-75)), 75.0, 1e-9);
  EXPECT_NEAR(BaseTiltDeg(FdRoll(180)), 180.0, 1e-6);
  // a yaw does not tilt; pitch after yaw tilts by the pitch; a non-unit quaternion is normalised
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(BaseTiltDeg(yaw), 0.0, 1e-9);
  const Eigen::Quaterniond pitch(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(BaseTiltDeg(yaw * pitch), 0.5 * 180 / std::numbers::pi, 1e-9);
  Eigen::Quaterniond scaled = FdRoll(45);
  scaled.coeffs() *= 3.0;
  EXPECT_NEAR(BaseTiltDeg(scaled), 45.0, 1e-9);
}

TEST(FallDetector, OnlyATiltHeldForTheMinimumDurationIsAFall) {
  FallDetector d("go1", "go1/trunk");
  // 0 .. 1 s upright-ish; 1.0 .. 1.3 s at 70 deg (a stumble, 0.3 s); 2.0 s on at 90 deg
  bool fell_once = false;
  for (int k = 0; k <= 400; ++k) {
    const double t = 0.01 * k;
    double tilt = 10;
    if (t >= 1.0 - 1e-9 && t < 1.3 - 1e-9) tilt = 70;
    if (t >= 2.0 - 1e-9) tilt = 90 + (t - 2.0);
    const bool now = d.Update(t, tilt);
    if (now) {
      EXPECT_FALSE(fell_once);
      fell_once = true;
      EXPECT_NEAR(t, 2.5, 1e-9);  // the sample that completes 0.5 s
    }
  }
  EXPECT_TRUE(fell_once);
  const RobotFall& r = d.result();
  EXPECT_TRUE(r.fell);
  EXPECT_NEAR(r.fall_time_sec, 2.0, 1e-9);  // the start of the episode, not the stumble
  EXPECT_NEAR(r.max_tilt_deg, 92.0, 1e-9);
  EXPECT_NEAR(r.max_tilt_time_sec, 4.0, 1e-9);

  // a tilt that stays at the threshold is not above it; one stumble only: no fall
  FallDetector e("go1", "go1/trunk");
  for (int k = 0; k <= 300; ++k) e.Update(0.01 * k, k < 200 ? 60.0 : (k < 240 ? 80.0 : 5.0));
  EXPECT_FALSE(e.result().fell);
  EXPECT_TRUE(std::isnan(e.result().fall_time_sec));
  EXPECT_EQ(e.result().max_tilt_deg, 80.0);
}

TEST(StartCheck, ADropOrATiltInTheFirstSecondIsAStumbleAndATakeOffIsNot) {
  const auto run = [](auto z_of_t, auto tilt_of_t) {
    StartCheck c;
    int fired = 0;
    for (int k = 0; k <= 200; ++k)
      fired += c.Update(0.01 * k, tilt_of_t(0.01 * k), z_of_t(0.01 * k));
    return std::pair(fired, c.stumbled());
  };
  const auto flat = [](double) { return 0.0; };
  EXPECT_EQ(run([](double t) { return 0.5 - 0.4 * std::min(t, 0.5); }, flat), std::pair(1, true));
  EXPECT_EQ(run([](double t) { return 0.5 + 1.5 * t; }, flat), std::pair(0, false)) << "take-off";
  EXPECT_EQ(run([](double) { return 0.3; }, [](double t) { return t < 0.8 ? 2.0 : 20.0; }),
            std::pair(1, true));
  // after the window nothing counts
  EXPECT_EQ(run([](double t) { return t < 1.2 ? 0.3 : 0.0; }, flat), std::pair(0, false));
  // a robot that starts tilted on a slope and stays so
  EXPECT_EQ(run([](double) { return 0.3; }, [](double) { return 40.0; }), std::pair(0, false));
}

}  // namespace
}  // namespace penumbra
