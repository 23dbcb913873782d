#include "penumbra/session/floor_map.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>

#include "penumbra/session/geom_extents.h"

namespace penumbra {
namespace {

// local bounding box (centre, half extents) of a geom in its own frame; false for planes
// and height fields (never blocking)
bool LocalBox(const SceneDescription& scene, const Geom& g, Eigen::Vector3d* c,
              Eigen::Vector3d* e) {
  *c = Eigen::Vector3d::Zero();
  if (const std::optional<Eigen::Vector3d> h = PrimitiveHalfExtents(g)) {
    *e = *h;
    return true;
  }
  // meshes: the box of their vertices
  if (g.shape != GeomShape::kMesh || g.mesh < 0 || g.mesh >= static_cast<int>(scene.meshes.size()))
    return false;
  const auto& v = scene.meshes[g.mesh].vertices;
  if (v.empty()) return false;
  Eigen::Vector3f lo = v[0], hi = v[0];
  for (const Eigen::Vector3f& p : v) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  *c = (0.5f * (lo + hi)).cast<double>();
  *e = (0.5f * (hi - lo)).cast<double>();
  return true;
}

}  // namespace

FloorMap::FloorMap(const SceneDescription& scene, const std::vector<Pose>& X_WB, double floor_z,
                   const Eigen::Vector2d& centre_W, double band_lo_m, double band_hi_m,
                   double reach_m)
    : floor_z_(floor_z) {
  struct Box2 {
    Eigen::Vector2d lo, hi;
  };
  std::vector<Box2> blockers;
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const Geom& g : scene.geoms) {
    if (g.body < 0 || g.body >= static_cast<int>(scene.bodies.size())) continue;
    if (!scene.bodies[g.body].is_static) continue;
    Eigen::Vector3d c, e;
    if (!LocalBox(scene, g, &c, &e)) continue;
    const Pose X_WG =
        (g.body < static_cast<int>(X_WB.size()) ? X_WB[g.body] : Pose::Identity()) * g.X_BG;
    const Eigen::Vector3d cw = X_WG * c;
    const Eigen::Vector3d ew = X_WG.linear().cwiseAbs() * e;
    lo = lo.cwiseMin((cw - ew).head<2>());
    hi = hi.cwiseMax((cw + ew).head<2>());
    has_bounds_ = true;
    // blocks the floor if it overlaps the band where people and vehicles are
    if (cw.z() + ew.z() < floor_z + band_lo_m || cw.z() - ew.z() > floor_z + band_hi_m) continue;
    blockers.push_back({(cw - ew).head<2>(), (cw + ew).head<2>()});
  }
  const Eigen::Vector2d near(5.0, 5.0), reach(reach_m, reach_m);
  min_ = centre_W - near;
  max_ = centre_W + near;
  if (has_bounds_) {
    static_min_ = lo;
    static_max_ = hi;
    min_ = min_.cwiseMin(lo).cwiseMax(centre_W - reach);
    max_ = max_.cwiseMax(hi).cwiseMin(centre_W + reach);
  }
  nx_ = std::max(1, static_cast<int>(std::ceil((max_.x() - min_.x()) / kCellM)));
  ny_ = std::max(1, static_cast<int>(std::ceil((max_.y() - min_.y()) / kCellM)));
  blocked_.assign(static_cast<size_t>(nx_) * ny_, 0);
  for (const Box2& b : blockers) {
    const int x0 = std::max(0, static_cast<int>(std::floor((b.lo.x() - min_.x()) / kCellM)));
    const int y0 = std::max(0, static_cast<int>(std::floor((b.lo.y() - min_.y()) / kCellM)));
    const int x1 = std::min(nx_ - 1, static_cast<int>(std::floor((b.hi.x() - min_.x()) / kCellM)));
    const int y1 = std::min(ny_ - 1, static_cast<int>(std::floor((b.hi.y() - min_.y()) / kCellM)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) blocked_[Index(x, y)] = 1;
  }
  for (int i = 0; i < nx_ * ny_; ++i)
    if (!blocked_[i]) reachable_.push_back(i);
}

bool FloorMap::IsFree(const Eigen::Vector2d& p, double clearance_m) const {
  if (p.x() - clearance_m < min_.x() || p.y() - clearance_m < min_.y() ||
      p.x() + clearance_m > max_.x() || p.y() + clearance_m > max_.y())
    return false;
  const int r = static_cast<int>(std::ceil(clearance_m / kCellM));
  const int cx = static_cast<int>(std::floor((p.x() - min_.x()) / kCellM));
  const int cy = static_cast<int>(std::floor((p.y() - min_.y()) / kCellM));
  for (int y = std::max(0, cy - r); y <= std::min(ny_ - 1, cy + r); ++y)
    for (int x = std::max(0, cx - r); x <= std::min(nx_ - 1, cx + r); ++x) {
      if (!blocked_[Index(x, y)]) continue;
      // distance from p to the cell's square
      const Eigen::Vector2d cell_lo = min_ + kCellM * Eigen::Vector2d(x, y);
      const Eigen::Vector2d q =
          p.cwiseMax(cell_lo).cwiseMin(cell_lo + Eigen::Vector2d::Constant(kCellM));
      if ((q - p).norm() < clearance_m) return false;
    }
  return true;
}

bool FloorMap::SegmentFree(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                           double clearance_m) const {
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.05)));
  for (int i = 0; i <= n; ++i)
    if (!IsFree(a + (b - a) * (static_cast<double>(i) / n), clearance_m)) return false;
  return true;
}

