#include "penumbra/effects/walkable_grid.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <queue>

#include "penumbra/core/error.h"

namespace penumbra {

WalkableGrid::WalkableGrid(const OccupancyGrid& occupancy, double radius_m,
                           const std::vector<Eigen::Vector2d>& seeds_W)
    : min_(occupancy.min_W),
      cell_m_(occupancy.cell_m),
      radius_m_(radius_m),
      nx_(occupancy.nx),
      ny_(occupancy.ny),
      blocked_(occupancy.blocked) {
  if (!(cell_m_ > 0) || nx_ < 1 || ny_ < 1 ||
      blocked_.size() != static_cast<size_t>(nx_) * static_cast<size_t>(ny_))
    throw Error("WalkableGrid: occupancy grid of " + std::to_string(nx_) + " x " +
                std::to_string(ny_) + " cells with " + std::to_string(blocked_.size()) +
                " entries; expected nx, ny >= 1, cell_m > 0 and nx ny entries");
  if (!(radius_m >= 0) || !std::isfinite(radius_m))
    throw Error("WalkableGrid: radius must be finite and >= 0");
  // inflate: a cell is free when its centre lies at least radius_m from every blocked cell's
  // square and from the grid's edge
  std::vector<uint8_t> free(blocked_.size(), 1);
  const int reach = static_cast<int>(std::ceil(radius_m / cell_m_)) + 1;
  std::vector<std::pair<int, int>> stamp;
  for (int dy = -reach; dy <= reach; ++dy)
    for (int dx = -reach; dx <= reach; ++dx) {
      const double ex = std::max(0.0, (std::abs(dx) - 0.5) * cell_m_);
      const double ey = std::max(0.0, (std::abs(dy) - 0.5) * cell_m_);
      if (ex * ex + ey * ey < radius_m * radius_m || (dx == 0 && dy == 0))
        stamp.emplace_back(dx, dy);
    }
  for (int iy = 0; iy < ny_; ++iy)
    for (int ix = 0; ix < nx_; ++ix) {
      if (!blocked_[Index(ix, iy)]) continue;
      for (const auto& [dx, dy] : stamp) {
        const int x = ix + dx, y = iy + dy;
        if (x >= 0 && y >= 0 && x < nx_ && y < ny_) free[Index(x, y)] = 0;
      }
    }
  for (int iy = 0; iy < ny_; ++iy)
    for (int ix = 0; ix < nx_; ++ix) {
      const double to_edge = cell_m_ * (std::min({ix, iy, nx_ - 1 - ix, ny_ - 1 - iy}) + 0.5);
      if (to_edge < radius_m) free[Index(ix, iy)] = 0;
    }
  // the components reachable from the free cells nearest the seeds
  walkable_.assign(free.size(), 0);
  for (const Eigen::Vector2d& seed_W : seeds_W) {
    int seed = -1;
    double best = 1e300;
    for (int iy = 0; iy < ny_; ++iy)
      for (int ix = 0; ix < nx_; ++ix) {
        if (!free[Index(ix, iy)]) continue;
        const double d = (CellCentre(ix, iy) - seed_W).squaredNorm();
        if (d < best) {
          best = d;
          seed = Index(ix, iy);
        }
      }
    if (seed < 0 || walkable_[seed]) continue;
    std::deque<int> queue{seed};
    walkable_[seed] = 1;
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      ++count_;
      const int x = i % nx_, y = i / nx_;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= nx_ || qy >= ny_) continue;
          const int j = Index(qx, qy);
          // diagonal steps only between two free side cells (no corner cutting)
          if (dx != 0 && dy != 0 && (!free[Index(x + dx, y)] || !free[Index(x, y + dy)])) continue;
          if (free[j] && !walkable_[j]) {
            walkable_[j] = 1;
            queue.push_back(j);
          }
        }
    }
  }
}

bool WalkableGrid::CellOf(const Eigen::Vector2d& p, int* ix, int* iy) const {
  if (!p.allFinite()) return false;
  const double fx = std::floor((p.x() - min_.x()) / cell_m_);
  const double fy = std::floor((p.y() - min_.y()) / cell_m_);
  if (fx < 0 || fy < 0 || fx >= nx_ || fy >= ny_) return false;
  *ix = static_cast<int>(fx);
  *iy = static_cast<int>(fy);
  return true;
}

bool WalkableGrid::CellWalkable(int ix, int iy) const {
  return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_ && walkable_[Index(ix, iy)];
}

