#include "penumbra/render/ray.h"

namespace penumbra {

Ray SpawnRay(const SurfaceHit& hit, const Eigen::Vector3f& d) {
  Ray r;
  r.o = OffsetRayOrigin(hit.p_W, d.dot(hit.ng_W) >= 0 ? hit.ng_W : Eigen::Vector3f(-hit.ng_W));
  r.d = d;
  return r;
}

Ray SpawnRayTo(const SurfaceHit& hit, const Eigen::Vector3f& p_W) {
  Ray r = SpawnRay(hit, p_W - hit.p_W);
  r.d = p_W - r.o;
  r.tmax = 1.0f - 1e-4f;
  return r;
}

}  // namespace penumbra
