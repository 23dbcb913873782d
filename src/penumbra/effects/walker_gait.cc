#include "penumbra/effects/walker_gait.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

constexpr double kGravity = 9.81;
constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kDeg = M_PI / 180.0;

// the reference walk the swing amplitudes are quoted at: 1.3 m/s for a 1.75 m person
double ReferenceHipAmplitude() {
  const double h = 0.530 * 1.75;
  return std::asin(WalkerStrideLength(1.3, h) / (4 * h));
}

Pose RotY(double angle) { return Pose(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY())); }
Pose Move(double x, double y, double z) { return Pose(Eigen::Translation3d(x, y, z)); }

// palettes, sRGB
constexpr std::array<AgentRgb, 12> kShirts = {{{0.80, 0.15, 0.12},
                                               {0.15, 0.35, 0.75},
                                               {0.20, 0.55, 0.25},
                                               {0.95, 0.60, 0.10},
                                               {0.55, 0.25, 0.60},
                                               {0.90, 0.90, 0.88},
                                               {0.10, 0.10, 0.12},
                                               {0.95, 0.85, 0.20},
                                               {0.40, 0.70, 0.85},
                                               {0.85, 0.45, 0.55},
                                               {0.45, 0.45, 0.48},
                                               {0.60, 0.30, 0.15}}};
constexpr std::array<AgentRgb, 6> kTrousers = {{{0.12, 0.14, 0.22},
                                                {0.05, 0.05, 0.06},
                                                {0.30, 0.30, 0.32},
                                                {0.45, 0.38, 0.28},
                                                {0.15, 0.25, 0.45},
                                                {0.20, 0.28, 0.18}}};
constexpr std::array<AgentRgb, 5> kSkins = {{{0.95, 0.78, 0.66},
                                             {0.85, 0.65, 0.50},
                                             {0.72, 0.52, 0.38},
                                             {0.52, 0.36, 0.25},
                                             {0.34, 0.23, 0.16}}};

}  // namespace

const char* WalkerSegmentName(WalkerSegment segment) {
  switch (segment) {
    case WalkerSegment::kThighL:
      return "thigh_l";
    case WalkerSegment::kThighR:
      return "thigh_r";
    case WalkerSegment::kShinL:
      return "shin_l";
    case WalkerSegment::kShinR:
      return "shin_r";
    case WalkerSegment::kUpperArmL:
      return "upper_arm_l";
    case WalkerSegment::kUpperArmR:
      return "upper_arm_r";
    case WalkerSegment::kForearmL:
      return "forearm_l";
    case WalkerSegment::kForearmR:
      return "forearm_r";
  }
  return "";
}

WalkerSkeleton WalkerSkeleton::FromHeight(double height_m) {
  if (!(std::isfinite(height_m) && height_m > 0 && height_m <= 3))
    throw Error("walker height " + std::to_string(height_m) + " m; expected (0, 3] m");
  WalkerSkeleton s;
  const double h = height_m;
  s.height_m = h;
  s.hip_height_m = 0.530 * h;
  s.hip_half_width_m = 0.05 * h;
  s.thigh_m = 0.245 * h;
  s.shank_m = 0.246 * h;
  s.ankle_height_m = 0.039 * h;
  s.shoulder_height_m = 0.818 * h;
  s.shoulder_half_width_m = 0.13 * h;
  s.upper_arm_m = 0.186 * h;
  s.forearm_m = 0.146 * h;
  s.hand_m = 0.108 * h;
  return s;
}

double WalkerStrideLength(double speed_m_s, double hip_height_m) {
  if (!(speed_m_s > 0) || !(hip_height_m > 0)) return 0;
  const double froude = speed_m_s * speed_m_s / (kGravity * hip_height_m);
  return std::min(2.3 * hip_height_m * std::pow(froude, 0.3), 3.2 * hip_height_m);
}

double WalkerStrideFrequency(double speed_m_s, double hip_height_m) {
  const double stride = WalkerStrideLength(speed_m_s, hip_height_m);
  return stride > 0 ? speed_m_s / stride : 0;
}

