#pragma once
// plan-view occupancy of a world's floor, for placing adversity-preset regions and NPC
// paths (session/effects_stage.h). built from the static geoms of the scene at the start.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/effects/walkable_grid.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// a 2-d grid over the floor (world xy) marking cells blocked by static geometry.
class FloorMap {
 public:
  /// grid cell size, m.
  static constexpr double kCellM = 0.1;

  /// @param scene    the static scene
  /// @param X_WB     pose of every scene body at the start (WorldSnapshot::X_WB)
  /// @param floor_z  height of the floor, m; geoms whose world bounding box overlaps
  ///                 [floor_z + 0.05, floor_z + 2.0] block the cells under them (planes never do)
  /// @param centre_W the grid covers the static geoms' bounding box (xy) joined with
  ///                 centre_W +- 5 m, clipped to centre_W +- 15 m
  /// @param band_lo_m, band_hi_m  the height band above the floor in which static geometry
  ///                 blocks a cell (an agent kind's step height and head clearance,
  ///                 effects/walkable_grid.h WalkableProfile); the defaults are the presets'
  /// @param reach_m  the clip: centre_W +- reach_m (15 m for the presets' area; the NPCs' map
  ///                 takes 40 m, a whole generated building)
  FloorMap(const SceneDescription& scene, const std::vector<Pose>& X_WB, double floor_z,
           const Eigen::Vector2d& centre_W, double band_lo_m = 0.05, double band_hi_m = 2.0,
           double reach_m = 15.0);

  /// lower / upper corner (xy) of the mapped area, m.
  const Eigen::Vector2d& min_W() const { return min_; }
  const Eigen::Vector2d& max_W() const { return max_; }
  /// true if the scene has static geoms other than planes and height fields.
  bool has_static_bounds() const { return has_bounds_; }
  /// plan-view bounding box of those static geoms (when has_static_bounds()), m.
  const Eigen::Vector2d& static_min_W() const { return static_min_; }
  const Eigen::Vector2d& static_max_W() const { return static_max_; }
  double floor_z() const { return floor_z_; }

  /// true if a disc of radius `clearance_m` at p lies inside the map and touches no blocked cell.
  bool IsFree(const Eigen::Vector2d& p, double clearance_m) const;
  /// true if every point of the segment a-b (sampled every 0.05 m) is IsFree.
  bool SegmentFree(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance_m) const;
  /// marks the free cells (at clearance_m) connected to `seed` (4-neighbours); cells of
  /// Reachable() are then the only ones RandomFreePoint draws from. if the seed cell is
  /// blocked, every free cell counts as reachable.
  void Flood(const Eigen::Vector2d& seed, double clearance_m);
  /// bounding box (xy) of the reachable cells (after Flood; every free cell before); false
  /// if there is none.
  bool ReachableBounds(Eigen::Vector2d* lo, Eigen::Vector2d* hi) const;
  /// a uniformly drawn reachable free point (cell centre), from the 64-bit draw `u`;
  /// false if there is none.
  bool RandomFreePoint(uint64_t u, Eigen::Vector2d* p) const;
  /// the blocked cells as an occupancy grid (effects/walkable_grid.h).
  OccupancyGrid Occupancy() const;

 private:
  int Index(int ix, int iy) const { return iy * nx_ + ix; }
  Eigen::Vector2d min_, max_;
  Eigen::Vector2d static_min_{0, 0}, static_max_{0, 0};
  int nx_ = 0, ny_ = 0;
  double floor_z_ = 0;
  bool has_bounds_ = false;
  std::vector<uint8_t> blocked_;  // (ny x nx)
  std::vector<int> reachable_;    // indices of reachable free cells
};

}  // namespace penumbra
