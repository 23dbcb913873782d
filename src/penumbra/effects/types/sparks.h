#pragma once
// the `sparks` effect type: ballistic embers from a point or from a fire.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// sparks: embers born at rate_per_s at `position_W` (or at the first emitter of the fire
/// named `fire`), with initial speed speed_m_s in a cone of spread_deg around +z, moving
/// ballistically (drag-free) under gravity_m_s2 (gravity minus buoyancy); each lives
/// lifetime_sec and its radius shrinks linearly to 0 as it burns out. emission: the
/// blackbody colour of temperature_k times luminance_cd_m2 (0 = the blackbody luminance).
/// ember k is born at k / rate_per_s and kept with probability weight(birth time).
struct SparksParams {
  static constexpr std::string_view kTypeName = "sparks";

  std::string fire;                     ///< name of a fire effect to sit on, or ""
  Eigen::Vector3d position_W{0, 0, 0};  ///< used when fire is ""
  double rate_per_s = 20;               ///< (0, 1e5]
  double speed_m_s = 2.5;               ///< [0, 100]
  double spread_deg = 25;               ///< [0, 90]
  double lifetime_sec = 1.5;            ///< (0, 60]
  double gravity_m_s2 = 4.0;            ///< net downward acceleration (gravity - buoyancy)
  double radius_m = 0.004;              ///< (0, 0.1]
  double temperature_k = 1600;          ///< [800, 4000]
  double luminance_cd_m2 = 0;           ///< 0 = blackbody luminance of temperature_k, else > 0

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
  /// a non-empty `fire` must name a fire effect of the run (problem at key "fire").
  std::optional<EffectProblem> CheckReferences(const std::vector<EffectConfig>& effects) const;
};

}  // namespace penumbra
