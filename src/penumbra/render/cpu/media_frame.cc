#include "penumbra/render/cpu/media_frame.h"

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

MediaFrame::MediaFrame(const SceneDescription& scene, RayQueryFactory make_query)
    : scene_(scene), shelter_(std::move(make_query)) {}

void MediaFrame::Prepare(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                         const Camera& camera, const CameraView& view,
                         const RenderSettings& settings, const LightSampler& lights,
                         const RayScene& rays, const SkyModel& base_sky,
                         SkyIrradianceVolume* sky_volume, ThreadPool* pool) {
  const EffectsFrame* fx = effects && !effects->empty() ? effects : nullptr;
  active_ = fx != nullptr;
  sky_ = &base_sky;
  realtime_ok_ = false;
  wetness_ = 0;
  if (!active_) {
    media_.Build(nullptr);
    particles_.Build(nullptr, camera, 0, StreakRays::kAny);
    return;
  }
  // sky: moved sun and luminance scale (render/sky/effects_sky.h, shared with the CUDA backend).
  const SkyModel& sky = effects_sky_.Update(scene_.sky, base_sky, fx);
  wetness_ = SurfaceWetnessOf(fx);
  if (&sky != &base_sky) {
    sky_ = &sky;
    sky_ambient_ = SkyAmbientRadiance(*sky_);
  } else {
    if (base_sky_seen_ != &base_sky) {
      base_sky_ambient_ = SkyAmbientRadiance(base_sky);
      base_sky_seen_ = &base_sky;
    }
    sky_ambient_ = base_sky_ambient_;
  }

  media_.Build(fx);
  const bool realtime = settings.tier == RenderSettings::Tier::kRealtime;
  // the sky let through by the static geometry, for the realtime media and the particles.
  const SkyIrradianceVolume* occluded_sky = nullptr;
  if (sky_volume != nullptr && ((realtime && !media_.empty()) || !fx->particles.empty())) {
    sky_volume->Update(scene_, snapshot, *sky_, pool);
    if (!sky_volume->empty()) occluded_sky = sky_volume;
  }
  if (!media_.empty() && realtime) {
    const uint64_t frame_key =
        HashKeys(HashKeys(settings.seed, static_cast<uint64_t>(view.camera_index)),
                 static_cast<uint64_t>(view.frame_index));
    realtime_.Build(media_, lights, rays, camera, frame_key, scene_.center_W.cast<float>(),
                    scene_.extent_m, sky_ambient_, occluded_sky, pool);
    realtime_ok_ = true;
  }
  bool sheltered = false;
  for (const ParticleSet& ps : fx->particles) sheltered = sheltered || ShelterApplies(ps);
  if (sheltered) shelter_.Update(scene_, snapshot, pool);
  particles_.Build(fx, camera, view.exposure_time_sec,
                   realtime ? StreakRays::kPixelCentres : StreakRays::kCamera, pool,
                   media_.empty() ? nullptr : &media_, sheltered ? &shelter_ : nullptr);
  if (!particles_.empty()) particles_.PrecomputeRain(lights, sky_ambient_, occluded_sky, pool);
}

}  // namespace penumbra
