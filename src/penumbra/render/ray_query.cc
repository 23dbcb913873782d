#include "penumbra/render/ray_query.h"

#include <string>

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

}  // namespace penumbra
