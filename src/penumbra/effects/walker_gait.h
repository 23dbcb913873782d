#pragma once
// articulated NPC people: the skeleton of a walker (segment lengths from its height), its
// procedural walking cycle (joint angles from the gait phase and the walking speed) and the
// forward kinematics that turn the angles into segment poses. pure functions, no state: the
// phase is integrated over sim time by effects/agent_animation.h.
//
// skeleton: segment lengths are fractions of the standing height H (Winter, "Biomechanics and
// Motor Control of Human Movement", 4th ed. 2009, fig. 4.1, after Drillis & Contini 1966):
// hip joint height 0.530 H, thigh 0.245 H, shank 0.246 H, ankle height 0.039 H, shoulder
// height 0.818 H, upper arm 0.186 H, forearm 0.146 H, hand 0.108 H.
//
// gait model: the stride length (two steps) follows the dynamic-similarity relation of
// Alexander, "Stride length and speed for adults, children, and fossil hominids", Am. J. Phys.
// Anthropol. 63:23-27 (1984): lambda / h = 2.3 (v^2 / (g h))^0.3 with h the hip height, so
// lambda grows as v^0.6 and the stride frequency f = v / lambda as v^0.4 (1.3 m/s, H = 1.75 m:
// lambda = 1.29 m, f = 1.0 Hz, 120 steps/min). the cycle is sinusoidal: the hip (thigh) angle
// is theta_max cos(2 pi phase) with theta_max = asin(lambda / (4 h)), so that at heel strike
// (phase 0 for the left leg, 0.5 for the right) the feet are a step (lambda / 2) apart; the
// pelvis drops by l (1 - cos theta), l the hip-to-ankle length, so the straight stance leg
// keeps its foot on the floor;
// the knee flexes only in the second half of the leg's cycle (swing, up to 60 deg at 1.3 m/s,
// scaled by theta_max); the arms swing against the legs (shoulder -0.6 x the opposite hip)
// with the elbow bent 15 deg plus up to 20 deg in the forward swing. the gait stays a walk at
// every speed (no flight phase); lambda is capped at 3.2 h (theta_max = 53 deg).
//
// frames: the agent frame A (effects/agent_path.h: origin on the floor under the agent, x
// forward, y left, z up). the root (pelvis) body frame R is A lifted by the pelvis drop
// (z = -drop). each limb segment S has its origin at its proximal joint (hip, knee, shoulder,
// elbow) and extends along its -z axis; a positive flexion swings the distal end forward (+x
// of A) for hips, shoulders and elbows and backward for knees.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

#include "penumbra/core/pose.h"

namespace penumbra {

/// the articulated segments of a walker besides the root (pelvis, torso and head).
enum class WalkerSegment {
  kThighL,
  kThighR,
  kShinL,
  kShinR,
  kUpperArmL,
  kUpperArmR,
  kForearmL,
  kForearmR,
};
inline constexpr int kWalkerSegmentCount = 8;

/// "thigh_l", "thigh_r", "shin_l", "shin_r", "upper_arm_l", "upper_arm_r", "forearm_l",
/// "forearm_r": the body name suffix of a segment (compose/agent_bodies.h).
const char* WalkerSegmentName(WalkerSegment segment);

/// segment lengths and joint positions of a walker of standing height height_m (see the file
/// header for the proportions), m.
struct WalkerSkeleton {
  double height_m = 1.75;
  double hip_height_m = 0;       ///< hip joint above the floor, standing
  double hip_half_width_m = 0;   ///< hip joints at y = +-this
  double thigh_m = 0;            ///< hip -> knee
  double shank_m = 0;            ///< knee -> ankle
  double ankle_height_m = 0;     ///< ankle above the sole
  double shoulder_height_m = 0;  ///< shoulder joint above the floor, standing
  double shoulder_half_width_m = 0;
  double upper_arm_m = 0;  ///< shoulder -> elbow
  double forearm_m = 0;    ///< elbow -> wrist
  double hand_m = 0;       ///< wrist -> finger tips

  /// the proportions of the file header for a standing height in (0, 3] m.
  /// @throws Error for a height outside (0, 3] m or not finite.
  static WalkerSkeleton FromHeight(double height_m);
};

/// stride length (m; two steps) at walking speed speed_m_s (>= 0) for hip height hip_height_m
/// (> 0): Alexander (1984), lambda = 2.3 h (v^2 / (g h))^0.3, capped at 3.2 h. 0 at speed 0.
double WalkerStrideLength(double speed_m_s, double hip_height_m);
/// stride frequency (Hz, full cycles per second) = speed / stride length; 0 at speed 0.
double WalkerStrideFrequency(double speed_m_s, double hip_height_m);

/// joint angles of one instant of the walking cycle, rad (signs: file header).
struct WalkerJointAngles {
  std::array<double, 2> hip{};       ///< [left, right] thigh flexion
  std::array<double, 2> knee{};      ///< knee flexion (>= 0)
  std::array<double, 2> shoulder{};  ///< upper arm flexion
  std::array<double, 2> elbow{};     ///< elbow flexion (>= 0)
  double pelvis_drop_m = 0;          ///< root lowered by this (>= 0), m
};

/// the angles at gait phase `phase` (cycles; only its fractional part matters; 0 = left heel
/// strike) when walking at speed_m_s (>= 0; 0 = standing: every angle 0 but the elbows' 15 deg).
WalkerJointAngles WalkerGaitAngles(const WalkerSkeleton& skeleton, double phase, double speed_m_s);

/// the walker's body frames in the agent frame A for joint angles `q`: X_AR (root) and X_AS of
/// every segment, indexed by WalkerSegment.
struct WalkerPose {
  Pose X_AR = Pose::Identity();
  std::array<Pose, kWalkerSegmentCount> X_AS;
};
WalkerPose WalkerForwardKinematics(const WalkerSkeleton& skeleton, const WalkerJointAngles& q);

/// sRGB colour (display-referred, as MJCF rgba).
struct AgentRgb {
  double r = 0, g = 0, b = 0;
  bool operator==(const AgentRgb&) const = default;
};

/// what a person looks like: its height and clothing and skin colours.
struct WalkerAppearance {
  double height_m = 1.75;
  AgentRgb shirt, trousers, skin;
};

/// the appearance of the person named `agent_name` in a run with world seed `seed`: a pure
/// function of (seed, name). the height is drawn from a normal distribution of mean 1.70 m and
/// standard deviation 0.09 m (adult stature, both sexes pooled; NCD-RisC, "A century of trends
/// in adult human height", eLife 5:e13410, 2016, reports national means of 1.50-1.83 m),
/// clipped to [1.50, 1.95] m, unless `given_height_m` > 0 (the world file's height_m), which
/// is used as is; shirt, trousers and skin are drawn from fixed palettes (12, 6 and 5 colours).
WalkerAppearance WalkerAppearanceOf(uint64_t seed, const std::string& agent_name,
                                    double given_height_m);

}  // namespace penumbra
