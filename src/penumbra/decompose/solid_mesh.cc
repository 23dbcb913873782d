#include "penumbra/decompose/solid_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "penumbra/core/error.h"

namespace penumbra {

std::array<Eigen::Vector3d, 2> MeshBounds(const SolidMesh& mesh) {
  if (mesh.vertices.empty()) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Vector3d lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Eigen::Vector3d& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return {lo, hi};
}

double MeshVolume(const SolidMesh& mesh) {
  if (mesh.vertices.empty()) return 0;
  // relative to the first vertex, so far-from-origin meshes keep their precision
  const Eigen::Vector3d o = mesh.vertices[0];
  double six_v = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] - o, b = mesh.vertices[t[1]] - o,
                          c = mesh.vertices[t[2]] - o;
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

double MeshArea(const SolidMesh& mesh) {
  double area = 0;
  for (const auto& t : mesh.triangles)
    area += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                      .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                      .norm();
  return area;
}

void ValidateClosedMesh(const SolidMesh& mesh, const std::string& name) {
  const int nv = static_cast<int>(mesh.vertices.size());
  if (nv < 4 || mesh.triangles.size() < 4)
    throw Error(
        fmt::format("{}: {} vertices and {} triangles; expected a closed mesh (at least 4 "
                    "of each)",
                    name, nv, mesh.triangles.size()));
  for (int i = 0; i < nv; ++i)
    if (!mesh.vertices[i].allFinite())
      throw Error(fmt::format("{}: vertex {} is not finite; expected finite coordinates", name, i));
  // directed edge -> count; a closed oriented manifold has each directed edge once and its
  // reverse once
  std::map<std::pair<int, int>, int> directed;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= nv)
        throw Error(fmt::format("{}: triangle {} has vertex index {}; expected 0..{}", name, t,
                                tri[k], nv - 1));
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      throw Error(
          fmt::format("{}: triangle {} repeats a vertex ({} {} {}); expected three "
                      "distinct vertices",
                      name, t, tri[0], tri[1], tri[2]));
    for (int k = 0; k < 3; ++k) {
      const int n = ++directed[{tri[k], tri[(k + 1) % 3]}];
      if (n > 1)
        throw Error(
            fmt::format("{}: edge {}-{} is used twice in the same direction (triangle "
                        "{}); expected a consistently oriented 2-manifold",
                        name, tri[k], tri[(k + 1) % 3], t));
    }
  }
  for (const auto& [edge, n] : directed) {
    if (!directed.count({edge.second, edge.first}))
      throw Error(
          fmt::format("{}: edge {}-{} has no opposite triangle; expected a closed "
                      "(watertight) mesh",
                      name, edge.first, edge.second));
  }
  const double volume = MeshVolume(mesh);
  if (!(volume > 0))
    throw Error(
        fmt::format("{}: enclosed volume {:.6g} m^3; expected a positive volume (outward "
                    "normals, counter-clockwise triangles seen from outside)",
                    name, volume));
}

SolidMesh CompactMesh(const SolidMesh& mesh) {
  SolidMesh out;
  std::vector<int> remap(mesh.vertices.size(), -1);
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    std::array<int, 3> nt;
    for (int k = 0; k < 3; ++k) {
      int& r = remap[t[k]];
      if (r < 0) {
        r = static_cast<int>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[t[k]]);
      }
      nt[k] = r;
    }
    out.triangles.push_back(nt);
  }
  out.cut_faces = mesh.cut_faces;
  return out;
}

namespace {
int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}
}  // namespace

std::vector<SolidMesh> ConnectedComponents(const SolidMesh& mesh) {
  std::vector<int> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& t : mesh.triangles) {
    for (int k = 1; k < 3; ++k) {
      const int a = Find(parent, t[0]), b = Find(parent, t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::map<int, int> component_of_root;  // root -> component index in first-triangle order
  std::vector<SolidMesh> parts;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const int root = Find(parent, mesh.triangles[i][0]);
    auto [it, inserted] = component_of_root.emplace(root, static_cast<int>(parts.size()));
    if (inserted) parts.emplace_back();
    SolidMesh& part = parts[it->second];
    part.triangles.push_back(mesh.triangles[i]);
    part.cut_faces.push_back(mesh.IsCutFace(i) ? 1 : 0);
  }
  for (SolidMesh& part : parts) {
    part.vertices = mesh.vertices;
    part = CompactMesh(part);
  }
  return parts;
}

SolidMesh WeldVertices(const SolidMesh& soup) {
  SolidMesh out;
  std::map<std::array<double, 3>, int> index;
  std::vector<int> remap(soup.vertices.size());
  for (size_t i = 0; i < soup.vertices.size(); ++i) {
    const Eigen::Vector3d& v = soup.vertices[i];
    const auto [it, added] = index.emplace(std::array<double, 3>{v.x(), v.y(), v.z()},
                                           static_cast<int>(out.vertices.size()));
    if (added) out.vertices.push_back(v);
    remap[i] = it->second;
  }
  for (const auto& t : soup.triangles) {
    const std::array<int, 3> r = {remap.at(t[0]), remap.at(t[1]), remap.at(t[2])};
    if (r[0] != r[1] && r[1] != r[2] && r[0] != r[2]) out.triangles.push_back(r);
  }
  return out;
}

SolidMesh CanonicalMesh(const SolidMesh& mesh) {
  std::vector<int> order(mesh.vertices.size());
  std::iota(order.begin(), order.end(), 0);
  auto less = [&](int a, int b) {
    const Eigen::Vector3d &p = mesh.vertices[a], &q = mesh.vertices[b];
    if (p.x() != q.x()) return p.x() < q.x();
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.z() != q.z()) return p.z() < q.z();
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> rank(order.size());
  SolidMesh out;
  for (size_t i = 0; i < order.size(); ++i) {
    rank[order[i]] = static_cast<int>(i);
    out.vertices.push_back(mesh.vertices[order[i]]);
  }
  for (const auto& t : mesh.triangles) {
    std::array<int, 3> r{rank[t[0]], rank[t[1]], rank[t[2]]};
    while (r[0] > r[1] || r[0] > r[2]) r = {r[1], r[2], r[0]};
    out.triangles.push_back(r);
  }
  std::sort(out.triangles.begin(), out.triangles.end());
  return out;
}

SolidMesh ConcatenateMeshes(const std::vector<const SolidMesh*>& meshes) {
  SolidMesh out;
  for (const SolidMesh* m : meshes) {
    const int base = static_cast<int>(out.vertices.size());
    out.vertices.insert(out.vertices.end(), m->vertices.begin(), m->vertices.end());
    for (size_t t = 0; t < m->triangles.size(); ++t) {
      const auto& tri = m->triangles[t];
      out.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
      out.cut_faces.push_back(m->IsCutFace(t) ? 1 : 0);
    }
  }
  return out;
}

}  // namespace penumbra
