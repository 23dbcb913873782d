#include "penumbra/effects/orca.h"

#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

constexpr double kEps = 1e-9;

double Det(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// the optimum on line `i` against lines [0, i) and the speed disc: the point closest to
// `target` (or, with `maximise`, farthest along `target` as a direction). false if the
// line's feasible interval is empty.
bool OptimiseOnLine(const std::vector<OrcaLine>& lines, size_t i, double max_speed,
                    const Eigen::Vector2d& target, bool maximise, Eigen::Vector2d* out) {
  const OrcaLine& li = lines[i];
  // where the line crosses the speed disc: |point + t direction| = max_speed
  const double dot = li.point.dot(li.direction);
  const double disc = dot * dot + max_speed * max_speed - li.point.squaredNorm();
  if (disc < 0) return false;
  double t_lo = -dot - std::sqrt(disc), t_hi = -dot + std::sqrt(disc);
  for (size_t j = 0; j < i; ++j) {
    const OrcaLine& lj = lines[j];
    // det(d_j, p_i + t d_i - p_j) >= 0  <=>  numer - t denom >= 0
    const double denom = Det(li.direction, lj.direction);
    const double numer = Det(lj.direction, li.point - lj.point);
    if (std::abs(denom) <= kEps) {
      if (numer < 0) return false;  // parallel and on the wrong side
      continue;
    }
    const double t = numer / denom;
    if (denom > 0)
      t_hi = std::min(t_hi, t);
    else
      t_lo = std::max(t_lo, t);
    if (t_lo > t_hi) return false;
  }
  double t;
  if (maximise)
    t = target.dot(li.direction) > 0 ? t_hi : t_lo;
  else
    t = std::clamp(li.direction.dot(target - li.point), t_lo, t_hi);
  *out = li.point + t * li.direction;
  return true;
}

// the 2-d program; returns the number of lines satisfied in order (lines.size() = all) and the
// optimum over those in *result
size_t Solve2d(const std::vector<OrcaLine>& lines, double max_speed, const Eigen::Vector2d& target,
               bool maximise, Eigen::Vector2d* result) {
  if (maximise) {
    *result = target * max_speed;  // target is a unit direction
  } else if (target.squaredNorm() > max_speed * max_speed) {
    *result = target.normalized() * max_speed;
  } else {
    *result = target;
  }
  for (size_t i = 0; i < lines.size(); ++i) {
    if (Det(lines[i].direction, *result - lines[i].point) >= 0) continue;
    Eigen::Vector2d candidate;
    if (!OptimiseOnLine(lines, i, max_speed, target, maximise, &candidate)) return i;
    *result = candidate;
  }
  return lines.size();
}

// the 3-d program from line `first` on: minimise the largest violation
void Solve3d(const std::vector<OrcaLine>& lines, size_t first, double max_speed,
             Eigen::Vector2d* result) {
  double violation = 0;
  for (size_t i = first; i < lines.size(); ++i) {
    const OrcaLine& li = lines[i];
    if (Det(li.direction, li.point - *result) <= violation) continue;
    // the earlier lines, moved to where they bisect with line i: a velocity on the same side of
    // every bisector is no more outside any earlier half-plane than outside half-plane i
    std::vector<OrcaLine> projected;
    for (size_t j = 0; j < i; ++j) {
      const OrcaLine& lj = lines[j];
      OrcaLine l;
      const double denom = Det(li.direction, lj.direction);
      if (std::abs(denom) <= kEps) {
        if (li.direction.dot(lj.direction) > 0) continue;  // same direction: line i dominates
        l.point = 0.5 * (li.point + lj.point);
      } else {
        l.point = li.point + (Det(lj.direction, li.point - lj.point) / denom) * li.direction;
      }
      const Eigen::Vector2d d = lj.direction - li.direction;
      if (d.norm() <= kEps) continue;
      l.direction = d.normalized();
      projected.push_back(l);
    }
    const Eigen::Vector2d keep = *result;
    // maximise along half-plane i's inward normal
    const Eigen::Vector2d inward(-li.direction.y(), li.direction.x());
    if (Solve2d(projected, max_speed, inward, true, result) < projected.size())
      *result = keep;  // only by rounding: the program is feasible in principle
    violation = Det(li.direction, li.point - *result);
  }
}

}  // namespace

OrcaLine OrcaHalfPlane(const Eigen::Vector2d& v_a, const Eigen::Vector2d& rel_position,
                       const Eigen::Vector2d& rel_velocity, double combined_radius, double tau,
                       double dt, double responsibility) {
  const Eigen::Vector2d& p = rel_position;
  const Eigen::Vector2d& v = rel_velocity;
  const double r = combined_radius;
  const double dist2 = p.squaredNorm();
  Eigen::Vector2d u, n;
  if (dist2 > r * r) {
    const Eigen::Vector2d w = v - p / tau;  // from the truncating disc's centre to v
    const double w_dot_p = w.dot(p);
    if (w_dot_p < 0 && w_dot_p * w_dot_p > r * r * w.squaredNorm()) {
      // the closest boundary point lies on the truncating arc
      const double w_len = w.norm();
      n = w_len > kEps ? Eigen::Vector2d(w / w_len) : Eigen::Vector2d(-p.normalized());
      u = (r / tau - w_len) * n;
    } else {
      // on a leg of the cone: tangents from the origin to the disc D(p, r)
      const double leg = std::sqrt(dist2 - r * r);
      Eigen::Vector2d d;
      if (Det(p, w) > 0) {
        // left leg (p rotated counter-clockwise); VO lies to its right
        d = Eigen::Vector2d(p.x() * leg - p.y() * r, p.x() * r + p.y() * leg) / dist2;
        n = Eigen::Vector2d(-d.y(), d.x());
      } else {
        // right leg (p rotated clockwise); VO lies to its left
        d = Eigen::Vector2d(p.x() * leg + p.y() * r, -p.x() * r + p.y() * leg) / dist2;
        n = Eigen::Vector2d(d.y(), -d.x());
      }
      u = v.dot(d) * d - v;
    }
  } else {
    // overlapping: leave the disc D(p / dt, r / dt) within one step
    const Eigen::Vector2d w = v - p / dt;
    const double w_len = w.norm();
    n = w_len > kEps ? Eigen::Vector2d(w / w_len)
                     : (p.norm() > kEps ? Eigen::Vector2d(-p.normalized()) : Eigen::Vector2d(1, 0));
    u = (r / dt - w_len) * n;
  }
  OrcaLine line;
  line.point = v_a + responsibility * u;
  line.direction = Eigen::Vector2d(n.y(), -n.x());  // the half-plane lies to its left, along n
  return line;
}

Eigen::Vector2d SolveOrcaVelocity(const std::vector<OrcaLine>& lines, double max_speed,
                                  const Eigen::Vector2d& preferred) {
  Eigen::Vector2d result;
  const size_t ok = Solve2d(lines, max_speed, preferred, false, &result);
  if (ok < lines.size()) Solve3d(lines, ok, max_speed, &result);
  return result;
}

}  // namespace penumbra
