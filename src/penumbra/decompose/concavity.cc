#include "penumbra/decompose/concavity.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace penumbra {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = K::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 ToCgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

std::vector<Triangle> CgalTriangles(const SolidMesh& mesh) {
  std::vector<Triangle> tris;
  tris.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Triangle tri(ToCgal(mesh.vertices[t[0]]), ToCgal(mesh.vertices[t[1]]),
                       ToCgal(mesh.vertices[t[2]]));
    if (!tri.is_degenerate()) tris.push_back(tri);
  }
  return tris;
}

// outward face planes (unit normal, offset) of a convex mesh
std::vector<std::pair<Eigen::Vector3d, double>> Planes(const SolidMesh& hull) {
  std::vector<std::pair<Eigen::Vector3d, double>> planes;
  for (const auto& t : hull.triangles) {
    const Eigen::Vector3d& a = hull.vertices[t[0]];
    Eigen::Vector3d nrm = (hull.vertices[t[1]] - a).cross(hull.vertices[t[2]] - a);
    const double len = nrm.norm();
    if (!(len > 0)) continue;
    nrm /= len;
    planes.emplace_back(nrm, nrm.dot(a));
  }
  return planes;
}

}  // namespace

std::vector<Eigen::Vector3d> SurfaceSamples(const SolidMesh& mesh, int count, bool skip_cut_faces) {
  std::vector<Eigen::Vector3d> samples;
  std::vector<double> cumulative;
  std::vector<int> ids;
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (skip_cut_faces && mesh.IsCutFace(t)) continue;
    const auto& tri = mesh.triangles[t];
    const double area = 0.5 * (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                                  .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]])
                                  .norm();
    if (!(area > 0)) continue;
    total += area;
    cumulative.push_back(total);
    ids.push_back(static_cast<int>(t));
  }
  if (ids.empty() || count <= 0) return samples;
  samples.reserve(count + ids.size());
  // R2 sequence (Roberts 2018): additive recurrence with the plastic number
  constexpr double kG = 1.32471795724474602596;
  constexpr double kA1 = 1.0 / kG, kA2 = 1.0 / (kG * kG);
  size_t t = 0;
  for (int j = 0; j < count; ++j) {
    const double target = (j + 0.5) / count * total;
    while (t + 1 < cumulative.size() && cumulative[t] < target) ++t;
    double r1 = std::fmod(0.5 + kA1 * (j + 1), 1.0), r2 = std::fmod(0.5 + kA2 * (j + 1), 1.0);
    if (r1 + r2 > 1) {
      r1 = 1 - r1;
      r2 = 1 - r2;
    }
    const auto& tri = mesh.triangles[ids[t]];
    const Eigen::Vector3d& a = mesh.vertices[tri[0]];
    samples.push_back(a + r1 * (mesh.vertices[tri[1]] - a) + r2 * (mesh.vertices[tri[2]] - a));
  }
  return samples;
}

ConcavityValue Concavity(const SolidMesh& solid, double solid_volume, const SolidMesh& hull,
                         const ConcavityOptions& options) {
  ConcavityValue value;
  if (hull.empty() || solid.empty()) return value;
  // S -> H: points of the solid's surface are inside the convex hull; their distance to the
  // hull boundary is the smallest distance to a face plane
  const auto planes = Planes(hull);
  double h1 = 0;
  for (const Eigen::Vector3d& p : SurfaceSamples(solid, options.samples, true)) {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& [nrm, off] : planes) d = std::min(d, off - nrm.dot(p));
    h1 = std::max(h1, std::max(d, 0.0));
  }
  // H -> S: distance from hull surface points to the solid's surface
  const std::vector<Triangle> tris = CgalTriangles(solid);
  double h2 = 0;
  if (!tris.empty()) {
    Tree tree(tris.begin(), tris.end());
    tree.accelerate_distance_queries();
    for (const Eigen::Vector3d& p : SurfaceSamples(hull, options.samples, false))
      h2 = std::max(h2, tree.squared_distance(ToCgal(p)));
    h2 = std::sqrt(h2);
  }
  value.boundary = std::max(h1, h2);
  const double excess = std::max(0.0, MeshVolume(hull) - solid_volume);
  value.interior = options.rv_k * std::cbrt(3.0 * excess / (4.0 * std::numbers::pi));
  return value;
}

double HullExcessDistance(const std::vector<SolidMesh>& hulls, const SolidMesh& mesh,
                          int samples_per_hull) {
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  Mesh sm;
  std::vector<Mesh::Vertex_index> vi;
  for (const Eigen::Vector3d& v : mesh.vertices) vi.push_back(sm.add_vertex(ToCgal(v)));
  for (const auto& t : mesh.triangles) sm.add_face(vi[t[0]], vi[t[1]], vi[t[2]]);
  const CGAL::Side_of_triangle_mesh<Mesh, K> inside(sm);
  const std::vector<Triangle> tris = CgalTriangles(mesh);
  Tree tree(tris.begin(), tris.end());
  tree.accelerate_distance_queries();
  double worst = 0;
  for (const SolidMesh& hull : hulls) {
    for (const Eigen::Vector3d& p : SurfaceSamples(hull, samples_per_hull, false)) {
      const K::Point_3 q = ToCgal(p);
      if (inside(q) != CGAL::ON_UNBOUNDED_SIDE) continue;
      worst = std::max(worst, std::sqrt(tree.squared_distance(q)));
    }
  }
  return worst;
}

}  // namespace penumbra
