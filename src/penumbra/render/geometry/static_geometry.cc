#include "penumbra/render/geometry/static_geometry.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/geometry/analytic_shapes.h"

namespace penumbra {

bool LocalHalfExtents(const SceneDescription& scene, const Geom& g, Eigen::Vector3d* lo,
                      Eigen::Vector3d* hi) {
  const Eigen::Vector3d& s = g.size;
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  switch (g.shape) {
    case GeomShape::kPlane:
      return false;
    case GeomShape::kSphere:
      h = Eigen::Vector3d::Constant(s.x());
      break;
    case GeomShape::kCapsule:
      h = {s.x(), s.x(), s.y() + s.x()};
      break;
    case GeomShape::kEllipsoid:
    case GeomShape::kBox:
      h = s;
      break;
    case GeomShape::kCylinder:
      h = {s.x(), s.x(), s.y()};
      break;
    case GeomShape::kMesh: {
      if (g.mesh < 0 || g.mesh >= static_cast<int>(scene.meshes.size())) return false;
      const TriangleMesh& m = scene.meshes[g.mesh];
      if (m.vertices.empty()) return false;
      Eigen::Vector3f a = m.vertices[0], b = m.vertices[0];
      for (const Eigen::Vector3f& v : m.vertices) a = a.cwiseMin(v), b = b.cwiseMax(v);
      *lo = a.cast<double>();
      *hi = b.cast<double>();
      return true;
    }
    case GeomShape::kHeightField: {
      if (g.hfield < 0 || g.hfield >= static_cast<int>(scene.hfields.size())) return false;
      const HeightField& f = scene.hfields[g.hfield];
      *lo = {-f.size_x, -f.size_y, -f.size_base};
      *hi = {f.size_x, f.size_y, f.size_z};
      return true;
    }
  }
  *lo = -h;
  *hi = h;
  return true;
}

// the geoms a RayQuery traces (render/ray_query.h: groups <= 2, alpha >= 0.5) of static bodies.
bool IsRayVisible(const SceneDescription& scene, const Geom& geom, const std::string& who) {
  if (geom.group > 2) return false;
  if (geom.material >= static_cast<int>(scene.materials.size()))
    throw Error(who + ": geom '" + geom.name + "' refers to missing material " +
                std::to_string(geom.material));
  return !(geom.material >= 0 && scene.materials[geom.material].alpha < 0.5f);
}

void ValidateRayGeom(const SceneDescription& scene, const Geom& geom, const std::string& who) {
  const std::string what = who + ": geom '" + geom.name + "' ";
  if (geom.body < 0 || geom.body >= static_cast<int>(scene.bodies.size()))
    throw Error(what + "refers to missing body " + std::to_string(geom.body));
  switch (geom.shape) {
    case GeomShape::kMesh:
      if (geom.mesh < 0 || geom.mesh >= static_cast<int>(scene.meshes.size()))
        throw Error(what + "refers to missing mesh " + std::to_string(geom.mesh));
      break;
    case GeomShape::kHeightField:
      if (geom.hfield < 0 || geom.hfield >= static_cast<int>(scene.hfields.size()))
        throw Error(what + "refers to missing height field " + std::to_string(geom.hfield));
      break;
    case GeomShape::kBox:
      if (!(geom.size.minCoeff() > 0) || !geom.size.allFinite())
        throw Error(what + "has a non-positive box size");
      break;
    case GeomShape::kPlane:
      if (!(geom.size.x() >= 0 && geom.size.y() >= 0) || !geom.size.allFinite())
        throw Error(what + "has a negative plane size");
      break;
    default: {
      AnalyticShape shape;
      shape.kind = geom.shape == GeomShape::kSphere      ? AnalyticKind::kSphere
                   : geom.shape == GeomShape::kCapsule   ? AnalyticKind::kCapsule
                   : geom.shape == GeomShape::kEllipsoid ? AnalyticKind::kEllipsoid
                                                         : AnalyticKind::kCylinder;
      shape.size = geom.size;
      const Eigen::Vector3d h = AnalyticHalfExtents(shape);
      if (!(h.minCoeff() > 0) || !h.allFinite())
        throw Error(what + "has a non-positive size for its shape");
    }
  }
}

std::vector<RayGeomGroup> GroupRayGeoms(const SceneDescription& scene, const std::string& who) {
  std::vector<RayGeomGroup> groups(1);
  std::vector<int> group_of_body(scene.bodies.size(), -1);
  for (int gi = 0; gi < static_cast<int>(scene.geoms.size()); ++gi) {
    const Geom& g = scene.geoms[gi];
    if (!IsRayVisible(scene, g, who)) continue;
    ValidateRayGeom(scene, g, who);
    if (g.body == 0 || scene.bodies[g.body].is_static) {
      groups[0].geoms.push_back(gi);
      continue;
    }
    int& k = group_of_body[g.body];
    if (k < 0) {
      k = static_cast<int>(groups.size());
      groups.emplace_back();
      groups.back().body = g.body;
    }
    groups[k].geoms.push_back(gi);
  }
  return groups;
}

void ValidateRayTendon(const SceneDescription& scene, const Tendon& tendon,
                       const std::string& who) {
  if (tendon.material < 0 || tendon.material >= static_cast<int>(scene.materials.size()))
    throw Error(who + ": tendon '" + tendon.name + "' refers to missing material " +
                std::to_string(tendon.material));
  if (!(tendon.width_m > 0) || !std::isfinite(tendon.width_m))
    throw Error(who + ": tendon '" + tendon.name + "' has a non-positive width");
}

bool IsStaticVisible(const SceneDescription& scene, const Geom& g) {
  if (g.group > 2) return false;
  if (g.material >= 0 && g.material < static_cast<int>(scene.materials.size()) &&
      scene.materials[g.material].alpha < 0.5f)
    return false;
  return g.body == 0 || (g.body > 0 && g.body < static_cast<int>(scene.bodies.size()) &&
                         scene.bodies[g.body].is_static);
}

bool IsStaticBody(const SceneDescription& scene, int b) {
  return b == 0 || scene.bodies[b].is_static;
}

SceneDescription StaticGeoms(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                             Eigen::Vector3d* lo_W, Eigen::Vector3d* hi_W) {
  SceneDescription statics = scene;
  statics.geoms.clear();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Geom& g : scene.geoms) {
    if (!IsStaticVisible(scene, g)) continue;
    statics.geoms.push_back(g);
    Eigen::Vector3d a, b;
    if (!LocalHalfExtents(scene, g, &a, &b)) continue;
    const Pose X_WG = X_WB[g.body] * g.X_BG;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner((c & 1) ? b.x() : a.x(), (c & 2) ? b.y() : a.y(),
                                   (c & 4) ? b.z() : a.z());
      const Eigen::Vector3d p = X_WG * corner;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  *lo_W = lo;
  *hi_W = hi;
  return statics;
}

}  // namespace penumbra