bool WalkableGrid::CellBlocked(int ix, int iy) const {
  return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_ && blocked_[Index(ix, iy)];
}

Eigen::Vector2d WalkableGrid::CellCentre(int ix, int iy) const {
  return min_ + cell_m_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
}

bool WalkableGrid::Walkable(const Eigen::Vector2d& p) const {
  int ix = 0, iy = 0;
  return CellOf(p, &ix, &iy) && walkable_[Index(ix, iy)];
}

bool WalkableGrid::SegmentWalkable(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / (0.5 * cell_m_))));
  for (int i = 0; i <= n; ++i)
    if (!Walkable(a + (b - a) * (static_cast<double>(i) / n))) return false;
  return true;
}

std::optional<Eigen::Vector2d> WalkableGrid::NearestWalkable(const Eigen::Vector2d& p) const {
  int ix = 0, iy = 0;
  if (CellOf(p, &ix, &iy) && walkable_[Index(ix, iy)]) return CellCentre(ix, iy);
  std::optional<Eigen::Vector2d> out;
  double best = 1e300;
  for (int y = 0; y < ny_; ++y)
    for (int x = 0; x < nx_; ++x) {
      if (!walkable_[Index(x, y)]) continue;
      const double d = (CellCentre(x, y) - p).squaredNorm();
      if (d < best) {
        best = d;
        out = CellCentre(x, y);
      }
    }
  return out;
}

std::optional<std::vector<Eigen::Vector2d>> WalkableGrid::Plan(
    const Eigen::Vector2d& from, const Eigen::Vector2d& to,
    const std::vector<std::pair<Eigen::Vector2d, double>>& keep_out) const {
  const auto kept_out = [&](const Eigen::Vector2d& p) {
    for (const auto& [c, r] : keep_out)
      if ((p - c).norm() < r) return true;
    return false;
  };
  const auto open_cell = [&](int x, int y) {
    return CellWalkable(x, y) && !kept_out(CellCentre(x, y));
  };
  const std::optional<Eigen::Vector2d> a = NearestWalkable(from), b = NearestWalkable(to);
  if (!a || !b) return std::nullopt;
  int sx = 0, sy = 0, gx = 0, gy = 0;
  CellOf(*a, &sx, &sy);
  CellOf(*b, &gx, &gy);
  const int start = Index(sx, sy), goal = Index(gx, gy);
  const auto h = [&](int i) {
    const double dx = std::abs(i % nx_ - gx), dy = std::abs(i / nx_ - gy);
    return std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy);
  };
  std::vector<double> g(walkable_.size(), 1e300);
  std::vector<int> parent(walkable_.size(), -1);
  std::vector<uint8_t> closed(walkable_.size(), 0);
  using Entry = std::pair<double, int>;  // (f, cell): the smallest f, then the lowest cell
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  g[start] = 0;
  open.push({h(start), start});
  while (!open.empty()) {
    const int i = open.top().second;
    open.pop();
    if (closed[i]) continue;
    closed[i] = 1;
    if (i == goal) break;
    const int x = i % nx_, y = i / nx_;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        if (!open_cell(x + dx, y + dy)) continue;
        if (dx != 0 && dy != 0 && (!open_cell(x + dx, y) || !open_cell(x, y + dy))) continue;
        const int j = Index(x + dx, y + dy);
        const double step = (dx != 0 && dy != 0) ? std::sqrt(2.0) : 1.0;
        if (g[i] + step < g[j]) {
          g[j] = g[i] + step;
          parent[j] = i;
          open.push({g[j] + h(j), j});
        }
      }
  }
  if (!closed[goal]) return std::nullopt;
  std::vector<Eigen::Vector2d> cells;
  for (int i = goal; i != -1; i = parent[i]) cells.push_back(CellCentre(i % nx_, i / nx_));
  std::reverse(cells.begin(), cells.end());
  cells.front() = Walkable(from) ? from : *a;
  cells.back() = Walkable(to) ? to : *b;
  // line-of-sight smoothing: from each kept point, on to the last of the cells it sees in a row
  std::vector<Eigen::Vector2d> path{cells.front()};
  size_t k = 0;
  while (k + 1 < cells.size()) {
    size_t next = k + 1;
    for (size_t m = k + 2; m < cells.size() && SegmentWalkable(cells[k], cells[m]) &&
                           (keep_out.empty() || !kept_out(0.5 * (cells[k] + cells[m])));
         ++m)
      next = m;
    path.push_back(cells[next]);
    k = next;
  }
  return path;
}

}  // namespace penumbra
