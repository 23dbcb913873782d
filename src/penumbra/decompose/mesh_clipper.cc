#include "penumbra/decompose/mesh_clipper.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Geometry>
#include <cmath>
#include <deque>
#include <map>
#include <utility>

namespace penumbra {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<int, K>;  // nesting level, -1 unset
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

// faces of the triangulation by nesting level: 0 outside, odd inside the cross-section.
void MarkNesting(Cdt& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::deque<Cdt::Face_handle> border{cdt.infinite_face()};
  int level = 0;
  while (!border.empty()) {
    std::deque<Cdt::Face_handle> next;
    while (!border.empty()) {
      Cdt::Face_handle start = border.front();
      border.pop_front();
      if (start->info() != -1) continue;
      std::deque<Cdt::Face_handle> queue{start};
      start->info() = level;
      while (!queue.empty()) {
        Cdt::Face_handle f = queue.front();
        queue.pop_front();
        for (int i = 0; i < 3; ++i) {
          Cdt::Face_handle n = f->neighbor(i);
          if (n->info() != -1) continue;
          if (cdt.is_constrained({f, i})) {
            next.push_back(n);
          } else {
            n->info() = level;
            queue.push_back(n);
          }
        }
      }
    }
    border = std::move(next);
    ++level;
  }
}

}  // namespace

ClipResult ClipMesh(const SolidMesh& mesh, const CutPlane& plane, double snap) {
  ClipResult result;
  const Eigen::Vector3d n = plane.normal;
  const size_t nv = mesh.vertices.size();
  std::vector<double> s(nv);
  double offset = plane.offset;
  // move the plane off the vertices (a few tries; the steps are irrational multiples of snap)
  for (int attempt = 0; attempt < 64; ++attempt) {
    bool on_plane = false;
    for (size_t i = 0; i < nv; ++i) {
      s[i] = n.dot(mesh.vertices[i]) - offset;
      if (std::abs(s[i]) <= snap) on_plane = true;
    }
    if (!on_plane) break;
    offset += snap * 2.6180339887498949 * (attempt % 2 == 0 ? 1 : -1) * (attempt + 1);
  }
  result.offset_used = offset;

  // cut vertices: one per crossed edge, shared by the triangles on both sides
  std::vector<Eigen::Vector3d> cut_points;
  std::map<std::pair<int, int>, int> cut_of_edge;
  auto cut_vertex = [&](int a, int b) {
    const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
    auto [it, inserted] = cut_of_edge.emplace(key, static_cast<int>(cut_points.size()));
    if (inserted) {
      const int p = key.first, q = key.second;
      const double t = s[p] / (s[p] - s[q]);
      cut_points.push_back(mesh.vertices[p] + t * (mesh.vertices[q] - mesh.vertices[p]));
    }
    return it->second;
  };
  // triangles per side; indices >= 0 are input vertices, < 0 are cut vertices (-1 - index)
  std::vector<std::array<int, 3>> below, above;
  std::vector<uint8_t> below_cut, above_cut;
  std::vector<std::pair<int, int>> segments;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const uint8_t flag = mesh.IsCutFace(t) ? 1 : 0;
    const bool neg[3] = {s[tri[0]] < 0, s[tri[1]] < 0, s[tri[2]] < 0};
    const int n_neg = neg[0] + neg[1] + neg[2];
    if (n_neg == 3) {
      below.push_back(tri);
      below_cut.push_back(flag);
      continue;
    }
    if (n_neg == 0) {
      above.push_back(tri);
      above_cut.push_back(flag);
      continue;
    }
    // the vertex alone on its side first, keeping the orientation
    int k = 0;
    for (int i = 0; i < 3; ++i) {
      const int alone = (n_neg == 1) ? neg[i] : !neg[i];
      if (alone) k = i;
    }
    const int a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
    const int p = -1 - cut_vertex(a, b), q = -1 - cut_vertex(a, c);
    auto& lone = neg[k] ? below : above;
    auto& lone_cut = neg[k] ? below_cut : above_cut;
    auto& rest = neg[k] ? above : below;
    auto& rest_cut = neg[k] ? above_cut : below_cut;
    lone.push_back({a, p, q});
    lone_cut.push_back(flag);
    rest.push_back({p, b, c});
    rest.push_back({p, c, q});
    rest_cut.push_back(flag);
    rest_cut.push_back(flag);
    segments.emplace_back(-1 - p, -1 - q);
  }

  // the cap: cross-section loops triangulated in the plane's 2D frame
  std::vector<std::array<int, 3>> cap;  // cut-vertex indices, oriented with normal +n
  if (!segments.empty()) {
    Eigen::Vector3d u = n.unitOrthogonal();
    Eigen::Vector3d w = n.cross(u);
    Cdt cdt;
    std::vector<Cdt::Vertex_handle> handles(cut_points.size());
    for (size_t i = 0; i < cut_points.size(); ++i) {
      handles[i] = cdt.insert(K::Point_2(u.dot(cut_points[i]), w.dot(cut_points[i])));
      handles[i]->info() = static_cast<int>(i);
    }
    for (const auto& [a, b] : segments)
      if (handles[a] != handles[b]) cdt.insert_constraint(handles[a], handles[b]);
    // points made where constraints crossed (only for self-touching sections) get new vertices
    for (Cdt::Vertex_handle v : cdt.finite_vertex_handles()) {
      bool known = false;
      const int info = v->info();
      if (info >= 0 && info < static_cast<int>(handles.size()) && handles[info] == v) known = true;
      if (!known) {
        const Eigen::Vector3d on_plane = offset * n + v->point().x() * u + v->point().y() * w;
        v->info() = static_cast<int>(cut_points.size());
        cut_points.push_back(on_plane);
      }
    }
    MarkNesting(cdt);
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
      if (f->info() % 2 != 1) continue;
      std::array<int, 3> tri{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
      // CGAL faces are counter-clockwise in (u, w), i.e. normal u x w = n
      cap.push_back(tri);
    }
  }

  auto build = [&](const std::vector<std::array<int, 3>>& tris, const std::vector<uint8_t>& flags,
                   bool cap_along_normal) {
    SolidMesh out;
    std::vector<int> remap(nv, -1), cut_remap(cut_points.size(), -1);
    auto index = [&](int i) {
      if (i >= 0) {
        if (remap[i] < 0) {
          remap[i] = static_cast<int>(out.vertices.size());
          out.vertices.push_back(mesh.vertices[i]);
        }
        return remap[i];
      }
      const int c = -1 - i;
      if (cut_remap[c] < 0) {
        cut_remap[c] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(cut_points[c]);
      }
      return cut_remap[c];
    };
    for (size_t t = 0; t < tris.size(); ++t) {
      out.triangles.push_back({index(tris[t][0]), index(tris[t][1]), index(tris[t][2])});
      out.cut_faces.push_back(flags[t]);
    }
    if (!tris.empty()) {
      for (const auto& c : cap) {
        const int a = index(-1 - c[0]), b = index(-1 - c[1]), d = index(-1 - c[2]);
        out.triangles.push_back(cap_along_normal ? std::array<int, 3>{a, b, d}
                                                 : std::array<int, 3>{a, d, b});
        out.cut_faces.push_back(1);
      }
    }
    return out;
  };
  result.below = build(below, below_cut, true);
  result.above = build(above, above_cut, false);
  return result;
}

}  // namespace penumbra
