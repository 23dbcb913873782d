#include "penumbra/render/sun_occluder_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/occluder_math.h"
#include "penumbra/render/static_geometry.h"

namespace penumbra {

void SunOccluderMap::Build(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                           int light_index, const Eigen::Vector3f& to_sun_W,
                           float cos_angular_radius, ThreadPool* pool) {
  if (X_WB.size() != scene.bodies.size())
    throw Error("SunOccluderMap::Build: " + std::to_string(X_WB.size()) +
                " body poses, scene has " + std::to_string(scene.bodies.size()) + " bodies");
  built_ = true;
  built_static_poses_ = X_WB;
  built_to_sun_ = to_sun_W;
  built_cos_radius_ = cos_angular_radius;
  light_index_ = light_index;
  boxes_.clear();
  cells_.clear();
  full_.clear();
  nx_ = ny_ = nz_ = 0;
  // the occluders: static visible boxes, shrunk.
  for (const Geom& g : scene.geoms) {
    if (g.shape != GeomShape::kBox || !IsStaticVisible(scene, g)) continue;
    const Eigen::Vector3d half = g.size - Eigen::Vector3d::Constant(kShrinkM);
    if (!(half.minCoeff() > 0) || !half.allFinite()) continue;
    const Pose X_WG = X_WB[g.body] * g.X_BG;
    Box b;
    b.R_GW = X_WG.linear().transpose().cast<float>();
    b.p_W = X_WG.translation().cast<float>();
    b.half = half.cast<float>();
    if (!b.R_GW.allFinite() || !b.p_W.allFinite()) continue;
    boxes_.push_back(b);
  }
  Eigen::Vector3d lo, hi;
  StaticGeoms(scene, X_WB, &lo, &hi);
  if (boxes_.empty() || !(lo.array() <= hi.array()).all()) return;
  // cells: kCellM, enlarged until the grid holds <= kMaxCells.
  double cell = kCellM;
  int nx = 0, ny = 0, nz = 0;
  for (;;) {
    nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)));
    ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)));
    nz = std::max(1, static_cast<int>(std::ceil((hi.z() - lo.z()) / cell)));
    if (static_cast<int64_t>(nx) * ny * nz <= kMaxCells) break;
    cell *= 1.25;
  }
  nx_ = nx, ny_ = ny, nz_ = nz;
  cell_m_ = static_cast<float>(cell);
  inv_cell_ = static_cast<float>(1.0 / cell);
  origin_ = lo.cast<float>();
  cells_.assign(static_cast<size_t>(nx) * ny * nz * kCandidates, -1);
  full_.assign(static_cast<size_t>(nx) * ny * nz, 0);
  // the directions of the sun's disc for the whole-cell test: 8 directions on a cone that
  // the octagon they span circumscribes the disc's cone widened by kDiscMarginRad (its
  // half-angle over cos(pi / 8)); rays within the disc widened by half that margin are the
  // ones a full cell skips (disc_sin2_), which leaves room for float rounding.
  const float half = std::acos(std::clamp(cos_angular_radius, -1.0f, 1.0f));
  const float wide =
      std::atan(std::tan(half + kDiscMarginRad) / std::cos(static_cast<float>(M_PI) / 8));
  const float inner = half + 0.5f * kDiscMarginRad;
  disc_sin2_ = std::sin(inner) * std::sin(inner);
  std::vector<Eigen::Vector3f> disc;
  {
    const Eigen::Vector3f a =
        std::abs(to_sun_W.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
    const Eigen::Vector3f t = to_sun_W.cross(a).normalized(), b = to_sun_W.cross(t);
    for (int k = 0; k < 8; ++k) {
      const float phi = static_cast<float>(k) * static_cast<float>(M_PI) / 4;
      disc.push_back(
          (std::cos(wide) * to_sun_W + std::sin(wide) * (std::cos(phi) * t + std::sin(phi) * b))
              .normalized());
    }
  }
  const int num_boxes = static_cast<int>(boxes_.size());
  std::vector<float> radius(num_boxes);
  for (int bi = 0; bi < num_boxes; ++bi) radius[bi] = boxes_[bi].half.norm() + kShrinkM;
  const float cell_radius = 0.8661f * cell_m_;  // half the cell's diagonal, rounded up
  // one z-y row of cells per task: per cell, every box scored by how many of the 9 rays
  // (centre, corners) towards the sun it blocks; the best kCandidates with a score > 0.
  auto row = [&](int64_t r) {
    const int iy = static_cast<int>(r % ny), iz = static_cast<int>(r / ny);
    std::vector<std::pair<int, int>> scored;  // (-score, box)
    for (int ix = 0; ix < nx; ++ix) {
      const Eigen::Vector3f c0 =
          origin_ + cell_m_ * Eigen::Vector3f(static_cast<float>(ix), static_cast<float>(iy),
                                              static_cast<float>(iz));
      std::array<Eigen::Vector3f, 9> pts;
      pts[0] = c0 + Eigen::Vector3f::Constant(0.5f * cell_m_);
      for (int k = 0; k < 8; ++k)
        pts[k + 1] = c0 + cell_m_ * Eigen::Vector3f(static_cast<float>(k & 1),
                                                    static_cast<float>((k >> 1) & 1),
                                                    static_cast<float>((k >> 2) & 1));
      scored.clear();
      for (int bi = 0; bi < num_boxes; ++bi) {
        // a box whose bounding sphere stays clear of the cell's rays blocks none of them.
        const Eigen::Vector3f rel = boxes_[bi].p_W - pts[0];
        const float along = rel.dot(to_sun_W);
        const float reach = radius[bi] + cell_radius;
        if (along < -reach || (rel - along * to_sun_W).squaredNorm() > reach * reach) continue;
        int score = 0;
        for (const Eigen::Vector3f& p : pts) score += HitsBox(boxes_[bi], p, to_sun_W) ? 1 : 0;
        if (score > 0) scored.emplace_back(-score, bi);
      }
      const int keep = std::min<int>(kCandidates, static_cast<int>(scored.size()));
      std::partial_sort(scored.begin(), scored.begin() + keep, scored.end());
      const size_t cell_index = (static_cast<size_t>(iz) * ny + iy) * nx + ix;
      for (int c = 0; c < keep; ++c) cells_[cell_index * kCandidates + c] = scored[c].second;
      // the whole cell: one candidate that blocks the rays from all 8 corners in every
      // direction of `disc` blocks every ray from the cell towards the sun's disc (file
      // comment).
      for (int c = 0; c < keep && scored[c].first == -9 && !full_[cell_index]; ++c) {
        bool all = true;
        for (int k = 1; k < 9 && all; ++k)
          for (const Eigen::Vector3f& d : disc)
            if (!CrossesBoxAhead(boxes_[scored[c].second], pts[k], d)) {
              all = false;
              break;
            }
        full_[cell_index] = all ? 1 : 0;
      }
    }
  };
  ParallelForOrSerial(pool, static_cast<int64_t>(ny) * nz, row);
}

