#include "penumbra/session/static_terrain_ray_caster.h"

#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/geometry/static_geometry.h"

namespace penumbra {

StaticTerrainRayCaster::StaticTerrainRayCaster(const SceneDescription& scene,
                                               const WorldSnapshot& snapshot,
                                               RenderSettings::Backend backend) {
  Eigen::Vector3d lo, hi;
  statics_ = StaticGeoms(scene, snapshot.X_WB, &lo, &hi);
  query_ = MakeRayQuery(statics_, backend);
  query_->Update(snapshot);
}

StaticTerrainRayCaster::~StaticTerrainRayCaster() = default;

void StaticTerrainRayCaster::CastDown(std::span<const Eigen::Vector3d> origins_W,
                                      double max_distance_m, std::span<double> hit_z) const {
  if (hit_z.size() < origins_W.size())
    throw Error("terrain ray caster: " + std::to_string(hit_z.size()) + " outputs for " +
                std::to_string(origins_W.size()) + " rays");
  const size_t n = origins_W.size();
  rays_.resize(n);
  hits_.resize(n);
  if (capacity_ < n) {
    did_hit_ = std::make_unique<bool[]>(n);
    capacity_ = n;
  }
  for (size_t k = 0; k < n; ++k) {
    rays_[k].o = origins_W[k].cast<float>();
    rays_[k].d = Eigen::Vector3f(0, 0, -1);
    rays_[k].tmin = 0;
    rays_[k].tmax = static_cast<float>(max_distance_m);
  }
  query_->Intersect(rays_, hits_, std::span<bool>(did_hit_.get(), n));
  for (size_t k = 0; k < n; ++k) hit_z[k] = did_hit_[k] ? hits_[k].p_W.z() : NAN;
}

}  // namespace penumbra
