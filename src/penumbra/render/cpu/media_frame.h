#pragma once
// everything of a frame's EffectsFrame (scene/effects_frame.h) that the renderer draws,
// prepared once per frame by EmbreeRenderer and handed to the integrators through
// FrameContext::effects (null in clear conditions, so a frame without effects takes none of
// the effects code paths):
//  - media (MediaScene; both tiers) and the realtime tier's light volumes (RealtimeMedia);
//  - particle streaks for the frame's camera and exposure (ParticleScene), without the
//    rain and snow that static geometry covers from above (ShelterMap);
//  - the sky moved to EffectsFrame::sun_direction_W and scaled by sky_luminance_scale, and the
//    surface wetness (ApplySurfaceWetness, material_eval.h): render/sky/effects_sky.h, which the
//    CUDA backend's realtime path shares.
// light intensity scales and extra lights are applied by LightSampler::Update.

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/embree/particle_scene.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/particles/shelter_map.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/sky/effects_sky.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// per-frame effects state of one renderer. not thread-safe; the accessors are, after Prepare.
class MediaFrame {
 public:
  /// `scene` (the renderer's copy) must outlive this object; `make_query` traces the shelter
  /// map of the precipitation (shelter_map.h) when a frame has rain or snow.
  MediaFrame(const SceneDescription& scene, RayQueryFactory make_query);

  /// prepares `effects` at `snapshot` (none when `effects` is null or empty) for
  /// `view` (its exposure time, camera and frame index) seen through `camera`. `lights` must
  /// already be posed for the snapshot and `rays` updated. realtime light volumes are built only
  /// for that tier. `sky_volume` (may be null) is the renderer's occluded sky light
  /// (sky_irradiance_volume.h): Prepare brings it up to date (Update) with the frame's sky when
  /// the media of the realtime tier or any particles need it, and they are then lit by the sky
  /// it lets through (in the pathtraced tier the media's sky light is occluded by its own
  /// shadow rays). it must outlive this object until the next Prepare.
  /// @throws ConfigError for malformed effects (see MediaScene::Build, ParticleScene::Build).
  void Prepare(const WorldSnapshot& snapshot, const EffectsFrame* effects, const Camera& camera,
               const CameraView& view, const RenderSettings& settings, const LightSampler& lights,
               const RayScene& rays, const SkyModel& base_sky, SkyIrradianceVolume* sky_volume,
               ThreadPool* pool);

  /// any effect is active this frame.
  bool active() const { return active_; }
  /// the sky to use this frame (base_sky of Prepare unless the effects change it).
  const SkyModel* sky() const { return sky_; }
  /// sphere-average radiance of sky() (unoccluded).
  const Eigen::Vector3f& sky_ambient() const { return sky_ambient_; }
  /// media, or null when there are none.
  const MediaScene* media() const { return media_.empty() ? nullptr : &media_; }
  /// realtime light volumes, or null (no media, or the pathtraced tier).
  const RealtimeMedia* realtime_media() const { return realtime_ok_ ? &realtime_ : nullptr; }
  /// particle streaks, or null when there are none.
  const ParticleScene* particles() const { return particles_.empty() ? nullptr : &particles_; }
  /// EffectsFrame::surface_wetness (0 when inactive).
  float surface_wetness() const { return wetness_; }

 private:
  const SceneDescription& scene_;
  bool active_ = false;
  const SkyModel* sky_ = nullptr;
  Eigen::Vector3f sky_ambient_{0, 0, 0};
  Eigen::Vector3f base_sky_ambient_{0, 0, 0};
  const SkyModel* base_sky_seen_ = nullptr;
  EffectsSky effects_sky_;
  MediaScene media_;
  RealtimeMedia realtime_;
  bool realtime_ok_ = false;
  ParticleScene particles_;
  ShelterMap shelter_;  // built at the first frame with rain or snow
  float wetness_ = 0;
};

}  // namespace penumbra
