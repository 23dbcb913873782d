#include "penumbra/render/frame/bvh_ray_query.h"

#include <memory>

#include "penumbra/render/bvh/bvh_traversal.h"

namespace penumbra::cuda {

RayQueryFactory BvhRayQueryFactory(ThreadPool* pool) {
  return [pool](const SceneDescription& scene) -> std::unique_ptr<RayQuery> {
    return std::make_unique<BvhRayQuery>(scene, pool);
  };
}

void BvhRayQuery::IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                                 std::span<bool> did_hit) const {
  const SceneView view = bvh_.view();
  for (size_t i = 0; i < rays.size(); ++i) {
    did_hit[i] = false;
    if (!IsTraceableRay(rays[i])) continue;
    TraceHit th;
    TraceClosest(view, ToTraceRay(rays[i]), &th);
    if (th.instance < 0) continue;
    did_hit[i] = true;
    bvh_.FinishHit(rays[i], th, &hits[i]);
  }
}

bool BvhRayQuery::Occluded(const Ray& ray) const {
  if (!IsTraceableRay(ray)) return false;
  return TraceOccluded(bvh_.view(), ToTraceRay(ray));
}

void BvhRayQuery::OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const {
  for (size_t i = 0; i < rays.size(); ++i) occluded[i] = Occluded(rays[i]);
}

}  // namespace penumbra::cuda
