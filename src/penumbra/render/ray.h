#pragma once
// the backend-neutral ray types: Ray, the SurfaceHit a ray query returns, and the helpers that
// spawn secondary rays off a hit. shared by the renderer's integrators, the sensors (LiDAR) and
// every ray-query backend (render/ray_query.h; Embree: render/embree/ray_scene.h).

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "penumbra/scene/scene_limits.h"

namespace penumbra {

/// a ray p(t) = o + t d, t in [tmin, tmax]. d need not be unit: t is then in units of |d|
/// (camera rays use d with optical-frame z = 1 so that t is the z-depth).
struct Ray {
  Eigen::Vector3f o{0, 0, 0};  ///< origin, world frame, m
  Eigen::Vector3f d{0, 0, 1};  ///< direction, world frame (non-zero)
  float tmin = 0.0f;
  float tmax = std::numeric_limits<float>::infinity();
};

/// the first surface a ray hits.
struct SurfaceHit {
  float t = 0;                   ///< ray parameter of the hit: p_W = o + t d
  Eigen::Vector3f p_W{0, 0, 0};  ///< hit point, world frame, m
  /// unit geometric normal, world frame, facing the ray (ng . d <= 0).
  Eigen::Vector3f ng_W{0, 0, 1};
  /// unit shading normal (interpolated for meshes), flipped together with ng_W.
  Eigen::Vector3f ns_W{0, 0, 1};
  Eigen::Vector2f uv{0, 0};  ///< mesh texcoords at the hit when the mesh has them, else (0, 0)
  bool has_uv = false;       ///< uv came from mesh texcoords
  /// with has_uv: texcoord units per metre of surface on the hit triangle, sqrt(uv area / area)
  /// (for texture level of detail); else 0.
  float uv_per_m = 0;
  /// with has_uv: the hit triangle's texcoord gradient, texcoord units per metre of a
  /// geom-frame displacement in its plane (duv = duv_dp_G dp_G; zero across the plane, and
  /// all zero for a triangle whose vertices or texcoords are degenerate); else zero.
  Eigen::Matrix<float, 2, 3> duv_dp_G = Eigen::Matrix<float, 2, 3>::Zero();
  /// unit direction of the ray in the geom frame (anisotropic texture filtering).
  Eigen::Vector3f d_G{0, 0, -1};
  bool front_face = true;        ///< the ray hit the outward side (before flipping the normals)
  Eigen::Vector3f p_G{0, 0, 0};  ///< hit point in the geom frame, m (planar texture mapping)
  Eigen::Vector3f n_G{0, 0, 1};  ///< unit outward geometric normal in the geom frame (not flipped)
  int geom = -1;                 ///< index into SceneDescription::geoms
  int material = -1;             ///< index into SceneDescription::materials, -1 = default material
};

/// starts every backend's SurfaceHit of `ray` at parameter t on (geom, material): t, p_W = o +
/// t d, the indices, and no mesh texcoords (has_uv false, uv, uv_per_m and duv_dp_G zero); the
/// backend sets the normals, frames and texcoords after.
inline void BeginSurfaceHit(const Ray& ray, float t, int geom, int material, SurfaceHit* hit) {
  hit->t = t;
  hit->p_W = ray.o + t * ray.d;
  hit->geom = geom;
  hit->material = material;
  hit->has_uv = false;
  hit->uv.setZero();
  hit->uv_per_m = 0;
  hit->duv_dp_G.setZero();
}

/// scale of the offset that moves secondary-ray origins off a surface (relative to 1 + |p|_inf).
constexpr float kRayOffsetScale = 5e-5f;

/// p_W moved off its surface along the unit normal n_W (to the side n_W points to) by
/// kRayOffsetScale (1 + |p_W|_inf): the origin of rays leaving that side.
inline Eigen::Vector3f OffsetRayOrigin(const Eigen::Vector3f& p_W, const Eigen::Vector3f& n_W) {
  return p_W + (kRayOffsetScale * (1.0f + p_W.cwiseAbs().maxCoeff())) * n_W;
}

/// a ray leaving `hit` in direction `d` (world), its origin pushed off the surface along the
/// geometric normal on the side `d` goes to, so that it does not hit the surface it starts on.
Ray SpawnRay(const SurfaceHit& hit, const Eigen::Vector3f& d);

/// a shadow ray from `hit` towards the world point `p_W` that stops just short of it.
Ray SpawnRayTo(const SurfaceHit& hit, const Eigen::Vector3f& p_W);

/// true if the ray o + t d, t in [tmin, tmax] may be traced: every component of o and d finite
/// with |component| <= kMaxRayComponent (scene/scene_limits.h; Embree 3 asserts on larger ones)
/// and tmin, tmax not NaN. every RayQuery (render/ray_query.h) and the Embree ParticleScene
/// treat other rays as misses (not occluded) instead of passing them to the backend.
inline bool IsTraceableRay(float ox, float oy, float oz, float dx, float dy, float dz, float tmin,
                           float tmax) {
  constexpr float m = kMaxRayComponent;
  // written so that NaN fails every comparison; `&` rather than `&&`: no branches, so that the
  // check of a packet's lanes vectorises (it runs for every ray traced)
  return (std::abs(ox) <= m) & (std::abs(oy) <= m) & (std::abs(oz) <= m) & (std::abs(dx) <= m) &
         (std::abs(dy) <= m) & (std::abs(dz) <= m) & (tmin == tmin) & (tmax == tmax);
}
inline bool IsTraceableRay(const Ray& r) {
  return IsTraceableRay(r.o.x(), r.o.y(), r.o.z(), r.d.x(), r.d.y(), r.d.z(), r.tmin, r.tmax);
}

}  // namespace penumbra
