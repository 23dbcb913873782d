#pragma once
// the effects stage: turns the world's effect configs, its seed and the sim time into an
// EffectsFrame (scene/effects_frame.h) for the renderer. models and units per effect type
// are documented in effects/types/<type>.h and docs/effects.md; the engine itself knows no
// type: it binds each effect through the registry (effect_types.h) and evaluates the
// instances in the order of the list.
//
// determinism: every random draw comes from core/rng.h keyed by (seed, effect index,
// particle / voxel / slot index); nothing depends on wall-clock time, call order of
// different times (except the fluid state, below) or thread count.
//
// stateful effects (smoke plume, fire) keep a grid fluid that is stepped with the fixed
// internal dt (FluidParams::dt_sec) from t = 0 up to the requested time: the state at
// time t is that after floor(t / dt) steps, whatever the sequence of earlier calls. calls
// are expected with non-decreasing t; when t goes backwards the fluid restarts from its
// t = 0 state and steps forward again (same result, more work).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// evaluates all effects of a world at given sim times.
class EffectsEngine {
 public:
  /// validates the configs (ValidateEffectsOrThrow) and binds them to the scene: light
  /// events find their target light by name, flashlights their body, vdb_smoke loads its
  /// file. `seed` is the world seed.
  /// @throws ConfigError("", 0, "effects[i].<key>", problem) for bad values, an unknown light
  ///         or body name, or a .vdb file that cannot be read or has no float grid `grid`.
  EffectsEngine(const std::vector<EffectConfig>& effects, uint64_t seed,
                const SceneDescription& scene);
  ~EffectsEngine();
  EffectsEngine(const EffectsEngine&) = delete;
  EffectsEngine& operator=(const EffectsEngine&) = delete;

  /// the EffectsFrame at sim time `time_sec` (>= 0). deterministic: depends only on the
  /// configs, the seed, the time and, for camera-following particles (rain, snow), on
  /// `viewer_W` (position of the viewer in the world, m), and for attached flashlights on
  /// `X_WB` (pose of every SceneDescription::bodies entry, as WorldSnapshot::X_WB; may be
  /// null when no flashlight is attached).
  /// light_intensity_scale has one entry per scene light when any light event or sun effect
  /// exists. a sun effect also moves the scene's directional lights: each is switched off
  /// (scale 0) and re-emitted in extra_lights pointing along -sun_direction_W with its
  /// configured illuminance taken as the illuminance at the zenith, times
  /// DirectSunAttenuation(apparent elevation) (0 below the horizon).
  /// @throws Error when an attached flashlight needs X_WB and it is null or too short.
  std::shared_ptr<const EffectsFrame> Evaluate(double time_sec, const Eigen::Vector3d& viewer_W,
                                               const std::vector<Pose>* X_WB = nullptr);

  /// number of effects.
  size_t size() const { return instances_.size(); }

 private:
  /// the configs the instances refer to (never resized after construction).
  const std::vector<EffectConfig> effects_;
  std::vector<std::unique_ptr<EffectInstance>> instances_;  ///< one per effect, same order
  size_t num_scene_lights_ = 0;
  bool scales_scene_lights_ = false;  ///< any instance ScalesSceneLights()
  /// threads (hardware concurrency) for the noise smoke voxels and the precipitation
  /// particles, made on first use; the results do not depend on the thread count.
  std::unique_ptr<ThreadPool> pool_;
  ThreadPool* Pool();
};

}  // namespace penumbra
