#include "penumbra/render/ray_query.h"

#include <string>
#include <vector>

#include "penumbra/core/error.h"

namespace penumbra {

void RayQuery::Intersect(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                         std::span<bool> did_hit) const {
  if (hits.size() < rays.size() || did_hit.size() < rays.size()) {
    throw Error("RayQuery::Intersect: " + std::to_string(rays.size()) + " rays but room for " +
                std::to_string(hits.size()) + " hits and " + std::to_string(did_hit.size()) +
                " hit flags");
  }
  if (!rays.empty()) IntersectBatch(rays, hits, did_hit);
}

void RayQuery::Occluded(std::span<const Ray> rays, std::span<bool> occluded) const {
  if (occluded.size() < rays.size()) {
    throw Error("RayQuery::Occluded: " + std::to_string(rays.size()) + " rays but room for " +
                std::to_string(occluded.size()) + " verdicts");
  }
  if (!rays.empty()) OccludedBatch(rays, occluded);
}

void RayQuery::OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const {
  // a closest hit within [tmin, tmax] exists iff something blocks the ray there
  std::vector<SurfaceHit> hits(rays.size());
  IntersectBatch(rays, hits, occluded);
}

}  // namespace penumbra
