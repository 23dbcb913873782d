#include "penumbra/decompose/exact_decomposition.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/convert_nef_polyhedron_to_polygon_mesh.h>
#include <CGAL/convex_decomposition_3.h>

#include <algorithm>

#include "penumbra/decompose/convex_hull.h"

namespace penumbra {
namespace {
using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Nef = CGAL::Nef_polyhedron_3<K>;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
}  // namespace

Decomposition DecomposeExact(const SolidMesh& mesh, const DecompositionOptions& options) {
  Decomposition out = StartDecomposition(DecompositionMethod::kExact, mesh);
  Mesh sm;
  std::vector<Mesh::Vertex_index> vi;
  for (const Eigen::Vector3d& v : mesh.vertices)
    vi.push_back(sm.add_vertex(K::Point_3(v.x(), v.y(), v.z())));
  for (const auto& t : mesh.triangles) sm.add_face(vi[t[0]], vi[t[1]], vi[t[2]]);
  Nef nef(sm);
  CGAL::convex_decomposition_3(nef);
  // volume 0 is the outer volume; each marked volume after it is one convex part
  auto volume = nef.volumes_begin();
  for (++volume; volume != nef.volumes_end(); ++volume) {
    if (!volume->mark()) continue;
    std::vector<Eigen::Vector3d> points;
    for (auto shell = volume->shells_begin(); shell != volume->shells_end(); ++shell) {
      struct Collect {
        std::vector<Eigen::Vector3d>* points;
        void visit(Nef::Vertex_const_handle v) {
          const K::Point_3& p = v->point();
          points->emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()),
                               CGAL::to_double(p.z()));
        }
        void visit(Nef::Halfedge_const_handle) {}
        void visit(Nef::Halffacet_const_handle) {}
        void visit(Nef::SHalfedge_const_handle) {}
        void visit(Nef::SHalfloop_const_handle) {}
        void visit(Nef::SFace_const_handle) {}
      } collect{&points};
      nef.visit_shell_objects(Nef::SFace_const_handle(shell), collect);
    }
    ConvexPart part;
    part.hull = ConvexHullOf(points);
    if (part.hull.empty()) continue;
    part.volume = MeshVolume(part.hull);
    out.parts.push_back(std::move(part));
  }
  // the parts are convex: each is its own hull, so its concavity is 0 up to sampling
  for (ConvexPart& part : out.parts) {
    part.concavity = Concavity(part.hull, part.volume, part.hull, options.concavity).value();
    out.max_concavity = std::max(out.max_concavity, part.concavity);
  }
  return out;
}

}  // namespace penumbra
