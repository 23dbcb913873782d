#pragma once
// the CUDA backend's scene on the host: the SceneDescription's traced geoms (those RayScene
// traces: groups <= 2, material alpha >= 0.5) as the flat arrays of bvh_types.h. boxes,
// meshes and height fields are triangles (render/triangle_shapes.h), planes, spheres, capsules,
// ellipsoids and cylinders analytic (render/analytic_shapes.h), grouped as RayScene groups
// them: the static bodies merged in the world frame, every moving body on its own. Update
// rewrites the instances' transforms from a snapshot (the BLASes are built once; the static one
// again only if a static body moved, normally once, at the first Update). tendons are not
// traced yet (docs/gpu.md).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/render/cuda/bvh_builder.h"
#include "penumbra/render/cuda/bvh_types.h"
#include "penumbra/render/ray.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra::cuda {

/// the traced scene's arrays on the host (see the file comment).
class BvhScene {
 public:
  /// builds every group's BLAS, bodies at the identity pose until Update. `scene` is referenced.
  /// @throws Error if a traced geom refers to a missing body, mesh, height field or material.
  explicit BvhScene(const SceneDescription& scene);

  /// poses the instances with snapshot.X_WB (rebuilding the static BLAS if a static body moved).
  /// @throws Error if snapshot.X_WB.size() differs from the number of bodies.
  void Update(const WorldSnapshot& snapshot);

  /// the arrays as host pointers.
  SceneView view() const;

  /// fills a SurfaceHit (t, p_W, ng_W, ns_W = ng_W, front_face, p_G, n_G, d_G, geom, material;
  /// no texcoords yet) from a traversal hit of world ray `ray`.
  void FinishHit(const Ray& ray, const TraceHit& th, SurfaceHit* hit) const;

  const SceneDescription& scene() const { return scene_; }
  const std::vector<BvhWideNode>& nodes() const { return nodes_; }
  const std::vector<PrimRef>& prims() const { return prims_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<AnalyticPrim>& analytics() const { return analytics_; }
  const std::vector<Blas>& blases() const { return blases_; }
  const std::vector<Instance>& instances() const { return instances_; }
  const std::vector<Record>& records() const { return records_; }
  /// counts of Update calls that changed the BLAS arrays (a device copy must be refreshed).
  int64_t geometry_version() const { return geometry_version_; }
  int64_t num_triangles() const { return static_cast<int64_t>(triangles_.size()); }
  /// seconds the last full BLAS build took (static group included).
  double build_seconds() const { return build_seconds_; }

 private:
  struct Group {
    int body = -1;  // -1: the static group
    std::vector<int> geoms;
    int blas = -1;  // -1: no primitives
    Pose X_WI = Pose::Identity();
  };
  void BuildAll();
  void AddGeom(int gi, const Pose& X_IG, std::vector<PrimBox>* boxes, int record);
  void SetInstances();

  const SceneDescription& scene_;
  std::vector<Group> groups_;
  std::vector<Pose> X_WB_;
  std::vector<Pose> static_poses_;
  std::vector<BvhWideNode> nodes_;  // every BLAS's inner nodes (WidenBvh)
  std::vector<PrimRef> prims_;
  std::vector<Triangle> triangles_;
  std::vector<AnalyticPrim> analytics_;
  std::vector<Blas> blases_;
  std::vector<Instance> instances_;
  std::vector<Record> records_;
  std::vector<int> record_group_;  // group of each record
  std::vector<Pose> X_GI_;         // by record: its group frame to its geom frame
  int64_t geometry_version_ = 0;
  double build_seconds_ = 0;
};

}  // namespace penumbra::cuda
