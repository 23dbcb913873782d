#include "penumbra/session/npc_map.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/session/floor_map.h"

namespace penumbra {
namespace {

// the map covers the static geometry up to this far from its centre, m (a whole building)
constexpr double kReachM = 40.0;

struct Rgb8 {
  uint8_t r, g, b;
};

void Put(ImageU8* img, int u, int v, Rgb8 c) {
  if (u < 0 || v < 0 || u >= img->width || v >= img->height) return;
  uint8_t* p = img->at(u, v);
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
}

void Disc(ImageU8* img, double u, double v, double radius, Rgb8 c) {
  const int r = static_cast<int>(std::ceil(radius));
  for (int dv = -r; dv <= r; ++dv)
    for (int du = -r; du <= r; ++du)
      if (du * du + dv * dv <= radius * radius)
        Put(img, static_cast<int>(std::lround(u)) + du, static_cast<int>(std::lround(v)) + dv, c);
}

}  // namespace

NpcMap::NpcMap(const SceneDescription& scene, const std::vector<Pose>& X_WB, double floor_z,
               const Eigen::Vector2d& centre_W, const std::vector<Eigen::Vector2d>& person_seeds,
               const std::vector<Eigen::Vector2d>& vehicle_seeds)
    : floor_z_(floor_z) {
  const WalkableProfile p = KindModel(AgentKind::kPerson).walkable;
  const WalkableProfile v = KindModel(AgentKind::kForklift).walkable;
  const FloorMap person_floor(scene, X_WB, floor_z, centre_W, p.step_height_m, p.head_clearance_m,
                              kReachM);
  const FloorMap vehicle_floor(scene, X_WB, floor_z, centre_W, v.step_height_m, v.head_clearance_m,
                               kReachM);
  person_ =
      std::make_shared<const WalkableGrid>(person_floor.Occupancy(), p.radius_m, person_seeds);
  vehicle_ =
      std::make_shared<const WalkableGrid>(vehicle_floor.Occupancy(), v.radius_m, vehicle_seeds);
}

ImageU8 NpcMap::Draw(const CrowdSites& sites, const std::vector<Eigen::Vector2d>& robots,
                     const std::vector<Eigen::Vector2d>& agents, int pixels_per_cell) const {
  const WalkableGrid& g = *person_;
  const int ppc = std::clamp(pixels_per_cell, 1, 16);
  ImageU8 img(g.nx() * ppc, g.ny() * ppc, 3, 0);
  for (int iy = 0; iy < g.ny(); ++iy)
    for (int ix = 0; ix < g.nx(); ++ix) {
      Rgb8 c{205, 205, 205};                                    // free, too close
      if (g.CellBlocked(ix, iy)) c = {70, 70, 75};              // blocked
      if (g.CellWalkable(ix, iy)) c = {150, 215, 140};          // people
      if (vehicle_->CellWalkable(ix, iy)) c = {110, 160, 225};  // vehicles (and people)
      for (int dv = 0; dv < ppc; ++dv)
        for (int du = 0; du < ppc; ++du) Put(&img, ix * ppc + du, (g.ny() - 1 - iy) * ppc + dv, c);
    }
  const auto to_px = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d c = (p - g.min_W()) / g.cell_m() * ppc;
    return Eigen::Vector2d(c.x(), g.ny() * ppc - c.y());
  };
  for (const CrowdSites::Lane& lane : sites.lanes)
    for (size_t i = 0; i + 1 < lane.points_W.size(); ++i) {
      const Eigen::Vector2d a = to_px(lane.points_W[i]), b = to_px(lane.points_W[i + 1]);
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() * 2)));
      for (int k = 0; k <= n; ++k) {
        const Eigen::Vector2d q = a + (b - a) * (static_cast<double>(k) / n);
        Disc(&img, q.x(), q.y(), 0.6 * ppc, {240, 140, 20});
      }
    }
  for (const CrowdSites::Area& area : sites.areas) {
    const Eigen::Vector2d c = to_px(0.5 * (area.min_W + area.max_W));
    Disc(&img, c.x(), c.y(), 1.5 * ppc, {210, 30, 30});
  }
  for (const Eigen::Vector2d& a : agents) {
    const Eigen::Vector2d c = to_px(a);
    Disc(&img, c.x(), c.y(), 1.6 * ppc, {0, 0, 0});
    Disc(&img, c.x(), c.y(), 1.1 * ppc, {255, 255, 255});
  }
  for (const Eigen::Vector2d& r : robots) {
    const Eigen::Vector2d c = to_px(r);
    Disc(&img, c.x(), c.y(), 2.0 * ppc, {0, 0, 0});
  }
  return img;
}

double NpcFloorHeight(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                      const std::vector<Eigen::Vector3d>& robot_starts, bool with_slabs) {
  double lowest = 0;
  if (!robot_starts.empty()) {
    lowest = robot_starts.front().z();
    for (const Eigen::Vector3d& r : robot_starts) lowest = std::min(lowest, r.z());
  }
  double floor_z = -1e300;
  for (const Geom& g : scene.geoms) {
    if (g.body < 0 || g.body >= static_cast<int>(scene.bodies.size()) ||
        !scene.bodies[g.body].is_static)
      continue;
    const Pose X_WG =
        (g.body < static_cast<int>(X_WB.size()) ? X_WB[g.body] : Pose::Identity()) * g.X_BG;
    if (X_WG.linear()(2, 2) < 0.99) continue;
    double z = -1e300;
    if (g.shape == GeomShape::kPlane) {
      z = X_WG.translation().z();
    } else if (with_slabs && g.shape == GeomShape::kBox && !robot_starts.empty()) {
      // a floor slab: an upright box under the first robot's start, at least 2 x 2 m
      const Eigen::Vector3d e = X_WG.linear().cwiseAbs() * g.size;
      const Eigen::Vector2d d = (robot_starts.front().head<2>() - X_WG.translation().head<2>());
      if (e.x() >= 1.0 && e.y() >= 1.0 && std::abs(d.x()) <= e.x() && std::abs(d.y()) <= e.y())
        z = X_WG.translation().z() + e.z();
    }
    if (z > -1e300 && z <= lowest + 0.05) floor_z = std::max(floor_z, z);
  }
  return floor_z == -1e300 ? lowest : floor_z;
}

}  // namespace penumbra
