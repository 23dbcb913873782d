#pragma once
// the seam through which controllers cast rays down onto the terrain (the policy controller's
// height_scan observation, control/policy_observation.h). control/ does not include the ray
// tracer: the session implements this over the RayQuery of the world's static geometry
// (session/static_terrain_ray_caster.h, render/ray_query.h) and hands it to the controllers
// that ask for it.

#include <Eigen/Core>
#include <span>

namespace penumbra {

/// vertical ray casts against the static scene. CastDown must be deterministic (a ray's hit
/// does not depend on the batch or the thread count) and callable from the physics thread.
class TerrainRayCaster {
 public:
  virtual ~TerrainRayCaster() = default;
  /// for each origin (world frame, m) the world z (m) of the first surface hit by the ray
  /// from it along -z within `max_distance_m`, or NaN on a miss.
  /// @throws Error if hit_z is shorter than origins_W.
  virtual void CastDown(std::span<const Eigen::Vector3d> origins_W, double max_distance_m,
                        std::span<double> hit_z) const = 0;
};

}  // namespace penumbra
