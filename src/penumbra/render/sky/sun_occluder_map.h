#pragma once
// which sun shadow rays the static geometry provably blocks, so that the realtime tier need not
// trace them (inside the house and the warehouse ~100 % of the sun's shadow rays are
// occluded). conservative: the map never skips a ray that would reach the sun; a skipped ray is
// one the exact test (RayScene::Occluded) reports as occluded, so the image is the same.
//
// occluders: the static visible box geoms (render/geometry/static_geometry.h: the world body and
// static bodies, group <= 2, material alpha >= 0.5), which RayScene traces as closed, two-sided,
// opaque triangle boxes. each is tested shrunk by kShrinkM on every side: a ray that passes
// through the shrunk box's interior ahead of its origin (entry at t > 0, chord longer than
// kMinChordM) crosses a face of the real box at t > 0, i.e. RayScene finds a hit for an
// infinite shadow ray (tmin 0, tmax +inf); the margin is far above the float rounding of
// coordinates of tens of metres (~1e-5 m), so no hit falls into a crack between triangles.
//
// map: over the world-frame bounds of the finite static geoms, a grid of cubic cells (kCellM,
// enlarged until at most kMaxCells), and per cell the (at most kCandidates) boxes that block
// the most rays towards the sun's centre from the cell's centre and its 8 corners (a box that
// blocks none of them is not a candidate). a query tests the candidate boxes of the cell that
// holds the ray's origin exactly (the slab test above, for the ray's own direction, which may
// be jittered over the sun's disc); outside the grid, or with no candidate, nothing is skipped.
// so the candidates only decide how many rays are skipped, never whether a skip is right.
//
// whole cells: a cell whose best candidate blocks the rays from all 8 corners in 8 directions
// around the sun's disc (spanning an octagon that circumscribes the disc widened by
// kDiscMarginRad) blocks every ray from the cell towards the disc, and is marked so that such
// rays are skipped after one table lookup. why: for a direction d, the points whose line meets
// a convex box form a convex cylinder, and along it the exit distance t_far is a concave
// function of the point (the box's far boundary seen along d), as is the chord length, so both
// are smallest at the cell's corners: corners with t_far > 0 and chord > kMinChordM mean every
// point of the cell has its exit ahead (the entry ahead too, or the point lies inside the solid
// box; either way the ray meets the box's surface at t > 0); and for a point outside the box,
// the directions whose ray meets it form a convex cone, which holds the octagon's cone once it
// holds its 8 directions.
//
// the sun: the first directional light of the LightSampler that casts shadows. the map is
// rebuilt when a static body moves or the sun's direction turns by more than kRebuildDeg
// from the one the candidates were chosen for.
//
// thread-safety: the queries are const and thread-safe; Build/Update are not. determinism: the
// map is a function of the static geometry and the sun's direction (any thread count).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/shading_lanes.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// the sun-occluder map of a static scene (see the file comment).
class SunOccluderMap {
 public:
  static constexpr float kCellM = 0.25f;          ///< smallest cell side, m
  static constexpr int kMaxCells = 1 << 17;       ///< cap on the cell count
  static constexpr int kCandidates = 4;           ///< boxes tested per cell
  static constexpr float kShrinkM = 2e-3f;        ///< boxes tested this much smaller per side, m
  static constexpr float kMinChordM = 2e-3f;      ///< shortest chord through a shrunk box, m
  static constexpr double kRebuildDeg = 2.0;      ///< sun turn that rebuilds the candidates, deg
  static constexpr float kDiscMarginRad = 2e-4f;  ///< disc widening of the whole-cell test

  /// chooses the candidates for the static boxes of `scene` posed by X_WB (one pose per body)
  /// and the unit direction `to_sun_W` towards the sun's centre (world frame) and the cosine of
  /// its disc's angular radius (PosedLight::cos_angular_radius; 1 = a point), the sun being
  /// light `light_index`. with no finite static geometry or no box the map stays empty.
  /// @throws Error if X_WB.size() != scene.bodies.size().
  void Build(const SceneDescription& scene, const std::vector<Pose>& X_WB, int light_index,
             const Eigen::Vector3f& to_sun_W, float cos_angular_radius, ThreadPool* pool);

  /// Build for the sun of `lights` (file comment) when the static bodies' poses in `snapshot`
  /// or the sun's direction changed as above (or on the first call); clears the map when
  /// `lights` have no shadow-casting directional light.
  void Update(const SceneDescription& scene, const WorldSnapshot& snapshot,
              const LightSampler& lights, ThreadPool* pool);

  /// the LightSampler index of the light the map is for; -1 when the map is empty.
  int light_index() const { return empty() ? -1 : light_index_; }
  bool empty() const { return boxes_.empty() || cells_.empty(); }

  /// true when a static box blocks the ray o_W + t d_W, t > 0 (the exact test above on the
  /// candidates of o_W's cell); false for non-finite rays and outside the grid. d_W need not
  /// be unit.
  bool Blocks(const Eigen::Vector3f& o_W, const Eigen::Vector3f& d_W) const;

  /// Blocks for every active lane; inactive lanes are false.
  LaneMask BlocksLanes(const Vec3Lanes& o_W, const Vec3Lanes& d_W, const LaneMask& active) const;

  /// how many static boxes the map holds, and the cell grid's shape.
  int num_boxes() const { return static_cast<int>(boxes_.size()); }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nz() const { return nz_; }
  float cell_m() const { return cell_m_; }

 private:
  struct Box {
    Eigen::Matrix3f R_GW;  // world to box frame
    Eigen::Vector3f p_W;   // centre
    Eigen::Vector3f half;  // shrunk half sizes
  };
  // the slab test of the file comment against box b.
  bool HitsBox(const Box& b, const Eigen::Vector3f& o_W, const Eigen::Vector3f& d_W) const;
  // the whole-cell test: the line o_W + t d_W passes through box b's interior with a chord
  // longer than kMinChordM whose far end lies ahead (t > 0); the origin may be inside.
  bool CrossesBoxAhead(const Box& b, const Eigen::Vector3f& o_W, const Eigen::Vector3f& d_W) const;
  int CellOf(const Eigen::Vector3f& p_W) const;  // -1 outside

  std::vector<Box> boxes_;
  std::vector<int32_t> cells_;  // [cell * kCandidates + c], -1 = none
  std::vector<uint8_t> full_;   // [cell]: 1 = every ray from the cell to the sun's disc blocked
  int nx_ = 0, ny_ = 0, nz_ = 0;
  float cell_m_ = kCellM, inv_cell_ = 1.0f / kCellM;
  Eigen::Vector3f origin_{0, 0, 0};  // the grid's low corner
  int light_index_ = -1;
  Eigen::Vector3f built_to_sun_{0, 0, 0};
  float built_cos_radius_ = 1;
  float disc_sin2_ = 0;  // a direction d with |d x built_to_sun_|^2 <= this is on the disc
  std::vector<Pose> built_static_poses_;
  bool built_ = false;
};

}  // namespace penumbra