void SunOccluderMap::Update(const SceneDescription& scene, const WorldSnapshot& snapshot,
                            const LightSampler& lights, ThreadPool* pool) {
  int sun = -1;
  for (int j = 0; j < lights.size() && sun < 0; ++j)
    if (lights.lights()[j].type == Light::Type::kDirectional && lights.lights()[j].cast_shadow)
      sun = j;
  if (sun < 0) {
    boxes_.clear();
    cells_.clear();
    full_.clear();
    built_ = false;
    return;
  }
  const Eigen::Vector3f to_sun = -lights.lights()[sun].direction_W.normalized();
  const float cos_radius = lights.lights()[sun].cos_angular_radius;
  bool rebuild =
      !built_ || sun != light_index_ || cos_radius != built_cos_radius_ ||
      snapshot.X_WB.size() != built_static_poses_.size() ||
      !(to_sun.dot(built_to_sun_) >= static_cast<float>(std::cos(kRebuildDeg * M_PI / 180.0)));
  for (size_t b = 0; !rebuild && b < snapshot.X_WB.size(); ++b)
    rebuild = IsStaticBody(scene, static_cast<int>(b)) &&
              snapshot.X_WB[b].matrix() != built_static_poses_[b].matrix();
  if (rebuild) Build(scene, snapshot.X_WB, sun, to_sun, cos_radius, pool);
}

bool SunOccluderMap::HitsBox(const Box& b, const Eigen::Vector3f& o_W,
                             const Eigen::Vector3f& d_W) const {
  const Eigen::Vector3f o = b.R_GW * (o_W - b.p_W);
  const Eigen::Vector3f d = b.R_GW * d_W;
  return BoxChordAhead(o.data(), d.data(), b.half.data(), d_W.norm(), kMinChordM, true);
}

bool SunOccluderMap::CrossesBoxAhead(const Box& b, const Eigen::Vector3f& o_W,
                                     const Eigen::Vector3f& d_W) const {
  const Eigen::Vector3f o = b.R_GW * (o_W - b.p_W);
  const Eigen::Vector3f d = b.R_GW * d_W;
  return BoxChordAhead(o.data(), d.data(), b.half.data(), d_W.norm(), kMinChordM, false);
}

int SunOccluderMap::CellOf(const Eigen::Vector3f& p_W) const {
  const Eigen::Vector3f f = (p_W - origin_) * inv_cell_;
  if (!(f.x() >= 0 && f.y() >= 0 && f.z() >= 0 && f.x() < nx_ && f.y() < ny_ && f.z() < nz_))
    return -1;
  return (static_cast<int>(f.z()) * ny_ + static_cast<int>(f.y())) * nx_ + static_cast<int>(f.x());
}

bool SunOccluderMap::Blocks(const Eigen::Vector3f& o_W, const Eigen::Vector3f& d_W) const {
  if (empty() || !o_W.allFinite() || !d_W.allFinite() || !(d_W.squaredNorm() > 0)) return false;
  const int cell = CellOf(o_W);
  if (cell < 0) return false;
  if (full_[cell]) {
    const Eigen::Vector3f d = d_W.normalized();
    if (d.dot(built_to_sun_) > 0 && d.cross(built_to_sun_).squaredNorm() <= disc_sin2_) return true;
  }
  for (int c = 0; c < kCandidates; ++c) {
    const int32_t bi = cells_[static_cast<size_t>(cell) * kCandidates + c];
    if (bi < 0) break;
    if (HitsBox(boxes_[bi], o_W, d_W)) return true;
  }
  return false;
}

LaneMask SunOccluderMap::BlocksLanes(const Vec3Lanes& o_W, const Vec3Lanes& d_W,
                                     const LaneMask& active) const {
  LaneMask blocked;
  if (empty()) return blocked;
  for (int k = 0; k < kLanes; ++k)
    if (active[k]) blocked[k] = Blocks(o_W.Lane(k), d_W.Lane(k));
  return blocked;
}

}  // namespace penumbra
