#pragma once
// the analytic lights of a scene (Light in scene_description.h) as seen from a shading
// point: incident direction, distance and the illuminance they deliver. photometric:
// light intensity is in candela and directional illuminance in lux, so a Lambertian
// surface of albedo rho facing a source of illuminance E has radiance E rho / pi (cd/m^2).
//
//   directional: illuminance E = Light::intensity arriving along -direction; with a
//                non-zero angular radius the direction is sampled uniformly in the cone of
//                the sun disc (soft shadows), each sample carrying the full E.
//   point:       E = I / d^2 (inverse-square law).
//   spot:        E = I s(cos theta) / d^2, s the smoothstep from cos(outer) to cos(inner)
//                (as in glTF KHR_lights_punctual / Filament, with a cubic smoothstep).
//   radius > 0:  point and spot lights sample a point uniformly on the sphere of that
//                radius (soft shadows); E = I / d^2 to the sampled point, which averages to
//                the point-light value for d >> radius.
//
// these are delta lights for MIS purposes (no surface can be hit by a BSDF-sampled ray):
// an estimator takes each sample with weight 1. light poses come from the snapshot: MJCF
// lights (mjcf_light >= 0) from light_position_W / light_direction_W, others from the pose
// of their body, X_WB position_B and R_WB direction_B.
//
// effects (the EffectsFrame given to Update, scene/effects_frame.h): Update multiplies the
// intensity of scene light i by EffectsFrame::light_intensity_scale[i] and appends
// EffectsFrame::extra_lights (world frame, or posed by their body) after the scene's lights, so
// light indices [0, num_scene_lights()) keep their meaning. without effects the lights are exactly
// the scene's.

#include <Eigen/Core>
#include <vector>

#include "penumbra/render/light/light_math.h"
#include "penumbra/render/shading_lanes.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// one light sample at a shading point.
struct LightSample {
  Eigen::Vector3f wi{0, 0, 1};  ///< unit direction from the shading point towards the light (world)
  float distance = 0;           ///< distance to the sampled emitter point, m; +inf for directional
  Eigen::Vector3f E{0, 0,
                    0};  ///< illuminance (lux per channel) on a surface facing wi, colour included
  bool cast_shadow = true;  ///< the light casts shadows (trace a shadow ray)
};

/// samples of one light for kLanes shading points (see LightSampler::SampleLanes).
struct LightSampleLanes {
  Vec3Lanes wi;    ///< unit directions towards the light
  Lanes distance;  ///< m; +inf for directional lights
  Vec3Lanes E;     ///< illuminance per channel (x = r, y = g, z = b), lux
  LaneMask
      valid;  ///< false where Sample() would return false (the other fields are then unspecified)
};

/// a light posed in the world for the current snapshot.
struct PosedLight {
  Light::Type type = Light::Type::kPoint;
  Eigen::Vector3f position_W{0, 0, 0};     ///< point, spot
  Eigen::Vector3f direction_W{0, 0, -1};   ///< unit, direction light travels (directional, spot)
  Eigen::Vector3f intensity_rgb{0, 0, 0};  ///< color x intensity (cd or lux per channel)
  float cos_inner = 1, cos_outer = 1;      ///< spot cone cosines
  float radius_m = 0;
  float cos_angular_radius = 1;  ///< directional: cosine of the sun disc's angular radius
  bool cast_shadow = true;
};

/// lights of a scene, posed per snapshot. Sample is thread-safe between Update calls.
class LightSampler {
 public:
  /// keeps the active lights of `scene` with non-zero intensity.
  explicit LightSampler(const SceneDescription& scene);

  /// poses every light from `snapshot` and applies `effects` (see above; null = none).
  /// @throws Error if an MJCF light id or body index is out of the snapshot's range;
  /// ConfigError for a negative or non-finite intensity scale
  /// (effects.light_intensity_scale[i]); scales beyond the scene's lights are ignored.
  void Update(const WorldSnapshot& snapshot, const EffectsFrame* effects = nullptr);

  /// number of lights (active, non-zero), extra lights of the effects included.
  int size() const { return static_cast<int>(lights_.size()); }
  /// number of lights that come from the scene (the first ones).
  int num_scene_lights() const { return static_cast<int>(sources_.size()); }
  /// the posed lights (after Update).
  const std::vector<PosedLight>& lights() const { return lights_; }
  /// the posed lights as plain data (render/light/light_math.h), one per lights() entry: what
  /// SampleLanes and the CUDA kernels sample.
  const std::vector<LightPod>& pods() const { return pods_; }

  /// samples light `i` as seen from world point p_W with two uniform numbers in [0, 1)
  /// (used only by lights with an extent). returns false when the light sends nothing to
  /// p_W (outside a spot cone, or p_W inside the emitter).
  bool Sample(int i, const Eigen::Vector3f& p_W, float u1, float u2, LightSample* s) const;

  /// Sample() for kLanes shading points at once, lane k with (p_W, u1, u2) lane k: the same
  /// model and random-number use, so it agrees with Sample() to float rounding. the arithmetic
  /// is the shared SampleLight (render/light/light_math.h) the CUDA kernels run.
  void SampleLanes(int i, const Vec3Lanes& p_W, const Lanes& u1, const Lanes& u2,
                   LightSampleLanes* s) const;

 private:
  std::vector<Light> sources_;    // the kept lights of the scene
  std::vector<int> scene_index_;  // per kept light: index in SceneDescription::lights
  std::vector<Eigen::Vector3f> base_intensity_rgb_;  // per kept light, before effects
  int num_bodies_ = 0;
  std::vector<PosedLight> lights_;
  std::vector<LightPod> pods_;  // lights_ as plain data (SyncPods)
  // rewrites pods_ from lights_.
  void SyncPods();
};

}  // namespace penumbra
