#include "penumbra/render/sky/effects_sky.h"

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

const SkyModel& EffectsSky::Update(const Sky& scene_sky, const SkyModel& base_sky,
                                   const EffectsFrame* effects) {
  if (effects == nullptr) return base_sky;
  const EffectsFrame& fx = *effects;
  if (!(fx.sky_luminance_scale >= 0) || !std::isfinite(fx.sky_luminance_scale))
    throw ConfigError("", 0, "effects.sky_luminance_scale", "expected a finite value >= 0");
  const bool sky_changed = fx.sun_direction_W.has_value() || fx.sky_luminance_scale != 1.0f;
  if (!sky_changed) return base_sky;
  bool rebuild = !sky_ || scale_ != fx.sky_luminance_scale ||
                 sun_.has_value() != fx.sun_direction_W.has_value();
  if (!rebuild && fx.sun_direction_W) {
    const double c = sun_->normalized().dot(fx.sun_direction_W->normalized());
    rebuild = c < std::cos(kSkyRebuildDeg * M_PI / 180.0);
  }
  if (rebuild) {
    Sky sky = scene_sky;
    if (fx.sun_direction_W) sky.sun_direction_W = *fx.sun_direction_W;
    sky.radiance *= fx.sky_luminance_scale;
    sky.zenith_luminance *= fx.sky_luminance_scale;
    sky_ = std::make_unique<SkyModel>(sky, base_sky.skybox());
    sun_ = fx.sun_direction_W;
    scale_ = fx.sky_luminance_scale;
  }
  return *sky_;
}

Eigen::Vector3f SkyAmbientRadiance(const SkyModel& sky) {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3f n = Eigen::Vector3f::Zero();
    n[k] = 1;
    sum += sky.Irradiance(n) + sky.Irradiance(-n);
  }
  return sum * static_cast<float>(1.0 / (6.0 * M_PI));
}

float SurfaceWetnessOf(const EffectsFrame* effects) {
  if (effects == nullptr) return 0.0f;
  if (!(effects->surface_wetness >= 0 && effects->surface_wetness <= 1))
    throw ConfigError("", 0, "effects.surface_wetness", "expected a value in [0, 1]");
  return effects->surface_wetness;
}

}  // namespace penumbra
