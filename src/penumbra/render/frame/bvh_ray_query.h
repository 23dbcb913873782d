#pragma once
// the CUDA backend's traversal (render/bvh/bvh_traversal.h) run on the CPU as a RayQuery: the
// same PB_HOST_DEVICE code the GPU kernels run, so the tests check the backend's geometry
// against Embree's RayScene on machines without a GPU. one thread; for the tests and as the
// reference of the GPU query, not for speed.

#include <span>

#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/ray_query.h"

namespace penumbra::cuda {

/// makes a BvhRayQuery over the scene it is given, its BVH built over `pool` (may be null; it
/// must outlive the queries, and the factory and the queries' Update must not be called inside
/// one of its loops): the statics' queries of CudaRenderer's and the batch's sky irradiance
/// volume and shelter map (RealtimeFrameData).
RayQueryFactory BvhRayQueryFactory(ThreadPool* pool = nullptr);

/// RayQuery over a BvhScene, traversed on the host (see the file comment).
class BvhRayQuery final : public RayQuery {
 public:
  /// @throws Error as BvhScene. `scene` is referenced: it must outlive the query. `pool` (may
  /// be null) builds the BVH as BvhScene's.
  explicit BvhRayQuery(const SceneDescription& scene, ThreadPool* pool = nullptr)
      : bvh_(scene, pool) {}
  const SceneDescription& scene() const override { return bvh_.scene(); }
  void Update(const WorldSnapshot& snapshot) override { bvh_.Update(snapshot); }
  /// true if anything blocks `ray` in (tmin, tmax); untraceable rays are not occluded.
  bool Occluded(const Ray& ray) const;
  /// RayQuery's batched occlusion: Occluded(ray) (TraceOccluded on the host) for each ray.
  using RayQuery::Occluded;
  const BvhScene& bvh() const { return bvh_; }

 private:
  void IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                      std::span<bool> did_hit) const override;
  void OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const override;
  BvhScene bvh_;
};

/// the traversal's form of `ray`.
inline TraceRay ToTraceRay(const Ray& r) {
  return {{r.o.x(), r.o.y(), r.o.z()}, {r.d.x(), r.d.y(), r.d.z()}, r.tmin, r.tmax};
}

}  // namespace penumbra::cuda
