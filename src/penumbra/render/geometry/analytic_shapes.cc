#include "penumbra/render/geometry/analytic_shapes.h"

#include <cmath>

namespace penumbra {
// the Eigen forms of the shared array functions (analytic_shapes.h).
bool IntersectAnalytic(const AnalyticShape& shape, const Eigen::Vector3d& o,
                       const Eigen::Vector3d& d, double tmin, double tmax, double* t,
                       ShapePart* part) {
  int p = 0;
  if (!IntersectAnalyticArrays(shape.kind, shape.size.data(), o.data(), d.data(), tmin, tmax, t,
                               &p))
    return false;
  *part = static_cast<ShapePart>(p);
  return true;
}

Eigen::Vector3d AnalyticNormal(const AnalyticShape& shape, const Eigen::Vector3d& p,
                               ShapePart part) {
  Eigen::Vector3d n;
  AnalyticNormalArrays(shape.kind, shape.size.data(), p.data(), static_cast<int>(part), n.data());
  return n;
}

Eigen::Vector3d AnalyticHalfExtents(const AnalyticShape& shape) {
  const Eigen::Vector3d& s = shape.size;
  switch (shape.kind) {
    case AnalyticKind::kPlane:
      return {s.x(), s.y(), 0};
    case AnalyticKind::kSphere:
      return {s.x(), s.x(), s.x()};
    case AnalyticKind::kEllipsoid:
      return s;
    case AnalyticKind::kCylinder:
      return {s.x(), s.x(), s.y()};
    case AnalyticKind::kCapsule:
      return {s.x(), s.x(), s.y() + s.x()};
  }
  return s;
}

}  // namespace penumbra
