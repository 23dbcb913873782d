#include "penumbra/decompose/convex_hull.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <map>
#include <numeric>

namespace penumbra {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
// quickhull triangulates a facet with more than 3 vertices (the flat top of a torus, a box
// side) in an order that depends on where the library's nodes were allocated, so the same
// points could give differently triangulated hulls in two processes. each facet (triangles
// joined across edges whose far vertex is exactly coplanar, CGAL's exact predicate) is
// triangulated again as a fan from its smallest vertex along its boundary loop: a pure
// function of the hull's vertex set. `hull` must be canonical (CanonicalMesh).
SolidMesh CanonicalFacets(const SolidMesh& hull) {
  const size_t n = hull.triangles.size();
  auto point = [&](int v) {
    const Eigen::Vector3d& p = hull.vertices[v];
    return Point(p.x(), p.y(), p.z());
  };
  std::map<std::pair<int, int>, size_t> triangle_of_edge;
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k)
      triangle_of_edge[{hull.triangles[t][k], hull.triangles[t][(k + 1) % 3]}] = t;
  std::vector<size_t> parent(n);
  std::iota(parent.begin(), parent.end(), size_t{0});
  auto root = [&](size_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  for (size_t t = 0; t < n; ++t) {
    const auto& a = hull.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const auto it = triangle_of_edge.find({a[(k + 1) % 3], a[k]});
      if (it == triangle_of_edge.end() || it->second <= t) continue;
      const auto& b = hull.triangles[it->second];
      int far = b[0] + b[1] + b[2] - a[k] - a[(k + 1) % 3];
      if (CGAL::coplanar(point(a[0]), point(a[1]), point(a[2]), point(far))) {
        const size_t ra = root(t), rb = root(it->second);
        parent[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  }
  // per facet: its triangles; boundary edges are those whose reverse lies in another facet
  std::map<size_t, std::vector<size_t>> facets;
  for (size_t t = 0; t < n; ++t) facets[root(t)].push_back(t);
  SolidMesh out;
  out.vertices = hull.vertices;
  for (const auto& [r, tris] : facets) {
    if (tris.size() == 1) {
      out.triangles.push_back(hull.triangles[tris[0]]);
      continue;
    }
    std::map<int, int> next;
    for (size_t t : tris) {
      const auto& a = hull.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const auto it = triangle_of_edge.find({a[(k + 1) % 3], a[k]});
        if (it == triangle_of_edge.end() || root(it->second) != r) next[a[k]] = a[(k + 1) % 3];
      }
    }
    // a convex facet has one boundary loop; anything else keeps quickhull's triangles
    const int start = next.begin()->first;
    std::vector<int> loop = {start};
    bool simple = true;
    for (int v = next[start]; v != start; v = next.count(v) ? next[v] : start) {
      if (loop.size() > next.size()) {
        simple = false;
        break;
      }
      loop.push_back(v);
    }
    if (!simple || loop.size() != next.size()) {
      for (size_t t : tris) out.triangles.push_back(hull.triangles[t]);
      continue;
    }
    for (size_t i = 1; i + 1 < loop.size(); ++i)
      out.triangles.push_back({loop[0], loop[i], loop[i + 1]});
  }
  return CanonicalMesh(out);
}

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
  return CanonicalFacets(CanonicalMesh(out));
}

}  // namespace penumbra
