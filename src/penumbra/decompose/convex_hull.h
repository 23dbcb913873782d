#pragma once
// the convex hull of a point set as a closed triangle mesh (CGAL::convex_hull_3, quickhull
// with exact predicates: deterministic and robust to coplanar and duplicate points).

#include <Eigen/Core>
#include <vector>

#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// the hull of `points` (m): outward-oriented triangles over the hull's extreme points. fewer
/// than 4 points, or points on one plane, give an empty mesh (no volume).
SolidMesh ConvexHullOf(const std::vector<Eigen::Vector3d>& points);

}  // namespace penumbra
