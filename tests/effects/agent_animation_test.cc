// articulated agents (effects/walker_gait.h, effects/agent_animation.h): the stride model of
// Alexander (1984), the leg angle oscillating at the stride frequency the walking speed
// implies, the stance foot on the floor, wheels that spin by distance / radius and steer by the
// bicycle model, appearance per seed, and poses that are pure functions of time.
#include "penumbra/effects/agent_animation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <set>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// a straight walk along +x from the origin at `speed` (a 100 m leg)
AgentPath StraightWalk(double speed, AgentKind kind = AgentKind::kPerson) {
  AgentConfig a;
  a.name = "w";
  a.kind = kind;
  a.waypoints = {{0, 0}, {100, 0}};
  a.speed_m_s = speed;
  a.route = AgentRoute::kOnce;
  return AgentPath(a);
}

// the rotation angle about +y of R (R = Ry(angle))
double AngleAboutY(const Eigen::Matrix3d& R) { return std::atan2(R(0, 2), R(0, 0)); }

struct Oscillation {
  double frequency_hz = 0;
  double amplitude = 0;
};

// frequency (upward zero crossings) and amplitude of the left thigh's flexion over [t0, t1],
// read from the thigh body's pose relative to the root (the forward kinematics, not the angles)
Oscillation ThighOscillation(AgentAnimator* a, double t0, double t1) {
  std::vector<double> crossings;
  double prev = 0, amp = 0;
  for (double t = t0; t <= t1; t += 1e-3) {
    const std::vector<Pose>& X = a->Poses(t);
    const Eigen::Matrix3d R_RS = X[0].linear().transpose() * X[1].linear();
    const double flexion = -AngleAboutY(R_RS);
    amp = std::max(amp, std::abs(flexion));
    if (t > t0 && prev < 0 && flexion >= 0)
      crossings.push_back(t - 1e-3 * flexion / (flexion - prev));
    prev = flexion;
  }
  Oscillation o;
  o.amplitude = amp;
  if (crossings.size() >= 2)
    o.frequency_hz = (crossings.size() - 1) / (crossings.back() - crossings.front());
  return o;
}

TEST(WalkerGait, StrideLengthFollowsAlexander1984AndGrowsWithSpeed) {
  const double h = 0.530 * 1.75;
  // lambda = 2.3 h (v^2 / (g h))^0.3 at 1.3 m/s: 1.29 m, 1.0 strides/s
  EXPECT_NEAR(WalkerStrideLength(1.3, h), 2.3 * h * std::pow(1.69 / (9.81 * h), 0.3), 1e-12);
  EXPECT_NEAR(WalkerStrideLength(1.3, h), 1.29, 0.01);
  EXPECT_NEAR(WalkerStrideFrequency(1.3, h), 1.3 / WalkerStrideLength(1.3, h), 1e-12);
  EXPECT_EQ(WalkerStrideLength(0, h), 0);
  EXPECT_EQ(WalkerStrideFrequency(0, h), 0);
  double prev_len = 0, prev_f = 0;
  for (double v = 0.2; v <= 2.5; v += 0.1) {
    EXPECT_GT(WalkerStrideLength(v, h), prev_len) << v;
    EXPECT_GT(WalkerStrideFrequency(v, h), prev_f) << v;
    prev_len = WalkerStrideLength(v, h);
    prev_f = WalkerStrideFrequency(v, h);
  }
  // capped at 3.2 h
  EXPECT_DOUBLE_EQ(WalkerStrideLength(20, h), 3.2 * h);
}

TEST(WalkerGait, TheThighOscillatesAtTheStrideFrequencyOfTheSpeedAndTheStrideGrowsWithIt) {
  double prev_stride = 0, prev_amp = 0;
  for (double v : {0.7, 1.3, 1.9}) {
    AgentPath path = StraightWalk(v);
    AgentAnimator a(AgentKind::kPerson, 1.75, [&path](double t) { return path.X_WA(t); });
    // after the start-up (the speed low-pass, 0.15 s), 10 s of steady walking
    const Oscillation o = ThighOscillation(&a, 2.0, 12.0);
    const double expected = WalkerStrideFrequency(v, a.skeleton().hip_height_m);
    const double stride = v / o.frequency_hz;  // distance walked per measured cycle
    std::printf("v %.1f m/s: thigh %.4f Hz (model %.4f Hz), stride %.3f m, amplitude %.1f deg\n", v,
                o.frequency_hz, expected, stride, o.amplitude * 180 / M_PI);
    EXPECT_NEAR(o.frequency_hz, expected, 1e-3 * expected) << v;
    EXPECT_GT(stride, prev_stride) << v;
    EXPECT_GT(o.amplitude, prev_amp) << v;
    // the amplitude puts the feet a step (stride / 2) apart at heel strike
    EXPECT_NEAR(std::sin(o.amplitude), stride / (4 * a.skeleton().hip_height_m), 1e-3);
    prev_stride = stride;
    prev_amp = o.amplitude;
  }
}

