#pragma once
// the traced scene as the transport reads it (the GPU's traversal walks these arrays; the CPU's
// EmbreeTracer names its hits by them, NameHit), built on the host: the SceneDescription's traced
// geoms (those RayScene traces: groups <= 2, material alpha >= 0.5) as the flat arrays of
// bvh_types.h. boxes, meshes and height fields are triangles (render/geometry/triangle_shapes.h),
// planes, spheres, capsules, ellipsoids and cylinders analytic (render/geometry/analytic_shapes.h),
// grouped as RayScene groups them: the static bodies merged in the world frame, every moving body
// on its own. Update rewrites the instances' transforms from a snapshot and rebuilds the top level
// over their world boxes (a few hundred at most; the BLASes are built once, the static one again
// only if a static body moved, normally once, at the first Update). visible spatial tendons
// (SceneDescription::tendons) are a last group in the world frame, as RayScene draws them: a
// capsule of the tendon's width around each segment of the snapshot's wrap-point paths (a sphere
// where a segment is shorter than 1e-9 m), records with geom -1 (segmentation: background), the
// tendon's material; Update rebuilds that group's BLAS alone when the paths changed.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/frame/bvh_builder.h"
#include "penumbra/render/ray.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra::cuda {

/// the traced scene's arrays on the host (see the file comment).
class BvhScene {
 public:
  /// builds every group's BLAS, bodies at the identity pose until Update. `scene` is referenced.
  /// `pool` (may be null; referenced, it must outlive the scene): the BLAS builds of the
  /// constructor and of Update run over it (BuildBvh: the same nodes and order, bit for bit, with
  /// any pool or none); neither may be called from inside one of the pool's ParallelFor loops.
  /// @throws Error if a traced geom refers to a missing body, mesh, height field or material,
  ///         or a tendon to a missing material or has a width that is not positive.
  explicit BvhScene(const SceneDescription& scene, ThreadPool* pool = nullptr);

  /// poses the instances with snapshot.X_WB (rebuilding the static BLAS if a static body moved)
  /// and the tendons' capsules with snapshot.tendon_paths (rebuilding their BLAS if they moved).
  /// @throws Error if snapshot.X_WB.size() differs from the number of bodies, or a tendon path
  ///         names a missing tendon.
  void Update(const WorldSnapshot& snapshot);

  /// the arrays as host pointers.
  SceneView view() const;

  /// fills a SurfaceHit (t, p_W, ng_W, ns_W, front_face, p_G, n_G, d_G, geom, material, and on
  /// a triangle with texcoords uv, has_uv, uv_per_m, duv_dp_G) from a traversal hit of world
  /// ray `ray`: ns_W the vertex normals' mix where the triangle has them (HitShadingNormal,
  /// primary_pixel.h, as the GPU shades it), else ng_W; uv from HitTexcoords; as RayScene.
  void FinishHit(const Ray& ray, const TraceHit& th, SurfaceHit* hit) const;

  /// the closest hit `th` (its t, u, v, part left as given) named as the traversal names it:
  /// th->prim and th->instance of a primitive named as RayScene (render/embree/ray_scene.h)
  /// names it: geom `geom` (a SceneDescription index; -1: the tendons' capsule number `segment`
  /// in the order both scenes add them, RayHitIds::segment) and its face `face` (0 for an
  /// analytic shape). false (th untouched) where this scene has no such primitive.
  bool NameHit(int geom, int segment, int face, TraceHit* th) const;

