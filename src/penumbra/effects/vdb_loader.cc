#include "penumbra/effects/vdb_loader.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "penumbra/core/error.h"

namespace penumbra {

GridMedium LoadVdbDensity(const VdbSmokeParams& p, const std::optional<BoxRegion>& region,
                          const std::string& key_prefix, const std::string& effect_name) {
  const std::string who = "effect '" + effect_name + "' (vdb_smoke): ";
  const std::string file_key = key_prefix + ".file";
  const std::string grid_key = key_prefix + ".grid";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p.file, ec)) {
    throw ConfigError("", 0, file_key,
                      who + "file not found: " + p.file + "; expected an existing .vdb file");
  }
  openvdb::initialize();
  openvdb::FloatGrid::Ptr grid;
  std::vector<std::string> names;
  try {
    openvdb::io::File file(p.file);
    file.open();
    for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
    if (file.hasGrid(p.grid))
      grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(p.grid));
    file.close();
  } catch (const openvdb::Exception& e) {
    throw ConfigError("", 0, file_key,
                      who + "cannot read " + p.file + " (" + e.what() +
                          "); expected an OpenVDB file with a float grid '" + p.grid + "'");
  }
  if (!grid) {
    std::string have;
    for (const std::string& n : names) have += (have.empty() ? "" : ", ") + n;
    throw ConfigError("", 0, grid_key,
                      who + p.file + " has no float grid '" + p.grid +
                          "' (it has: " + (have.empty() ? "no grids" : have) +
                          "); expected a float grid named '" + p.grid + "' (a density grid)");
  }
  const openvdb::CoordBBox bbox = grid->evalActiveVoxelBoundingBox();
  if (bbox.empty()) {
    throw ConfigError("", 0, grid_key,
                      who + "grid '" + p.grid + "' of " + p.file +
                          " has no active voxels; expected a non-empty density grid");
  }
  // world bounds of the active voxels (corners +- half a voxel through the transform)
  const openvdb::math::Transform& xf = grid->transform();
  Eigen::Vector3d wmin = Eigen::Vector3d::Constant(1e300), wmax = -wmin;
  for (int c = 0; c < 8; ++c) {
    const openvdb::Vec3d idx((c & 1) ? bbox.max().x() + 0.5 : bbox.min().x() - 0.5,
                             (c & 2) ? bbox.max().y() + 0.5 : bbox.min().y() - 0.5,
                             (c & 4) ? bbox.max().z() + 0.5 : bbox.min().z() - 0.5);
    const openvdb::Vec3d w = xf.indexToWorld(idx);
    for (int a = 0; a < 3; ++a) {
      wmin[a] = std::min(wmin[a], w[a]);
      wmax[a] = std::max(wmax[a], w[a]);
    }
  }
  const openvdb::Coord dim = bbox.dim();
  const int max_dim = std::max({dim.x(), dim.y(), dim.z()});
  const double scale = std::min(1.0, static_cast<double>(p.max_resolution) / max_dim);
  GridMedium g;
  g.nx = std::max(1, static_cast<int>(std::lround(dim.x() * scale)));
  g.ny = std::max(1, static_cast<int>(std::lround(dim.y() * scale)));
  g.nz = std::max(1, static_cast<int>(std::lround(dim.z() * scale)));
  const Eigen::Vector3d bmin = region ? region->min_W : wmin;
  const Eigen::Vector3d bmax = region ? region->max_W : wmax;
  const Eigen::Vector3d bext = bmax - bmin, wext = wmax - wmin;
  auto density = std::make_shared<std::vector<float>>(static_cast<size_t>(g.nx) * g.ny * g.nz);
  float max_density = 0;
  openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Eigen::Vector3d f((i + 0.5) / g.nx, (j + 0.5) / g.ny, (k + 0.5) / g.nz);
        const Eigen::Vector3d w = wmin + f.cwiseProduct(wext);
        const openvdb::Vec3d idx = xf.worldToIndex(openvdb::Vec3d(w.x(), w.y(), w.z()));
        const float d = std::max(0.0f, openvdb::tools::BoxSampler::sample(acc, idx));
        (*density)[(static_cast<size_t>(k) * g.ny + j) * g.nx + i] = d;
        max_density = std::max(max_density, d);
      }
  g.X_WG = Pose::Identity();
  g.X_WG.translation() = 0.5 * (bmin + bmax);
  g.half_extents_m = 0.5 * bext;
  g.density = std::move(density);
  g.max_density = max_density;
  g.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(p.density_scale_per_m));
  g.albedo = p.albedo.cast<float>();
  g.g = static_cast<float>(p.g);
  return g;
}

}  // namespace penumbra
