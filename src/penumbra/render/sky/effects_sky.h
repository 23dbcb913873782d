#pragma once
// the sky and surface wetness of a frame under effects (scene/effects_frame.h), for both
// backends: the CPU's MediaFrame (render/cpu/media_frame.h) and the CUDA backend's realtime
// path (render/cuda/realtime_frame.h) take them from here, so the two rebuild the sky at the
// same frames and draw the same sky.
//  - EffectsFrame::sun_direction_W and sky_luminance_scale: a SkyModel of the scene's Sky with
//    the sun moved and sky.radiance and zenith_luminance scaled, built when the sun moved by
//    more than kSkyRebuildDeg since the last one or the scale (or whether the sun is set)
//    changed (building SkyModel's tables is not free, docs/performance.md; the sun moves
//    slowly). the sky light occluded by the static geometry (SkyIrradianceVolume::Update)
//    relights when the SkyModel object changes.
//  - EffectsFrame::surface_wetness, checked to lie in [0, 1] (applied by ApplySurfaceWetness /
//    SurfaceWetnessTerms, render/material/wetness_math.h).
// light intensity scales and extra lights are applied by LightSampler::Update.

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "penumbra/render/sky/sky_model.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// the sun must move by more than this (degrees) before the sky tables are rebuilt.
constexpr double kSkyRebuildDeg = 0.1;

/// the sky of the frames of one renderer under effects (file comment). not thread-safe.
class EffectsSky {
 public:
  /// the sky of a frame under `effects` (null: none): `base_sky` when they neither move the sun
  /// nor scale the sky, else the effects' SkyModel of `scene_sky` (the scene's Sky, which
  /// base_sky was built from; the new model keeps base_sky's skybox), rebuilt as the file
  /// comment says. the reference stays valid until the next call (or while this object lives,
  /// for base_sky: while the caller keeps it).
  /// @throws ConfigError (key effects.sky_luminance_scale) for a negative or non-finite scale.
  const SkyModel& Update(const Sky& scene_sky, const SkyModel& base_sky,
                         const EffectsFrame* effects);

 private:
  std::unique_ptr<SkyModel> sky_;
  std::optional<Eigen::Vector3d> sun_;
  float scale_ = 1.0f;
};

/// sphere-average radiance of a sky (cd/m^2 per channel): the mean of its irradiance on the
/// six axis-aligned normals divided by pi (exact for radiance that is linear in direction). the
/// open sky's ambient term of the media and the particles.
Eigen::Vector3f SkyAmbientRadiance(const SkyModel& sky);

/// EffectsFrame::surface_wetness of `effects` (0 for null).
/// @throws ConfigError (key effects.surface_wetness) for a value outside [0, 1] or NaN.
float SurfaceWetnessOf(const EffectsFrame* effects);

}  // namespace penumbra
