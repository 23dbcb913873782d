#include "penumbra/session/geom_extents.h"

namespace penumbra {

std::optional<Eigen::Vector3d> PrimitiveHalfExtents(const Geom& g) {
  const Eigen::Vector3d& s = g.size;
  switch (g.shape) {
    case GeomShape::kSphere:
      return Eigen::Vector3d::Constant(s.x());
    case GeomShape::kCapsule:
      return Eigen::Vector3d(s.x(), s.x(), s.x() + s.y());
    case GeomShape::kCylinder:
      return Eigen::Vector3d(s.x(), s.x(), s.y());
    case GeomShape::kEllipsoid:
    case GeomShape::kBox:
      return s;
    default:
      return std::nullopt;
  }
}

}  // namespace penumbra
