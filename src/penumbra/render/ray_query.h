#pragma once
// the backend-neutral ray-query interface: closest hits of batches of rays against the
// geometry the cameras see, posed from a WorldSnapshot. the LiDAR (sensors/lidar_scanner.h) and
// the sky irradiance volume (render/sky/sky_irradiance_volume.h) trace only through it, so that a
// new backend (e.g. a GPU ray tracer) implements RayQuery next to its Renderer and the sensors
// stay untouched. the shape follows pbrt-v4's Primitive::Intersect / IntersectP, batched as
// wavefront and GPU tracers consume rays; it holds only what its users call (closest hits and
// occlusion of ray batches, posing, the scene). the realtime media's light volumes
// (render/media/media_realtime.h) trace their shadow rays through Occluded.
//
// implementations: RayScene (Embree 3, render/embree/ray_scene.h). MakeRayQuery
// (render/backends/renderer_factory.h) builds the one RenderSettings::backend names.
//
// contract of every backend:
//  - traced geoms: those in MJCF groups <= 2 whose material has alpha >= 0.5;
//  - surfaces are two-sided and opaque: the normals of a SurfaceHit face the incoming ray;
//  - a ray that is not IsTraceableRay (render/ray.h) is a miss;
//  - a ray's hit does not depend on the batch it is traced in, its position there or the
//    thread count (bit-identical).

#include <functional>
#include <memory>
#include <span>

#include "penumbra/render/ray.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// closest-hit and occlusion queries of one SceneDescription (see the file comment). Intersect
/// and Occluded are thread-safe between Update calls; Update must not run concurrently with them.
class RayQuery {
 public:
  virtual ~RayQuery() = default;

  /// the scene traced: SurfaceHit::geom and SurfaceHit::material index its geoms and materials.
  virtual const SceneDescription& scene() const = 0;

  /// poses every body with snapshot.X_WB (world frame); until the first Update every body has
  /// the identity pose.
  /// @throws Error if snapshot.X_WB.size() differs from the number of bodies.
  virtual void Update(const WorldSnapshot& snapshot) = 0;

  /// closest hits of `rays`, each within its [tmin, tmax]: did_hit[i] is whether rays[i] hit
  /// something, and hits[i] is then that hit (otherwise unspecified). neighbouring rays of a
  /// batch should be coherent (nearby origins, similar directions, e.g. a scan line or a probe's
  /// neighbouring directions): backends trace neighbours together (Embree: packets of 16).
  /// @throws Error if hits or did_hit is shorter than rays.
  void Intersect(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                 std::span<bool> did_hit) const;

  /// occlusion of `rays`: occluded[i] is whether anything blocks rays[i] within its [tmin,
  /// tmax] (the same geometry Intersect traces; an untraceable ray is not occluded). the
  /// verdict of a ray does not depend on its batch (as Intersect's hits).
  /// @throws Error if occluded is shorter than rays.
  void Occluded(std::span<const Ray> rays, std::span<bool> occluded) const;

 protected:
  /// Intersect after its size check: hits and did_hit hold at least rays.size() elements.
  virtual void IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                              std::span<bool> did_hit) const = 0;
  /// Occluded after its size check (occluded holds at least rays.size() elements). this
  /// default asks IntersectBatch for the closest hits (a ray is occluded iff it has one);
  /// backends with an any-hit traversal override it (Embree's rtcOccluded1, the CUDA kernel).
  virtual void OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const;
};

/// builds a RayQuery over `scene`, which is referenced, not copied: it must outlive the query.
using RayQueryFactory = std::function<std::unique_ptr<RayQuery>(const SceneDescription& scene)>;

}  // namespace penumbra