TEST(WalkerGait, TheStanceFootStaysOnTheFloorAndAStandingWalkerIsStraight) {
  const WalkerSkeleton k = WalkerSkeleton::FromHeight(1.8);
  for (double phase = 0; phase < 0.5; phase += 0.01) {
    const WalkerJointAngles q = WalkerGaitAngles(k, phase, 1.4);
    const WalkerPose p = WalkerForwardKinematics(k, q);
    // left leg in stance: the ankle of the straight leg is ankle_height above the floor
    const Pose& shin = p.X_AS[static_cast<int>(WalkerSegment::kShinL)];
    const Eigen::Vector3d ankle = shin * Eigen::Vector3d(0, 0, -k.shank_m);
    EXPECT_NEAR(ankle.z() - k.ankle_height_m, 0, 1e-4) << phase;
    EXPECT_EQ(q.knee[0], 0) << phase;
  }
  const WalkerJointAngles still = WalkerGaitAngles(k, 0.3, 0);
  EXPECT_EQ(still.hip[0], 0);
  EXPECT_EQ(still.knee[1], 0);
  EXPECT_EQ(still.pelvis_drop_m, 0);
  const WalkerPose p = WalkerForwardKinematics(k, still);
  // standing: the sole of each foot on the floor, the thighs vertical below the hips
  const Eigen::Vector3d ankle =
      p.X_AS[static_cast<int>(WalkerSegment::kShinR)] * Eigen::Vector3d(0, 0, -k.shank_m);
  EXPECT_NEAR(ankle.z(), k.ankle_height_m, 1e-12);
  EXPECT_NEAR(ankle.y(), -k.hip_half_width_m, 1e-12);
  EXPECT_THROW(WalkerSkeleton::FromHeight(0), Error);
  EXPECT_THROW(WalkerSkeleton::FromHeight(3.5), Error);
}

TEST(WalkerGait, AppearanceIsAPureFunctionOfSeedAndName) {
  const WalkerAppearance a = WalkerAppearanceOf(7, "adversity_person0", 0);
  const WalkerAppearance b = WalkerAppearanceOf(7, "adversity_person0", 0);
  EXPECT_EQ(a.height_m, b.height_m);
  EXPECT_EQ(a.shirt, b.shirt);
  EXPECT_EQ(a.trousers, b.trousers);
  EXPECT_EQ(a.skin, b.skin);
  // a given height is kept; the colours still come from the seed
  EXPECT_EQ(WalkerAppearanceOf(7, "adversity_person0", 1.62).height_m, 1.62);
  EXPECT_EQ(WalkerAppearanceOf(7, "adversity_person0", 1.62).shirt, a.shirt);
  // over many people: heights in [1.5, 1.95] around 1.70 m, several shirts, seeds differ
  double sum = 0, sum2 = 0;
  std::set<std::pair<double, double>> shirts;
  int differs = 0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    const std::string name = "p" + std::to_string(i);
    const WalkerAppearance x = WalkerAppearanceOf(1, name, 0);
    EXPECT_GE(x.height_m, 1.5);
    EXPECT_LE(x.height_m, 1.95);
    sum += x.height_m;
    sum2 += x.height_m * x.height_m;
    shirts.insert({x.shirt.r, x.shirt.g});
    differs += WalkerAppearanceOf(2, name, 0).height_m != x.height_m;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  std::printf("heights of %d people: mean %.3f m, sd %.3f m, %zu shirt colours\n", n, mean, sd,
              shirts.size());
  EXPECT_NEAR(mean, 1.70, 0.015);
  EXPECT_NEAR(sd, 0.09, 0.015);
  EXPECT_GE(shirts.size(), 10u);
  EXPECT_GE(differs, n - 10);  // only heights clipped to 1.50 or 1.95 m can coincide
}

