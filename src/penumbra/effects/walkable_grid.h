#pragma once
// walkable regions of NPC agents: the floor's occupancy grid (static geometry in the
// band an agent kind can neither step over nor pass under, session/floor_map.h) inflated by
// the agent's radius, restricted to the connected part reachable from a seed point, plus A*
// planning on it.
//
// why A* on the grid and not a navigation mesh: the occupancy is already a raster (0.1 m
// cells), inflating it by a kind's radius is exact per cell (a Minkowski sum with a disc),
// doors and aisles narrower than a kind's width close by themselves, and a grid of the
// warehouse (30 x 20 m, 60 000 cells) is searched in milliseconds. a navigation mesh would
// need a polygonisation step (Recast-style) whose only gain, fewer nodes, does not matter at
// this size; line-of-sight smoothing of the grid path gives the straight legs a mesh path
// would have.
//
// frames: world xy (x east, y north), m. cell (ix, iy) covers
// [min_W + cell_m (ix, iy), min_W + cell_m (ix + 1, iy + 1)).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

namespace penumbra {

/// a plan-view occupancy grid: 1 = blocked by static geometry.
struct OccupancyGrid {
  Eigen::Vector2d min_W{0, 0};   ///< lower corner of cell (0, 0), m
  double cell_m = 0.1;           ///< cell size, m (> 0)
  int nx = 0, ny = 0;            ///< cells along x and y
  std::vector<uint8_t> blocked;  ///< (ny x nx), row iy at [iy nx, (iy + 1) nx)
};

/// what decides an agent kind's walkable region.
struct WalkableProfile {
  /// the agent's centre keeps this far (plan view) from every blocked cell, m: a person's
  /// body radius; a vehicle's half width plus a margin (vehicles follow lanes lengthwise).
  double radius_m = 0.3;
  /// geometry whose top is at most this high above the floor is stepped or driven over, m.
  double step_height_m = 0.15;
  /// geometry whose bottom is at least this high above the floor is passed under, m.
  double head_clearance_m = 2.0;
  /// vehicles: the smallest turning radius of the rear axle's centre, m (0 for people).
  double turning_radius_m = 0;
};

/// the walkable region of one agent kind on one floor.
class WalkableGrid {
 public:
  /// @param occupancy the floor's occupancy (blocked cells)
  /// @param radius_m  clearance of the agent's centre from blocked cells, m (>= 0)
  /// @param seeds_W   the region is the union of the 8-connected sets of free cells reachable
  ///                  from the free cell nearest to each seed (empty if no cell is free)
  /// @throws Error for an inconsistent occupancy grid or a negative radius.
  WalkableGrid(const OccupancyGrid& occupancy, double radius_m,
               const std::vector<Eigen::Vector2d>& seeds_W);
  /// one seed.
  WalkableGrid(const OccupancyGrid& occupancy, double radius_m, const Eigen::Vector2d& seed_W)
      : WalkableGrid(occupancy, radius_m, std::vector<Eigen::Vector2d>{seed_W}) {}

  /// true if p lies in a walkable cell.
  bool Walkable(const Eigen::Vector2d& p) const;
  /// true if every point of a-b sampled every half cell is Walkable.
  bool SegmentWalkable(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const;
  /// the centre of the walkable cell nearest to p (ties: lowest cell index), or nothing.
  std::optional<Eigen::Vector2d> NearestWalkable(const Eigen::Vector2d& p) const;
  /// a path from `from` to `to` through walkable cells: A* on the 8-connected grid (octile
  /// distance heuristic, no corner cutting, ties broken by the lower cell index), smoothed by
  /// line of sight (SegmentWalkable). the first point is `from`, the last `to` (both snapped
  /// to their nearest walkable cell centre when outside the region). nothing if `to` cannot
  /// be reached. Hart, Nilsson, Raphael, "A Formal Basis for the Heuristic Determination of
  /// Minimum Cost Paths", IEEE Trans. SSC 4(2), 1968.
  /// `keep_out` discs (centre, radius; e.g. a robot and the clearance an agent keeps from it)
  /// are not entered, except where the path starts.
  std::optional<std::vector<Eigen::Vector2d>> Plan(
      const Eigen::Vector2d& from, const Eigen::Vector2d& to,
      const std::vector<std::pair<Eigen::Vector2d, double>>& keep_out = {}) const;

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double cell_m() const { return cell_m_; }
  const Eigen::Vector2d& min_W() const { return min_; }
  double radius_m() const { return radius_m_; }
  /// true if cell (ix, iy) is walkable (false outside the grid).
  bool CellWalkable(int ix, int iy) const;
  /// true if cell (ix, iy) is blocked in the occupancy the region came from.
  bool CellBlocked(int ix, int iy) const;
  /// centre of cell (ix, iy), m.
  Eigen::Vector2d CellCentre(int ix, int iy) const;
  /// number of walkable cells.
  int walkable_cells() const { return count_; }

 private:
  int Index(int ix, int iy) const { return iy * nx_ + ix; }
  bool CellOf(const Eigen::Vector2d& p, int* ix, int* iy) const;

  Eigen::Vector2d min_;
  double cell_m_ = 0.1;
  double radius_m_ = 0;
  int nx_ = 0, ny_ = 0;
  int count_ = 0;
  std::vector<uint8_t> blocked_;
  std::vector<uint8_t> walkable_;
};

}  // namespace penumbra
