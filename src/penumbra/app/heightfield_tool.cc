#include "penumbra/app/heightfield_tool.h"

#include <fmt/format.h>

#include <filesystem>

#include "penumbra/assets/height_field_model.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/height_field_sampling.h"
#include "penumbra/render/static_geometry.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

int RunHeightField(const HeightFieldOptions& o) {
  const WorldConfig world = LoadWorldFile(o.world_file);
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(world, so);
  const WorldSnapshot snap = session.sim().Snapshot();
  Eigen::Vector3d lo, hi;
  SceneDescription statics = StaticGeoms(session.scene(), snap.X_WB, &lo, &hi);
  if (!o.model.empty()) {
    // only the model's geoms, and their bounds
    bool known = false;
    for (const ModelConfig& m : world.models) known = known || m.name == o.model;
    if (!known)
      throw ConfigError("", 0, "--model", "no model '" + o.model + "' in " + o.world_file);
    SceneDescription only = statics;
    only.geoms.clear();
    for (const Geom& g : statics.geoms)
      if (g.name.rfind(o.model + "/", 0) == 0) only.geoms.push_back(g);
    statics = std::move(only);
    StaticGeoms(statics, snap.X_WB, &lo, &hi);
  }
  if (statics.geoms.empty() || !(lo.x() <= hi.x()))
    throw Error("nothing to sample: no finite static geom" +
                (o.model.empty() ? std::string() : " of model '" + o.model + "'"));
  Eigen::Vector2d a = lo.head<2>(), b = hi.head<2>();
  if (o.extent) a = {(*o.extent)[0], (*o.extent)[1]}, b = {(*o.extent)[2], (*o.extent)[3]};
  const std::unique_ptr<RayQuery> query = MakeRayQuery(statics, world.render.backend);
  query->Update(snap);
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
