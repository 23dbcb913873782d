#include "penumbra/app/heightfield_tool.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "penumbra/assets/height_field_model.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/text_match.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/geometry/height_field_sampling.h"
#include "penumbra/render/geometry/static_geometry.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool MatchesAny(const std::vector<std::string>& globs, const std::string& name, bool fold_case) {
  for (const std::string& g : globs)
    if (fold_case ? GlobMatch(Lower(g), Lower(name)) : GlobMatch(g, name)) return true;
  return false;
}

}  // namespace

const std::vector<std::string>& GroundGeomGlobs() {
  static const std::vector<std::string> globs = {"*floor*", "*ground*", "*terrain*"};
  return globs;
}

SceneDescription HeightFieldGeoms(const SceneDescription& statics,
                                  const std::vector<std::string>& world_models,
                                  const HeightFieldOptions& o) {
  if (o.all && (!o.model.empty() || !o.geoms.empty()))
    throw ConfigError("", 0, "--all",
                      "--all samples every static geom; expected it without --model or --geoms");
  if (!o.model.empty() &&
      std::find(world_models.begin(), world_models.end(), o.model) == world_models.end())
    throw ConfigError("", 0, "--model",
                      "no model '" + o.model + "' in the world; expected one of: " +
                          fmt::format("{}", fmt::join(world_models, ", ")));
  const bool ground = !o.all && o.model.empty() && o.geoms.empty();
  SceneDescription only = statics;
  only.geoms.clear();
  for (const Geom& g : statics.geoms) {
    bool take = true;
    if (ground) {
      take = g.shape == GeomShape::kPlane || g.shape == GeomShape::kHeightField ||
             MatchesAny(GroundGeomGlobs(), g.name, true);
    } else if (!o.all) {
      if (!o.model.empty()) take = g.name.rfind(o.model + "/", 0) == 0;
      if (!o.geoms.empty()) take = take && MatchesAny(o.geoms, g.name, false);
    }
    if (take) only.geoms.push_back(g);
  }
  if (!only.geoms.empty()) return only;
  if (ground)
    throw ConfigError(
        "", 0, "--geoms",
        fmt::format("the world has no ground to sample: by default the height field samples the "
                    "static planes, height fields and geoms named {} (not trees, rocks or "
                    "furniture); expected --model NAME, --geoms GLOB,... or --all",
                    fmt::join(GroundGeomGlobs(), ", ")));
  std::vector<std::string> names;
  for (const Geom& g : statics.geoms)
    if (names.size() < 20 && !g.name.empty()) names.push_back(g.name);
  throw ConfigError(
      "", 0, o.geoms.empty() ? "--model" : "--geoms",
      fmt::format(
          "no static geom {}{}; expected a selection that matches some of the world's "
          "static geoms (e.g. {})",
          o.model.empty() ? "" : "of model '" + o.model + "' ",
          o.geoms.empty() ? std::string() : fmt::format("matches {}", fmt::join(o.geoms, ", ")),
          names.empty() ? std::string("none has a name")
                        : fmt::format("{}", fmt::join(names, ", "))));
}

int RunHeightField(const HeightFieldOptions& o) {
  const WorldConfig world = LoadWorldFile(o.world_file);
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(world, so);
  const WorldSnapshot snap = session.sim().Snapshot();
  Eigen::Vector3d lo, hi;
  std::vector<std::string> models;
  for (const ModelConfig& m : world.models) models.push_back(m.name);
  SceneDescription statics =
      HeightFieldGeoms(StaticGeoms(session.scene(), snap.X_WB, &lo, &hi), models, o);
  StaticGeoms(statics, snap.X_WB, &lo, &hi);
  if (!(lo.x() <= hi.x()) && !o.extent)
    throw Error(
        "nothing with finite bounds to sample (only planes); expected --extent X0,Y0,X1,Y1");
  Eigen::Vector2d a = lo.head<2>(), b = hi.head<2>();
  if (o.extent) a = {(*o.extent)[0], (*o.extent)[1]}, b = {(*o.extent)[2], (*o.extent)[3]};
  const std::unique_ptr<RayQuery> query = MakeRayQuery(statics, world.render.backend);
  query->Update(snap);
  // planes only: their own height bounds the rays
  if (!(lo.z() <= hi.z())) {
    lo.z() = hi.z() = 0;
    for (const Geom& g : statics.geoms) {
      const double z = snap.X_WB[g.body].translation().z() + g.X_BG.translation().z();
      lo.z() = std::min(lo.z(), z), hi.z() = std::max(hi.z(), z);
    }
  }
  const double z_top = hi.z() + 1;
  const SampledHeightField field = SampleHeightField(*query, a, b, o.cell_m, z_top, lo.z());
  const HeightFieldError err = ErrorAtCellCentres(*query, field, z_top);

  const std::string name = !o.name.empty() ? o.name : !o.model.empty() ? o.model : "terrain";
  std::filesystem::create_directories(o.out_dir);
  const std::filesystem::path dir = std::filesystem::absolute(o.out_dir);
  const std::string hfield = (dir / (name + ".hfield")).string();
  WriteFileAtomic(hfield, HfieldFileBytes(field));
  const std::string xml = (dir / (name + ".xml")).string();
  WriteFileAtomic(xml, HeightFieldMjcf(name, field, hfield, o.base_m, {0.45, 0.42, 0.35}));
  const auto [zmin, zmax] = std::minmax_element(field.z.begin(), field.z.end());
  std::vector<std::string> sampled;
  for (const Geom& g : statics.geoms) sampled.push_back(g.name.empty() ? "(unnamed)" : g.name);
  if (sampled.size() > 12) {
    const size_t more = sampled.size() - 10;
    sampled.resize(10);
    sampled.push_back(fmt::format("and {} more", more));
  }
  fmt::print("sampled {} static geom(s): {}\n", statics.geoms.size(), fmt::join(sampled, ", "));
  fmt::print(
      "height field: {} x {} samples every {} m over x [{:.3f}, {:.3f}], y [{:.3f}, {:.3f}], z "
      "[{:.3f}, {:.3f}] m; {} rays missed\n"
      "error against the geometry at {} cell centres: max {:.4f} m, mean {:.4f} m\n"
      "wrote {} and {}\n",
      field.cols, field.rows, field.cell_m, field.x0, field.x0 + (field.cols - 1) * field.cell_m,
      field.y0, field.y0 + (field.rows - 1) * field.cell_m, *zmin, *zmax, field.misses, err.cells,
      err.max_m, err.mean_m, hfield, xml);
  return 0;
}

}  // namespace penumbra
