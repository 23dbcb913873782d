#pragma once
// the ray-traceable form of a SceneDescription, on Intel Embree 3.
//
// layout (two-level, as Embree's instancing tutorial): the geoms of every moving body form
// one RTCScene in the body frame, built once; the geoms of all static bodies (the world body
// and bodies with Body::is_static) are merged into one RTCScene in the world frame. a top-level
// scene instances these with the body poses X_WB (identity for the static scene). Update()
// only rewrites the instance transforms of bodies that moved and recommits the top level, so
// moving bodies costs O(bodies); the static scene is rebuilt only if a static body's pose
// changes (normally once, at the first Update, which brings their actual poses).
//
// geom shapes: box, mesh and height field are triangle geometry (box faces are exact
// planes; meshes carry vertex normals for smooth shading and texcoords); plane, sphere,
// capsule, ellipsoid and cylinder are Embree user geometry intersected analytically in
// double precision, so depths are exact up to float rounding of the ray (LiDAR ranges). the
// user-geometry callbacks intersect all lanes of an Embree packet together
// (IntersectAnalyticLanes, analytic_lanes.h: IntersectAnalytic's arithmetic on vectorised
// lanes, bit-identical results without FMA). an infinite plane (MJCF half-size 0) is clipped
// to kInfinitePlaneHalfSize.
//
// planes stay user geometry: as two Embree triangles (exact for axis-aligned planes with the
// depth recomputed in double) they cost more (docs/performance.md), and tilted float
// triangles 1e4 m wide would move the plane by ~1e-3 m.

// static-only fast path: rays that provably miss every moving geom (MovingBounds: boxes of the
// moving geoms, posed by Update) are traced against the static scene directly, which skips the
// top level and the instances of the moving bodies that the rays pass near (a camera on a
// robot starts every ray inside its own robot's instance bounds). the hits are the same as
// through the top level: the static instance has the identity pose, so Embree sees the same
// ray (default world: images byte-identical). IntersectGrid tests a cone of the grid's rays,
// OccludedLanes each shadow segment against the bodies' spheres.
//
// tendons (SceneDescription::tendons): one more instanced scene, in the world frame, holds a
// capsule (user geometry, as analytic geoms) around every segment of the snapshot's tendon
// paths; Update rebuilds it when the paths change. hits on it report geom -1 and the tendon's
// material. a scene with tendons never takes the static-only fast path (the capsules have no
// MovingBounds); scenes without tendons are traced as before.
//
// visibility: geoms in MJCF groups > 2 (MuJoCo shows groups 0-2 by default) and geoms
// whose material has alpha < 0.5 are left out.
//
// surfaces are two-sided and opaque: the normals of a SurfaceHit face the incoming ray.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "penumbra/render/ray.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/shading_lanes.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

struct RayCone;

/// a closest hit named by what was hit rather than by its surface (RayScene::IntersectIds): the
/// transport's Embree tracer (render/cpu/embree_tracer.h) turns it into the BVH scene's
/// numbering (BvhScene::NameHit).
struct RayHitIds {
  float t = 0;       ///< ray parameter of the hit
  int geom = -1;     ///< SceneDescription geom index; -1: a tendon's capsule (segment)
  int segment = -1;  ///< with geom -1: the capsule's index among the tendons' finite segments
  int face = 0;      ///< the triangle's face index in its geom's shape; 0 for analytic shapes
  bool analytic = false;
  float u = 0, v = 0;  ///< a triangle's barycentrics (weights of its 2nd and 3rd vertex)
  int part = 0;        ///< an analytic shape's part (ShapePart) hit
};

/// half-size (m) of the quad that stands in for an infinite MJCF plane.
constexpr double kInfinitePlaneHalfSize = 1e4;

/// Embree scenes of one SceneDescription; the Embree RayQuery (render/ray_query.h). Intersect,
/// Occluded and the other queries are thread-safe between Update calls; Update must not run
/// concurrently with them.
class RayScene final : public RayQuery {
 public:
  /// builds the body scenes (and an identity pose for every body until Update). `scene` is
  /// referenced, not copied: it must outlive this object.
  /// @throws Error if Embree fails, or a visible geom refers to a missing body, material, mesh
  /// or height field, or has a non-positive size for its shape, or a tendon refers to a missing
  /// material or has a non-positive width.
  explicit RayScene(const SceneDescription& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// poses every body with snapshot.X_WB, rebuilds the tendon capsules if
  /// snapshot.tendon_paths changed, and recommits the top level if anything changed.
  /// @throws Error if snapshot.X_WB.size() differs from the number of bodies, or a tendon path
  /// refers to a missing tendon.
  void Update(const WorldSnapshot& snapshot) override;

  /// RayQuery's batched closest hits (IntersectMany with coherent rays).
  using RayQuery::Intersect;

  /// closest hit along `ray` in [tmin, tmax]; fills `hit` and returns true, or returns false.
  bool Intersect(const Ray& ray, SurfaceHit* hit) const;

  /// the closest hit along `ray` in [tmin, tmax] as Intersect finds it, named (RayHitIds)
  /// instead of finished into a SurfaceHit; false where none.
  bool IntersectIds(const Ray& ray, RayHitIds* ids) const;

  /// true if anything blocks `ray` in [tmin, tmax].
  bool Occluded(const Ray& ray) const;
  /// RayQuery's batched occlusion: Occluded(ray) (rtcOccluded1) for each ray in turn.
  using RayQuery::Occluded;

  /// closest hits of `n` rays: `coherent` rays (e.g. camera rays of neighbouring pixels) are
  /// traced in packets of 16, others one by one. hit[i] is valid iff did_hit[i].
  void IntersectMany(const Ray* rays, int n, bool coherent, SurfaceHit* hits, bool* did_hit) const;

  /// closest hits of the rays of a width x height pixel grid stored row-major (ray of grid
  /// cell (x, y) at rays[y * width + x]; hits and did_hit likewise), e.g. the camera rays of a
  /// tile: traced in packets of 4 x 4 neighbouring cells, which are more coherent than rows.
  /// the same hits as IntersectMany. `cone`, when given, must hold every ray (e.g.
  /// RayCone::FromCorners for a pinhole camera's tile); else the rays' cone is computed here
  /// (RayCone::FromRays, O(n)). when no ray of the cone can touch a moving geom, the grid is
  /// traced against the static scene alone (file comment), and true is returned.
  bool IntersectGrid(const Ray* rays, int width, int height, SurfaceHit* hits, bool* did_hit,
                     const RayCone* cone = nullptr) const;

  /// occlusion of one packet of kLanes rays o + t d, t in [0, tmax], given as lanes (the
  /// realtime tier's shadow rays); lanes with active[k] == false get occluded[k] = false.
  /// a packet whose segments all pass clear of the moving bodies' bounding spheres is traced
  /// against the static scene alone (file comment), and true is returned.
  bool OccludedLanes(const Vec3Lanes& o, const Vec3Lanes& d, const Lanes& tmax,
                     const LaneMask& active, LaneMask* occluded) const;

  /// the body poses currently in the scene (X_WB by body index).
  const std::vector<Pose>& X_WB() const { return X_WB_; }

  /// the scene this was built from.
  const SceneDescription& scene() const override { return scene_; }

  /// how many times Update recommitted the top-level scene (bodies moved); moving bodies'
  /// scenes are never rebuilt after construction.
  int64_t num_top_level_commits() const { return num_top_level_commits_; }

  /// how many geoms are ray traced (visible) and how many triangles they hold.
  int num_visible_geoms() const { return num_visible_geoms_; }
  int64_t num_triangles() const { return num_triangles_; }

  /// how many rays were not traced because IsTraceableRay was false (they count as misses);
  /// the first one also logs a warning with its origin and direction.
  int64_t num_untraceable_rays() const;

 private:
  void IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                      std::span<bool> did_hit) const override;
  void OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const override;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  const SceneDescription& scene_;
  std::vector<Pose> X_WB_;
  int num_visible_geoms_ = 0;
  int64_t num_triangles_ = 0;
  int64_t num_top_level_commits_ = 0;
};

/// a RayQueryFactory (render/ray_query.h) of RayScenes: what the realtime tiers' static maps
/// (sky irradiance volume, shelter map) and the CPU backend's effects trace through.
RayQueryFactory RaySceneFactory();

}  // namespace penumbra