  const SceneDescription& scene() const { return scene_; }
  const std::vector<BvhWideNode>& nodes() const { return nodes_; }
  const std::vector<PrimRef>& prims() const { return prims_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<AnalyticPrim>& analytics() const { return analytics_; }
  const std::vector<Blas>& blases() const { return blases_; }
  const std::vector<Instance>& instances() const { return instances_; }
  /// the top level over the instances' world boxes (BuildBvh and WidenBvh over Instance::lo,
  /// hi; rebuilt by an Update that changes them): its inner nodes, its leaves' instance indices
  /// (SceneView::tlas_instances) and its root. view() leaves it out where it is deeper than
  /// the occlusion traversal's stack (tlas_depth() >= kMaxTlasDepth, bvh_traversal.h).
  const std::vector<BvhWideNode>& tlas_nodes() const { return tlas_nodes_; }
  const std::vector<int32_t>& tlas_instances() const { return tlas_instances_; }
  const Blas& tlas() const { return tlas_; }
  /// the deepest inner node's depth in the top level (the root's is 0; 0 also for a leaf root).
  int tlas_depth() const { return tlas_depth_; }
  const std::vector<Record>& records() const { return records_; }
  /// the shading attributes of the triangles that have vertex normals or texcoords
  /// (PrimRef::shading).
  const std::vector<TriangleShading>& shading() const { return shading_; }
  /// counts of Update calls that changed the BLAS arrays (a device copy must be refreshed).
  int64_t geometry_version() const { return geometry_version_; }
  int64_t num_triangles() const { return static_cast<int64_t>(triangles_.size()); }
  /// seconds the last full BLAS build took (static group included).
  double build_seconds() const { return build_seconds_; }

 private:
  struct Group {
    int body = -1;         // -1: the static group (or the tendons')
    bool tendons = false;  // the tendons' capsules (world frame; the last group)
    std::vector<int> geoms;
    int blas = -1;  // -1: no primitives
    Pose X_WI = Pose::Identity();
  };
  // where the tendon group's arrays start (it is last in every array)
  struct TendonStart {
    size_t nodes = 0, prims = 0, analytics = 0, records = 0, blases = 0;
  };
  void BuildAll();
  // appends group k's records, primitives, BLAS nodes and Blas (prim_index: BuildBvh's order of
  // every primitive so far; the group's primitives are then in its leaves' order)
  void BuildGroup(int k, std::vector<int32_t>* prim_index);
  // appends record `rec` of group k posed at X_IG (its primitives start at the next one);
  // returns its index
  int AddRecord(const Record& rec, int k, const Pose& X_IG);
  void AddGeom(int gi, const Pose& X_IG, std::vector<PrimBox>* boxes, int record);
  void AddAnalytic(AnalyticKind kind, const double size[3], const Pose& X_IG,
                   const std::string& what, std::vector<PrimBox>* boxes, int record);
  // the tendon group's records and capsules from tendon_paths_
  void AddTendons(int k, std::vector<PrimBox>* boxes);
  // rebuilds the tendon group alone (the arrays' tails from tendon_start_)
  void RebuildTendons();
  void SetInstances();
  // the top level over instances_' boxes
  void BuildTlas();

  const SceneDescription& scene_;
  ThreadPool* pool_ = nullptr;  // the BLAS builds' (may be null)
  std::vector<Group> groups_;
  std::vector<Pose> X_WB_;
  std::vector<Pose> static_poses_;
  std::vector<BvhWideNode> nodes_;  // every BLAS's inner nodes (WidenBvh)
  std::vector<PrimRef> prims_;
  std::vector<Triangle> triangles_;
  std::vector<TriangleShading> shading_;  // by PrimRef::shading
  std::vector<AnalyticPrim> analytics_;
  std::vector<Blas> blases_;
  std::vector<Instance> instances_;
  std::vector<BvhWideNode> tlas_nodes_;  // the top level's inner nodes (WidenBvh)
  std::vector<int32_t> tlas_instances_;  // its leaves' instances (BuildBvh's order)
  Blas tlas_;
  int tlas_depth_ = 0;
  std::vector<PrimBox> tlas_boxes_;  // the instances' boxes it was built over
  bool tlas_built_ = false;
  std::vector<Record> records_;
  std::vector<int> record_group_;  // group of each record
  std::vector<Pose> X_GI_;         // by record: its group frame to its geom frame
  // NameHit's tables: by record its first primitive in the order they were added (the input
  // order: a geom's faces in turn), by input index its place in prims_, by geom its record
  // (-1: not traced) and by group its instance (-1: none)
  std::vector<int32_t> record_first_input_;
  std::vector<int32_t> prim_of_input_;
  std::vector<int32_t> record_of_geom_;
  std::vector<int32_t> instance_of_group_;
  int64_t geometry_version_ = 0;
  double build_seconds_ = 0;
  int tendon_group_ = -1;                                // index into groups_, -1 without tendons
  std::vector<WorldSnapshot::TendonPath> tendon_paths_;  // as the tendon group was built
  TendonStart tendon_start_;
};

}  // namespace penumbra::cuda