WalkerJointAngles WalkerGaitAngles(const WalkerSkeleton& s, double phase, double speed_m_s) {
  WalkerJointAngles q;
  const double stride = WalkerStrideLength(speed_m_s, s.hip_height_m);
  const double amp = std::asin(std::min(stride / (4 * s.hip_height_m), 0.8));
  const double scale = amp / ReferenceHipAmplitude();  // 1 at the reference walk
  const double frac = phase - std::floor(phase);
  for (int side = 0; side < 2; ++side) {
    // left leg at phase 0 is at heel strike, the right one half a cycle later
    double u = frac + 0.5 * side;
    u -= std::floor(u);
    q.hip[side] = amp * std::cos(kTwoPi * u);
    // swing: the second half of the leg's cycle, knee flexion peaking mid-swing
    const double swing = u >= 0.5 ? std::sin(kTwoPi * (u - 0.5)) : 0.0;
    q.knee[side] = 60 * kDeg * scale * swing * swing;
    // the arm swings with the opposite leg
    double w = u + 0.5;
    w -= std::floor(w);
    const double opposite_hip = amp * std::cos(kTwoPi * w);
    q.shoulder[side] = -0.6 * opposite_hip;
    q.elbow[side] = 15 * kDeg + 20 * kDeg * scale * std::max(0.0, -std::cos(kTwoPi * w));
  }
  // the straight stance leg (hip to ankle) keeps the ankle at its standing height
  q.pelvis_drop_m = (s.thigh_m + s.shank_m) * (1 - std::cos(q.hip[0]));
  return q;
}

WalkerPose WalkerForwardKinematics(const WalkerSkeleton& s, const WalkerJointAngles& q) {
  WalkerPose p;
  p.X_AR = Move(0, 0, -q.pelvis_drop_m);
  for (int side = 0; side < 2; ++side) {
    const double y = side == 0 ? 1.0 : -1.0;
    // a flexion swings the segment's -z end towards +x: rotation about +y by -angle
    const Pose hip = p.X_AR * Move(0, y * s.hip_half_width_m, s.hip_height_m) * RotY(-q.hip[side]);
    const Pose knee = hip * Move(0, 0, -s.thigh_m) * RotY(q.knee[side]);
    const Pose shoulder = p.X_AR * Move(0, y * s.shoulder_half_width_m, s.shoulder_height_m) *
                          RotY(-q.shoulder[side]);
    const Pose elbow = shoulder * Move(0, 0, -s.upper_arm_m) * RotY(-q.elbow[side]);
    p.X_AS[static_cast<int>(WalkerSegment::kThighL) + side] = hip;
    p.X_AS[static_cast<int>(WalkerSegment::kShinL) + side] = knee;
    p.X_AS[static_cast<int>(WalkerSegment::kUpperArmL) + side] = shoulder;
    p.X_AS[static_cast<int>(WalkerSegment::kForearmL) + side] = elbow;
  }
  return p;
}

WalkerAppearance WalkerAppearanceOf(uint64_t seed, const std::string& agent_name,
                                    double given_height_m) {
  Rng rng(HashKeys(seed, Fnv1a64(agent_name), 0x57A1CE5ULL));
  WalkerAppearance a;
  // Box-Muller from two uniform draws
  const double u1 = 1.0 - rng.UniformD();  // (0, 1]
  const double u2 = rng.UniformD();
  const double normal = std::sqrt(-2 * std::log(u1)) * std::cos(kTwoPi * u2);
  a.height_m = given_height_m > 0 ? given_height_m : std::clamp(1.70 + 0.09 * normal, 1.50, 1.95);
  a.shirt = kShirts[rng.NextU64() % kShirts.size()];
  a.trousers = kTrousers[rng.NextU64() % kTrousers.size()];
  a.skin = kSkins[rng.NextU64() % kSkins.size()];
  return a;
}

}  // namespace penumbra
