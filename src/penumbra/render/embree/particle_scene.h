#pragma once
// the particles' streaks (render/particles/particle_streaks.h) as an Embree scene, for the
// pathtraced tier's jittered camera rays: every streak of the frame is one Embree round linear
// curve (a capsule: cone segment with spherical ends) in this class's own RTCScene, built per frame
// (BVH over all streaks). the realtime tier splats the same streaks per pixel instead
// (ParticleStreaks::PixelHit) and builds no Embree scene.

#include <memory>

#include "penumbra/render/particles/particle_streaks.h"
#include "penumbra/render/ray.h"

namespace penumbra {

/// the streaks of one frame and camera, traceable. Build, then Intersect is thread-safe.
class ParticleScene : public ParticleStreaks {
 public:
  ParticleScene();
  ~ParticleScene();

  /// ParticleStreaks::Build; for rays other than kPixelCentres also the Embree scene of the
  /// streaks (Intersect).
  /// @throws as ParticleStreaks::Build; Error if the Embree device cannot be created.
  void Build(const EffectsFrame* fx, const Camera& camera, double exposure_time_sec,
             StreakRays rays, ThreadPool* pool = nullptr, const MediaScene* media = nullptr,
             const ShelterMap* shelter = nullptr);

  /// nearest streak along `ray` within [ray.tmin, tmax] (Build for rays other than
  /// kPixelCentres); false if none.
  bool Intersect(const Ray& ray, float tmax, ParticleHit* hit) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra
