#pragma once
// the plan of a generated environment while it is being furnished: the footprints taken so far
// and the walkways to keep clear, and the random numbers of one seed.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/environment/environment_generator.h"
#include "penumbra/environment/mjcf_builder.h"

namespace penumbra {

/// uniform draws from one counter-based stream (core/rng.h), keyed by the environment's seed
/// and a purpose, so that adding draws for one purpose leaves the others unchanged.
class PlanRandom {
 public:
  PlanRandom(uint64_t seed, uint64_t purpose) : rng_(HashKeys(seed, purpose)) {}
  /// uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * rng_.UniformD(); }
  /// uniform integer in [lo, hi].
  int Int(int lo, int hi) {
    return lo + static_cast<int>(rng_.NextU64() % static_cast<uint64_t>(hi - lo + 1));
  }
  /// true with probability p.
  bool Chance(double p) { return rng_.UniformD() < p; }
  /// a 64-bit value (seeds of procedural materials).
  uint64_t Bits() { return rng_.NextU64(); }
  /// one element of `v` (not empty), each equally likely; draws one Int.
  template <typename T>
  const T& Pick(const std::vector<T>& v) {
    return v[static_cast<size_t>(Int(0, static_cast<int>(v.size()) - 1))];
  }

 private:
  Rng rng_;
};

/// footprints (plan rectangles) of the furniture placed so far, and the walkways.
class PlanLayout {
 public:
  explicit PlanLayout(std::vector<Walkway> walkways) : walkways_(std::move(walkways)) {}

  /// true when `r` keeps `gap_m` from every footprint taken and the walkways' half widths
  /// from every walkway, and lies inside `bounds`.
  bool Fits(const PlanRect& r, const PlanRect& bounds, double gap_m = 0.05) const;
  /// takes `r`.
  void Take(const PlanRect& r) { taken_.push_back(r); }
  /// Fits, then Take; returns whether it fitted.
  bool TryTake(const PlanRect& r, const PlanRect& bounds, double gap_m = 0.05);

  const std::vector<Walkway>& walkways() const { return walkways_; }

 private:
  std::vector<Walkway> walkways_;
  std::vector<PlanRect> taken_;
};

/// the plan rectangle of a local rectangle [x0, x1] x [y0, y1] of `frame` (yaw a multiple of
/// 90 deg; other yaws give the bounding rectangle of the turned corners).
PlanRect FootprintOf(const PlanFrame& frame, double x0, double y0, double x1, double y1);

/// distance (plan view) from point p to the segment a-b, m.
double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b);

/// distance from the rectangle r (0 inside) to the polyline `points`, m.
double RectDistanceToPolyline(const PlanRect& r, const std::vector<Eigen::Vector2d>& points);

}  // namespace penumbra
