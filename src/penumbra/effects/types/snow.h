#pragma once
// the `snow` effect type: flakes with turbulent drift around the viewer.

#include <Eigen/Core>
#include <memory>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// snow: flakes of diameter flake_diameter_mm (+-30% uniform per flake), bulk density
/// flake_density_kg_m3, falling at the aggregate speed of Locatelli & Hobbs, J. Geophys.
/// Res. 79, 1974: v = 0.81 D^0.16 m/s (D in mm). the number density follows from the
/// water-equivalent rate: n = (rho_w R) / (m_flake v) with m_flake = rho_f pi D^3 / 6.
/// turbulent drift: each flake adds turbulence_m_s * (sin(2 pi f t + phi_x), sin(2 pi f t +
/// phi_y), 0.3 sin(2 pi f t + phi_z)) with f drawn in [0.5, 1.5] drift_frequency_hz.
/// placement around the viewer as for rain (effects/precipitation.h).
struct SnowParams {
  static constexpr std::string_view kTypeName = "snow";

  double rate_mm_h = 1;                         ///< water equivalent, (0, 100]
  double flake_diameter_mm = 5;                 ///< [0.5, 30]
  double flake_density_kg_m3 = 100;             ///< [20, 900]
  Eigen::Vector3d wind_m_s{0, 0, 0};            ///< horizontal (z ignored)
  double turbulence_m_s = 0.3;                  ///< >= 0
  double drift_frequency_hz = 0.5;              ///< > 0
  Eigen::Vector3d box_half_extents_m{4, 4, 3};  ///< each > 0
  int max_particles = 200000;                   ///< [1, 5e6]
  Eigen::Vector3d color{0.95, 0.95, 0.97};      ///< [0, 1]
  /// true: no flake is drawn under static geometry (render/particles/shelter_map.h); false:
  /// everywhere.
  bool sheltered = true;

  /// effect-type hooks (effects/effect_type.h).
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
