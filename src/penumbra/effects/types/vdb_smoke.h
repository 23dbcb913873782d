#pragma once
// the `vdb_smoke` effect type: a density grid read from an OpenVDB file.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// vdb_smoke: a `density` float grid from an OpenVDB file, resampled (trilinear) to a
/// dense GridMedium (effects/vdb_loader.h). placement: if the effect has a region, the
/// grid's active bounding box is stretched to fill it; otherwise the file's own transform
/// (world frame, metres) is used. the extinction scales with the effect's weight.
struct VdbSmokeParams {
  static constexpr std::string_view kTypeName = "vdb_smoke";

  std::string file;                       ///< .vdb path (absolute after loading a world file)
  std::string grid = "density";           ///< float grid name
  int max_resolution = 128;               ///< cap of voxels per axis after resampling, [4, 512]
  double density_scale_per_m = 1.0;       ///< sigma_t at density 1, > 0
  Eigen::Vector3d albedo{0.7, 0.7, 0.7};  ///< [0, 1]
  double g = 0.0;                         ///< (-1, 1)

  /// effect-type hooks (effects/effect_type.h). Read resolves a relative `file` against the
  /// world file's folder; Validate checks that the file exists; Bind loads the grid.
  static std::vector<std::string_view> Keys();
  void Read(const EffectParamReader& r);
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  /// @throws ConfigError("", 0, "effects[i].file" / ".grid", ...) from LoadVdbDensity.
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
