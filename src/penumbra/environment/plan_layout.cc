#include "penumbra/environment/plan_layout.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/environment/mjcf_builder.h"

namespace penumbra {

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

namespace {

// distance between two segments in the plane (0 when they cross)
double SegmentDistance(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                       const Eigen::Vector2d& d) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 0;
  return std::min({DistanceToSegment(a, c, d), DistanceToSegment(b, c, d),
                   DistanceToSegment(c, a, b), DistanceToSegment(d, a, b)});
}

}  // namespace

double RectDistanceToPolyline(const PlanRect& r, const std::vector<Eigen::Vector2d>& points) {
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d c[4] = {{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}};
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d& p = points[i];
    if (p.x() >= r.x0 && p.x() <= r.x1 && p.y() >= r.y0 && p.y() <= r.y1) return 0;
    if (i + 1 == points.size()) break;
    for (int e = 0; e < 4; ++e)
      best = std::min(best, SegmentDistance(points[i], points[i + 1], c[e], c[(e + 1) % 4]));
  }
  if (points.size() == 1) {
    for (int e = 0; e < 4; ++e)
      best = std::min(best, DistanceToSegment(points[0], c[e], c[(e + 1) % 4]));
  }
  return best;
}

bool PlanLayout::Fits(const PlanRect& r, const PlanRect& bounds, double gap_m) const {
  if (r.x0 < bounds.x0 || r.y0 < bounds.y0 || r.x1 > bounds.x1 || r.y1 > bounds.y1) return false;
  for (const PlanRect& t : taken_) {
    if (r.x0 < t.x1 + gap_m && t.x0 < r.x1 + gap_m && r.y0 < t.y1 + gap_m && t.y0 < r.y1 + gap_m)
      return false;
  }
  for (const Walkway& w : walkways_)
    if (RectDistanceToPolyline(r, w.points) < w.half_width_m) return false;
  return true;
}

bool PlanLayout::TryTake(const PlanRect& r, const PlanRect& bounds, double gap_m) {
  if (!Fits(r, bounds, gap_m)) return false;
  Take(r);
  return true;
}

PlanRect FootprintOf(const PlanFrame& frame, double x0, double y0, double x1, double y1) {
  PlanRect r{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
             -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y0),
                                   Eigen::Vector2d(x1, y1), Eigen::Vector2d(x0, y1)}) {
    const Eigen::Vector3d q = frame.Apply({p.x(), p.y(), 0});
    r.x0 = std::min(r.x0, q.x());
    r.y0 = std::min(r.y0, q.y());
    r.x1 = std::max(r.x1, q.x());
    r.y1 = std::max(r.y1, q.y());
  }
  return r;
}

}  // namespace penumbra
