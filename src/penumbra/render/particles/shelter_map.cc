#include "penumbra/render/particles/shelter_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/geometry/static_geometry.h"

namespace penumbra {

bool ShelterApplies(const ParticleSet& ps) {
  return ps.sheltered && ps.kind != ParticleKind::kSpark;
}

ShelterMap::ShelterMap(RayQueryFactory make_query) : make_query_(std::move(make_query)) {
  if (!make_query_) throw Error("ShelterMap: needs a RayQueryFactory");
}

void ShelterMap::Build(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                       ThreadPool* pool) {
  if (X_WB.size() != scene.bodies.size())
    throw Error("ShelterMap::Build: " + std::to_string(X_WB.size()) + " body poses, scene has " +
                std::to_string(scene.bodies.size()) + " bodies");
  built_ = true;
  ++version_;
  built_static_poses_ = X_WB;
  roof_.clear();
  nx_ = ny_ = 0;
  // the static geoms and the bounds of the finite ones, world frame.
  Eigen::Vector3d lo, hi;
  SceneDescription statics = StaticGeoms(scene, X_WB, &lo, &hi);
  if (!(lo.array() <= hi.array()).all()) return;  // no finite static geometry
  // cells: kCellM, enlarged until the padded grid holds <= kMaxCells.
  double cell = kCellM;
  int nx = 0, ny = 0;
  for (;;) {
    nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 2;
    ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 2;
    if (static_cast<int64_t>(nx) * ny <= kMaxCells) break;
    cell *= 1.25;
  }
  nx_ = nx, ny_ = ny;
  cell_m_ = static_cast<float>(cell);
  inv_cell_ = static_cast<float>(1.0 / cell);
  origin_ = Eigen::Vector2f(static_cast<float>(lo.x() - cell), static_cast<float>(lo.y() - cell));
  const float z_top = static_cast<float>(hi.z() + 1.0);
  const std::unique_ptr<RayQuery> query = make_query_(statics);
  WorldSnapshot snap;
  snap.X_WB = X_WB;
  query->Update(snap);
  roof_.assign(static_cast<size_t>(nx) * ny, -std::numeric_limits<float>::infinity());
  // kRows rows of cells per task, their rays in one batch (a GPU query pays a launch and a round
  // trip a batch; a ray's hit does not depend on its batch, RayQuery's contract), each row a
  // coherent run of parallel rays.
  constexpr int kRows = 16;
  auto rows = [&](int64_t chunk) {
    const int y0 = static_cast<int>(chunk) * kRows, y1 = std::min(ny, y0 + kRows);
    const size_t count = static_cast<size_t>(y1 - y0) * nx;
    std::vector<Ray> rays(count);
    std::vector<SurfaceHit> hits(count);
    std::unique_ptr<bool[]> did(new bool[count]);
    for (int iy = y0; iy < y1; ++iy)
      for (int ix = 0; ix < nx; ++ix) {
        Ray& r = rays[static_cast<size_t>(iy - y0) * nx + ix];
        r.o = Eigen::Vector3f(origin_.x() + (ix + 0.5f) * cell_m_,
                              origin_.y() + (static_cast<float>(iy) + 0.5f) * cell_m_, z_top);
        r.d = Eigen::Vector3f(0, 0, -1);
      }
    query->Intersect(rays, std::span<SurfaceHit>(hits), std::span<bool>(did.get(), count));
    for (size_t k = 0; k < count; ++k)
      if (did[k]) roof_[static_cast<size_t>(y0) * nx + k] = z_top - hits[k].t;
  };
  ParallelForOrSerial(pool, (ny + kRows - 1) / kRows, rows);
}

void ShelterMap::Update(const SceneDescription& scene, const WorldSnapshot& snapshot,
                        ThreadPool* pool) {
  bool rebuild = !built_ || snapshot.X_WB.size() != built_static_poses_.size();
  for (size_t b = 0; !rebuild && b < snapshot.X_WB.size(); ++b)
    rebuild = IsStaticBody(scene, static_cast<int>(b)) &&
              snapshot.X_WB[b].matrix() != built_static_poses_[b].matrix();
  if (rebuild) Build(scene, snapshot.X_WB, pool);
}

float ShelterMap::RoofHeight(float x, float y) const {
  if (roof_.empty()) return -std::numeric_limits<float>::infinity();
  return ShelterRoofHeight(pod(), x, y);
}

bool ShelterMap::Sheltered(const Eigen::Vector3f& p_W) const {
  return ShelterSheltered(pod(), Float3{p_W.x(), p_W.y(), p_W.z()});
}

ShelterPod ShelterMap::pod() const {
  ShelterPod s;
  if (roof_.empty()) return s;
  s.roof = roof_.data();
  s.nx = nx_;
  s.ny = ny_;
  s.origin_x = origin_.x();
  s.origin_y = origin_.y();
  s.inv_cell = inv_cell_;
  s.margin = kShelterMarginM;
  s.version = version_;
  return s;
}

}  // namespace penumbra
