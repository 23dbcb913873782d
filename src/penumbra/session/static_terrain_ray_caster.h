#pragma once
// the terrain ray caster (control/terrain_ray_caster.h) of a session: vertical rays against
// the world's static geometry (the world body and static bodies, render/geometry/static_geometry.h)
// through the RayQuery of the world's render backend (render/ray_query.h), posed once at
// load. robots and other moving bodies are not hit, so a robot's own legs never shadow its
// height scan (as Isaac Lab's RayCaster sees only its mesh_prim_paths, the terrain, and
// legged_gym samples only the terrain height field).

#include <memory>
#include <vector>

#include "penumbra/control/terrain_ray_caster.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// vertical rays against the static geoms of a scene. CastDown may be called from one thread
/// at a time (it reuses its buffers); results do not depend on batch or thread count
/// (RayQuery's contract).
class StaticTerrainRayCaster final : public TerrainRayCaster {
 public:
  /// the static geoms of `scene` posed by `snapshot` (X_WB of every body), traced by `backend`.
  /// @throws ConfigError for an unknown backend; Error as the backend's constructor.
  StaticTerrainRayCaster(const SceneDescription& scene, const WorldSnapshot& snapshot,
                         RenderSettings::Backend backend);
  ~StaticTerrainRayCaster() override;

  void CastDown(std::span<const Eigen::Vector3d> origins_W, double max_distance_m,
                std::span<double> hit_z) const override;

 private:
  SceneDescription statics_;  ///< referenced by query_: declared first, destroyed last
  std::unique_ptr<RayQuery> query_;
  mutable std::vector<Ray> rays_;
  mutable std::vector<SurfaceHit> hits_;
  mutable std::unique_ptr<bool[]> did_hit_;
  mutable size_t capacity_ = 0;
};

}  // namespace penumbra
