#pragma once
// where precipitation can fall: a top-down height map of the static geometry (the highest
// static surface above each plan cell), so that rain and snow fall only where the sky is open
// above them (indoor scenes stay dry).
//
// build (once per static scene, again when a static body moves): over the plan-view bounds of
// the finite static geoms (planes are left out of the bounds, as in the sky irradiance volume,
// but traced) padded by one cell, a regular grid of square cells (kCellM, enlarged so that
// the grid holds at most kMaxCells cells), and per cell one ray straight down (-z) from above
// the geometry's top through its centre, traced against the static geoms (the world body and
// Body::is_static; moving bodies are not baked) through a RayQuery of them (render/ray_query.h)
// built by a RayQueryFactory. the cell's roof height is the z of the first hit (-inf when the
// ray meets nothing).
//
// query: a point is sheltered when it lies below the roof height of its cell (nearest cell,
// no interpolation) by more than kShelterMarginM; outside the grid nothing shelters it. one
// ray per cell: features thinner than a cell (a 5 cm beam with 10 cm cells) may be missed or
// widened to a cell; a particle under an overhang that its cell's ray misses (a roof edge
// between cell centres) falls.
//
// thread-safety: Sheltered is const and thread-safe; Build/Update are not. determinism: every
// cell's ray is fixed, so the map is the same whatever the thread count.

#include <Eigen/Core>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/particles/streak_cull_math.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// whether a shelter map keeps the particles of `ps` from falling under static geometry: rain
/// and snow sets with ParticleSet::sheltered; never sparks.
bool ShelterApplies(const ParticleSet& ps);

/// the static geometry's roof height per plan cell (see the file comment).
class ShelterMap {
 public:
  static constexpr float kCellM = 0.1f;            ///< smallest cell size, m
  static constexpr int kMaxCells = 1 << 20;        ///< cap on the cell count
  static constexpr float kShelterMarginM = 0.01f;  ///< below the roof by more than this

  /// @throws Error if make_query is empty.
  explicit ShelterMap(RayQueryFactory make_query);

  /// traces the roof heights of the static geoms of `scene` posed by X_WB (one pose per body).
  /// with no finite static geometry the map stays empty (nothing is sheltered).
  /// @throws Error if X_WB.size() != scene.bodies.size(), or as the RayQueryFactory.
  void Build(const SceneDescription& scene, const std::vector<Pose>& X_WB, ThreadPool* pool);

  /// Build when the static bodies' poses in `snapshot` differ from the last build's (or on the
  /// first call).
  void Update(const SceneDescription& scene, const WorldSnapshot& snapshot, ThreadPool* pool);

  /// true when static geometry lies above p_W (world frame, m) in its cell. false for
  /// non-finite points and outside the grid.
  bool Sheltered(const Eigen::Vector3f& p_W) const;

  /// roof height (world z, m) of the cell holding (x, y); -inf outside the grid or where the
  /// cell's ray met nothing.
  float RoofHeight(float x, float y) const;

  /// the map as the shared test reads it (render/particles/streak_cull_math.h: ShelterSheltered,
  /// which Sheltered and the CUDA backend's drop culling call); its roof points into this map
  /// (valid until the next Build). roof null when the map is empty.
  ShelterPod pod() const;

  bool empty() const { return roof_.empty(); }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  float cell_m() const { return cell_m_; }

 private:
  RayQueryFactory make_query_;
  int nx_ = 0, ny_ = 0;
  float cell_m_ = kCellM, inv_cell_ = 1.0f / kCellM;
  Eigen::Vector2f origin_{0, 0};  // plan position of the grid's corner (cell 0's low corner)
  std::vector<float> roof_;       // [ix + nx iy] roof z, -inf where nothing
  std::vector<Pose> built_static_poses_;
  bool built_ = false;
  uint64_t version_ = 0;  // Build count (ShelterPod::version)
};

}  // namespace penumbra
