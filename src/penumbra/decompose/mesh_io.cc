#include "penumbra/decompose/mesh_io.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
}  // namespace

SolidMesh ReadMeshFile(const std::string& path, double scale) {
  if (!std::filesystem::is_regular_file(path))
    throw Error(path + ": no such file; expected a mesh (.off, .obj, .stl, .ply)");
  Mesh sm;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_mesh(path, sm, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    throw Error(path + ": cannot read the mesh (" + e.what() + ")");
  }
  if (!ok || sm.number_of_faces() == 0)
    throw Error(path +
                ": cannot read a polygon mesh from it; expected a closed, manifold "
                "surface in .off, .obj, .stl or .ply");
  CGAL::Polygon_mesh_processing::triangulate_faces(sm);
  SolidMesh out;
  std::map<Mesh::Vertex_index, int> index;
  for (auto v : sm.vertices()) {
    index[v] = static_cast<int>(out.vertices.size());
    const auto& p = sm.point(v);
    out.vertices.emplace_back(p.x() * scale, p.y() * scale, p.z() * scale);
  }
  for (auto f : sm.faces()) {
    std::array<int, 3> tri{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
      if (k < 3) tri[k++] = index[v];
    out.triangles.push_back(tri);
  }
  return out;
}

void WritePartsObj(const Decomposition& decomposition, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot open for writing");
  out << fmt::format("# {} convex parts ({}), m\n", decomposition.parts.size(),
                     DecompositionMethodName(decomposition.method));
  int base = 1;
  for (size_t i = 0; i < decomposition.parts.size(); ++i) {
    const SolidMesh& hull = decomposition.parts[i].hull;
    out << "o part_" << i << "\n";
    for (const Eigen::Vector3d& v : hull.vertices)
      out << fmt::format("v {:.17g} {:.17g} {:.17g}\n", v.x(), v.y(), v.z());
    for (const auto& t : hull.triangles)
      out << fmt::format("f {} {} {}\n", t[0] + base, t[1] + base, t[2] + base);
    base += static_cast<int>(hull.vertices.size());
  }
  if (!out) throw Error(path + ": write failed");
}

PartsMjcf PartsToMjcf(const Decomposition& decomposition, const std::string& prefix,
                      const std::string& geom_attributes) {
  PartsMjcf mjcf;
  for (size_t i = 0; i < decomposition.parts.size(); ++i) {
    const std::string name = fmt::format("{}_{}", prefix, i);
    std::string vertex;
    for (const Eigen::Vector3d& v : decomposition.parts[i].hull.vertices)
      vertex +=
          fmt::format("{}{:.17g} {:.17g} {:.17g}", vertex.empty() ? "" : " ", v.x(), v.y(), v.z());
    mjcf.assets += fmt::format("<mesh name=\"{}\" vertex=\"{}\"/>\n", name, vertex);
    mjcf.geoms += fmt::format("<geom type=\"mesh\" mesh=\"{}\"{}{}/>\n", name,
                              geom_attributes.empty() ? "" : " ", geom_attributes);
  }
  return mjcf;
}

}  // namespace penumbra
