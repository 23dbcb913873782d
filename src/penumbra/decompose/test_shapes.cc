#include "penumbra/decompose/test_shapes.h"

#include <cmath>
#include <numbers>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

// ear clipping of a simple counter-clockwise polygon; triangles as index triples
std::vector<std::array<int, 3>> EarClip(const std::vector<Eigen::Vector2d>& poly) {
  std::vector<int> idx(poly.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
  std::vector<std::array<int, 3>> tris;
  while (idx.size() > 3) {
    bool clipped = false;
    for (size_t i = 0; i < idx.size(); ++i) {
      const int a = idx[(i + idx.size() - 1) % idx.size()], b = idx[i],
                c = idx[(i + 1) % idx.size()];
      if (Cross(poly[a], poly[b], poly[c]) <= 0) continue;  // reflex
      bool contains = false;
      for (int j : idx) {
        if (j == a || j == b || j == c) continue;
        if (Cross(poly[a], poly[b], poly[j]) >= 0 && Cross(poly[b], poly[c], poly[j]) >= 0 &&
            Cross(poly[c], poly[a], poly[j]) >= 0)
          contains = true;
      }
      if (contains) continue;
      tris.push_back({a, b, c});
      idx.erase(idx.begin() + i);
      clipped = true;
      break;
    }
    if (!clipped) throw Error("ExtrudePolygon: outline is not a simple counter-clockwise polygon");
  }
  tris.push_back({idx[0], idx[1], idx[2]});
  return tris;
}

}  // namespace

SolidMesh ExtrudePolygon(const std::vector<Eigen::Vector2d>& outline, double height) {
  const int n = static_cast<int>(outline.size());
  SolidMesh mesh;
  for (const auto& p : outline) mesh.vertices.emplace_back(p.x(), p.y(), 0.0);
  for (const auto& p : outline) mesh.vertices.emplace_back(p.x(), p.y(), height);
  for (const auto& t : EarClip(outline)) {
    mesh.triangles.push_back({t[0], t[2], t[1]});              // bottom, facing -z
    mesh.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});  // top, facing +z
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    mesh.triangles.push_back({i, j, j + n});
    mesh.triangles.push_back({i, j + n, i + n});
  }
  return mesh;
}

SolidMesh MakeLShape() {
  return ExtrudePolygon({{0, 0}, {1, 0}, {1, 0.4}, {0.4, 0.4}, {0.4, 1}, {0, 1}}, 0.4);
}

SolidMesh MakeUShape() {
  return ExtrudePolygon(
      {{0, 0}, {1, 0}, {1, 1}, {0.7, 1}, {0.7, 0.3}, {0.3, 0.3}, {0.3, 1}, {0, 1}}, 0.4);
}

SolidMesh MakeTorus(double major, double minor, int ring_segments, int tube_segments) {
  SolidMesh mesh;
  const double two_pi = 2 * std::numbers::pi;
  for (int i = 0; i < ring_segments; ++i) {
    const double u = two_pi * i / ring_segments;
    for (int j = 0; j < tube_segments; ++j) {
      const double v = two_pi * j / tube_segments;
      const double r = major + minor * std::cos(v);
      mesh.vertices.emplace_back(r * std::cos(u), r * std::sin(u), minor * std::sin(v));
    }
  }
  auto id = [&](int i, int j) { return (i % ring_segments) * tube_segments + (j % tube_segments); };
  for (int i = 0; i < ring_segments; ++i)
    for (int j = 0; j < tube_segments; ++j) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  return mesh;
}

SolidMesh MakeBowl(double outer, double inner, int segments, int rings) {
  SolidMesh mesh;
  const double two_pi = 2 * std::numbers::pi;
  // rings r = 0 (rim) .. rings - 1 on each sphere, polar angle from the rim down; then a pole
  auto ring_point = [&](double radius, int r, int s) {
    const double phi = 0.5 * std::numbers::pi * r / rings;  // 0 at the rim
    const double theta = two_pi * s / segments;
    return Eigen::Vector3d(radius * std::cos(phi) * std::cos(theta),
                           radius * std::cos(phi) * std::sin(theta), -radius * std::sin(phi));
  };
  auto outer_id = [&](int r, int s) { return r * segments + (s % segments); };
  const int inner_base = rings * segments;
  auto inner_id = [&](int r, int s) { return inner_base + r * segments + (s % segments); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) mesh.vertices.push_back(ring_point(outer, r, s));
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) mesh.vertices.push_back(ring_point(inner, r, s));
  const int outer_pole = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0, 0, -outer);
  const int inner_pole = outer_pole + 1;
  mesh.vertices.emplace_back(0, 0, -inner);
  for (int s = 0; s < segments; ++s) {
    // rim annulus, facing +z
    mesh.triangles.push_back({outer_id(0, s), outer_id(0, s + 1), inner_id(0, s + 1)});
    mesh.triangles.push_back({outer_id(0, s), inner_id(0, s + 1), inner_id(0, s)});
    for (int r = 0; r + 1 < rings; ++r) {
      // outer surface faces away from the centre
      mesh.triangles.push_back({outer_id(r, s), outer_id(r + 1, s), outer_id(r + 1, s + 1)});
      mesh.triangles.push_back({outer_id(r, s), outer_id(r + 1, s + 1), outer_id(r, s + 1)});
      // inner surface faces the centre
      mesh.triangles.push_back({inner_id(r, s), inner_id(r + 1, s + 1), inner_id(r + 1, s)});
      mesh.triangles.push_back({inner_id(r, s), inner_id(r, s + 1), inner_id(r + 1, s + 1)});
    }
    mesh.triangles.push_back({outer_id(rings - 1, s), outer_pole, outer_id(rings - 1, s + 1)});
    mesh.triangles.push_back({inner_id(rings - 1, s), inner_id(rings - 1, s + 1), inner_pole});
  }
  return mesh;
}

SolidMesh MakeTestShape(const std::string& name) {
  if (name == "l") return MakeLShape();
  if (name == "u") return MakeUShape();
  if (name == "torus") return MakeTorus();
  if (name == "bowl") return MakeBowl();
  throw Error("unknown test shape '" + name + "'; expected l, u, torus or bowl");
}

std::vector<std::string> TestShapeNames() { return {"l", "u", "torus", "bowl"}; }

}  // namespace penumbra
