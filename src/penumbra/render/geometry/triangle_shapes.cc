#include "penumbra/render/geometry/triangle_shapes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// appends a quad a-b-c-d (counter-clockwise from outside) with its own vertices and the
// flat normal n, so that its shading is not smoothed with neighbouring faces.
void AddQuad(TriangleShape* s, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
             const Eigen::Vector3f& c, const Eigen::Vector3f& d, const Eigen::Vector3f& n) {
  const int i = static_cast<int>(s->vertices.size());
  for (const Eigen::Vector3f& v : {a, b, c, d}) {
    s->vertices.push_back(v);
    s->normals.push_back(n);
  }
  s->faces.emplace_back(i, i + 1, i + 2);
  s->faces.emplace_back(i, i + 2, i + 3);
}

}  // namespace

TriangleShape BoxTriangles(const Eigen::Vector3d& half) {
  TriangleShape s;
  const Eigen::Vector3f h = half.cast<float>();
  // corner k has coordinates (+-hx, +-hy, +-hz) with bit 0 -> x, bit 1 -> y, bit 2 -> z.
  for (int k = 0; k < 8; ++k)
    s.vertices.emplace_back(k & 1 ? h.x() : -h.x(), k & 2 ? h.y() : -h.y(), k & 4 ? h.z() : -h.z());
  // two triangles per face, counter-clockwise seen from outside.
  const int quads[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3},
                           {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};
  for (const auto& q : quads) {
    s.faces.emplace_back(q[0], q[1], q[2]);
    s.faces.emplace_back(q[0], q[2], q[3]);
  }
  return s;
}

TriangleShape MeshTriangles(const TriangleMesh& mesh) {
  TriangleShape s;
  const int n = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= n)
      throw Error("mesh '" + mesh.name + "': face indexes vertex outside [0, " + std::to_string(n) +
                  ")");
  }
  s.vertices = mesh.vertices;
  s.faces = mesh.faces;
  if (static_cast<int>(mesh.normals.size()) == n) s.normals = mesh.normals;
  if (static_cast<int>(mesh.texcoords.size()) == n) s.texcoords = mesh.texcoords;
  return s;
}

TriangleShape HeightFieldTriangles(const HeightField& hf) {
  const int rows = hf.rows, cols = hf.cols;
  if (rows < 2 || cols < 2 ||
      static_cast<int64_t>(hf.elevation.size()) != static_cast<int64_t>(rows) * cols)
    throw Error("height field '" + hf.name +
                "': expected rows, cols >= 2 and rows x cols elevation samples");
  TriangleShape s;
  const float sx = static_cast<float>(hf.size_x), sy = static_cast<float>(hf.size_y);
  const float sz = static_cast<float>(hf.size_z), base = -static_cast<float>(hf.size_base);
  const float dx = 2 * sx / (cols - 1), dy = 2 * sy / (rows - 1);
  auto x_at = [&](int c) { return -sx + dx * c; };
  auto y_at = [&](int r) { return -sy + dy * r; };
  auto z_at = [&](int r, int c) { return hf.elevation[static_cast<size_t>(r) * cols + c] * sz; };
  auto top = [&](int r, int c) { return Eigen::Vector3f(x_at(c), y_at(r), z_at(r, c)); };

  // grid: vertex (r, c) at index r cols + c, normal from central (one-sided at borders)
  // differences.
  s.vertices.reserve(static_cast<size_t>(rows) * cols + 4 * (rows + cols) * 2);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      s.vertices.push_back(top(r, c));
      const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, cols - 1);
      const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, rows - 1);
      const float dzdx = (z_at(r, c1) - z_at(r, c0)) / (dx * (c1 - c0));
      const float dzdy = (z_at(r1, c) - z_at(r0, c)) / (dy * (r1 - r0));
      s.normals.push_back(Eigen::Vector3f(-dzdx, -dzdy, 1).normalized());
    }
  }
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) {
      const int v00 = r * cols + c, v01 = v00 + 1, v10 = v00 + cols, v11 = v10 + 1;
      s.faces.emplace_back(v00, v01, v11);
      s.faces.emplace_back(v00, v11, v10);
    }
  }
  // side walls, one quad per border segment, from the surface down to the base.
  auto down = [&](const Eigen::Vector3f& p) { return Eigen::Vector3f(p.x(), p.y(), base); };
  for (int c = 0; c + 1 < cols; ++c) {
    const Eigen::Vector3f a = top(0, c), b = top(0, c + 1);  // y = -sy, outward -y
    AddQuad(&s, down(a), down(b), b, a, -Eigen::Vector3f::UnitY());
    const Eigen::Vector3f e = top(rows - 1, c), f = top(rows - 1, c + 1);  // y = +sy
    AddQuad(&s, down(f), down(e), e, f, Eigen::Vector3f::UnitY());
  }
  for (int r = 0; r + 1 < rows; ++r) {
    const Eigen::Vector3f a = top(r, 0), b = top(r + 1, 0);  // x = -sx, outward -x
    AddQuad(&s, down(b), down(a), a, b, -Eigen::Vector3f::UnitX());
    const Eigen::Vector3f e = top(r, cols - 1), f = top(r + 1, cols - 1);  // x = +sx
    AddQuad(&s, down(e), down(f), f, e, Eigen::Vector3f::UnitX());
  }
  // bottom, facing -z.
  AddQuad(&s, {-sx, -sy, base}, {-sx, sy, base}, {sx, sy, base}, {sx, -sy, base},
          -Eigen::Vector3f::UnitZ());
  return s;
}

TriangleShadingTerms ShadingTermsOf(const TriangleShape& shape, const Eigen::Matrix3f& R_IG) {
  TriangleShadingTerms out;
  out.normals_I.reserve(shape.normals.size());
  for (const Eigen::Vector3f& n : shape.normals) out.normals_I.push_back((R_IG * n).normalized());
  if (shape.texcoords.empty()) return out;
  const std::vector<Eigen::Vector3f>& vertices_G = shape.vertices;
  out.uv_per_m.reserve(shape.faces.size());
  out.duv_dp_G.reserve(shape.faces.size());
  for (const Eigen::Vector3i& f : shape.faces) {
    const Eigen::Vector3f& p0 = vertices_G[f[0]];
    const float area = (vertices_G[f[1]] - p0).cross(vertices_G[f[2]] - p0).norm();
    const Eigen::Vector2f& t0 = shape.texcoords[f[0]];
    const Eigen::Vector2f e1 = shape.texcoords[f[1]] - t0, e2 = shape.texcoords[f[2]] - t0;
    const float uv_area = std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    out.uv_per_m.push_back(area > 0 ? std::sqrt(uv_area / area) : 0.0f);
    // J with J e1 = duv1, J e2 = duv2, J n = 0: J = [duv1 duv2 0] [e1 e2 n]^-1.
    const Eigen::Vector3f p1 = vertices_G[f[1]] - p0, p2 = vertices_G[f[2]] - p0;
    const Eigen::Vector3f n = p1.cross(p2);
    Eigen::Matrix<float, 2, 3> J = Eigen::Matrix<float, 2, 3>::Zero();
    if (area > 0 && uv_area > 0) {
      Eigen::Matrix3f E;
      E << p1, p2, n / area;
      Eigen::Matrix<float, 2, 3> F = Eigen::Matrix<float, 2, 3>::Zero();
      F.col(0) = e1;
      F.col(1) = e2;
      J = F * E.inverse();
      if (!J.allFinite()) J.setZero();
    }
    out.duv_dp_G.push_back(J);
  }
  return out;
}

}  // namespace penumbra
