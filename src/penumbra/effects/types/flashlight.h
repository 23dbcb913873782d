#pragma once
// the `flashlight` effect type: a spot light on waypoints or attached to a body.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// one pose sample of a flashlight path (linear in position, normalised-lerp in direction).
struct FlashlightWaypoint {
  double t_sec = 0;  ///< sim time, strictly increasing along the list
  Eigen::Vector3d position_W{0, 0, 1};
  Eigen::Vector3d direction_W{1, 0, 0};  ///< beam direction, non-zero
};

/// flashlight: a spot light moving along waypoints (held at the ends) or attached to a
/// body (`attach` = body name of SceneDescription::bodies; its pose comes from the
/// caller's X_WB at Evaluate). intensity scales with the effect's weight.
struct FlashlightParams {
  static constexpr std::string_view kTypeName = "flashlight";

  std::vector<FlashlightWaypoint> waypoints;  ///< used when attach is ""
  std::string attach;                         ///< body name, or "" for waypoints
  Eigen::Vector3d position_B{0, 0, 0};        ///< attached: position in the body frame
  Eigen::Vector3d direction_B{1, 0, 0};       ///< attached: beam direction in the body frame
  double intensity_cd = 300;                  ///< on-axis luminous intensity, > 0
  double inner_angle_deg = 10, outer_angle_deg = 20;  ///< 0 < inner <= outer < 90
  Eigen::Vector3d color{1.0, 0.95, 0.85};             ///< tint, [0, 1], max component > 0
  double radius_m = 0.02;                             ///< >= 0

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  /// @throws ConfigError("", 0, "effects[i].attach", ...) when the scene has no such body.
  /// the instance throws Error at Evaluate when attached and ctx.X_WB lacks the body's pose.
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
