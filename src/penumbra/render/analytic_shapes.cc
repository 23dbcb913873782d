#include "penumbra/render/analytic_shapes.h"

#include <cmath>
#include <utility>

namespace penumbra {
namespace {

// running closest root in (tmin, tmax).
struct Closest {
  double tmin, tmax;
  bool found = false;
  double t = 0;
  ShapePart part = ShapePart::kMain;
  void Offer(double tc, ShapePart p) {
    if (tc > tmin && tc < tmax && (!found || tc < t)) {
      found = true;
      t = tc;
      part = p;
    }
  }
};

// roots of |o + t d|^2 = r^2 over the first `dim` coordinates (2: infinite cylinder about z,
// 3: sphere), stable form (pbrt-v4 sec. 6.8.1): the discriminant comes from the squared
// distance of the line to the centre instead of b^2 - 4ac. returns false if the line misses.
template <int dim>
bool QuadricRoots(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double* t0,
                  double* t1) {
  const auto od = o.head<dim>();
  const auto dd = d.head<dim>();
  const double a = dd.squaredNorm();
  if (!(a > 0)) return false;
  const double b = 2 * od.dot(dd);
  const double c = od.squaredNorm() - r * r;
  const Eigen::Matrix<double, dim, 1> v = od - (b / (2 * a)) * dd;
  const double disc = 4 * a * (r * r - v.squaredNorm());
  if (disc < 0) return false;
  const double root = std::sqrt(disc);
  const double q = b < 0 ? -0.5 * (b - root) : -0.5 * (b + root);
  if (q == 0) {
    // b == 0 and a tangent ray: a double root at t = 0 (c == 0) or none.
    if (c != 0) return false;
    *t0 = *t1 = 0;
    return true;
  }
  *t0 = q / a;
  *t1 = c / q;
  if (*t0 > *t1) std::swap(*t0, *t1);
  return true;
}

}  // namespace

bool IntersectAnalytic(const AnalyticShape& shape, const Eigen::Vector3d& o,
                       const Eigen::Vector3d& d, double tmin, double tmax, double* t,
                       ShapePart* part) {
  Closest best{tmin, tmax};
  double t0, t1;
  switch (shape.kind) {
    case AnalyticKind::kPlane: {
      if (d.z() == 0) return false;
      const double tc = -o.z() / d.z();
      const double x = o.x() + tc * d.x(), y = o.y() + tc * d.y();
      if (std::abs(x) <= shape.size.x() && std::abs(y) <= shape.size.y())
        best.Offer(tc, ShapePart::kMain);
      break;
    }
    case AnalyticKind::kSphere:
      if (QuadricRoots<3>(o, d, shape.size.x(), &t0, &t1)) {
        best.Offer(t0, ShapePart::kMain);
        best.Offer(t1, ShapePart::kMain);
      }
      break;
    case AnalyticKind::kEllipsoid: {
      // a unit sphere after scaling each axis by 1 / radius (t is unchanged by the scaling).
      const Eigen::Vector3d inv = shape.size.cwiseInverse();
      if (QuadricRoots<3>(o.cwiseProduct(inv), d.cwiseProduct(inv), 1.0, &t0, &t1)) {
        best.Offer(t0, ShapePart::kMain);
        best.Offer(t1, ShapePart::kMain);
      }
      break;
    }
    case AnalyticKind::kCylinder:
    case AnalyticKind::kCapsule: {
      const double r = shape.size.x(), h = shape.size.y();
      // side: infinite cylinder about z, kept where |z| <= h.
      if (QuadricRoots<2>(o, d, r, &t0, &t1)) {
        for (double tc : {t0, t1})
          if (std::abs(o.z() + tc * d.z()) <= h) best.Offer(tc, ShapePart::kMain);
      }
      if (shape.kind == AnalyticKind::kCylinder) {
        // flat caps at z = +-h.
        if (d.z() != 0) {
          for (int s : {1, -1}) {
            const double tc = (s * h - o.z()) / d.z();
            const double x = o.x() + tc * d.x(), y = o.y() + tc * d.y();
            if (x * x + y * y <= r * r)
              best.Offer(tc, s > 0 ? ShapePart::kTop : ShapePart::kBottom);
          }
        }
      } else {
        // hemispheres centred at z = +-h, kept on their outer halves.
        for (int s : {1, -1}) {
          const Eigen::Vector3d oc = o - Eigen::Vector3d(0, 0, s * h);
          if (!QuadricRoots<3>(oc, d, r, &t0, &t1)) continue;
          for (double tc : {t0, t1})
            if (s * (oc.z() + tc * d.z()) >= 0)
              best.Offer(tc, s > 0 ? ShapePart::kTop : ShapePart::kBottom);
        }
      }
      break;
    }
  }
  if (!best.found) return false;
  *t = best.t;
  *part = best.part;
  return true;
}

Eigen::Vector3d AnalyticNormal(const AnalyticShape& shape, const Eigen::Vector3d& p,
                               ShapePart part) {
  Eigen::Vector3d n = p;  // sphere
  switch (shape.kind) {
    case AnalyticKind::kPlane:
      return Eigen::Vector3d::UnitZ();
    case AnalyticKind::kSphere:
      break;
    case AnalyticKind::kEllipsoid:
      // gradient of sum (x_i / r_i)^2.
      n = p.cwiseQuotient(shape.size.cwiseProduct(shape.size));
      break;
    case AnalyticKind::kCylinder:
      if (part == ShapePart::kTop) return Eigen::Vector3d::UnitZ();
      if (part == ShapePart::kBottom) return -Eigen::Vector3d::UnitZ();
      n = Eigen::Vector3d(p.x(), p.y(), 0);
      break;
    case AnalyticKind::kCapsule:
      if (part == ShapePart::kTop) {
        n = p - Eigen::Vector3d(0, 0, shape.size.y());
      } else if (part == ShapePart::kBottom) {
        n = p + Eigen::Vector3d(0, 0, shape.size.y());
      } else {
        n = Eigen::Vector3d(p.x(), p.y(), 0);
      }
      break;
  }
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::UnitZ();
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
