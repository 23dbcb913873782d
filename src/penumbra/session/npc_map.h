#pragma once
// the walkable map of a world's NPCs (docs/npcs.md): the walkable regions of people
// and of vehicles on one floor (effects/walkable_grid.h), built from the static geometry at the
// start in each kind's height band (session/floor_map.h), and its picture (`penumbra npc-map`,
// npc_map.png in a run's folder).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/pose.h"
#include "penumbra/effects/crowd_sim.h"
#include "penumbra/effects/walkable_grid.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// the walkable regions of people and vehicles on one floor.
class NpcMap {
 public:
  /// @param scene, X_WB   the static scene and every body's pose at the start
  /// @param floor_z       the floor's height, m
  /// @param centre_W      centre of the mapped area (FloorMap: the static geometry's box
  ///                      joined with +-5 m around it, clipped to +-40 m)
  /// @param person_seeds, vehicle_seeds  points whose connected free areas make up each
  ///                      region (WalkableGrid)
  /// people use KindModel(kPerson).walkable, vehicles KindModel(kForklift).walkable.
  NpcMap(const SceneDescription& scene, const std::vector<Pose>& X_WB, double floor_z,
         const Eigen::Vector2d& centre_W, const std::vector<Eigen::Vector2d>& person_seeds,
         const std::vector<Eigen::Vector2d>& vehicle_seeds);

  const std::shared_ptr<const WalkableGrid>& person() const { return person_; }
  const std::shared_ptr<const WalkableGrid>& vehicle() const { return vehicle_; }
  double floor_z() const { return floor_z_; }

  /// the map as an sRGB image, north up, `pixels_per_cell` pixels per 0.1 m cell: blocked
  /// for people dark grey, free but too close to an obstacle light grey, walkable by people
  /// green, by vehicles too blue, lanes orange, area centres red, robots black, agents'
  /// start points white with a black ring.
  ImageU8 Draw(const CrowdSites& sites, const std::vector<Eigen::Vector2d>& robots,
               const std::vector<Eigen::Vector2d>& agents, int pixels_per_cell = 4) const;

 private:
  double floor_z_;
  std::shared_ptr<const WalkableGrid> person_, vehicle_;
};

/// the floor height of a preset's NPCs: the highest static upward plane, or (with_slabs) top
/// of an upright static box at least 2 x 2 m under the first robot's start (a floor slab), at
/// or below the lowest robot start (+ 0.05 m); else the lowest start's z (0 without robots).
/// the preset's fog base and robots' area use planes only (with_slabs false).
double NpcFloorHeight(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                      const std::vector<Eigen::Vector3d>& robot_starts, bool with_slabs = true);

}  // namespace penumbra
