#include "penumbra/decompose/convex_hull.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <map>

namespace penumbra {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
}  // namespace

SolidMesh ConvexHullOf(const std::vector<Eigen::Vector3d>& points) {
  SolidMesh out;
  if (points.size() < 4) return out;
  std::vector<Point> pts;
  pts.reserve(points.size());
  for (const Eigen::Vector3d& p : points) pts.emplace_back(p.x(), p.y(), p.z());
  // all on one plane (or line): no solid hull
  const Point& p0 = pts[0];
  size_t i1 = 1;
  while (i1 < pts.size() && pts[i1] == p0) ++i1;
  if (i1 >= pts.size()) return out;
  size_t i2 = i1 + 1;
  while (i2 < pts.size() && CGAL::collinear(p0, pts[i1], pts[i2])) ++i2;
  if (i2 >= pts.size()) return out;
  size_t i3 = i2 + 1;
  while (i3 < pts.size() && CGAL::coplanar(p0, pts[i1], pts[i2], pts[i3])) ++i3;
  if (i3 >= pts.size()) return out;
  CGAL::Surface_mesh<Point> hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  std::map<CGAL::Surface_mesh<Point>::Vertex_index, int> index;
  for (auto v : hull.vertices()) {
    index[v] = static_cast<int>(out.vertices.size());
    const Point& p = hull.point(v);
    out.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : hull.faces()) {
    std::array<int, 3> tri{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      if (k < 3) tri[k] = index[v];
      ++k;
    }
    if (k == 3) out.triangles.push_back(tri);
  }
  return out;
}

}  // namespace penumbra
