#pragma once
// parts shared by the homogeneous media (fog, dust): the extinction given directly or as
// meteorological optical range, and the HomogeneousMedium they evaluate to.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/effects/effect_type.h"

namespace penumbra {

/// extinction given either directly or as meteorological optical range (MOR, WMO No. 8,
/// 2018: distance at which the contrast of a black object falls to 5%):
///   sigma_t = -ln(0.05) / MOR = 2.996 / MOR  (Koschmieder's law).
/// exactly one of the two must be set.
struct ExtinctionSpec {
  std::optional<double> sigma_t_per_m;  ///< extinction coefficient, 1/m, > 0 (<= 1e3)
  std::optional<double> mor_m;          ///< MOR, m, > 0 (>= 1e-3)
  /// sigma_t in 1/m (throws nothing; call after validation).
  double SigmaT() const;
};

/// reads the keys sigma_t_per_m and mor_m of an effect entry (whichever are present).
void ReadExtinction(const EffectParamReader& r, ExtinctionSpec* e);

/// exactly one of the two set, in range; problems at "sigma_t_per_m" / "mor_m".
void CheckExtinction(const ExtinctionSpec& e, EffectChecker* c);

/// the medium of a fog / dust effect at weight w: sigma_t * w per channel, the given
/// albedo, g, height falloff (1/m) and base height (m), inside `region`, or without one in
/// the layer below world z layer_top_m (+inf = everywhere).
HomogeneousMedium MakeHomogeneousMedium(double sigma_t_per_m, const Eigen::Vector3d& albedo,
                                        double g, double height_falloff_per_m, double base_height_m,
                                        const std::optional<BoxRegion>& region, double layer_top_m,
                                        double w);

/// the default top (world z, m) of an unbounded medium's layer in `scene`: the top of the
/// model's bounding sphere, center_W.z + extent_m (MuJoCo's stat.center and stat.extent).
double DefaultLayerTopM(const SceneDescription& scene);

/// the effect-type hooks (effects/effect_type.h) of a homogeneous medium (fog, dust): the
/// two types differ only in their defaults and in the name of the albedo key. P derives
/// from HomogeneousMediumType<P> and has the fields `ExtinctionSpec extinction`, `double g`
/// (Henyey-Greenstein asymmetry), `double height_falloff_per_m`, `double base_height_m`,
/// `std::optional<double> layer_top_m`, and
/// the albedo per channel (Eigen::Vector3d) at the pointer to member P::kAlbedo, read from
/// the key P::kAlbedoKey. instantiated for FogParams and DustParams (homogeneous.cc).
template <typename P>
struct HomogeneousMediumType {
  /// sigma_t_per_m, mor_m, the albedo key, g, height_falloff_per_m, base_height_m, layer_top_m.
  static std::vector<std::string_view> Keys();
  /// reads the keys that are present.
  void Read(const EffectParamReader& r);
  /// extinction as CheckExtinction, albedo in [0, 1], g in (-1, 1), falloff >= 0, base and
  /// layer top finite.
  void Validate(const EffectConfig& e, EffectChecker* c) const;
  /// one HomogeneousMedium (MakeHomogeneousMedium) in the effect's region (or its layer, top
  /// layer_top_m or DefaultLayerTopM(ctx.scene)) while the weight is > 0.
  std::unique_ptr<EffectInstance> Bind(const EffectConfig& e, const EffectBindContext& ctx) const;
};

}  // namespace penumbra
