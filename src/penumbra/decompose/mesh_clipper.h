#pragma once
// cuts a closed triangle mesh by a plane into the closed solids on either side: triangles that
// cross the plane are split at the edge intersections, and the cross-section (possibly several
// loops, nested for holes) is filled with a constrained Delaunay triangulation (CGAL) as cap
// faces, flagged in SolidMesh::cut_faces. the cut of CoACD (Wei et al., "Approximate Convex
// Decomposition for 3D Meshes with Collision-Aware Concavity and Tree Search", SIGGRAPH 2022,
// section 5: meshes are cut by planes directly, no voxels).

#include <Eigen/Core>

#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// the plane {x : normal . x = offset}; normal unit length, offset in m.
struct CutPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double offset = 0;
};

/// the two sides of a cut.
struct ClipResult {
  SolidMesh below;  ///< normal . x < offset (may be empty)
  SolidMesh above;  ///< normal . x > offset (may be empty)
  /// the offset actually used: when a vertex lies within `snap` of the plane the plane is
  /// moved by small steps along its normal until none does (so no vertex lies on it).
  double offset_used = 0;
};

/// cuts `mesh` (closed, outward oriented) by `plane`. `snap` (m, > 0) is the distance under
/// which a vertex counts as on the plane. deterministic: the result depends only on the input
/// values and their order.
ClipResult ClipMesh(const SolidMesh& mesh, const CutPlane& plane, double snap);

}  // namespace penumbra
