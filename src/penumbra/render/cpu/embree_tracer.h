#pragma once
// the transport's ray tracer on the CPU (a Tracer of render/transport/path_trace.h: Closest,
// Occluded): Embree's single rays (RayScene::IntersectIds, RayScene::Occluded) with each closest
// hit named as the BVH scene's arrays name it (BvhScene::NameHit: instance, primitive; Embree's
// barycentrics u, v, an analytic shape's part and t as Embree found them), so that the
// transport's surface code (EvaluateSurface, HitNormal) reads the same shading data from the
// same arrays as on the GPU. counts the rays it traces (rays).

#include <cstdint>

#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/ray.h"

namespace penumbra {

/// the Tracer over `rays` (posed for the frame) with hits named as `bvh` (Updated for the same
/// snapshot) names them. one per thread (the ray count is not atomic).
struct EmbreeTracer {
  const RayScene& rays;
  const cuda::BvhScene& bvh;
  /// rays traced so far (closest and occlusion).
  mutable int64_t traced = 0;

  /// the closest hit of r in [tmin, tmax]; hit->instance -1 where none (or where the BVH scene
  /// has no such primitive).
  void Closest(const cuda::TraceRay& r, cuda::TraceHit* hit) const {
    ++traced;
    hit->instance = -1;
    RayHitIds ids;
    if (!rays.IntersectIds(RayOf(r), &ids)) return;
    cuda::TraceHit h;
    h.t = ids.t;
    h.u = ids.u;
    h.v = ids.v;
    h.part = ids.part;
    if (bvh.NameHit(ids.geom, ids.segment, ids.face, &h)) *hit = h;
  }

  /// whether anything blocks r in [tmin, tmax].
  bool Occluded(const cuda::TraceRay& r) const {
    ++traced;
    return rays.Occluded(RayOf(r));
  }

  /// the traversal's ray as a Ray.
  static Ray RayOf(const cuda::TraceRay& r) {
    Ray ray;
    ray.o = Eigen::Vector3f(r.o.x, r.o.y, r.o.z);
    ray.d = Eigen::Vector3f(r.d.x, r.d.y, r.d.z);
    ray.tmin = r.tmin;
    ray.tmax = r.tmax;
    return ray;
  }
};

}  // namespace penumbra