void FloorMap::Flood(const Eigen::Vector2d& seed, double clearance_m) {
  const auto centre = [&](int i) {
    return Eigen::Vector2d(min_.x() + (i % nx_ + 0.5) * kCellM,
                           min_.y() + (i / nx_ + 0.5) * kCellM);
  };
  std::vector<uint8_t> free(static_cast<size_t>(nx_) * ny_, 0);
  for (int i = 0; i < nx_ * ny_; ++i) free[i] = IsFree(centre(i), clearance_m);
  const int sx = static_cast<int>(std::floor((seed.x() - min_.x()) / kCellM));
  const int sy = static_cast<int>(std::floor((seed.y() - min_.y()) / kCellM));
  reachable_.clear();
  if (sx < 0 || sy < 0 || sx >= nx_ || sy >= ny_ || !free[Index(sx, sy)]) {
    for (int i = 0; i < nx_ * ny_; ++i)
      if (free[i]) reachable_.push_back(i);
    return;
  }
  std::vector<uint8_t> seen(free.size(), 0);
  std::deque<int> queue{Index(sx, sy)};
  seen[Index(sx, sy)] = 1;
  while (!queue.empty()) {
    const int i = queue.front();
    queue.pop_front();
    reachable_.push_back(i);
    const int x = i % nx_, y = i / nx_;
    const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
    for (const auto& n : nb) {
      if (n[0] < 0 || n[1] < 0 || n[0] >= nx_ || n[1] >= ny_) continue;
      const int j = Index(n[0], n[1]);
      if (free[j] && !seen[j]) {
        seen[j] = 1;
        queue.push_back(j);
      }
    }
  }
  std::sort(reachable_.begin(), reachable_.end());
}

bool FloorMap::ReachableBounds(Eigen::Vector2d* lo, Eigen::Vector2d* hi) const {
  if (reachable_.empty()) return false;
  *lo = Eigen::Vector2d(1e300, 1e300);
  *hi = -*lo;
  for (int i : reachable_) {
    const Eigen::Vector2d c(min_.x() + (i % nx_) * kCellM, min_.y() + (i / nx_) * kCellM);
    *lo = lo->cwiseMin(c);
    *hi = hi->cwiseMax(c + Eigen::Vector2d::Constant(kCellM));
  }
  return true;
}

OccupancyGrid FloorMap::Occupancy() const {
  OccupancyGrid g;
  g.min_W = min_;
  g.cell_m = kCellM;
  g.nx = nx_;
  g.ny = ny_;
  g.blocked = blocked_;
  return g;
}

bool FloorMap::RandomFreePoint(uint64_t u, Eigen::Vector2d* p) const {
  if (reachable_.empty()) return false;
  const int i = reachable_[u % reachable_.size()];
  *p = Eigen::Vector2d(min_.x() + (i % nx_ + 0.5) * kCellM, min_.y() + (i / nx_ + 0.5) * kCellM);
  return true;
}

}  // namespace penumbra