TEST(AgentAnimation, AWheelTurnsByDistanceOverRadius) {
  for (AgentKind kind : {AgentKind::kForklift, AgentKind::kCart}) {
    AgentPath path = StraightWalk(2.0, kind);
    AgentAnimator a(kind, 1.75, [&path](double t) { return path.X_WA(t); });
    const std::vector<AgentWheel> wheels = AgentWheels(kind);
    ASSERT_EQ(wheels.size(), 4u);
    for (double t : {0.0, 0.37, 1.0, 2.555, 7.3}) {
      const double distance = path.Position(t).x();
      const std::vector<Pose>& X = a.Poses(t);
      for (size_t j = 0; j < wheels.size(); ++j) {
        const double spin = a.WheelSpin(t, wheels[j]);
        EXPECT_NEAR(spin, distance / wheels[j].radius_m, 1e-9) << t;
        // the wheel body: at its axle, rotated by the spin about the axle (mod 2 pi)
        const Pose X_AW = X[0].inverse() * X[j + 1];
        EXPECT_NEAR((X_AW.translation() - wheels[j].centre).norm(), 0, 1e-12);
        const double body_angle = AngleAboutY(X_AW.linear());
        EXPECT_NEAR(std::remainder(body_angle - spin, 2 * M_PI), 0, 1e-9) << t;
      }
    }
  }
}

TEST(AgentAnimation, SteeredWheelsFollowTheBicycleModelOnACircle) {
  // a forklift on a circle of radius 4 m at 1.5 m/s, counter-clockwise
  const double R = 4, v = 1.5, w = v / R;
  const auto circle = [&](double t) {
    Pose X = Pose::Identity();
    X.translation() = Eigen::Vector3d(R * std::sin(w * t), R * (1 - std::cos(w * t)), 0);
    X.linear() = Eigen::AngleAxisd(w * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return X;
  };
  AgentAnimator a(AgentKind::kForklift, 1.75, circle);
  const std::vector<AgentWheel> wheels = AgentWheels(AgentKind::kForklift);
  const double delta = std::atan(AgentWheelbase(AgentKind::kForklift) / R);
  for (const AgentWheel& wh : wheels) {
    const double steer = a.SteerAngle(5.0, wh);
    // the forklift steers with its rear wheels: their angle is the bicycle model's, negated
    EXPECT_NEAR(steer, wh.steer == -1 ? -delta : 0.0, 1e-3) << wh.name;
  }
  EXPECT_NEAR(a.Motion(5.0).speed_m_s, v, 1e-3);
  EXPECT_NEAR(a.Motion(5.0).yaw_rate, w, 1e-4);
}

TEST(AgentAnimation, PosesArePureFunctionsOfTimeInAnyQueryOrder) {
  AgentConfig c;
  c.name = "w";
  c.waypoints = {{0, 0}, {3, 0}, {3, 2}};
  c.speed_m_s = 1.2;
  c.pause_sec = 0.7;
  const AgentPath path(c);
  const auto f = [&path](double t) { return path.X_WA(t); };
  AgentAnimator forward(AgentKind::kPerson, 1.66, f), shuffled(AgentKind::kPerson, 1.66, f);
  std::vector<double> times;
  for (int i = 0; i < 400; ++i) times.push_back(0.0137 * i);
  std::vector<std::vector<Pose>> expected;
  for (double t : times) expected.push_back(forward.Poses(t));
  // backwards, then a fresh animator at a late time first
  for (size_t i = times.size(); i-- > 0;) {
    const std::vector<Pose>& X = shuffled.Poses(times[i]);
    for (size_t j = 0; j < X.size(); ++j)
      ASSERT_TRUE(X[j].matrix() == expected[i][j].matrix()) << times[i] << " part " << j;
  }
  AgentAnimator late(AgentKind::kPerson, 1.66, f);
  EXPECT_TRUE(late.Poses(times.back())[3].matrix() == expected.back()[3].matrix());
  // while paused at a waypoint the legs come to rest (smoothed speed -> 0)
  const double arrive = 3.0 / 1.2;
  EXPECT_LT(std::abs(forward.Angles(arrive + 0.65).hip[0]), 0.05);
  EXPECT_GT(forward.Motion(arrive - 0.5).speed_m_s, 1.19);
}

}  // namespace
}  // namespace penumbra
